#version 450
// Non-tessellated draw of an already refined mesh (the CPU subdivision baseline): the vertex
// stage does what a TES does for the tessellated techniques, so shade.frag sees the same inputs.
#include "frame.glsl"
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
void main() {
    out_world = in_position;
    out_normal = in_normal;
    gl_Position = frame.view_proj * vec4(in_position, 1.0);
}
