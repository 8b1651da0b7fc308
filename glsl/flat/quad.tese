#version 450
// Flat tessellation of a quad: the bilinear point at (u, v) (flat.glsl).
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "sine.glsl"
#include "tese_out.glsl"
#include "flat.glsl"
layout(quads, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
void main() {
    float u = gl_TessCoord.x, v = gl_TessCoord.y;
    vec3 p[4] = vec3[4](in_position[0], in_position[1], in_position[2], in_position[3]);
    vec3 n[4] = vec3[4](in_normal[0], in_normal[1], in_normal[2], in_normal[3]);
    vec3 m = flat_quad(n, u, v);
    emit_sample(displace_sine(flat_quad(p, u, v), m), m, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
