#version 450
#extension GL_EXT_control_flow_attributes : require
// Regular patches: the bicubic uniform B-spline of 16 control points (row-major 4x4 around the
// face, phantom points already in place for boundaries and infinitely sharp creases), as the
// Bezier net regular.tesc converted it to.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tese_out.glsl"
layout(quads, SPACING, ccw) in;

layout(location = 1) in vec3 tc_bezier[];

#include "regular_eval.glsl"

#include "tese_main.glsl"
