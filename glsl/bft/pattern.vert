#version 450
// Loop limit surface by basis-function tables on the refinement-pattern path: one instance of
// a pattern per level-1 face, bft_eval (bft.glsl, the evaluation stage's function) at the
// pattern vertex's barycentric domain point. Patterns come at power-of-two edge levels in equal
// spacing, so every pattern vertex is a table point (SPACING_EQUAL: the exact path only).
// Rows are read from the global buffers (no control stage gathers a patch block).
//
// Vertex inputs (tess::gpu::pattern_input::PATCH_IDS): the domain point at location 0 and, per
// instance, the level-1 face at location 1 (x), with its morph weights as unorm16 pairs: y
// (edges 0 and 1), z (edge 2), w (the inside), in bft_locate's edge numbering (edge e runs
// v_e -> v_(e+1)).
//
// The GEOMORPH build (fractional-even spacing on this path) slides each odd vertex toward the
// even one the pattern of half the level keeps, by 1 - weight, and evaluates the surface at the
// moved point (on the level-L virtual mesh between table points, as the evaluation stage's
// fractional factors do). An edge vertex slides along its owner's edge, counted in the owner's
// direction, so both faces of the edge move it to the same bits; an inside vertex by the rule
// of the planned patches' triangles (glsl/common/morph.glsl). At weight 0 the pattern draws
// the surface of its half level, at 1 its own. The capture records the moved point.
// Built with and without capture and the surface code (glsl/manifest.toml; stage_out.glsl).
#extension GL_EXT_control_flow_attributes : require
#define TECHNIQUE_PUSH_CONSTANTS
#define BFT_PATCH_LOCAL
#ifndef GEOMORPH
#define SPACING_EQUAL
#endif
#include "frame.glsl"
#include "bft.glsl"
#include "stage_out.glsl"
#include "normals.glsl"
#include "morph.glsl"
#ifdef SURFACE_BUILD
#include "sine.glsl"
#endif
layout(location = 0) in vec3 in_domain;
layout(location = 1) in uvec4 in_patch;
#ifdef SURFACE_BUILD
layout(location = 5) flat out vec3 out_albedo;
#endif

// Regular, extraordinary, boundary, private-table patches (as bft.tese).
const vec3 KIND_COLOURS[4] = vec3[4](vec3(0.55, 0.75, 0.95), vec3(0.95, 0.45, 0.35), vec3(0.55, 0.85, 0.45), vec3(0.75, 0.5, 0.9));

#ifdef GEOMORPH
// The level of edge e (edge 0 = v0v1 is gl_TessLevelOuter[2], 1 = v1v2 is [0], 2 = v2v0 is [1]).
float edge_level(int e) { return bft.pattern_outer[e == 0 ? 2 : (e == 1 ? 0 : 1)]; }

float edge_morph(int e) { return unpackUnorm2x16(e < 2 ? in_patch.y : in_patch.z)[e & 1]; }

// Owner-frame parameter t of an edge vertex moved by the edge's weight: an odd index slides
// toward the owner's edge start.
float morph_edge(int e, float t) {
    float n = edge_level(e), w = edge_morph(e);
    float k = round(t * n);
    return (w < 1.0 && mod(k, 2.0) == 1.0) ? t - (1.0 - w) / n : t;
}

// An inside vertex at uv (weights of v1, v2) moved by the inside's weight (morph.glsl).
vec2 morph_inside(vec2 uv) {
    float n = max(bft.pattern_outer[0], max(bft.pattern_outer[1], bft.pattern_outer[2]));
    return morph_triangle_inside(uv, n, unpackUnorm2x16(in_patch.w).x);
}

// The surface at pattern point b of `face`, moved by the instance's weights; `at` the moved
// point as b.xy (weights of v0, v1) in the face's frame.
bool morph_eval(uint face, vec3 b, bool geometric, out vec3 p, out vec3 n, out vec2 at) {
    uint g;
    vec2 uv;
    int corner, edge;
    float t;
    bft_locate(face, b, g, uv, corner, edge, t);
    at = b.xy;
    if (corner >= 0) return bft_eval_at(g, false, uv, geometric, p, n);
    if (edge >= 0) {
        float moved = morph_edge(edge, t);
        float own = g == face ? moved : 1.0 - moved;
        at = edge == 0 ? vec2(1.0 - own, own) : (edge == 1 ? vec2(0.0, 1.0 - own) : vec2(own, 0.0));
        uint ge = owner_local(PATCH(face).edge_owner[edge]);
        return bft_eval_at(g, false, bft_edge_point(ge, moved), geometric, p, n);
    }
    vec2 m = morph_inside(b.yz);
    at = vec2(1.0 - m.x - m.y, m.x);
    return bft_eval(face, vec3(at, m.y), geometric, p, n);
}
#endif

void main() {
    uint face = in_patch.x;
    tc_head = uvec4(face, 0u, 0u, 0u);
    bool geometric = (bft.options & uint(BFT_OPTION_GEOMETRIC_NORMALS)) != 0u;
    vec3 p, n;
#ifdef GEOMORPH
    vec2 at;
    bool exact = morph_eval(face, in_domain, geometric, p, n, at);
#else
    vec2 at = in_domain.xy;
    bool exact = bft_eval(face, in_domain, geometric, p, n);
#endif
    uint kind = table_entries[PATCH(face).entry].kind;
#ifdef SURFACE_BUILD
    out_albedo = (bft.options & uint(BFT_OPTION_PATCH_COLOURS)) != 0u ? KIND_COLOURS[min(kind, 3u)] : frame.base_color.rgb;
    p = displace_sine(p, n);
#endif
    emit_vertex_at(p, safe_normalize(n, vec3(0.0)), face,
        (exact ? uint(CAPTURE_FLAG_EXACT) : 0u) | (kind << CAPTURE_FLAG_KIND_SHIFT), at);
}
