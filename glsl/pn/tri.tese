#version 450
// Curved PN triangle evaluation at the tessellator's domain point (pn.glsl's pn_evaluate, with
// the coefficients the control stage computed), normal normalised.
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
#include "sine.glsl"
#include "tese_out.glsl"
#include "normals.glsl"
#include "pn.glsl"
layout(triangles, SPACING, ccw) in;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
layout(location = 2) patch in vec3 b_edge[6];
layout(location = 8) patch in vec3 b111;
layout(location = 9) patch in vec3 n_edge[3];
void main() {
    vec3 c[3] = vec3[3](in_position[0], in_position[1], in_position[2]);
    vec3 n[3] = vec3[3](in_normal[0], in_normal[1], in_normal[2]);
    PnPatch q = PnPatch(b_edge, b111, n_edge);
    vec3 p, m;
    pn_evaluate(c, n, q, gl_TessCoord, p, m);
    m = safe_normalize(m, vec3(0.0));
    emit_sample(displace_sine(p, m), m, draw.first_patch + uint(gl_PrimitiveID), 0u);
}
