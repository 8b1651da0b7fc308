#version 450
// Regular patches: the 16 B-spline control points converted to the bicubic Bezier net once per
// patch (invocation i + 4 j computes Bezier point (i, j)), so the TES reads its net from the
// patch instead of fetching 16 indexed vertices per tessellated vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tesc_levels.glsl"
layout(vertices = 16) out;
layout(location = 0) flat in uint in_patch[];
layout(location = 0) patch out uint tc_patch;
layout(location = 2) patch out uint tc_info;
layout(location = 1) out vec3 tc_bezier[];

// Uniform cubic B-spline to Bezier, one row: Bezier point k from B-spline points 0..3.
const mat4 TO_BEZIER = mat4(
    vec4(1.0, 0.0, 0.0, 0.0) / 6.0,
    vec4(4.0, 4.0, 2.0, 1.0) / 6.0,
    vec4(1.0, 2.0, 4.0, 4.0) / 6.0,
    vec4(0.0, 0.0, 0.0, 1.0) / 6.0);

void main() {
    uint id = in_patch[0];
    AdaptivePatch p = PATCHES[id];
    uint k = uint(gl_InvocationID);
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
    tc_bezier[gl_InvocationID] = b;
    if (gl_InvocationID == 0) {
        tc_patch = id;
        tc_info = p.info;
        set_patch_levels(p);
    }
}
