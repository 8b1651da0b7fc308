#version 450
// Level-1 limit normals from the Loop limit tangent masks over each vertex's one-ring
// (boundary fans use the boundary masks): where subdivision shading starts.
#define BFT_WRITES_LEVEL1
#include "bft.glsl"
#include "normals.glsl"
layout(local_size_x = BFT_LOCAL_SIZE) in;
void main() {
    if (gl_GlobalInvocationID.x >= bft.count) return;
    // Global indices, less each windowed buffer's base (the chunk's windows).
    uint v = bft.first_vertex + gl_GlobalInvocationID.x;
    uint row = v - bft.level1_base;
    precise vec3 t1 = vec3(0.0), t2 = vec3(0.0);
    for (uint k = tangent_offsets[row]; k < tangent_offsets[row + 1u]; ++k) {
        TangentTerm t = tangent_terms[k - bft.tangent_base];
        vec3 x = L1_POS(t.index).xyz;
        t1 += t.weight_t1 * x;
        t2 += t.weight_t2 * x;
    }
    L1_NRM(v) = vec4(safe_normalize(cross(t1, t2), vec3(0.0)), 0.0);
}
