// The stencil evaluator (crates/tess/src/stencil): CSR rows of (source vertex, weight) terms,
// one destination vertex each. Mirrors `tess::stencil::StencilTerm` and
// `tess::gpu::StencilPush` (offsets checked against the SPIR-V by a test). Every buffer is a
// window of a larger one: indices are global and have their window's base subtracted.
#include "bindings.glsl"

struct StencilTerm {
    uint index;    // source vertex (an element of the whole source buffer)
    float weight;
};

layout(std430, set = STENCIL_SET, binding = STENCIL_OFFSETS_BINDING) readonly buffer StencilOffsets { uint stencil_offsets[]; };
layout(std430, set = STENCIL_SET, binding = STENCIL_TERMS_BINDING) readonly buffer StencilTerms { StencilTerm stencil_terms[]; };
layout(std430, set = STENCIL_SET, binding = STENCIL_SOURCE_BINDING) readonly buffer StencilSource { vec4 source_vertices[]; };
layout(std430, set = STENCIL_SET, binding = STENCIL_DESTINATION_BINDING) writeonly buffer StencilDestination { vec4 destination_vertices[]; };

// Push constant of the evaluator (`tess::gpu::StencilPush`): one dispatch.
layout(push_constant) uniform StencilPush {
    uint first_row;          // the dispatch's first row (global)
    uint count;              // rows in the dispatch
    uint row_base;           // window base of stencil_offsets
    uint term_base;          // window base of stencil_terms
    uint source_base;        // window base of source_vertices
    uint destination_first;  // first row's destination, in the destination window
} stencil;
