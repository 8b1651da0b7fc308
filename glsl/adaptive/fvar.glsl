// Smooth texture coordinates: the face-varying patches of topology::patches::fvar, looked up
// by the base (sub-)face parameter. Mirrors FVarPatches::texcoord (and
// PlannedPatches::texcoord on the host). The patches are one uint array, FVAR
// (tess::techniques::planned_patches::layout::fvar_words): a header (the first word of the
// tree nodes, of the leaves, of the points), the nodes (the entries of the four quadrants,
// q = (s >= 1/2) + 2 (t >= 1/2)), the leaves (1 for a 15-point Gregory triangle, else 0 for
// the 20-point Gregory form; first point) and the points (two float bit patterns each).
// Every read is checked against arrays.fvar_count: a bad entry gives the fallback, never a
// read out of bounds.

// topology::patches::fvar's FVAR_LEAF and FVAR_EMPTY (also PatchSurface::fvar_root's "none"),
// in hex: a #define'd decimal cannot carry the high bit. A host test checks these lines.
const uint FVAR_LEAF = 0x80000000u;
const uint FVAR_EMPTY = 0xffffffffu;

void gregory_triangle(vec3 c[15], vec2 uv, out vec3 pos, out vec3 du, out vec3 dv);

uint fvar_word(uint i) { return i < arrays.fvar_count ? FVAR[i] : FVAR_EMPTY; }

vec2 fvar_point(uint k) {
    uint i = fvar_word(2u) + 2u * k;
    if (i >= arrays.fvar_count || i + 1u >= arrays.fvar_count) return vec2(0.0);
    return vec2(uintBitsToFloat(FVAR[i]), uintBitsToFloat(FVAR[i + 1u]));
}

// (a F + b G) / (a + b), the midpoint where both weights vanish (gregory.tese's blend).
vec2 fvar_blend(float a, float b, vec2 f, vec2 g) {
    float d = a + b;
    return d < 1e-7 ? 0.5 * (f + g) : (a * f + b * g) / d;
}

// A 20-point Gregory patch (gregory.tese's point order) at (u, v): the point only. The
// Bezier net is summed in a loop that stays a loop, reading each point where it is used: no
// local arrays (this runs in every surface-build TES, and lavapipe pays for its code size
// even where no patch has face-varying coordinates).
vec2 fvar_gregory(uint first, vec2 uv) {
    // Bezier point b[i + 4 j] -> Gregory point; the four interior ones are blended first.
    const uint SLOT[16] = uint[16](0u, 1u, 7u, 5u, 2u, 0u, 0u, 6u, 16u, 0u, 0u, 12u, 15u, 17u, 11u, 10u);
    float u = uv.x, v = uv.y, s = 1.0 - u, t = 1.0 - v;
    vec2 b5 = fvar_blend(u, v, fvar_point(first + 3u), fvar_point(first + 4u));
    vec2 b6 = fvar_blend(s, v, fvar_point(first + 9u), fvar_point(first + 8u));
    vec2 b10 = fvar_blend(t, s, fvar_point(first + 14u), fvar_point(first + 13u));
    vec2 b9 = fvar_blend(t, u, fvar_point(first + 18u), fvar_point(first + 19u));
    vec4 bu = vec4(s * s * s, 3.0 * u * s * s, 3.0 * u * u * s, u * u * u);
    vec4 bv = vec4(t * t * t, 3.0 * v * t * t, 3.0 * v * v * t, v * v * v);
    vec2 acc = vec2(0.0);
    [[dont_unroll]] for (uint k = 0u; k < 16u; ++k) {
        vec2 b = k == 5u ? b5 : k == 6u ? b6 : k == 9u ? b9 : k == 10u ? b10 : fvar_point(first + SLOT[k]);
        acc += bu[k & 3u] * bv[k >> 2u] * b;
    }
    return acc;
}

// A 15-point Gregory triangle at barycentric (u, v) (surface.glsl's gregory_triangle).
vec2 fvar_triangle(uint first, vec2 uv) {
    vec3 c[15];
    for (uint i = 0u; i < 15u; ++i) c[i] = vec3(fvar_point(first + i), 0.0);
    vec3 pos, du, dv;
    gregory_triangle(c, uv, pos, du, dv);
    return pos.xy;
}

// The texture coordinate under root entry `root` at (sub-)face parameter `st` (a triangle
// patch's barycentric (u, v)); `fallback` where the tree names nothing there.
vec2 fvar_texcoord(uint root, vec2 st, vec2 fallback) {
    uint entry = root;
    vec2 p = st;
    for (uint depth = 0u; depth <= uint(ADAPTIVE_FVAR_MAX_DEPTH); ++depth) {
        if (entry == FVAR_EMPTY) return fallback;
        if ((entry & FVAR_LEAF) != 0u) {
            uint leaf = fvar_word(1u) + 2u * (entry & ~FVAR_LEAF);
            uint triangle = fvar_word(leaf), first = fvar_word(leaf + 1u);
            if (triangle == 1u) return fvar_triangle(first, p);
            if (triangle == 0u) return fvar_gregory(first, clamp(p, 0.0, 1.0));
            return fallback;
        }
        bvec2 high = greaterThanEqual(p, vec2(0.5));
        uint q = (high.x ? 1u : 0u) + (high.y ? 2u : 0u);
        entry = fvar_word(fvar_word(0u) + 4u * entry + q);
        p = 2.0 * p - vec2(high);
    }
    return fallback;
}
