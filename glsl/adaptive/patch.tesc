#version 450
// Bilinear (Coons) end caps: one output point carries the patch; the TES reads the cap's
// canonical curves itself.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tesc_levels.glsl"
layout(vertices = 1) out;
layout(location = 0) flat in uint in_patch[];
layout(location = 0) patch out uint tc_patch;
layout(location = 2) patch out uint tc_info;
void main() {
    uint id = in_patch[0];
    tc_patch = id;
    AdaptivePatch p = PATCHES[id];
    tc_info = p.info;
    set_patch_levels(p);
}
