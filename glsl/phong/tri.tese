#version 450
// Phong tessellation at the tessellator's domain point (phong.glsl); the shape factor alpha is
// frame.tess.z (default 3/4).
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "sine.glsl"
#include "tese_out.glsl"
#include "phong.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
void main() {
    vec3 b = gl_TessCoord;
    vec3 c[3] = vec3[3](in_position[0], in_position[1], in_position[2]);
    vec3 n[3] = vec3[3](in_normal[0], in_normal[1], in_normal[2]);
    vec3 m = phong_normal(n, b);
    emit_sample(displace_sine(phong_point(c, n, b, frame.tess.z), m), m,
        draw.first_patch + uint(gl_PrimitiveID), 0u);
}
