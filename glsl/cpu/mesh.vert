#version 450
// A mesh refined on the CPU (M^k on the limit surface), drawn without the tessellation stage:
// the vertex stage is the last before rasterization, so it hands shade.frag what an evaluation
// stage would, and its capture build records each vertex's index in the frame's numbering
// (draw.first_patch + gl_VertexIndex): the technique knows where that vertex lies on the base
// mesh. The domain coordinate is unused (0).
#include "frame.glsl"
#include "stage_out.glsl"
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
void main() {
    emit_vertex_at(in_position, in_normal, draw.first_patch + uint(gl_VertexIndex), 0u, vec2(0.0));
}
