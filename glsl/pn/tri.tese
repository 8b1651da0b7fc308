#version 450
// Curved PN triangle evaluation: cubic Bézier position (Vlachos et al.'s Bernstein weights,
// with the multinomial factors 3 and 6) and the appendix's quadratic normal field
// n = N1 u^2 + N2 v^2 + N3 w^2 + n110 uv + n011 vw + n101 wu, normalised. Barycentric
// (u, v, w) = gl_TessCoord weights of corners 0, 1, 2.
// Corners are the control points themselves; points on an edge come from the edge's canonical
// formula (pn.glsl), so the two patches of a shared edge emit the same bits; only interior
// points sum the whole patch.
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#include "frame.glsl"
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
    vec3 b = gl_TessCoord;
    float u = b.x, v = b.y, w = b.z;
    int corner = u == 1.0 ? 0 : (v == 1.0 ? 1 : (w == 1.0 ? 2 : -1));
    // Edge e joins corners e and e + 1 mod 3: the third weight is exactly 0 on it.
    int edge = w == 0.0 ? 0 : (u == 0.0 ? 1 : (v == 0.0 ? 2 : -1));
    vec3 p, n;
    if (corner >= 0) {
        p = in_position[corner];
        n = in_normal[corner];
    } else if (edge >= 0) {
        int i = edge, j = (edge + 1) % 3;
        vec3 pa = in_position[i], na = in_normal[i], bab = b_edge[2 * edge];
        vec3 pb = in_position[j], nb = in_normal[j], bba = b_edge[2 * edge + 1];
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
        n = pn_edge_quadratic(na, n_edge[edge], nb, wa, wb);
    } else {
        p = in_position[0] * (u * u * u) + in_position[1] * (v * v * v) + in_position[2] * (w * w * w)
            + b_edge[0] * (3.0 * u * u * v) + b_edge[1] * (3.0 * u * v * v)
            + b_edge[2] * (3.0 * v * v * w) + b_edge[3] * (3.0 * v * w * w)
            + b_edge[4] * (3.0 * w * w * u) + b_edge[5] * (3.0 * w * u * u)
            + b111 * (6.0 * u * v * w);
        n = in_normal[0] * (u * u) + in_normal[1] * (v * v) + in_normal[2] * (w * w)
            + n_edge[0] * (u * v) + n_edge[1] * (v * w) + n_edge[2] * (w * u);
    }
    emit_sample(p, safe_normalize(n, vec3(0.0)), draw.first_patch + uint(gl_PrimitiveID), 0u);
}
