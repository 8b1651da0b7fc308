// A regular patch's bicubic Bezier point k = i + 4 j (i along u) from its 16 uniform B-spline
// control points: what regular.tesc's invocation k computes once per patch and the pattern
// vertex stage (pattern_regular.vert) once per vertex, in one operand order, so both paths
// evaluate the same net bits.

// Uniform cubic B-spline to Bezier, one row: Bezier point k from B-spline points 0..3.
const mat4 TO_BEZIER = mat4(
    vec4(1.0, 0.0, 0.0, 0.0) / 6.0,
    vec4(4.0, 4.0, 2.0, 1.0) / 6.0,
    vec4(1.0, 2.0, 4.0, 4.0) / 6.0,
    vec4(0.0, 0.0, 0.0, 1.0) / 6.0);

vec3 bezier_point(AdaptivePatch p, uint k) {
    uint i = k & 3u, j = k >> 2;
    vec3 b = vec3(0.0);
    for (uint r = 0u; r < 4u; ++r) {
        float wv = TO_BEZIER[r][j];
        if (wv == 0.0) continue;
        vec3 row = vec3(0.0);
        for (uint c = 0u; c < 4u; ++c) {
            float wu = TO_BEZIER[c][i];
            if (wu != 0.0) row += wu * vtx(CONTROL_POINTS[p.cp_offset + 4u * r + c]);
        }
        b += wv * row;
    }
    return b;
}
