#version 450
// The initial GPU subdivision step: level-1 positions as stencils over the base positions, so
// an animated base mesh costs one upload of its positions per frame.
#define BFT_WRITES_LEVEL1
#include "bft.glsl"
layout(local_size_x = 64) in;
void main() {
    uint v = gl_GlobalInvocationID.x;
    if (v >= bft.count) return;
    precise vec3 p = vec3(0.0);
    for (uint k = stencil_offsets[v]; k < stencil_offsets[v + 1u]; ++k) {
        uint i = stencil_indices[k];
        p += stencil_weights[k] * vec3(base_xyz[3u * i], base_xyz[3u * i + 1u], base_xyz[3u * i + 2u]);
    }
    level1_pos[v] = vec4(p, 1.0);
}
