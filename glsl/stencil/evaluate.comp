#version 450
// The stencil evaluator: row first_row + i of the table, written to destination vertex
// destination_first + i (both windowed). Rows are affine (their weights sum to 1), so each is
// summed in table order, with `precise` (no fused products), as offsets from its first term's
// vertex: the f32 rounding is then relative to the row's spread, not to the coordinates'
// magnitude (`tess::stencil::GpuStencils::row_point` is this sum's f32 mirror).
#include "stencil.glsl"
layout(local_size_x = STENCIL_LOCAL_SIZE) in;

vec3 source(uint v) { return source_vertices[v - stencil.source_base].xyz; }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= stencil.count) return;
    uint r = stencil.first_row + i;
    uint k0 = stencil_offsets[r - stencil.row_base];
    uint k1 = stencil_offsets[r + 1u - stencil.row_base];
    vec3 anchor = k0 < k1 ? source(stencil_terms[k0 - stencil.term_base].index) : vec3(0.0);
    precise vec3 d = vec3(0.0);
    for (uint k = k0; k < k1; ++k) {
        StencilTerm t = stencil_terms[k - stencil.term_base];
        d += t.weight * (source(t.index) - anchor);
    }
    precise vec3 p = anchor + d;
    destination_vertices[stencil.destination_first + i] = vec4(p, 1.0);
}
