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

// A Gregory triangle patch (triangle.tese: gl_TessCoord = (u, v, 1 - u - v) at patch
// corners 1, 2, 0): outer 0 is the edge u = 0 (patch edge 2), 1 is v = 0 (edge 0), 2 is
// 1 - u - v = 0 (edge 1).
void set_triangle_levels(AdaptivePatch p) {
    float e0 = edge_level(p, 0u), e1 = edge_level(p, 1u), e2 = edge_level(p, 2u);
    gl_TessLevelOuter[0] = e2;
    gl_TessLevelOuter[1] = e0;
    gl_TessLevelOuter[2] = e1;
    gl_TessLevelInner[0] = max(max(e0, e1), e2);
}
