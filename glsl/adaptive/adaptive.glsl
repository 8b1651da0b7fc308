// Catmull-Clark patch plans (adaptive, gregory, acc; crates/tess/src/techniques/planned_patches):
// the arrays, push constants and the evaluation every stage shares. Mirrors
// `tess::techniques::planned_patches::layout` (offsets checked against the SPIR-V by a test).
//
// Every array is read through a buffer reference (GL_EXT_buffer_reference) at the device
// address the uniform block `AdaptiveArrays` holds, not through a descriptor: no
// `maxStorageBufferRange` limits them, so a plan is drawn whatever its size, as long as it
// fits in device memory. `VERTICES[i]`, `PATCHES[i]`, ... name them as arrays.
//
// Watertightness by canonical curves: every patch boundary edge is one cubic Bezier curve of
// the global vertex buffer (computed once per frame by the canonical kernel, from one owner
// patch). A TES vertex on a patch boundary is evaluated from that curve, at a parameter both
// sides of the edge derive identically (from the vertex's index along the edge when the
// factor is an integer, else from the mirrored tess coordinate), with `precise` arithmetic in
// one fixed operand order. So the two sides produce the same bits, across level transitions
// and end caps too.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "bindings.glsl"

struct AdaptivePatch {
    uint cp_offset;   // first control-point index in CONTROL_POINTS[]
    uint info;        // kind | level << 4 | boundary mask << 8 | transition mask << 12
    uint edge_info;   // per edge i, 4 bits at 4i: kind (2 bits), reversed[0], reversed[1]
    uint pad;
    uint curves[8];   // edge i: curves[2i], curves[2i + 1]
};

