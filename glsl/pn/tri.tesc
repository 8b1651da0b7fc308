#version 450
// Curved PN triangles: the TCS computes the cubic position and quadratic normal Bézier
// coefficients of the patch once (per-patch outputs), following the corrected formulas of
// Boubekeur et al. 2005, appendix A (pn.glsl; see pn.tese for the evaluation). Every edge
// coefficient is a function of its edge's two corners only, taken in an order both patches of
// the edge agree on (pn.glsl), so shared edges get the same bits from both sides.
#include "frame.glsl"
#include "tess_levels.glsl"
#include "pn.glsl"
layout(vertices = 3) out;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
layout(location = 0) out vec3 out_position[];
layout(location = 1) out vec3 out_normal[];
// Edge coefficients b210, b120, b021, b012, b102, b201: for edge e (corners e, e + 1 mod 3),
// b_edge[2e] is next to corner e and b_edge[2e + 1] next to corner e + 1.
layout(location = 2) patch out vec3 b_edge[6];
layout(location = 8) patch out vec3 b111;
// Mid-edge normal coefficients n110, n011, n101 (edge e), each computed from the edge's lower
// corner (pn_corner_below).
layout(location = 9) patch out vec3 n_edge[3];

void main() {
    out_position[gl_InvocationID] = in_position[gl_InvocationID];
    out_normal[gl_InvocationID] = in_normal[gl_InvocationID];
    if (gl_InvocationID == 0) {
        for (int e = 0; e < 3; e++) {
            int i = e, j = (e + 1) % 3;
            vec3 pi = in_position[i], ni = in_normal[i];
            vec3 pj = in_position[j], nj = in_normal[j];
            b_edge[2 * e] = pn_edge_point(pi, pj, ni);
            b_edge[2 * e + 1] = pn_edge_point(pj, pi, nj);
            n_edge[e] = pn_corner_below(pi, ni, pj, nj) ? pn_edge_normal(pi, ni, pj, nj)
                                                        : pn_edge_normal(pj, nj, pi, ni);
        }
        // b111 = 1/4 sum(edge points) - 1/6 sum(corners), as e + (e - v) / 2 with e and v the
        // means; only interior points use it.
        vec3 e = (b_edge[0] + b_edge[1] + b_edge[2] + b_edge[3] + b_edge[4] + b_edge[5]) / 6.0;
        vec3 v = (in_position[0] + in_position[1] + in_position[2]) / 3.0;
        b111 = e + 0.5 * (e - v);
    }
    set_uniform_levels_tri();
}
