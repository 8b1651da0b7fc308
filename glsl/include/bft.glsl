// Loop limit surfaces from basis-function tables (Holländer & Boubekeur): the buffers of the
// BFT pipeline (set 1) and the evaluation every BFT stage shares. Layouts are written by
// `topology::bft::GpuBft`; `GpuBft::eval_tess` is this file's f32 mirror, kept in step.

layout(std430, set = 1, binding = 0) readonly buffer BasePositions { float base_xyz[]; };
layout(std430, set = 1, binding = 1) readonly buffer StencilOffsets { uint stencil_offsets[]; };
layout(std430, set = 1, binding = 2) readonly buffer StencilIndices { uint stencil_indices[]; };
layout(std430, set = 1, binding = 3) readonly buffer StencilWeights { float stencil_weights[]; };
layout(std430, set = 1, binding = 4) readonly buffer TangentOffsets { uint tangent_offsets[]; };
layout(std430, set = 1, binding = 5) readonly buffer TangentIndices { uint tangent_indices[]; };
layout(std430, set = 1, binding = 6) readonly buffer TangentWeights { vec2 tangent_weights[]; };
#ifdef BFT_WRITES_LEVEL1
layout(std430, set = 1, binding = 7) buffer Level1Positions { vec4 level1_pos[]; };
layout(std430, set = 1, binding = 8) buffer Level1Normals { vec4 level1_nrm[]; };
#else
layout(std430, set = 1, binding = 7) readonly buffer Level1Positions { vec4 level1_pos[]; };
layout(std430, set = 1, binding = 8) readonly buffer Level1Normals { vec4 level1_nrm[]; };
#endif
layout(std430, set = 1, binding = 9) readonly buffer Patches { uint patches[]; };
layout(std430, set = 1, binding = 10) readonly buffer TableWords { uint table_words[]; };
layout(std430, set = 1, binding = 11) readonly buffer TableWeights { float table_weights[]; };

// Push constant of every BFT pipeline (`tess::gpu::BftPush`).
layout(push_constant) uniform BftDraw {
    uint mode;            // 0: shaded, 1: wireframe
    uint first_patch;     // patch index of this draw's first patch (draw splits)
    uint factor_mode;     // 0: uniform, 1: screen-space edge length, 2: camera distance
    uint options;         // bit 0: geometric normals, 1: patch colours, 2: fractional factors
    float uniform_level;  // segments per level-1 edge (uniform mode)
    float pixels_per_segment;
    float distance_ref;   // distance at which an edge gets max_level segments
    float max_level;      // 2^L: the tables' level
    uint count;           // compute passes: number of level-1 vertices
} bft;

const uint PATCH_HEADER_WORDS = 9u;
const uint ENTRY_WORDS = 8u;

uint patch_word(uint face, uint k) { return patches[face * PATCH_HEADER_WORDS + k]; }

uint entry_word(uint entry, uint k) { return table_words[table_words[4] + entry * ENTRY_WORDS + k]; }

// Row of grid point (a, b) in the face's table and whether the slots are mirrored; 0xffffffff
// when the point carries no row.
uint bft_row(uint face, uint a, uint b, out bool flip) {
    uint h2 = patch_word(face, 2u);
    bool mirrored = (h2 >> 31) != 0u;
    uint entry = h2 & 0x7fffffffu;
    bool half_table = entry_word(entry, 1u) != 0u;
    uint grid = table_words[2];
    flip = mirrored;
    if (mirrored) { uint t = a; a = b; b = t; }
    if (half_table && a < b) { uint t = a; a = b; b = t; flip = !flip; }
    uint map = half_table ? table_words[7] : table_words[6];
    return table_words[map + a * (grid + 1u) + b];
}

