#version 450
// The GPU subdivision tables, applied every frame: one dispatch per refinement level (its rows
// read only earlier levels), then one for the local points (phantom B-spline points, Gregory
// points, limit corners, curve Bezier points). `mode` 1 copies the base positions in first.
// Rows are stencils over the global vertex buffer, summed in table order with `precise`, as
// offsets from the row's first vertex (rows are affine).
// A block larger than the storage range runs as several dispatches (chunks of rows), each
// bound to a window of the stencil offsets and terms: indices into them subtract the window
// bases (`row_base`, `term_base`); the vertex buffer is bound whole.
#define ADAPTIVE_WRITES_VERTICES
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
layout(local_size_x = ADAPTIVE_LOCAL_SIZE) in;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= adaptive.count) return;
    if (adaptive.mode == 1u) {
        uint v = adaptive.first_row + i;
        vertices[v] = vec4(base_positions[3u * v], base_positions[3u * v + 1u], base_positions[3u * v + 2u], 1.0);
        return;
    }
    uint r = adaptive.first_row + i;
    uint k0 = stencil_offsets[r - adaptive.row_base];
    uint k1 = stencil_offsets[r + 1u - adaptive.row_base];
    // Every row is affine (its weights sum to 1), so it is summed as offsets from its first
    // term's vertex: the f32 rounding is then relative to the row's spread, not to the
    // coordinates' magnitude. Deep levels around a pole chain many wide rows (721 terms at a
    // valence-360 pole), and absolute sums made catmark_pole360's regular patches 1.4e-5 of the
    // diagonal off the CPU plan.
    vec3 anchor = k0 < k1 ? vertices[stencil_terms[k0 - adaptive.term_base].index].xyz : vec3(0.0);
    precise vec3 d = vec3(0.0);
    for (uint k = k0; k < k1; ++k) {
        StencilTerm t = stencil_terms[k - adaptive.term_base];
        d += t.weight * (vertices[t.index].xyz - anchor);
    }
    precise vec3 p = anchor + d;
    vertices[adaptive.base_count + r] = vec4(p, 1.0);
}
