#version 450
// Bilinear (Coons) end caps: one output point carries the patch; the TES reads the cap's
// canonical curves itself.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tesc_levels.glsl"
layout(vertices = 1) out;
layout(location = 0) flat in uint in_patch[];
void main() {
    uint id = in_patch[0];
    AdaptivePatch p = patches[id];
    write_patch_block(p, id, 0u, 1u);
    set_patch_levels(p);
}
