#version 450
// The deepest depth of the Doo-Sabin vertex patches, drawn from the vertex stage
// (`tess::techniques::vertex_patches`): the index buffer holds every patch's owned faces as
// triangle fans (slots of the deepest depth's arrays, one patch after another), the points are
// what `refine.comp` wrote this frame. A point's normal is the sum over the face corners it lies
// in of (next - p) x (previous - p), the neighbours named by slots (every copy of a shared point
// holds the same bits, so any copy serves). The capture build records the slot
// (draw.first_patch + gl_VertexIndex), which the technique maps to the refined mesh's vertex.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "frame.glsl"
#include "stage_out.glsl"
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer VertexPatchPointArray { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer VertexPatchCornerArray { uvec2 v[]; };
// `tess::gpu::VertexPatchArrays`: each address a uvec2, low word first.
layout(std140, set = VERTEX_PATCHES_SET, binding = VERTEX_PATCHES_ARRAYS_BINDING) uniform VertexPatchArrays {
    uvec2 points;   // the deepest depth's first slot in the patch buffer
    uvec2 corners;  // DOO_SABIN_MAX_CORNERS (next, previous) slots per slot
} arrays;
#define points VertexPatchPointArray(arrays.points).v
#define corners VertexPatchCornerArray(arrays.corners).v

void main() {
    uint v = uint(gl_VertexIndex);
    vec3 p = points[v].xyz;
    vec3 n = vec3(0.0);
    for (uint k = 0u; k < DOO_SABIN_MAX_CORNERS; ++k) {
        uvec2 c = corners[DOO_SABIN_MAX_CORNERS * v + k];
        n += cross(points[c.x].xyz - p, points[c.y].xyz - p);
    }
    float len = length(n);
    emit_vertex_at(p, len > 0.0 ? n / len : vec3(0.0, 0.0, 1.0), draw.first_patch + v, 0u, vec2(0.0));
}
