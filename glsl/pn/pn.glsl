// Curved PN triangles (Vlachos et al. 2001) with the corrected quadratic normal field of
// Boubekeur et al. 2005, appendix A: what the control and evaluation stages share.
//
// Watertight by canonical edges. A shared edge is drawn by two patches that list its corners
// in opposite orders and at different places of the patch, so summing the cubic's ten terms
// in patch order rounds differently on each side (bit-level cracks). Here a point on a patch
// edge is evaluated from the edge's own data only (its two corners and the two edge control
// points, and the corners' two tess weights, which the tessellator mirrors exactly), in one
// canonical order: from the edge's lower corner, where "lower" compares the corners' data bits
// (position, then normal), which both patches read from the same vertices. So it does not
// depend on vertex indices: two vertices with the same position and normal (an OBJ that
// repeats them) are one point for both patches. The interior terms are not added as zeros
// (x + 0 * y is not x when y is inf or NaN, and flips -0): on an edge they are not evaluated
// at all. `precise` keeps each formula's operand order and rounding (no contraction to fused
// multiply-adds that one call site might get and another not).

// The comparison key of patch corner i: position bits, then normal bits.
bool pn_corner_below(vec3 pi, vec3 ni, vec3 pj, vec3 nj) {
    uvec3 a = floatBitsToUint(pi), b = floatBitsToUint(pj);
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    if (a.z != b.z) return a.z < b.z;
    a = floatBitsToUint(ni);
    b = floatBitsToUint(nj);
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
}

// b_ij = (2 P_i + P_j - s_ij N_i) / 3 with s_ij = (P_j - P_i) . N_i: the edge control point
// next to P_i. A function of (P_i, P_j, N_i) in that order, so both patches of an edge get
// the same bits for it.
vec3 pn_edge_point(vec3 pi, vec3 pj, vec3 ni) {
    precise float s = dot(pj - pi, ni);
    precise vec3 b = (2.0 * pi + pj - s * ni) / 3.0;
    return b;
}

// n_ij = N_i + N_j - t_ij (P_j - P_i) with t_ij = 4 (P_j - P_i).(N_i + N_j) / |P_j - P_i|^2,
// the appendix's corrected control point: with its normal field sum n_ijk u^i v^j w^k (no
// multinomial factors), n at the edge midpoint is exactly (N_i + N_j) mirrored in the edge's
// normal plane. Symmetric in i, j in exact arithmetic; called with (lower, upper) corners
// only, so also in floating point.
vec3 pn_edge_normal(vec3 pi, vec3 ni, vec3 pj, vec3 nj) {
    precise vec3 d = pj - pi;
    precise vec3 s = ni + nj;
    precise float len2 = dot(d, d);
    precise float t = len2 > 0.0 ? 4.0 * dot(d, s) / len2 : 0.0;
    precise vec3 n = s - t * d;
    return n;
}

// The cubic on an edge from corner a (weight wa) to corner b (weight wb), wa + wb = 1:
// P_a wa^3 + 3 b_ab wa^2 wb + 3 b_ba wa wb^2 + P_b wb^3, summed in this order.
vec3 pn_edge_cubic(vec3 pa, vec3 bab, vec3 bba, vec3 pb, float wa, float wb) {
    precise vec3 p = pa * (wa * wa * wa) + bab * (3.0 * wa * wa * wb)
        + bba * (3.0 * wa * wb * wb) + pb * (wb * wb * wb);
    return p;
}

// The quadratic normal field on the same edge: N_a wa^2 + n_ab wa wb + N_b wb^2.
vec3 pn_edge_quadratic(vec3 na, vec3 nab, vec3 nb, float wa, float wb) {
    precise vec3 n = na * (wa * wa) + nab * (wa * wb) + nb * (wb * wb);
    return n;
}
