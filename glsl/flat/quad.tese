#version 450
// Flat tessellation of a quad: the bilinear point at (u, v); v0 (0,0), v1 (1,0), v2 (1,1), v3 (0,1).
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "tese_out.glsl"
layout(quads, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
void main() {
    float u = gl_TessCoord.x, v = gl_TessCoord.y;
    vec3 p = mix(mix(in_position[0], in_position[1], u), mix(in_position[3], in_position[2], u), v);
    vec3 n = mix(mix(in_normal[0], in_normal[1], u), mix(in_normal[3], in_normal[2], u), v);
    emit_sample(p, n, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
