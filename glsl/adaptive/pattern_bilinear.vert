#version 450
#extension GL_EXT_control_flow_attributes : require
// Bilinear end caps on the refinement-pattern path (pattern_patch.glsl): bilinear.tese's Coons
// patch of the cap's curves at the pattern vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "pattern_patch.glsl"

void pattern_begin() {
    begin_patch();
}

#include "bilinear_eval.glsl"
#include "tese_main.glsl"
