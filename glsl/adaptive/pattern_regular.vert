#version 450
#extension GL_EXT_control_flow_attributes : require
// Regular patches on the refinement-pattern path (pattern_patch.glsl): the Bezier net of
// regular.tesc, then regular.tese's evaluation at the pattern vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "pattern_patch.glsl"
#include "regular_net.glsl"
vec3 tc_bezier[16];

void pattern_begin() {
    vec3 cp[16];
    bspline_points(begin_patch(), cp);
    for (uint k = 0u; k < 16u; ++k) tc_bezier[k] = bezier_point(cp, k);
}

#include "regular_eval.glsl"
#include "tese_main.glsl"
