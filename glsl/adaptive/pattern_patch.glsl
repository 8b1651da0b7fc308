// The planned patches' refinement-pattern path (tess::techniques::planned_patches, crate::pattern):
// a vertex stage that evaluates the instance's patch at the pattern vertex with the evaluation
// stage's own code (tese_main.glsl). Vertex inputs (tess::gpu::pattern_input::PATCH_IDS): the
// pattern vertex's domain point at location 0 ((u, v, 1 - u - v) on triangles, (u, v, 0) on
// quads) and, per instance, the frame-wide id of the patch drawn at location 1. Each draw is
// one pattern, keyed by the patches' edge levels (adaptive.pattern_outer): a canonical vertex
// finds its index along the edge from them as the evaluation stage does from
// gl_TessLevelOuter.
//
// Geomorphing (ADAPTIVE_OPTION_GEOMORPH): the instance also carries its morph weights, unorm16
// pairs (edges 0, 1; edges 2, 3; the inside along u, v). A pattern of power-of-two levels drawn
// at weight w puts each odd vertex (odd on its edge, or odd along u or v inside) the fraction
// 1 - w of the way to the even vertex below it, which the pattern of half the level also has:
// at w = 0 the pattern draws its half-level pattern's surface (its cells collapse onto the
// coarser cells, split along the same diagonal), at w = 1 its own. The patch is evaluated at
// the moved domain point, so every vertex stays on the surface, and the capture records that
// point.
#define PATTERN_PATH
#include "stage_out.glsl"
#include "morph.glsl"
layout(location = 0) in vec3 in_domain;
layout(location = 1) in uvec4 in_patch;
uint tc_patch;
uint tc_info;
// Where the patch was evaluated (the pattern vertex's domain point, moved when morphing).
vec2 tc_at;
#define TESS_COORD in_domain
#define OUTER_LEVEL(i) adaptive.pattern_outer[i]

void emit_sample(vec3 p, vec3 n, uint patch_id, uint flags) {
    emit_vertex_at(p, n, patch_id, flags, tc_at);
}

bool geomorphing() { return (adaptive.options & uint(ADAPTIVE_OPTION_GEOMORPH)) != 0u; }

// The morph weight of patch edge e.
float edge_morph(uint e) {
    uint word = e < 2u ? in_patch.y : in_patch.z;
    return unpackUnorm2x16(word)[e & 1u];
}

// An interior pattern vertex at uv moved by the inside's weights (see above): the inner
// levels are the larger of each facing pair of edge levels, as the pattern's key sets them.
// On quads an odd lattice index k slides to k - 1, but the first (k = 1, beside the strip
// along a patch edge) to 2: the lattice of half the level starts there, its strip covering
// what the finer strip and first column do. On triangles, the rule of glsl/common/morph.glsl.
vec2 morph_inside(vec2 uv) {
#ifdef TRIANGLE_DOMAIN
    float n = max(OUTER_LEVEL(0), max(OUTER_LEVEL(1), OUTER_LEVEL(2)));
    return morph_triangle_inside(uv, n, unpackUnorm2x16(in_patch.w).x);
#else
    vec2 levels = vec2(max(OUTER_LEVEL(1), OUTER_LEVEL(3)), max(OUTER_LEVEL(0), OUTER_LEVEL(2)));
    vec2 w = unpackUnorm2x16(in_patch.w);
    vec2 k = round(uv * levels);
    vec2 first = step(k, vec2(1.0)) * step(vec2(3.0), levels);
    vec2 below = mix(k - 1.0, vec2(2.0), first);
    vec2 odd = mod(k, 2.0);
    return uv + odd * (1.0 - w) * (mix(k, below, odd) / levels - uv);
#endif
}

// The point at parameter a along patch edge e (tese_main.glsl's edge numbering).
vec2 edge_domain_point(uint e, float a) {
#ifdef TRIANGLE_DOMAIN
    return e == 0u ? vec2(a, 0.0) : (e == 1u ? vec2(1.0 - a, a) : vec2(0.0, 1.0 - a));
#else
    return e == 0u ? vec2(a, 0.0) : (e == 1u ? vec2(1.0, a) : (e == 2u ? vec2(1.0 - a, 1.0) : vec2(0.0, 1.0 - a)));
#endif
}

// The patch record's part of pattern_begin: what every control stage hands the evaluation
// stage besides the points.
AdaptivePatch begin_patch() {
    tc_patch = in_patch.x;
    AdaptivePatch p = PATCHES[tc_patch];
    tc_info = p.info;
    return p;
}
