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

// A curved PN triangle's coefficients beyond its corners: edge points b_edge (for edge e,
// corners e and e + 1 mod 3: b_edge[2e] next to corner e, b_edge[2e + 1] next to corner e + 1,
// that is b210, b120, b021, b012, b102, b201), the centre b111 and the mid-edge normal
// coefficients n_edge (n110, n011, n101), each computed from the edge's lower corner.
struct PnPatch {
    vec3 b_edge[6];
    vec3 b111;
    vec3 n_edge[3];
};

// b111 = 1/4 sum(edge points) - 1/6 sum(corners), as e + (e - v) / 2 with e and v the means;
// only interior points use it.
vec3 pn_centre(vec3 b_edge[6], vec3 c[3]) {
    precise vec3 e = (b_edge[0] + b_edge[1] + b_edge[2] + b_edge[3] + b_edge[4] + b_edge[5]) / 6.0;
    precise vec3 v = (c[0] + c[1] + c[2]) / 3.0;
    precise vec3 b111 = e + 0.5 * (e - v);
    return b111;
}

PnPatch pn_patch(vec3 c[3], vec3 n[3]) {
    PnPatch q;
    for (int e = 0; e < 3; e++) {
        int i = e, j = (e + 1) % 3;
        q.b_edge[2 * e] = pn_edge_point(c[i], c[j], n[i]);
        q.b_edge[2 * e + 1] = pn_edge_point(c[j], c[i], n[j]);
        q.n_edge[e] = pn_corner_below(c[i], n[i], c[j], n[j]) ? pn_edge_normal(c[i], n[i], c[j], n[j])
                                                            : pn_edge_normal(c[j], n[j], c[i], n[i]);
    }
    q.b111 = pn_centre(q.b_edge, c);
    return q;
}

// The position (cubic Bézier, Vlachos et al.'s Bernstein weights with the multinomial factors
// 3 and 6) and the unnormalised quadratic normal field
// n = N1 u^2 + N2 v^2 + N3 w^2 + n110 uv + n011 vw + n101 wu at barycentric b = (u, v, w),
// the weights of corners 0, 1, 2. Corners are the control points themselves; points on an
// edge come from the edge's canonical formula, so the two patches of a shared edge get the
// same bits; only interior points sum the whole patch.
void pn_evaluate(vec3 c[3], vec3 n[3], PnPatch q, vec3 b, out vec3 p, out vec3 m) {
    float u = b.x, v = b.y, w = b.z;
    int corner = u == 1.0 ? 0 : (v == 1.0 ? 1 : (w == 1.0 ? 2 : -1));
    // Edge e joins corners e and e + 1 mod 3: the third weight is exactly 0 on it.
    int edge = w == 0.0 ? 0 : (u == 0.0 ? 1 : (v == 0.0 ? 2 : -1));
    if (corner >= 0) {
        p = c[corner];
        m = n[corner];
    } else if (edge >= 0) {
        int i = edge, j = (edge + 1) % 3;
        vec3 pa = c[i], na = n[i], bab = q.b_edge[2 * edge];
        vec3 pb = c[j], nb = n[j], bba = q.b_edge[2 * edge + 1];
        float wa = b[i], wb = b[j];
        // From the lower corner; a corner pair with equal data is one point twice, ordered by
        // weight so that both sides still agree.
        bool keep = pn_corner_below(pa, na, pb, nb)
            || (!pn_corner_below(pb, nb, pa, na) && wa >= wb);
        if (!keep) {
            vec3 t3 = pa; pa = pb; pb = t3;
            t3 = na; na = nb; nb = t3;
            t3 = bab; bab = bba; bba = t3;
            float t = wa; wa = wb; wb = t;
        }
        p = pn_edge_cubic(pa, bab, bba, pb, wa, wb);
        m = pn_edge_quadratic(na, q.n_edge[edge], nb, wa, wb);
    } else {
        // `precise`: the same bits in the evaluation stage and the pattern vertex stage.
        precise vec3 pi = c[0] * (u * u * u) + c[1] * (v * v * v) + c[2] * (w * w * w)
            + q.b_edge[0] * (3.0 * u * u * v) + q.b_edge[1] * (3.0 * u * v * v)
            + q.b_edge[2] * (3.0 * v * v * w) + q.b_edge[3] * (3.0 * v * w * w)
            + q.b_edge[4] * (3.0 * w * w * u) + q.b_edge[5] * (3.0 * w * u * u)
            + q.b111 * (6.0 * u * v * w);
        precise vec3 mi = n[0] * (u * u) + n[1] * (v * v) + n[2] * (w * w)
            + q.n_edge[0] * (u * v) + q.n_edge[1] * (v * w) + q.n_edge[2] * (w * u);
        p = pi;
        m = mi;
    }
}

#ifdef SCALAR_TAGS
// A curved PN triangle of a scalar-tagged mesh (Boubekeur et al., appendix B): where corner k
// is tagged (bn[k].w != 0), its two edge control points are the ones its tags make,
// computed on the CPU from the edge alone (tess::techniques::pn::scalar_tags): bn[k] on the
// edge to corner k + 1, bp[k] on the edge to corner k - 1. Untagged corners keep PN's
// (pn_patch), so a triangle without tags is PN's to the bit, and both patches of an edge
// get the same edge points. The corner normals n are the sides' sharp normals.
PnPatch pn_patch_tagged(vec3 c[3], vec3 n[3], vec4 bn[3], vec4 bp[3]) {
    PnPatch q = pn_patch(c, n);
    for (int k = 0; k < 3; k++) {
        if (bn[k].w != 0.0) {
            q.b_edge[2 * k] = bn[k].xyz;
            q.b_edge[2 * ((k + 2) % 3) + 1] = bp[k].xyz;
        }
    }
    q.b111 = pn_centre(q.b_edge, c);
    return q;
}
#endif
