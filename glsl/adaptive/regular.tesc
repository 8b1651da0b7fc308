#version 450
// Regular patches: the 16 B-spline control points converted to the bicubic Bezier net once per
// patch (invocation i + 4 j computes Bezier point (i, j)), so the TES reads its net from the
// patch instead of fetching 16 indexed vertices per tessellated vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tesc_levels.glsl"
#include "regular_net.glsl"
layout(vertices = 16) out;
layout(location = 0) flat in uint in_patch[];
layout(location = 0) patch out uint tc_patch;
layout(location = 2) patch out uint tc_info;
layout(location = 1) out vec3 tc_bezier[];

void main() {
    uint id = in_patch[0];
    AdaptivePatch p = PATCHES[id];
    vec3 cp[16];
    bspline_points(p, cp);
    tc_bezier[gl_InvocationID] = bezier_point(cp, uint(gl_InvocationID));
    if (gl_InvocationID == 0) {
        tc_patch = id;
        tc_info = p.info;
        set_patch_levels(p);
    }
}
