#version 450
// Level-1 limit normals from the Loop limit tangent masks over each vertex's one-ring
// (boundary fans use the boundary masks): where subdivision shading starts.
#define BFT_WRITES_LEVEL1
#include "bft.glsl"
#include "normals.glsl"
layout(local_size_x = BFT_LOCAL_SIZE) in;
void main() {
    uint v = gl_GlobalInvocationID.x;
    if (v >= bft.count) return;
    precise vec3 t1 = vec3(0.0), t2 = vec3(0.0);
    for (uint k = tangent_offsets[v]; k < tangent_offsets[v + 1u]; ++k) {
        TangentTerm t = tangent_terms[k];
        vec3 x = level1_pos[t.index].xyz;
        t1 += t.weight_t1 * x;
        t2 += t.weight_t2 * x;
    }
    level1_nrm[v] = vec4(safe_normalize(cross(t1, t2), vec3(0.0)), 0.0);
}
