#version 450
// Tessellation factors of a level-1 face, and its header words; in the BFT_PATCH_BLOCK build
// its patch block too (bft.glsl): the ring's level-1 positions and normals, read here once
// instead of once per tessellated vertex. Every edge factor is computed from the edge's two
// endpoints only, taken in global index order, so both faces of an edge compute the same bits
// and the tessellator makes the same points on it: no cracks by construction.
#extension GL_EXT_control_flow_attributes : require
#define TECHNIQUE_PUSH_CONSTANTS
#define BFT_PATCH_OUT
#include "frame.glsl"
#include "bft.glsl"
layout(vertices = 1) out;
layout(location = 0) flat in uint in_face[];

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
    uint ring = PATCH(face).ring_offset;
    uint rs = PATCH(face).ring_size;
    uint entry = PATCH(face).entry;
#ifdef BFT_PATCH_BLOCK
    bool gathered = rs <= BFT_GATHER_SLOTS;
#else
    bool gathered = false;
#endif
    uint info = rs | (PATCH(face).mirrored != 0u ? BFT_INFO_MIRRORED : 0u)
        | (table_entries[entry].half_table != 0u ? BFT_INFO_HALF : 0u)
        | (gathered ? BFT_INFO_GATHERED : 0u)
        | (table_entries[entry].kind << BFT_INFO_KIND_SHIFT);
    tc_head = uvec4(face, info, table_entries[entry].position_offset, table_entries[entry].du_offset);
    uvec3 perm_words = uvec3(0u);
#ifdef BFT_PATCH_BLOCK
    uint perm = table_entries[entry].perm_offset;
    float slots[4 * BFT_GATHER_VEC4];
    [[unroll]] for (uint s = 0u; s < BFT_GATHER_SLOTS; ++s) {
        vec3 x = vec3(0.0), nrm = vec3(0.0);
        if (gathered && s < rs) {
            uint v = RING(ring + s);
            x = L1_POS(v).xyz;
            nrm = L1_NRM(v).xyz;
            perm_words[s / 6u] |= mirror_perms[perm + s] << (5u * (s % 6u));
        }
        slots[6u * s] = x.x; slots[6u * s + 1u] = x.y; slots[6u * s + 2u] = x.z;
        slots[6u * s + 3u] = nrm.x; slots[6u * s + 4u] = nrm.y; slots[6u * s + 5u] = nrm.z;
    }
    [[unroll]] for (int k = 0; k < BFT_GATHER_VEC4; ++k) {
        tc_ring[k] = vec4(slots[4 * k], slots[4 * k + 1], slots[4 * k + 2], slots[4 * k + 3]);
    }
#endif
    tc_aux = uvec4(table_entries[entry].dv_offset, perm_words);
    uint v0 = RING(ring), v1 = RING(ring + 1u), v2 = RING(ring + 2u);
    // gl_TessLevelOuter[i] is the edge opposite corner i: v1v2, v2v0, v0v1.
    float e0 = edge_factor(v1, v2), e1 = edge_factor(v2, v0), e2 = edge_factor(v0, v1);
    gl_TessLevelOuter[0] = e0;
    gl_TessLevelOuter[1] = e1;
    gl_TessLevelOuter[2] = e2;
    gl_TessLevelInner[0] = max(e0, max(e1, e2));
}
