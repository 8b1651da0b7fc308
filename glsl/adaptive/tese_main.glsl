// The main of every adaptive TES; the including file defines
// `void evaluate(uint id, vec2 uv, out vec3 pos, out vec3 du, out vec3 dv)` for its patch kind
// (patch `id`). Only boundary vertices read the patch record (its curves). Points on the patch boundary come from the canonical curves instead (see
// adaptive.glsl), so shared edges are bit-identical; normals always come from the patch.
//
// The refinement-pattern path's vertex stages (pattern_*.vert) include it too: they define
// PATTERN_PATH, the globals tc_patch and tc_info, TESS_COORD (the pattern vertex's domain
// point), OUTER_LEVEL(i) (the drawn pattern's edge levels, in gl_TessLevelOuter's order),
// emit_sample, and pattern_begin(), which sets the globals and the patch's control points
// (what the control stage does on the tessellation path).
#include "normals.glsl"
#ifndef PATTERN_PATH
layout(location = 0) patch in uint tc_patch;
layout(location = 2) patch in uint tc_info;
#define TESS_COORD gl_TessCoord
#define OUTER_LEVEL(i) gl_TessLevelOuter[i]
#endif
#ifdef SURFACE_BUILD
// Only the surface build hands the fragment stage an albedo and a texture coordinate: each
// varying costs lavapipe's rasterizer on every triangle (docs/benchmarks.md, "varyings are
// frame time"); the plain build shades with frame.base_color.
layout(location = 5) out vec3 out_albedo;
layout(location = 6) out vec2 out_texcoord;
#endif
#include "surface.glsl"
#ifdef SURFACE_BUILD
#include "sine.glsl"
#endif
#ifdef PATCH_SHADING_NORMAL
// A patch kind whose shading normal is not cross(du, dv) defines this after including this
// file (gregory.tese: ACC-1 nets and their tangent patches); `n` is cross(du, dv)'s.
vec3 patch_shading_normal(uint id, vec2 uv, vec3 n);
#endif

// Regular, Gregory, bilinear, Gregory triangle.
const vec3 KIND_COLOURS[4] = vec3[4](vec3(0.45, 0.65, 0.95), vec3(0.95, 0.45, 0.35), vec3(0.95, 0.8, 0.3), vec3(0.75, 0.4, 0.85));

