#version 450
// Flat tessellation of a triangle: the planar point at the barycentric tess coordinate
// (flat.glsl). Built in every spacing, with and without capture (glsl/manifest.toml;
// tese_out.glsl).
#include "frame.glsl"
#include "sine.glsl"
#include "tese_out.glsl"
#include "flat.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
void main() {
    vec3 b = gl_TessCoord;
    vec3 p[3] = vec3[3](in_position[0], in_position[1], in_position[2]);
    vec3 n[3] = vec3[3](in_normal[0], in_normal[1], in_normal[2]);
    vec3 m = flat_triangle(n, b);
    emit_sample(displace_sine(flat_triangle(p, b), m), m, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
