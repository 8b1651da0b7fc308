#version 450
// Regular patches: the bicubic uniform B-spline of 16 control points (row-major 4x4 around the
// face, phantom points already in place for boundaries and infinitely sharp creases),
// evaluated directly in the B-spline basis.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tese_out.glsl"
layout(quads, SPACING, ccw) in;

void bspline(float t, out vec4 b, out vec4 d) {
    float s = 1.0 - t, t2 = t * t, t3 = t2 * t;
    b = vec4(s * s * s, 3.0 * t3 - 6.0 * t2 + 4.0, -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0, t3) / 6.0;
    d = vec4(-s * s, 3.0 * t2 - 4.0 * t, -3.0 * t2 + 2.0 * t + 1.0, t2) * 0.5;
}

void evaluate(AdaptivePatch p, vec2 uv, out vec3 pos, out vec3 du, out vec3 dv) {
    vec4 bu, bv, du_w, dv_w;
    bspline(uv.x, bu, du_w);
    bspline(uv.y, bv, dv_w);
    pos = vec3(0.0); du = vec3(0.0); dv = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        vec3 row = vec3(0.0), drow = vec3(0.0);
        for (int i = 0; i < 4; ++i) {
            vec3 c = vtx(control_points[p.cp_offset + uint(4 * j + i)]);
            row += bu[i] * c;
            drow += du_w[i] * c;
        }
        pos += bv[j] * row;
        du += bv[j] * drow;
        dv += dv_w[j] * row;
    }
}

#include "tese_main.glsl"
