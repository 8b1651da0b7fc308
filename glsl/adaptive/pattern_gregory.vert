#version 450
#extension GL_EXT_control_flow_attributes : require
// Gregory end caps and ACC-1 nets on the refinement-pattern path (pattern_patch.glsl): the 20
// points gregory.tesc fetches, then gregory.tese's evaluation at the pattern vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#ifdef SURFACE_BUILD
#define PATCH_SHADING_NORMAL
#endif
#include "frame.glsl"
#include "adaptive.glsl"
#include "pattern_patch.glsl"
vec3 tc_points[20];

void pattern_begin() {
    AdaptivePatch p = begin_patch();
    for (uint k = 0u; k < 20u; ++k) tc_points[k] = vtx(CONTROL_POINTS[p.cp_offset + k]);
}

#include "gregory_eval.glsl"
#include "tese_main.glsl"
#include "gregory_normal.glsl"
