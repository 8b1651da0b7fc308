// A regular patch's bicubic Bezier point k = i + 4 j (i along u) from its 16 uniform B-spline
// control points: what regular.tesc's invocation k computes once per patch and the pattern
// vertex stage (pattern_regular.vert) once per vertex, in one operand order, so both paths
// evaluate the same net bits. Both read the 16 points once (bspline_points): the pattern stage
// does it per vertex, where lavapipe runs each storage load lane by lane.

// Uniform cubic B-spline to Bezier, one row: Bezier point k from B-spline points 0..3.
const mat4 TO_BEZIER = mat4(
    vec4(1.0, 0.0, 0.0, 0.0) / 6.0,
    vec4(4.0, 4.0, 2.0, 1.0) / 6.0,
    vec4(1.0, 2.0, 4.0, 4.0) / 6.0,
    vec4(0.0, 0.0, 0.0, 1.0) / 6.0);

// The patch's 16 B-spline points, row-major.
void bspline_points(AdaptivePatch p, out vec3 cp[16]) {
    for (uint k = 0u; k < 16u; ++k) cp[k] = vtx(CONTROL_POINTS[p.cp_offset + k]);
}

vec3 bezier_point(vec3 cp[16], uint k) {
    uint i = k & 3u, j = k >> 2;
    vec3 b = vec3(0.0);
    for (uint r = 0u; r < 4u; ++r) {
        float wv = TO_BEZIER[r][j];
        if (wv == 0.0) continue;
        vec3 row = vec3(0.0);
        for (uint c = 0u; c < 4u; ++c) {
            float wu = TO_BEZIER[c][i];
            if (wu != 0.0) row += wu * cp[4u * r + c];
        }
        b += wv * row;
    }
    return b;
}
