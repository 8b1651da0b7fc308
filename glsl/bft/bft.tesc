#version 450
// Tessellation factors of a level-1 face. Every edge factor is computed from the edge's two
// endpoints only, taken in global index order, so both faces of an edge compute the same bits
// and the tessellator makes the same points on it: no cracks by construction.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "bft.glsl"
layout(vertices = 1) out;
layout(location = 0) flat in uint in_face[];
layout(location = 0) patch out uint tc_face;

float edge_factor(uint a, uint b) {
    uint lo = min(a, b), hi = max(a, b);
    vec3 p = L1_POS(lo).xyz, q = L1_POS(hi).xyz;
    float f;
    if (bft.factor_mode == BFT_FACTORS_SCREEN) {
        vec4 cp = frame.view_proj * vec4(p, 1.0), cq = frame.view_proj * vec4(q, 1.0);
        if (cp.w <= 1e-6 || cq.w <= 1e-6) {
            f = bft.max_level; // crosses the eye plane: no screen length, refine fully
        } else {
            vec2 sp = cp.xy / cp.w * 0.5 * frame.viewport.xy;
            vec2 sq = cq.xy / cq.w * 0.5 * frame.viewport.xy;
            f = length(sp - sq) / bft.pixels_per_segment;
        }
    } else if (bft.factor_mode == BFT_FACTORS_DISTANCE) {
        float d = distance(frame.camera_pos.xyz, 0.5 * (p + q));
        f = bft.max_level * bft.distance_ref / max(d, 1e-6);
    } else {
        f = bft.uniform_level;
    }
    f = clamp(f, 1.0, bft.max_level);
    // Power-of-two factors keep every tess vertex on a table point (exact limit); fractional
    // factors morph continuously on the level-L virtual mesh instead.
    if ((bft.options & uint(BFT_OPTION_FRACTIONAL)) == 0u) f = exp2(ceil(log2(f) - 1e-4));
    return f;
}

void main() {
    uint face = in_face[0];
    tc_face = face;
    uint ring = PATCH(face).ring_offset;
    uint v0 = RING(ring), v1 = RING(ring + 1u), v2 = RING(ring + 2u);
    // gl_TessLevelOuter[i] is the edge opposite corner i: v1v2, v2v0, v0v1.
    float e0 = edge_factor(v1, v2), e1 = edge_factor(v2, v0), e2 = edge_factor(v0, v1);
    gl_TessLevelOuter[0] = e0;
    gl_TessLevelOuter[1] = e1;
    gl_TessLevelOuter[2] = e2;
    gl_TessLevelInner[0] = max(e0, max(e1, e2));
}
