// A regular patch's evaluation from its bicubic Bezier net `tc_bezier[16]` (row-major, i along
// u): the evaluation stage's patch inputs (regular.tese) or the pattern vertex stage's copy
// (pattern_regular.vert).
void bernstein(float t, out vec4 b, out vec4 d) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    d = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}

void evaluate(uint id, vec2 uv, out vec3 pos, out vec3 du, out vec3 dv) {
    vec4 bu, bv, du_w, dv_w;
    bernstein(uv.x, bu, du_w);
    bernstein(uv.y, bv, dv_w);
    pos = vec3(0.0); du = vec3(0.0); dv = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        vec3 row = bu.x * tc_bezier[4 * j] + bu.y * tc_bezier[4 * j + 1] + bu.z * tc_bezier[4 * j + 2] + bu.w * tc_bezier[4 * j + 3];
        vec3 drow = du_w.x * tc_bezier[4 * j] + du_w.y * tc_bezier[4 * j + 1] + du_w.z * tc_bezier[4 * j + 2] + du_w.w * tc_bezier[4 * j + 3];
        pos += bv[j] * row;
        du += bv[j] * drow;
        dv += dv_w[j] * row;
    }
}
