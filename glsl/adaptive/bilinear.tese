#version 450
#extension GL_EXT_control_flow_attributes : require
// Bilinear end caps, made watertight: the bilinearly blended (Coons) patch of the cap's four
// canonical boundary curves, so the cap follows its neighbours' boundaries exactly; between
// two caps the curves are straight and it is the bilinear patch of the limit corners.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tese_out.glsl"
layout(quads, SPACING, ccw) in;

#include "bilinear_eval.glsl"

#include "tese_main.glsl"
