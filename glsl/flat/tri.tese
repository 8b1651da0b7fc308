#version 450
// Flat tessellation of a triangle: the planar point at the barycentric tess coordinate.
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "tese_out.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
void main() {
    vec3 b = gl_TessCoord;
    // `precise`: no contraction to fused multiply-adds, whose rounding depends on the operand
    // order. On an edge the third weight is 0, and the other two products sum to the same bits
    // in either patch's corner order.
    precise vec3 p = b.x * in_position[0] + b.y * in_position[1] + b.z * in_position[2];
    precise vec3 n = b.x * in_normal[0] + b.y * in_normal[1] + b.z * in_normal[2];
    emit_sample(p, n, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
