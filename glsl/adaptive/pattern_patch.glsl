// The planned patches' refinement-pattern path (tess::techniques::planned_patches, crate::pattern):
// a vertex stage that evaluates the instance's patch at the pattern vertex with the evaluation
// stage's own code (tese_main.glsl). Vertex inputs (tess::gpu::pattern_input::PATCH_IDS): the
// pattern vertex's domain point at location 0 ((u, v, 1 - u - v) on triangles, (u, v, 0) on
// quads) and, per instance, the frame-wide id of the patch drawn at location 1. Each draw is
// one pattern, keyed by the patches' edge levels (adaptive.pattern_outer): a canonical vertex
// finds its index along the edge from them as the evaluation stage does from
// gl_TessLevelOuter.
#define PATTERN_PATH
#include "stage_out.glsl"
layout(location = 0) in vec3 in_domain;
layout(location = 1) in uint in_patch;
uint tc_patch;
uint tc_info;
#define TESS_COORD in_domain
#define OUTER_LEVEL(i) adaptive.pattern_outer[i]

void emit_sample(vec3 p, vec3 n, uint patch_id, uint flags) {
    emit_vertex_at(p, n, patch_id, flags, in_domain.xy);
}

// The patch record's part of pattern_begin: what every control stage hands the evaluation
// stage besides the points.
AdaptivePatch begin_patch() {
    tc_patch = in_patch;
    AdaptivePatch p = PATCHES[tc_patch];
    tc_info = p.info;
    return p;
}
