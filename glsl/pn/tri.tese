#version 450
// Curved PN triangle evaluation: cubic Bézier position (standard Bernstein weights) and the
// appendix's quadratic normal field n = N1 u^2 + N2 v^2 + N3 w^2 + n110 uv + n011 vw + n101 wu,
// normalised. Barycentric (u, v, w) = gl_TessCoord weights of corners 0, 1, 2.
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "tese_out.glsl"
#include "normals.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
layout(location = 2) patch in vec3 b_edge[6];
layout(location = 8) patch in vec3 b111;
layout(location = 9) patch in vec3 n_edge[3];
void main() {
    float u = gl_TessCoord.x, v = gl_TessCoord.y, w = gl_TessCoord.z;
    vec3 p = in_position[0] * (u * u * u) + in_position[1] * (v * v * v) + in_position[2] * (w * w * w)
        + b_edge[0] * (3.0 * u * u * v) + b_edge[1] * (3.0 * u * v * v)
        + b_edge[2] * (3.0 * v * v * w) + b_edge[3] * (3.0 * v * w * w)
        + b_edge[4] * (3.0 * w * w * u) + b_edge[5] * (3.0 * w * u * u)
        + b111 * (6.0 * u * v * w);
    vec3 n = in_normal[0] * (u * u) + in_normal[1] * (v * v) + in_normal[2] * (w * w)
        + n_edge[0] * (u * v) + n_edge[1] * (v * w) + n_edge[2] * (w * u);
    emit_sample(p, safe_normalize(n, vec3(0.0)), draw.first_patch + uint(gl_PrimitiveID), 0u);
}
