#version 450
// Pass-through: the control points of each patch are the mesh vertices (object = world space).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec3 out_position;
layout(location = 1) out vec3 out_normal;
void main() {
    out_position = in_position;
    out_normal = in_normal;
}
