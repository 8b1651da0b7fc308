#version 450
// The initial GPU subdivision step: level-1 positions as stencils over the base positions, so
// an animated base mesh costs one upload of its positions per frame.
#define BFT_WRITES_LEVEL1
#include "bft.glsl"
layout(local_size_x = BFT_LOCAL_SIZE) in;
void main() {
    uint v = gl_GlobalInvocationID.x;
    if (v >= bft.count) return;
    precise vec3 p = vec3(0.0);
    for (uint k = stencil_offsets[v]; k < stencil_offsets[v + 1u]; ++k) {
        StencilTerm t = stencil_terms[k];
        BasePosition b = base_positions[t.index];
        p += t.weight * vec3(b.x, b.y, b.z);
    }
    level1_pos[v] = vec4(p, 1.0);
}