// Sums one row's weights over the face's ring, slot by slot (one code path, `precise`, so two
// faces evaluating the same owner row produce the same bits). p: position; q: subdivision-
// shading normal, or du when geometric; r: dv when geometric.
void bft_accumulate(uint face, uint row, bool flip, bool geometric,
                    out vec3 p, out vec3 q, out vec3 r) {
    uint ring = patch_word(face, 0u);
    uint rs = patch_word(face, 1u);
    uint entry = patch_word(face, 2u) & 0x7fffffffu;
    uint perm = table_words[5] + entry_word(entry, 6u);
    uint off_pos = entry_word(entry, 3u);
    uint off_du = entry_word(entry, flip ? 5u : 4u);
    uint off_dv = entry_word(entry, flip ? 4u : 5u);
    precise vec3 ap = vec3(0.0), aq = vec3(0.0), ar = vec3(0.0);
    for (uint s = 0u; s < rs; ++s) {
        uint slot = flip ? table_words[perm + s] : s;
        uint base = row * rs + slot;
        uint v = patches[ring + s];
        vec3 x = level1_pos[v].xyz;
        float w = table_weights[off_pos + base];
        ap += w * x;
        if (geometric) {
            aq += table_weights[off_du + base] * x;
            ar += table_weights[off_dv + base] * x;
        } else {
            aq += w * level1_nrm[v].xyz;
        }
    }
    p = ap; q = aq; r = ar;
}

// The limit point (and normal source) at tess coordinate b (weights of v0, v1, v2) of `face`.
// Edge and corner points are evaluated by their owner face in the owner's frame; grid points
// with a row exactly; any other point by linear interpolation on the level-L lattice (the
// paper's virtual mesh at maximum level: fractional factors morph linearly). Returns whether
// the point was a table point.
bool bft_eval(uint face, vec3 b, bool geometric, out vec3 p, out vec3 n) {
    uint g = face;
    float u = b.y, v = b.z;
    int corner = b.x == 1.0 ? 0 : (b.y == 1.0 ? 1 : (b.z == 1.0 ? 2 : -1));
    int edge = b.z == 0.0 ? 0 : (b.x == 0.0 ? 1 : (b.y == 0.0 ? 2 : -1));
    if (corner >= 0) {
        uint o = patch_word(face, 6u + uint(corner));
        g = o >> 2;
        uint c = o & 3u;
        u = c == 1u ? 1.0 : 0.0;
        v = c == 2u ? 1.0 : 0.0;
    } else if (edge >= 0) {
        float t = edge == 0 ? b.y : (edge == 1 ? b.z : b.x);
        uint o = patch_word(face, 3u + uint(edge));
        g = o >> 2;
        if (g != face) t = 1.0 - t;
        uint ge = o & 3u;
        u = ge == 0u ? t : (ge == 1u ? 1.0 - t : 0.0);
        v = ge == 0u ? 0.0 : (ge == 1u ? t : 1.0 - t);
    }
    float grid = float(table_words[2]);
    float nseg = float(table_words[1]);
    vec2 ga = vec2(u, v) * grid;
    vec2 ra = floor(ga + 0.5);
    vec3 q, r;
    if (all(lessThan(abs(ga - ra), vec2(0.02)))) {
        bool flip;
        uint row = bft_row(g, uint(ra.x), uint(ra.y), flip);
        if (row != 0xffffffffu) {
            bft_accumulate(g, row, flip, geometric, p, q, r);
            n = geometric ? cross(q, r) : q;
            return true;
        }
    }
    float x = u * nseg, y = v * nseg;
    float i0 = min(floor(x), nseg - 1.0);
    float j0 = min(floor(y), nseg - 1.0 - i0);
    float fx = x - i0, fy = y - j0;
    uvec2 c0, c1, c2;
    vec3 w;
    if (fx + fy <= 1.0) {
        c0 = uvec2(i0, j0); c1 = uvec2(i0 + 1.0, j0); c2 = uvec2(i0, j0 + 1.0);
        w = vec3(1.0 - fx - fy, fx, fy);
    } else {
        c0 = uvec2(i0 + 1.0, j0 + 1.0); c1 = uvec2(i0, j0 + 1.0); c2 = uvec2(i0 + 1.0, j0);
        w = vec3(fx + fy - 1.0, 1.0 - fx, 1.0 - fy);
    }
    precise vec3 sp = vec3(0.0), sq = vec3(0.0), sr = vec3(0.0);
    uvec2 cs[3] = uvec2[3](c0, c1, c2);
    for (int k = 0; k < 3; ++k) {
        bool flip;
        uint row = bft_row(g, 3u * cs[k].x, 3u * cs[k].y, flip);
        vec3 pk, qk, rk;
        bft_accumulate(g, row, flip, geometric, pk, qk, rk);
        sp += w[k] * pk;
        sq += w[k] * qk;
        sr += w[k] * rk;
    }
    p = sp;
    n = geometric ? cross(sq, sr) : sq;
    return false;
}