void main() {
#ifdef PATTERN_PATH
    pattern_begin();
#endif
    vec2 uv = TESS_COORD.xy;
#ifdef TRIANGLE_DOMAIN
    // TESS_COORD = (u, v, 1 - u - v): the weights of patch corners 1, 2, 0.
    float w0 = TESS_COORD.z;
    bool canonical = uv.x == 0.0 || uv.y == 0.0 || w0 == 0.0;
#else
    bool canonical = uv.x == 0.0 || uv.x == 1.0 || uv.y == 0.0 || uv.y == 1.0;
#endif
    AdaptivePatch p;
    if (canonical) p = PATCHES[tc_patch];
    // Patch edge e and the parameter along it (edges run v0 -> v1 -> v2 -> v3 -> v0);
    // 1 - x is exact for tess coordinates. Corners take either edge: both give the curve's end
    // point, the same global vertex.
    uint curve = 0u;
    float s = 0.0;
    // The edge and the parameter along it, then one call (one inlined copy: see below).
    uint e = 0u;
    float t = 0.0, tess_level = 1.0;
#ifdef TRIANGLE_DOMAIN
    // Every triangle edge is a transition edge (two level-1 halves): integer levels.
    if (uv.y == 0.0) {
        e = 0u; t = uv.x; tess_level = OUTER_LEVEL(1);
    } else if (w0 == 0.0) {
        e = 1u; t = uv.y; tess_level = OUTER_LEVEL(2);
    } else {
        e = 2u; t = w0; tess_level = OUTER_LEVEL(0);
    }
#else
    if (uv.y == 0.0) {
        e = 0u; t = uv.x; tess_level = OUTER_LEVEL(1);
    } else if (uv.x == 1.0) {
        e = 1u; t = uv.y; tess_level = OUTER_LEVEL(2);
    } else if (uv.y == 1.0) {
        e = 2u; t = 1.0 - uv.x; tess_level = OUTER_LEVEL(3);
    } else {
        e = 3u; t = 1.0 - uv.y; tess_level = OUTER_LEVEL(0);
    }
#endif
    // Geomorphing on the pattern path (pattern_patch.glsl) moves the point evaluated: a
    // boundary point along its canonical curve, an interior point inside the domain.
    float morph = 1.0;
#ifdef PATTERN_PATH
    bool morphing = geomorphing();
    if (morphing && canonical) morph = edge_morph(e);
    if (morphing && !canonical) uv = morph_inside(uv);
#endif
    vec3 edge_pos = vec3(0.0);
    if (canonical) {
        bool integer_level = !fractional_factors() || edge_kind(p, e) != ADAPTIVE_EDGE_PLAIN;
        float at;
        edge_pos = canonical_edge_point(p, e, t, tess_level, integer_level, morph, curve, s, at);
#ifdef PATTERN_PATH
        if (morph < 1.0) uv = edge_domain_point(e, at);
#endif
    }
#ifdef PATTERN_PATH
    tc_at = uv;
#endif
    vec3 pos, du, dv;
    evaluate(tc_patch, uv, pos, du, dv);
    if (canonical) pos = edge_pos;
    vec3 n = safe_normalize(cross(du, dv), vec3(0.0, 0.0, 1.0));
#ifdef PATCH_SHADING_NORMAL
    n = patch_shading_normal(tc_patch, uv, n);
#endif
    uint kind = tc_info & 15u, level = (tc_info >> 4) & 15u;
#ifdef SURFACE_BUILD
    // The surface build (Technique::surface_build): texture coordinates, displacement, owners'
    // normals, the parameter views, patch colours. The plain build leaves them out, a much
    // smaller TES with two varyings fewer.
    // The reparameterized parameter, for the shift view (the texture coordinate is the loop's
    // below).
    PatchSurface own_surface = SURFACES[tc_patch];
    bool show_shift = (adaptive.options & uint(ADAPTIVE_OPTION_SHOW_PARAM_SHIFT)) != 0u;
    vec2 st = (reparam_on() || show_shift) ? reparameterize(own_surface.reparam_rows, uv) : uv;
    // A boundary point is displaced by its curve's owner (normal and height), so both sides of
    // every edge move it identically; with ADAPTIVE_OPTION_CANONICAL_NORMALS (single-pass
    // methods) it is shaded in the owner's frame too. Each heavy function below has one call
    // site: lavapipe compiles every inlined copy into the TES, and a second copy of the owner
    // evaluation made every adaptive frame 1.5x slower even where it never ran.
    bool displace = (adaptive.options & uint(ADAPTIVE_OPTION_DISPLACE)) != 0u;
    bool sine = frame.sine.x != 0.0;
    bool owner_shading = canonical && (adaptive.options & uint(ADAPTIVE_OPTION_CANONICAL_NORMALS)) != 0u;
    uint oid = tc_patch;
    vec2 ouv = uv;
    vec3 on = n, odu = du, odv = dv;
    if (canonical && (displace || sine || owner_shading)) {
        canonical_owner(curve, s, oid, ouv);
        owner_frame(oid, ouv, on, odu, odv);
    }
    // Shaded in this frame: the owner's with canonical normals, else the patch's own.
    uint sid = owner_shading ? oid : tc_patch;
    vec2 suv = owner_shading ? ouv : uv;
    const float h = 1.0 / 1024.0;
    vec2 lo = max(suv - vec2(h), vec2(0.0)), hi = min(suv + vec2(h), vec2(1.0));
    // The patch's own texture coordinate and, displacing, five heights, in one loop that stays
    // a loop (one inlined texture-coordinate look-up, the face-varying descent of fvar.glsl
    // included: a second copy made lavapipe's textured frames 2x slower): the own coordinate,
    // then where the point moves (its owner's on a boundary), then around the shading point for
    // the displaced normal's slope.
    uint ids[6] = uint[6](tc_patch, oid, sid, sid, sid, sid);
    vec2 at[6] = vec2[6](uv, ouv, vec2(hi.x, suv.y), vec2(lo.x, suv.y), vec2(suv.x, hi.y), vec2(suv.x, lo.y));
    float height[6];
    vec2 tex = vec2(0.0);
    int looks = displace ? 6 : 1;
    [[dont_unroll]] for (int k = 0; k < looks; ++k) {
        vec2 t = patch_texcoord(ids[k], at[k]);
        if (k == 0) tex = t; else height[k] = surface_height(t);
    }
    out_texcoord = tex;
    // The seed's a sin(f |P|) moves a boundary point along its owner's normal too, so both
    // sides of an edge move it to the same bits; after the height map, along the same normal.
    vec3 moving = canonical ? on : n;
    if (displace) {
        vec3 sn = owner_shading ? on : n, sdu = owner_shading ? odu : du, sdv = owner_shading ? odv : dv;
        precise vec3 moved = pos + (canonical ? on : n) * (adaptive.displace_scale * height[1]);
        pos = moved;
        // Shade the displaced surface, not the base one (positions above are already final).
        n = displaced_normal(sn, sdu, sdv, (height[2] - height[3]) / (hi.x - lo.x), (height[4] - height[5]) / (hi.y - lo.y));
    } else if (owner_shading) {
        n = on;
    }
    pos = displace_sine(pos, moving);
    vec3 albedo = frame.base_color.rgb;
    if (show_shift) {
        // How far the reparameterization moves the texture parameter, in patch units: 0 blue,
        // 0.05 and beyond red.
        float shift = clamp(length(st - uv) / 0.05, 0.0, 1.0);
        albedo = mix(vec3(0.2, 0.35, 0.9), vec3(0.95, 0.25, 0.15), shift);
    } else if ((adaptive.options & uint(ADAPTIVE_OPTION_SHOW_PARAM_ERROR)) != 0u) {
        albedo = param_error_colour(param_error(tc_patch, uv));
    } else if ((adaptive.options & uint(ADAPTIVE_OPTION_PATCH_COLOURS)) != 0u) {
        // Odd levels lighter, even levels darker, a little lighter with depth: adjacent
        // levels always differ.
        albedo = KIND_COLOURS[min(kind, 3u)] * ((level & 1u) == 1u ? 1.0 : 0.62);
        albedo = mix(albedo, vec3(1.0), 0.05 * float(level));
        // Transition patches (a finer neighbour) darker, boundary / crease patches greener.
        if (((tc_info >> 12) & 15u) != 0u) albedo *= 0.7;
        if (((tc_info >> 8) & 15u) != 0u) albedo = mix(albedo, vec3(0.3, 0.8, 0.35), 0.5);
    }
    out_albedo = albedo;
#endif
    emit_sample(pos, n, tc_patch,
                kind | (level << ADAPTIVE_FLAG_LEVEL_SHIFT) | (canonical ? uint(ADAPTIVE_FLAG_CANONICAL) : 0u));
}
