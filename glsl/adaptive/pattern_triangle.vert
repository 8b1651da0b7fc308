#version 450
#extension GL_EXT_control_flow_attributes : require
// Gregory triangle patches on the refinement-pattern path (pattern_patch.glsl): the 15 points
// triangle.tesc fetches, then triangle.tese's evaluation at the pattern vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#define TRIANGLE_DOMAIN
#include "frame.glsl"
#include "adaptive.glsl"
#include "pattern_patch.glsl"
vec3 tc_points[15];

void pattern_begin() {
    AdaptivePatch p = begin_patch();
    for (uint k = 0u; k < 15u; ++k) tc_points[k] = vtx(CONTROL_POINTS[p.cp_offset + k]);
}

#include "triangle_eval.glsl"
#include "tese_main.glsl"
