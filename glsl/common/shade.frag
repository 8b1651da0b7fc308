#version 450
// Lambert + Blinn-Phong with one directional light; the wireframe pass draws a flat colour.
#include "frame.glsl"
#include "shading.glsl"
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec4 out_color;
void main() {
    if (draw.mode == DRAW_MODE_WIREFRAME) {
        out_color = vec4(frame.wire_color.rgb, 1.0);
        return;
    }
    out_color = shade(in_world, in_normal, frame.base_color.rgb);
}
