#version 450
// The initial GPU subdivision step: level-1 positions as stencils over the base positions, so
// an animated base mesh costs one upload of its positions per frame.
#define BFT_WRITES_LEVEL1
#include "bft.glsl"
layout(local_size_x = BFT_LOCAL_SIZE) in;
void main() {
    if (gl_GlobalInvocationID.x >= bft.count) return;
    // Global indices, less each windowed buffer's base (the chunk's windows).
    uint v = bft.first_vertex + gl_GlobalInvocationID.x;
    uint row = v - bft.level1_base;
    precise vec3 p = vec3(0.0);
    for (uint k = stencil_offsets[row]; k < stencil_offsets[row + 1u]; ++k) {
        StencilTerm t = stencil_terms[k - bft.stencil_base];
        BasePosition b = base_positions[t.index - bft.base_vertex_base];
        p += t.weight * vec3(b.x, b.y, b.z);
    }
    L1_POS(v) = vec4(p, 1.0);
}
