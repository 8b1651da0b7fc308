#version 450
// Curved PN triangles: the TCS computes the cubic position and quadratic normal Bézier
// coefficients of the patch once (per-patch outputs), following the corrected formulas of
// Boubekeur et al. 2005, appendix A (see pn.tese for the evaluation).
#include "frame.glsl"
#include "tess_levels.glsl"
layout(vertices = 3) out;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
layout(location = 0) out vec3 out_position[];
layout(location = 1) out vec3 out_normal[];
// Edge coefficients b210, b120, b021, b012, b102, b201, then b111.
layout(location = 2) patch out vec3 b_edge[6];
layout(location = 8) patch out vec3 b111;
// Mid-edge normal coefficients n110, n011, n101.
layout(location = 9) patch out vec3 n_edge[3];

// b_ij = (2 P_i + P_j - s_ij N_i) / 3 with s_ij = (P_j - P_i) . N_i
vec3 edge_point(int i, int j) {
    vec3 pi = in_position[i], pj = in_position[j], ni = in_normal[i];
    return (2.0 * pi + pj - dot(pj - pi, ni) * ni) / 3.0;
}

// n_ij = N_i + N_j - t_ij (P_j - P_i) with t_ij = 4 (P_j - P_i).(N_i + N_j) / |P_j - P_i|^2,
// the paper's corrected control point: with its normal field sum n_ijk u^i v^j w^k (no multinomial
// factors), n at the edge midpoint is exactly (N_i + N_j) mirrored in the edge's normal plane.
vec3 edge_normal(int i, int j) {
    vec3 d = in_position[j] - in_position[i];
    vec3 s = in_normal[i] + in_normal[j];
    float len2 = dot(d, d);
    float t = len2 > 0.0 ? 4.0 * dot(d, s) / len2 : 0.0;
    return s - t * d;
}

void main() {
    out_position[gl_InvocationID] = in_position[gl_InvocationID];
    out_normal[gl_InvocationID] = in_normal[gl_InvocationID];
    if (gl_InvocationID == 0) {
        b_edge[0] = edge_point(0, 1); // b210
        b_edge[1] = edge_point(1, 0); // b120
        b_edge[2] = edge_point(1, 2); // b021
        b_edge[3] = edge_point(2, 1); // b012
        b_edge[4] = edge_point(2, 0); // b102
        b_edge[5] = edge_point(0, 2); // b201
        vec3 e = (b_edge[0] + b_edge[1] + b_edge[2] + b_edge[3] + b_edge[4] + b_edge[5]) / 6.0;
        vec3 v = (in_position[0] + in_position[1] + in_position[2]) / 3.0;
        b111 = e + 0.5 * (e - v);
        n_edge[0] = edge_normal(0, 1);
        n_edge[1] = edge_normal(1, 2);
        n_edge[2] = edge_normal(2, 0);
    }
    set_uniform_levels_tri();
}
