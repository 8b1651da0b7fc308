// Edge levels of one patch from its canonical curves only (see adaptive.glsl): the two sides
// of every edge compute the same level; a coarse transition edge gets twice its fine halves'.
void set_patch_levels(AdaptivePatch p) {
    float e0 = edge_level(p, 0u), e1 = edge_level(p, 1u), e2 = edge_level(p, 2u), e3 = edge_level(p, 3u);
    // Quad domain: outer 0 is the edge u = 0 (patch edge 3), 1 is v = 0 (edge 0), 2 is u = 1
    // (edge 1), 3 is v = 1 (edge 2).
    gl_TessLevelOuter[0] = e3;
    gl_TessLevelOuter[1] = e0;
    gl_TessLevelOuter[2] = e1;
    gl_TessLevelOuter[3] = e2;
    gl_TessLevelInner[0] = max(e0, e2);
    gl_TessLevelInner[1] = max(e1, e3);
}

// The per-patch block every adaptive evaluation stage reads (see ADAPTIVE_TESE in
// adaptive.glsl): header (patch id, info, edge info) and the 8 curve slots' 32 points packed as
// 96 floats in 24 vec4 (100 components in all, within the 120 every device has).
layout(location = 0) patch out uvec4 tc_head;
layout(location = 2) patch out vec4 tc_curve_floats[24];

// Float f of the packed curve points: point f / 3 is slot f / 12's point (f / 3) % 4.
float curve_float(AdaptivePatch p, uint f) {
    uint i = f / 3u;
    uvec4 b = curves[p.curves[i >> 2]];
    return vertices[b[i & 3u]][f % 3u];
}

// Writes vec4 blocks first, first + stride, ... (each block whole, by one invocation).
void write_patch_block(AdaptivePatch p, uint id, uint first, uint stride) {
    for (uint k = first; k < 24u; k += stride) {
        uint f = 4u * k;
        tc_curve_floats[k] = vec4(curve_float(p, f), curve_float(p, f + 1u), curve_float(p, f + 2u), curve_float(p, f + 3u));
    }
    if (first == 0u) tc_head = uvec4(id, p.info, p.edge_info, 0u);
}
