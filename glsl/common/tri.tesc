#version 450
// Triangle patches (flat and Phong): control points pass through, levels are uniform.
#include "frame.glsl"
#include "tess_levels.glsl"
layout(vertices = 3) out;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
layout(location = 0) out vec3 out_position[];
layout(location = 1) out vec3 out_normal[];
void main() {
    out_position[gl_InvocationID] = in_position[gl_InvocationID];
    out_normal[gl_InvocationID] = in_normal[gl_InvocationID];
    set_uniform_levels_tri();
}
