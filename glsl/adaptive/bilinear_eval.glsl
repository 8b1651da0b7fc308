// A bilinear (Coons) end cap's evaluation from its four canonical curves (see bilinear.tese),
// shared by the evaluation stage and the pattern vertex stage (pattern_bilinear.vert).
void evaluate(uint id, vec2 uv, out vec3 pos, out vec3 du, out vec3 dv) {
    AdaptivePatch p = PATCHES[id];
    float u = uv.x, v = uv.y;
    // Boundary curves in the patch's (u, v): bottom (v = 0), right (u = 1), top (v = 1), left (u = 0).
    vec3 b = edge_point(p, 0u, u), r = edge_point(p, 1u, v);
    vec3 t = edge_point(p, 2u, 1.0 - u), l = edge_point(p, 3u, 1.0 - v);
    vec3 c0 = edge_point(p, 0u, 0.0), c1 = edge_point(p, 1u, 0.0), c2 = edge_point(p, 2u, 0.0), c3 = edge_point(p, 3u, 0.0);
    pos = (1.0 - v) * b + v * t + (1.0 - u) * l + u * r
        - ((1.0 - u) * (1.0 - v) * c0 + u * (1.0 - v) * c1 + u * v * c2 + (1.0 - u) * v * c3);
    // Derivatives by central differences along the boundary curves (normals only).
    const float h = 1.0 / 512.0;
    vec3 db = (edge_point(p, 0u, min(u + h, 1.0)) - edge_point(p, 0u, max(u - h, 0.0))) / (min(u + h, 1.0) - max(u - h, 0.0));
    vec3 dt = -(edge_point(p, 2u, min(1.0 - u + h, 1.0)) - edge_point(p, 2u, max(1.0 - u - h, 0.0))) / (min(1.0 - u + h, 1.0) - max(1.0 - u - h, 0.0));
    vec3 dr = (edge_point(p, 1u, min(v + h, 1.0)) - edge_point(p, 1u, max(v - h, 0.0))) / (min(v + h, 1.0) - max(v - h, 0.0));
    vec3 dl = -(edge_point(p, 3u, min(1.0 - v + h, 1.0)) - edge_point(p, 3u, max(1.0 - v - h, 0.0))) / (min(1.0 - v + h, 1.0) - max(1.0 - v - h, 0.0));
    du = (1.0 - v) * db + v * dt - l + r - ((1.0 - v) * (c1 - c0) + v * (c2 - c3));
    dv = -b + t + (1.0 - u) * dl + u * dr - ((1.0 - u) * (c3 - c0) + u * (c2 - c1));
}