#ifdef ADAPTIVE_WRITES_VERTICES
layout(buffer_reference, std430, buffer_reference_align = 16) buffer VertexArray { vec4 v[]; };
#else
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer VertexArray { vec4 v[]; };
#endif
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer PatchArray { AdaptivePatch v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ControlPointArray { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer CurveArray { uvec4 v[]; };

// Texture coordinates (topology::texcoord): per patch, the coordinates at its corners and each
// corner's row of the reparameterization table; per curve, the patch that defines its normals
// and coordinates for both sides (seamless displacement).
struct PatchSurface {
    vec2 uv[4];         // corners (0,0), (1,0), (1,1), (0,1)
    uint reparam_rows;  // 8 bits per corner: row of reparam_rows[] (0 = identity)
    uint tangent_valences; // ACC-1: 8 bits per corner, its valence (tangent patches); else 0
    uint fvar_root;     // smooth texture coordinates: root entry in FVAR, uv[] then the (sub-)face
                        // parameter; FVAR_EMPTY (fvar.glsl): uv[] are the texture coordinates
    uint pad;
};
struct CurveOwner {
    uint patch_id;      // frame-wide patch id
    uint info;          // edge | part << 2 | forward << 4
};
struct ReparamRow {
    vec4 a;             // c0, c1, c2, c3
    vec4 b;             // c4
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SurfaceArray { PatchSurface v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer ReparamArray { ReparamRow v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer CurveOwnerArray { CurveOwner v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer CornerOwnerArray { uvec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ParamErrorArray { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer FVarArray { uint v[]; };

// The arrays' device addresses (`tess::gpu::AdaptiveArrays`; each a uvec2, low word first).
layout(std140, set = ADAPTIVE_SET, binding = ADAPTIVE_ARRAYS_BINDING) uniform AdaptiveArrays {
    uvec2 vertices;        // vec4 per global vertex: base, levels, local points, canonical points
    uvec2 patches;         // one AdaptivePatch per patch, frame-wide order
    uvec2 control_points;  // global vertex indices of every patch, back to back
    uvec2 curves;          // canonical boundary curves, four global vertices each
    uvec2 surfaces;        // PatchSurface per patch
    uvec2 reparam;         // ReparamRow: row 0 the identity, row v - 2 valence v
    uvec2 curve_owners;    // CurveOwner per canonical curve
    uvec2 corner_owners;   // uvec2(patch, corner) per canonical corner (global vertex - first_corner)
    uvec2 param_errors;    // the Eq. 1 error lattice per patch
    uint param_error_count; // its entries (0: not built)
    uint fvar_count;       // words of the face-varying patches
    uvec2 fvar;            // the face-varying patches (fvar.glsl)
} arrays;
#define VERTICES VertexArray(arrays.vertices).v
#define PATCHES PatchArray(arrays.patches).v
#define CONTROL_POINTS ControlPointArray(arrays.control_points).v
#define CURVES CurveArray(arrays.curves).v
#define SURFACES SurfaceArray(arrays.surfaces).v
#define REPARAM_TABLE ReparamArray(arrays.reparam).v
#define CURVE_OWNERS CurveOwnerArray(arrays.curve_owners).v
#define CORNER_OWNERS CornerOwnerArray(arrays.corner_owners).v
#define PARAM_ERRORS ParamErrorArray(arrays.param_errors).v
#define FVAR FVarArray(arrays.fvar).v
layout(set = ADAPTIVE_SET, binding = ADAPTIVE_TEXTURE_BINDING) uniform sampler2D surface_texture;
layout(set = ADAPTIVE_SET, binding = ADAPTIVE_HEIGHT_BINDING) uniform sampler2D height_map;

// Push constant of every adaptive pipeline (`tess::gpu::AdaptivePush`).
layout(push_constant) uniform AdaptivePush {
    uint mode;             // DRAW_MODE_SHADED or DRAW_MODE_WIREFRAME
    uint first_patch;      // frame-wide id of the array's first patch
    uint factor_mode;      // BFT_FACTORS_UNIFORM, _SCREEN or _DISTANCE
    uint options;          // ADAPTIVE_OPTION_* bits
    float uniform_level;   // segments per patch edge (uniform mode)
    float pixels_per_segment;
    float distance_ref;    // distance at which an edge gets max_level segments
    float max_level;       // the device's maximum tessellation level
    uint first_item;       // canonical kernel: first regular corner or curve point of this dispatch
    uint count;            // canonical kernel: items in this dispatch
    float displace_scale;  // displacement along the normal per unit of height
    uint first_corner;     // global id of the first canonical corner (CORNER_OWNERS[0])
    vec4 pattern_outer;    // pattern path: the drawn pattern's edge levels (gl_TessLevelOuter's order)
} adaptive;

uint patch_kind(AdaptivePatch p) { return p.info & 15u; }
uint patch_level(AdaptivePatch p) { return (p.info >> 4) & 15u; }
uint edge_kind(AdaptivePatch p, uint e) { return (p.edge_info >> (4u * e)) & 3u; }
bool edge_reversed(AdaptivePatch p, uint e, uint half_) { return ((p.edge_info >> (4u * e + 2u + half_)) & 1u) != 0u; }

vec3 vtx(uint i) { return VERTICES[i].xyz; }

// The canonical curve evaluation: one formula, one operand order, `precise`, so every patch
// that reads a curve at the same parameter gets the same bits. s = 0 and s = 1 give the end
// points exactly (the weights are exactly 1, 0, 0, 0).
vec3 curve_point(uint c, float s) {
    uvec4 b = CURVES[c];
    precise float r = 1.0 - s;
    precise float w0 = r * r * r;
    precise float w1 = 3.0 * s * r * r;
    precise float w2 = 3.0 * s * s * r;
    precise float w3 = s * s * s;
    precise vec3 p = w0 * vtx(b.x) + w1 * vtx(b.y) + w2 * vtx(b.z) + w3 * vtx(b.w);
    return p;
}

// Where patch edge e is at parameter t along the patch's edge direction (e runs v_e -> v_e+1),
// for interior blends (not canonical).
vec3 edge_point(AdaptivePatch p, uint e, float t) {
    uint kind = edge_kind(p, e);
    uint h = 0u;
    float s = t;
    if (kind == ADAPTIVE_EDGE_COARSE) {
        h = t < 0.5 ? 0u : 1u;
        s = h == 0u ? 2.0 * t : 2.0 * t - 1.0;
    }
    if (edge_reversed(p, e, h)) s = 1.0 - s;
    return curve_point(p.curves[2u * e + h], s);
}

// The canonical boundary point of patch edge e at parameter t (as above) with the edge's
// tessellation level n: integer levels name the vertex k = round(t n) and both sides evaluate
// k / n on the curve in its own direction; fractional levels mirror t exactly (1 - t is exact
// for tess coordinates). `morph` is the edge's geomorph weight (1: none; the pattern path's
// fractional-even spacing): an odd vertex k, counted in the curve's direction, slides toward
// k - 1 by 1 - morph, to the even vertex the level below keeps, so both sides slide it alike.
// `at` is the point as a parameter along the patch's own edge.
vec3 canonical_edge_point(AdaptivePatch p, uint e, float t, float n, bool integer_level, float morph, out uint curve, out float s, out float at) {
    uint kind = edge_kind(p, e);
    at = t;
    if (!integer_level) {
        bool rev = edge_reversed(p, e, 0u);
        curve = p.curves[2u * e];
        s = rev ? 1.0 - t : t;
        return curve_point(curve, s);
    }
    uint own = uint(round(t * n));
    uint k = own;
    uint segs = uint(round(n));
    uint h = 0u;
    if (kind == ADAPTIVE_EDGE_COARSE) {
        segs /= 2u;
        if (k > segs) { h = 1u; k -= segs; }
    }
    bool rev = edge_reversed(p, e, h);
    if (rev) k = segs - k;
    curve = p.curves[2u * e + h];
    float kf = float(k);
    if (morph < 1.0 && (k & 1u) == 1u) {
        float d = 1.0 - morph;
        kf -= d;
        at = (float(own) + (rev ? d : -d)) / n;
    }
    s = kf / float(segs);
    return curve_point(curve, s);
}

// The factor one curve asks for under the frame's policy: computed from the curve's own four
// points (data both sides of an edge share), in the curve's order.
float curve_factor(uint c) {
    uvec4 b = CURVES[c];
    vec3 p0 = vtx(b.x), p1 = vtx(b.y), p2 = vtx(b.z), p3 = vtx(b.w);
    float f;
    if (adaptive.factor_mode == BFT_FACTORS_SCREEN) {
        vec4 c0 = frame.view_proj * vec4(p0, 1.0), c1 = frame.view_proj * vec4(p1, 1.0);
        vec4 c2 = frame.view_proj * vec4(p2, 1.0), c3 = frame.view_proj * vec4(p3, 1.0);
        if (min(min(c0.w, c1.w), min(c2.w, c3.w)) <= 1e-6) {
            f = adaptive.max_level; // crosses the eye plane: no screen length, refine fully
        } else {
            vec2 h = 0.5 * frame.viewport.xy;
            vec2 s0 = c0.xy / c0.w * h, s1 = c1.xy / c1.w * h, s2 = c2.xy / c2.w * h, s3 = c3.xy / c3.w * h;
            // The control polygon bounds the curve's length.
            f = (distance(s0, s1) + distance(s1, s2) + distance(s2, s3)) / adaptive.pixels_per_segment;
        }
    } else if (adaptive.factor_mode == BFT_FACTORS_DISTANCE) {
        float d = distance(frame.camera_pos.xyz, 0.5 * (p0 + p3));
        f = adaptive.max_level * adaptive.distance_ref / max(d, 1e-6);
    } else {
        f = adaptive.uniform_level;
    }
    return f;
}

bool fractional_factors() { return (adaptive.options & uint(ADAPTIVE_OPTION_FRACTIONAL)) != 0u; }

// Level of patch edge e. Transition edges (both halves and the coarse side) take F from both
// half curves (max is symmetric), F an integer (even when fractional) so the coarse side's
// 2F puts a vertex at every fine vertex; the coarse side doubles it.
float edge_level(AdaptivePatch p, uint e) {
    uint kind = edge_kind(p, e);
    float lim = adaptive.max_level;
    if (kind == ADAPTIVE_EDGE_PLAIN) {
        float f = curve_factor(p.curves[2u * e]);
        if (fractional_factors()) return clamp(f, 2.0, lim);
        f = clamp(f, 1.0, lim);
        if ((adaptive.options & uint(ADAPTIVE_OPTION_POW2)) != 0u) f = exp2(ceil(log2(f) - 1e-4));
        return min(ceil(f), lim);
    }
    float f = max(curve_factor(p.curves[2u * e]), curve_factor(p.curves[2u * e + 1u]));
    float half_lim = floor(lim * 0.5);
    if (fractional_factors()) {
        f = 2.0 * ceil(clamp(f, 2.0, half_lim) * 0.5);
    } else {
        f = clamp(f, 1.0, half_lim);
        if ((adaptive.options & uint(ADAPTIVE_OPTION_POW2)) != 0u) f = exp2(ceil(log2(f) - 1e-4));
        f = min(ceil(f), half_lim);
    }
    return kind == ADAPTIVE_EDGE_COARSE ? 2.0 * f : f;
}
