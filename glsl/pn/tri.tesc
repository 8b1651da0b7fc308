#version 450
// Curved PN triangles: the TCS computes the cubic position and quadratic normal Bézier
// coefficients of the patch once (per-patch outputs), following the corrected formulas of
// Boubekeur et al. 2005, appendix A (pn.glsl; see pn.tese for the evaluation). Every edge
// coefficient is a function of its edge's two corners only, taken in an order both patches of
// the edge agree on (pn.glsl), so shared edges get the same bits from both sides. The
// scalar-tagged build takes tagged corners' edge points from the vertex stage.
#include "frame.glsl"
#include "tess_levels.glsl"
#include "pn.glsl"
layout(vertices = 3) out;
layout(location = 0) in vec3 in_position[];
layout(location = 1) in vec3 in_normal[];
#ifdef SCALAR_TAGS
// Each corner's tagged edge control points (tagged_mesh.vert; pn.glsl's pn_patch_tagged).
layout(location = 2) in vec4 in_b_next[];
layout(location = 3) in vec4 in_b_prev[];
#endif
layout(location = 0) out vec3 out_position[];
layout(location = 1) out vec3 out_normal[];
// PnPatch's fields (pn.glsl), handed to the evaluation stage as per-patch outputs.
layout(location = 2) patch out vec3 b_edge[6];
layout(location = 8) patch out vec3 b111;
layout(location = 9) patch out vec3 n_edge[3];

void main() {
    out_position[gl_InvocationID] = in_position[gl_InvocationID];
    out_normal[gl_InvocationID] = in_normal[gl_InvocationID];
    if (gl_InvocationID == 0) {
        vec3 c[3] = vec3[3](in_position[0], in_position[1], in_position[2]);
        vec3 n[3] = vec3[3](in_normal[0], in_normal[1], in_normal[2]);
#ifdef SCALAR_TAGS
        vec4 bn[3] = vec4[3](in_b_next[0], in_b_next[1], in_b_next[2]);
        vec4 bp[3] = vec4[3](in_b_prev[0], in_b_prev[1], in_b_prev[2]);
        PnPatch q = pn_patch_tagged(c, n, bn, bp);
#else
        PnPatch q = pn_patch(c, n);
#endif
        b_edge = q.b_edge;
        b111 = q.b111;
        n_edge = q.n_edge;
    }
    set_uniform_levels_tri();
}
