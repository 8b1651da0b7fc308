// Geomorphing inside a triangle pattern (the refinement-pattern path of BFT and of the planned
// surfaces' Gregory triangles): a pattern of even inner level n drawn at the inside's weight w
// puts each odd lattice vertex the fraction 1 - w of the way to an even neighbour, which the
// pattern of half the level also has. The barycentric indices (i, j, k) of a vertex at uv (its
// weights i / n, j / n) sum to n, so it has two odd indices or none; it slides to the neighbour
// that makes both even, away from the edge where one index is 1 and the other can give.
vec2 morph_triangle_inside(vec2 uv, float n, float w) {
    vec2 ij = round(uv * n);
    float k = n - ij.x - ij.y;
    vec3 odd = mod(vec3(ij, k), 2.0);
    if (odd.x + odd.y + odd.z == 0.0) return uv;
    vec2 d;
    if (odd.x > 0.0 && odd.y > 0.0) {
        d = ij.x >= 3.0 ? vec2(-1.0, 1.0) : (ij.y >= 3.0 ? vec2(1.0, -1.0) : vec2(-1.0, -1.0));
    } else if (odd.x > 0.0) {
        d = (ij.x >= 3.0 || k < 3.0) ? vec2(-1.0, 0.0) : vec2(1.0, 0.0);
    } else {
        d = (ij.y >= 3.0 || k < 3.0) ? vec2(0.0, -1.0) : vec2(0.0, 1.0);
    }
    return uv + (1.0 - w) * ((ij + d) / n - uv);
}
