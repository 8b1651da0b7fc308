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
    // Written out and `precise`, not mix(): mix's rounding is the driver's (NVIDIA's is
    // x + a (y - x), not y at a = 1), and contraction to fused multiply-adds depends on operand
    // order. So every edge point is a (1 - t) + b t from whichever side, the same two products
    // summed, and both quads of an edge emit the same bits.
    precise vec3 p = (in_position[0] * (1.0 - u) + in_position[1] * u) * (1.0 - v)
        + (in_position[3] * (1.0 - u) + in_position[2] * u) * v;
    precise vec3 n = (in_normal[0] * (1.0 - u) + in_normal[1] * u) * (1.0 - v)
        + (in_normal[3] * (1.0 - u) + in_normal[2] * u) * v;
    emit_sample(p, n, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
