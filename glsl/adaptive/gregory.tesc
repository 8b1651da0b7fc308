#version 450
// Gregory end caps: the 20 control points fetched once per patch (invocation i fetches point i)
// instead of per tessellated vertex.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "tesc_levels.glsl"
layout(vertices = 20) out;
layout(location = 0) flat in uint in_patch[];
layout(location = 0) patch out uint tc_patch;
layout(location = 2) patch out uint tc_info;
layout(location = 1) out vec3 tc_points[];
void main() {
    uint id = in_patch[0];
    AdaptivePatch p = PATCHES[id];
    tc_points[gl_InvocationID] = vtx(CONTROL_POINTS[p.cp_offset + uint(gl_InvocationID)]);
    if (gl_InvocationID == 0) {
        tc_patch = id;
        tc_info = p.info;
        set_patch_levels(p);
    }
}
