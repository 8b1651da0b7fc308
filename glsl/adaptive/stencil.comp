#version 450
// The GPU subdivision tables, applied every frame: one dispatch per refinement level (its rows
// read only earlier levels), then one for the local points (phantom B-spline points, Gregory
// points, limit corners, curve Bezier points). `mode` 1 copies the base positions in first.
// Rows are stencils over the global vertex buffer, summed in table order with `precise`.
#define ADAPTIVE_WRITES_VERTICES
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
layout(local_size_x = ADAPTIVE_LOCAL_SIZE) in;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= adaptive.count) return;
    if (adaptive.mode == 1u) {
        vertices[i] = vec4(base_positions[3u * i], base_positions[3u * i + 1u], base_positions[3u * i + 2u], 1.0);
        return;
    }
    uint r = adaptive.first_row + i;
    precise vec3 p = vec3(0.0);
    for (uint k = stencil_offsets[r]; k < stencil_offsets[r + 1u]; ++k) {
        StencilTerm t = stencil_terms[k];
        p += t.weight * vertices[t.index].xyz;
    }
    vertices[adaptive.base_count + r] = vec4(p, 1.0);
}
