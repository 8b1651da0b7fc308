#version 450
// Phong tessellation (Boubekeur & Alexa 2008): the linear point projected onto each corner's
// tangent plane, the projections blended barycentrically, then mixed with the linear point by
// the shape factor alpha (frame.tess.z, default 3/4). Normals are interpolated linearly.
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "tese_out.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
vec3 project(vec3 q, int i) {
    vec3 n = in_normal[i];
    return q - dot(q - in_position[i], n) * n;
}
void main() {
    vec3 b = gl_TessCoord;
    // `precise` barycentric sums (flat/tri.tese): both patches of an edge get the same bits.
    // Each projection depends on its corner alone, so it is the same in either patch.
    precise vec3 p = b.x * in_position[0] + b.y * in_position[1] + b.z * in_position[2];
    precise vec3 phong = b.x * project(p, 0) + b.y * project(p, 1) + b.z * project(p, 2);
    float alpha = frame.tess.z;
    precise vec3 n = b.x * in_normal[0] + b.y * in_normal[1] + b.z * in_normal[2];
    precise vec3 blended = (1.0 - alpha) * p + alpha * phong;
    emit_sample(blended, n, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
