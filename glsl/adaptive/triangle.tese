#version 450
#extension GL_EXT_control_flow_attributes : require
// Gregory triangle patches (single-pass plans, one per triangle; topology::gregory's
// gregory_triangle_weights): the quartic with rational interior points of surface.glsl, plus
// the boundary correction that puts each edge on its two level-1 canonical halves
// (topology::AdaptivePlan::evaluate). Domain: gl_TessCoord = (u, v, 1 - u - v), corner 0 at
// (0, 0), 1 at (1, 0), 2 at (0, 1).
#define TECHNIQUE_PUSH_CONSTANTS
#define TRIANGLE_DOMAIN
#include "frame.glsl"
#include "adaptive.glsl"
#include "tese_out.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 1) in vec3 tc_points[];

#include "triangle_eval.glsl"

#include "tese_main.glsl"
