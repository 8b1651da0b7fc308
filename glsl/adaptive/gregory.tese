#version 450
#extension GL_EXT_control_flow_attributes : require
// Gregory end caps (Loop, Schaefer, Ni, Castano 2009; OpenSubdiv's Gregory basis): 20 control
// points, per corner i = 0..3 (v0 at (0,0), v1 (1,0), v2 (1,1), v3 (0,1)): P, Ep (towards
// corner i+1), Em (towards corner i-1), Fp (the interior point paired with Ep), Fm. The
// interior Bezier points are rational blends of Fp and Fm, so each is the right one on the
// edge it controls the cross derivative of. Mirrors topology::gregory::gregory_weights.
#define TECHNIQUE_PUSH_CONSTANTS
#ifdef SURFACE_BUILD
// ACC-1's tangent patches (acc only, which always draws the surface build).
#define PATCH_SHADING_NORMAL
#endif
#include "frame.glsl"
#include "adaptive.glsl"
#include "tese_out.glsl"
layout(quads, SPACING, ccw) in;
layout(location = 1) in vec3 tc_points[];

#include "gregory_eval.glsl"

#include "tese_main.glsl"
#include "gregory_normal.glsl"
