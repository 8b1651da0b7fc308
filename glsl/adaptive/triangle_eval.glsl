// A Gregory triangle patch's evaluation from its 15 points `tc_points[]` and its coarse edges' curves (see
// triangle.tese): the evaluation stage's patch inputs or the pattern vertex stage's copy
// (pattern_triangle.vert).
void gregory_triangle(vec3 c[15], vec2 uv, out vec3 pos, out vec3 du, out vec3 dv);
void bernstein3(float t, out vec4 b, out vec4 d);

// Point and derivative (by t, in the patch's edge direction) of patch edge e from its curves.
void edge_sample(AdaptivePatch p, uint e, float t, out vec3 x, out vec3 dx) {
    uint h = 0u;
    float s = t, scale = 1.0;
    if (edge_kind(p, e) == ADAPTIVE_EDGE_COARSE) {
        h = t < 0.5 ? 0u : 1u;
        s = h == 0u ? 2.0 * t : 2.0 * t - 1.0;
        scale = 2.0;
    }
    if (edge_reversed(p, e, h)) { s = 1.0 - s; scale = -scale; }
    uvec4 b = CURVES[p.curves[2u * e + h]];
    vec4 w, d;
    bernstein3(s, w, d);
    vec3 p0 = vtx(b.x), p1 = vtx(b.y), p2 = vtx(b.z), p3 = vtx(b.w);
    x = w.x * p0 + w.y * p1 + w.z * p2 + w.w * p3;
    dx = scale * (d.x * p0 + d.y * p1 + d.z * p2 + d.w * p3);
}

void evaluate(uint id, vec2 uv, out vec3 pos, out vec3 du, out vec3 dv) {
    vec3 c[15];
    for (int k = 0; k < 15; ++k) c[k] = tc_points[k];
    gregory_triangle(c, uv, pos, du, dv);
    AdaptivePatch p = PATCHES[id];
    float l[3] = float[3](1.0 - uv.x - uv.y, uv.x, uv.y);
    const vec2 DL[3] = vec2[3](vec2(-1.0, -1.0), vec2(1.0, 0.0), vec2(0.0, 1.0));
    // Edge e (corner e to e + 1) adds (l_e + l_q)^2 (C(t) - B(t)), t = l_q / (l_e + l_q).
    for (uint e = 0u; e < 3u; ++e) {
        if (edge_kind(p, e) != ADAPTIVE_EDGE_COARSE) continue;
        uint q = (e + 1u) % 3u;
        float s = l[e] + l[q];
        if (s <= 1e-6) continue;
        float t = l[q] / s;
        vec3 x, dx;
        edge_sample(p, e, t, x, dx);
        vec4 w, d;
        bernstein3(t, w, d);
        vec3 a = c[5u * e], b1 = c[5u * e + 1u], b2 = c[5u * q + 2u], b3 = c[5u * q];
        vec3 diff = x - (w.x * a + w.y * b1 + w.z * b2 + w.w * b3);
        vec3 ddiff = dx - (d.x * a + d.y * b1 + d.z * b2 + d.w * b3);
        vec2 ds = DL[e] + DL[q];
        pos += (s * s) * diff;
        du += (2.0 * s * ds.x) * diff + (DL[q].x * s - l[q] * ds.x) * ddiff;
        dv += (2.0 * s * ds.y) * diff + (DL[q].y * s - l[q] * ds.y) * ddiff;
    }
}
