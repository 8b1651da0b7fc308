// A Gregory (or ACC-1) patch's evaluation from its 20 control points `tc_points[]` (see
// gregory.tese): the evaluation stage's patch inputs or the pattern vertex stage's copy
// (pattern_gregory.vert).
void bernstein(float t, out vec4 b, out vec4 d) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    d = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}

// (a F + b G) / (a + b) and its derivatives by a and by b.
void blend(float a, float b, vec3 f, vec3 g, out vec3 x, out vec3 dx_da, out vec3 dx_db) {
    float d = a + b;
    if (d < 1e-7) {
        x = 0.5 * (f + g);
        dx_da = vec3(0.0);
        dx_db = vec3(0.0);
        return;
    }
    x = (a * f + b * g) / d;
    dx_da = b * (f - g) / (d * d);
    dx_db = a * (g - f) / (d * d);
}

void evaluate(uint id, vec2 uv, out vec3 pos, out vec3 du, out vec3 dv) {
    vec3 c[20];
    for (int i = 0; i < 20; ++i) c[i] = tc_points[i];
    float u = uv.x, v = uv.y;
    // The 4x4 Bezier net b[i + 4 j] (i along u, j along v) and the interior derivatives.
    vec3 b[16];
    vec3 bu[16], bv[16];
    for (int k = 0; k < 16; ++k) { bu[k] = vec3(0.0); bv[k] = vec3(0.0); }
    b[0] = c[0];  b[1] = c[1];  b[2] = c[7];  b[3] = c[5];
    b[7] = c[6];  b[11] = c[12]; b[15] = c[10];
    b[14] = c[11]; b[13] = c[17]; b[12] = c[15];
    b[8] = c[16]; b[4] = c[2];
    vec3 da, db;
    // b11: Fp0 on v = 0 (weight u), Fm0 on u = 0 (weight v).
    blend(u, v, c[3], c[4], b[5], da, db);
    bu[5] = da; bv[5] = db;
    // b21: Fm1 on v = 0 (weight 1-u), Fp1 on u = 1 (weight v).
    blend(1.0 - u, v, c[9], c[8], b[6], da, db);
    bu[6] = -da; bv[6] = db;
    // b22: Fm2 on u = 1 (weight 1-v), Fp2 on v = 1 (weight 1-u).
    blend(1.0 - v, 1.0 - u, c[14], c[13], b[10], da, db);
    bu[10] = -db; bv[10] = -da;
    // b12: Fp3 on u = 0 (weight 1-v), Fm3 on v = 1 (weight u).
    blend(1.0 - v, u, c[18], c[19], b[9], da, db);
    bu[9] = db; bv[9] = -da;
    vec4 Bu, Bv, Du, Dv;
    bernstein(u, Bu, Du);
    bernstein(v, Bv, Dv);
    pos = vec3(0.0); du = vec3(0.0); dv = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            int k = i + 4 * j;
            pos += Bu[i] * Bv[j] * b[k];
            du += Du[i] * Bv[j] * b[k] + Bu[i] * Bv[j] * bu[k];
            dv += Bu[i] * Dv[j] * b[k] + Bu[i] * Bv[j] * bv[k];
        }
    }
}
