#version 450
// Doo-Sabin's deepest refined level, drawn from the vertex stage: the index buffer holds the
// level's faces as triangle fans (level-local point numbers), the points are what the stencil
// evaluator wrote this frame (`tess::techniques::doo_sabin`). A point's normal is the sum over
// the face corners it lies in of (next - p) x (previous - p): the area-weighted normal of the
// corners' triangles, from its at most four neighbours, no table of normals. The capture build
// records each point's number in the frame's numbering (draw.first_patch + gl_VertexIndex),
// which the technique maps back to the base mesh; the domain coordinate is unused (0).
//
// The points and the corners are read through buffer references (GL_EXT_buffer_reference) at
// the device addresses the uniform block `DooSabinArrays` holds, not through descriptors: no
// `maxStorageBufferRange` limits them, so a level is drawn whenever it fits in device memory.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "frame.glsl"
#include "stage_out.glsl"
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer DooSabinPointArray { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DooSabinCornerArray { uvec2 v[]; };
// `tess::gpu::DooSabinArrays`: each address a uvec2, low word first.
layout(std140, set = DOO_SABIN_SET, binding = DOO_SABIN_ARRAYS_BINDING) uniform DooSabinArrays {
    uvec2 points;   // the deepest level's first point in the refined vertex buffer
    uvec2 corners;  // DOO_SABIN_MAX_CORNERS (next, previous) pairs per point
} arrays;
#define points DooSabinPointArray(arrays.points).v
#define corners DooSabinCornerArray(arrays.corners).v

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
