#version 450
// Lambert + Blinn-Phong with one directional light; the wireframe pass draws a flat colour.
#include "frame.glsl"
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec4 out_color;
void main() {
    if (draw.mode == 1u) {
        out_color = vec4(frame.wire_color.rgb, 1.0);
        return;
    }
    vec3 n = normalize(in_normal);
    vec3 view_dir = normalize(frame.camera_pos.xyz - in_world);
    if (dot(n, view_dir) < 0.0) n = -n; // two-sided lighting for open meshes
    vec3 l = normalize(frame.light_dir.xyz);
    vec3 h = normalize(l + view_dir);
    float diffuse = max(dot(n, l), 0.0);
    float specular = pow(max(dot(n, h), 0.0), 48.0) * 0.35;
    vec3 ambient = 0.18 * frame.base_color.rgb;
    vec3 c = ambient + diffuse * frame.base_color.rgb + specular * vec3(1.0);
    out_color = vec4(c, 1.0);
}
