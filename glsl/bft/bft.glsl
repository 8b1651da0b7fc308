// Loop limit surfaces from basis-function tables (Holländer & Boubekeur): the buffers of the
// BFT pipeline and the evaluation every BFT stage shares.
//
// Every struct here mirrors one of `tess::bft` (crates/tess/src/techniques/bft/layout.rs) and is
// read by field name; set and binding numbers come from bindings.glsl; a test checks each
// block's binding, member offsets and array stride in the SPIR-V against the Rust structs.
// `GpuBft::eval_tess` is this file's f32 mirror, kept in step.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "bindings.glsl"

// One term of the two limit-tangent masks of a level-1 vertex (same control points).
struct TangentTerm { uint index; float weight_t1; float weight_t2; };
// Owners pack `face << BFT_OWNER_SHIFT | local index` (owner_face, owner_local); edge e runs
// v_e → v_(e+1), corner c is v_c.
struct PatchHeader {
    uint ring_offset;     // first slot of the patch's ring in patch_rings
    uint ring_size;
    uint entry;           // its table in table_entries
    uint mirrored;        // 1: the table is the mirror image (rows read transposed)
    uint edge_owner[3];
    uint corner_owner[3];
};
struct TableHeader {
    uint level;           // L: the tables' level
    uint segments;        // 2^L segments per patch edge
    uint grid;            // 3 * 2^L: the grid the row maps are indexed on
    uint entry_count;
    uint full_map_offset; // row map of full tables in row_maps
    uint half_map_offset; // row map of half (mirror-symmetric) tables
};
struct TableEntry {
    uint ring_size;
    uint half_table;      // 1: only the a >= b half is stored
    uint rows;
    uint position_offset; // weight blocks in table_weights (du/dv: 0xffffffff without tangents)
    uint du_offset;
    uint dv_offset;
    uint perm_offset;     // mirror permutation in mirror_perms
    uint kind;            // BFT_KIND_*: regular, extraordinary, boundary, private
};

layout(std430, set = BFT_SET, binding = BFT_TANGENT_OFFSETS_BINDING) readonly buffer TangentOffsets { uint tangent_offsets[]; };
layout(std430, set = BFT_SET, binding = BFT_TANGENT_TERMS_BINDING) readonly buffer TangentTerms { TangentTerm tangent_terms[]; };
#ifdef BFT_WRITES_LEVEL1
layout(std430, set = BFT_SET, binding = BFT_LEVEL1_POSITIONS_BINDING) buffer Level1Positions { vec4 level1_pos[]; };
layout(std430, set = BFT_SET, binding = BFT_LEVEL1_NORMALS_BINDING) buffer Level1Normals { vec4 level1_nrm[]; };
#else
layout(std430, set = BFT_SET, binding = BFT_LEVEL1_POSITIONS_BINDING) readonly buffer Level1Positions { vec4 level1_pos[]; };
layout(std430, set = BFT_SET, binding = BFT_LEVEL1_NORMALS_BINDING) readonly buffer Level1Normals { vec4 level1_nrm[]; };
#endif
layout(std430, set = BFT_SET, binding = BFT_PATCH_HEADERS_BINDING) readonly buffer PatchHeaders { PatchHeader patches[]; };
layout(std430, set = BFT_SET, binding = BFT_PATCH_RINGS_BINDING) readonly buffer PatchRings { uint patch_rings[]; };
// The tables are read through buffer references (GL_EXT_buffer_reference) at the device
// addresses the uniform block `BftTableArrays` holds, not through descriptors: every patch may
// read any table, so they cannot be windowed, and no `maxStorageBufferRange` limits them.
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Tables { TableHeader header; TableEntry entries[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer MirrorPerms { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer RowMaps { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer TableWeights { float v[]; };
// `tess::gpu::BftTableArrays`: each address a uvec2, low word first.
layout(std140, set = BFT_SET, binding = BFT_TABLE_ARRAYS_BINDING) uniform BftTableArrays {
    uvec2 tables;   // TableHeader, then one TableEntry per table
    uvec2 perms;    // mirror permutations of the tables' ring slots
    uvec2 maps;     // row maps: grid point -> table row, full tables then half tables
    uvec2 weights;  // basis-function weights of every table
} table_arrays;
#define table Tables(table_arrays.tables).header
#define table_entries Tables(table_arrays.tables).entries
#define mirror_perms MirrorPerms(table_arrays.perms).v
#define row_maps RowMaps(table_arrays.maps).v
#define table_weights TableWeights(table_arrays.weights).v

// Push constant of every BFT pipeline (`tess::gpu::BftPush`).
layout(push_constant) uniform BftPush {
    uint mode;            // DRAW_MODE_SHADED or DRAW_MODE_WIREFRAME
    uint first_patch;     // patch index of this draw's first patch (draw splits)
    uint factor_mode;     // BFT_FACTORS_UNIFORM, _SCREEN or _DISTANCE
    uint options;         // BFT_OPTION_* bits
    float uniform_level;  // segments per level-1 edge (uniform mode)
    float pixels_per_segment;
    float distance_ref;   // distance at which an edge gets max_level segments
    float max_level;      // 2^L: the tables' level
    uint count;           // compute passes: level-1 vertices of this chunk
    uint first_vertex;    // compute passes: the chunk's first level-1 vertex
    // Window bases of the chunk (tess::techniques::windows): every index into a windowed
    // buffer is global and has its space's base subtracted (the PATCH/RING/L1/... macros).
    uint patch_base;      // patches
    uint ring_base;       // patch_rings
    uint level1_base;     // level1_pos, level1_nrm, tangent_offsets
    uint tangent_base;    // tangent_terms
    uvec2 pad;
    vec4 pattern_outer;   // pattern path: the drawn pattern's edge levels (gl_TessLevelOuter's order)
} bft;

// Windowed reads by global index.
#define PATCH(f) patches[(f) - bft.patch_base]
#define RING(i) patch_rings[(i) - bft.ring_base]
#define L1_POS(v) level1_pos[(v) - bft.level1_base]
#define L1_NRM(v) level1_nrm[(v) - bft.level1_base]

const uint NO_ROW = 0xffffffffu;

uint owner_face(uint owner) { return owner >> BFT_OWNER_SHIFT; }
uint owner_local(uint owner) { return owner & uint(BFT_OWNER_LOCAL_MASK); }

// Row of grid point (a, b) in a table (mirrored: the face is the table's mirror image; half:
// only a >= b is stored) and whether the slots are mirrored; NO_ROW when the point has no row.
uint bft_row_of(bool mirrored, bool half_table, uint a, uint b, out bool flip) {
    uint grid = table.grid;
    flip = mirrored;
    if (mirrored) { uint t = a; a = b; b = t; }
    if (half_table && a < b) { uint t = a; a = b; b = t; flip = !flip; }
    uint map = half_table ? table.half_map_offset : table.full_map_offset;
    return row_maps[map + a * (grid + 1u) + b];
}

// bft_row_of for `face`, its table read from the headers.
uint bft_row(uint face, uint a, uint b, out bool flip) {
    bool mirrored = PATCH(face).mirrored != 0u;
    bool half_table = table_entries[PATCH(face).entry].half_table != 0u;
    return bft_row_of(mirrored, half_table, a, b, flip);
}

// Sums one row's weights over the face's ring, slot by slot (one code path, `precise`, so two
// faces evaluating the same owner row produce the same bits). p: position; q: subdivision-
// shading normal, or du when geometric; r: dv when geometric. One weight block a pass
// (position, then du and dv when geometric), as bft_accumulate_patch sums them: lavapipe runs
// a branch's reads even where no lane takes it, so a loop whose trip count the push constants
// fix costs less than du/dv reads behind an `if` in every slot.
void bft_accumulate_global(uint face, uint row, bool flip, bool geometric,
                           out vec3 p, out vec3 q, out vec3 r) {
    uint ring = PATCH(face).ring_offset;
    uint rs = PATCH(face).ring_size;
    uint entry = PATCH(face).entry;
    uint perm = table_entries[entry].perm_offset;
    p = vec3(0.0); q = vec3(0.0); r = vec3(0.0);
    precise vec3 an = vec3(0.0);
    uint blocks = geometric ? 3u : 1u;
    for (uint blk = 0u; blk < blocks; ++blk) {
        // du and dv exchange under the mirror.
        uint which = blk == 0u ? 0u : (flip ? 3u - blk : blk);
        uint off = (which == 0u ? table_entries[entry].position_offset
                    : (which == 1u ? table_entries[entry].du_offset : table_entries[entry].dv_offset)) + row * rs;
        precise vec3 a = vec3(0.0);
        for (uint s = 0u; s < rs; ++s) {
            uint slot = flip ? mirror_perms[perm + s] : s;
            uint v = RING(ring + s);
            float w = table_weights[off + slot];
            a += w * L1_POS(v).xyz;
            if (!geometric) an += w * L1_NRM(v).xyz;
        }
        if (blk == 0u) p = a; else if (blk == 1u) q = a; else r = a;
    }
    if (!geometric) q = an;
}

// The patch block: what the TCS gathers once per patch for the TES (lavapipe runs the TES on
// the CPU, where every storage-buffer read indexed by the patch is a per-lane gather while a
// patch input is one load for all of the patch's vertices). Header words, the slot
// permutation (5 bits a slot), then per ring slot its level-1 position and normal (6 floats),
// for rings of at most BFT_GATHER_SLOTS slots (valence 12 at an extraordinary vertex); larger
// rings read the global buffers. 29 locations, 116 components: within the 120 per-patch
// output components every Vulkan device has. Only in the BFT_PATCH_BLOCK build (the manifest's
// patch_block axis, `BftOptions::patch_block`): on a GPU the block's size costs more than the
// global reads it saves. Without it the TCS hands the TES the two header words alone.
#define BFT_GATHER_SLOTS 18u
#define BFT_GATHER_VEC4 27
#define BFT_INFO_RING_MASK 0xffu
#define BFT_INFO_MIRRORED 0x100u
#define BFT_INFO_HALF 0x200u
#define BFT_INFO_GATHERED 0x400u
#define BFT_INFO_KIND_SHIFT 12u
#if defined(BFT_PATCH_OUT)
#define BFT_PATCH_QUALIFIER patch out
#elif defined(BFT_PATCH_IN)
#define BFT_PATCH_QUALIFIER patch in
#endif
#ifdef BFT_PATCH_LOCAL
// The refinement-pattern vertex stage (pattern.vert): no control stage gathers the patch, so
// its head is a plain variable the stage fills (face only: no ring gathered, every row read
// from the global buffers, as the evaluation stage reads shared points).
uvec4 tc_head;
#endif
#ifdef BFT_PATCH_QUALIFIER
// x: face, y: info (ring size, BFT_INFO_* bits, kind), z: position_offset, w: du_offset.
layout(location = 0) BFT_PATCH_QUALIFIER uvec4 tc_head;
// x: dv_offset, y..w: the mirror permutation, six 5-bit slots a word.
layout(location = 1) BFT_PATCH_QUALIFIER uvec4 tc_aux;
#ifdef BFT_PATCH_BLOCK
layout(location = 2) BFT_PATCH_QUALIFIER vec4 tc_ring[BFT_GATHER_VEC4];
#endif
#endif

#if defined(BFT_PATCH_IN) && defined(BFT_PATCH_BLOCK)
float bft_gathered(uint k) { return tc_ring[k >> 2u][k & 3u]; }

// bft_accumulate_global over the gathered ring of this patch, for its interior points only
// (bft_eval): no other patch evaluates them, so their bits need not equal the global path's,
// and on NVIDIA's compiler they do not.
void bft_accumulate_patch(uint row, bool flip, bool geometric,
                          out vec3 p, out vec3 q, out vec3 r) {
    uint rs = tc_head.y & BFT_INFO_RING_MASK;
    uint off_du = flip ? tc_aux.x : tc_head.w;
    uint off_dv = flip ? tc_head.w : tc_aux.x;
    p = vec3(0.0); q = vec3(0.0); r = vec3(0.0);
    precise vec3 an = vec3(0.0);
    uint blocks = geometric ? 3u : 1u;
    for (uint blk = 0u; blk < blocks; ++blk) {
        uint off = (blk == 0u ? tc_head.z : (blk == 1u ? off_du : off_dv)) + row * rs;
        precise vec3 a = vec3(0.0);
        // No `if (s < rs)`: slots past the ring hold zero points (bft.tesc) and read a weight
        // clamped into the row, so their products are ±0, which leave the sum's bits as the
        // global path's (a running sum that starts at +0 never becomes -0); llvmpipe would run
        // the masked slots anyway, and the mask bookkeeping is saved.
        [[unroll]] for (uint s = 0u; s < BFT_GATHER_SLOTS; ++s) {
            uint mirrored_slot = (tc_aux[1u + s / 6u] >> (5u * (s % 6u))) & 31u;
            vec3 x = vec3(bft_gathered(6u * s), bft_gathered(6u * s + 1u), bft_gathered(6u * s + 2u));
            float w = table_weights[off + min(flip ? mirrored_slot : s, rs - 1u)];
            a += w * x;
            an += w * vec3(bft_gathered(6u * s + 3u), bft_gathered(6u * s + 4u), bft_gathered(6u * s + 5u));
        }
        if (blk == 0u) p = a; else if (blk == 1u) q = a; else r = a;
    }
    if (!geometric) q = an;
}
#endif

#if defined(BFT_PATCH_IN) || defined(BFT_PATCH_LOCAL)
// One row of face g: from the patch block when g is this patch and its ring was gathered,
// else from the global buffers (the same arithmetic either way).
uint bft_row_at(uint g, bool local, uint a, uint b, out bool flip) {
    if (local) {
        uint info = tc_head.y;
        return bft_row_of((info & BFT_INFO_MIRRORED) != 0u, (info & BFT_INFO_HALF) != 0u, a, b, flip);
    }
    return bft_row(g, a, b, flip);
}

void bft_accumulate(uint g, bool local, uint row, bool flip, bool geometric,
                    out vec3 p, out vec3 q, out vec3 r) {
#ifdef BFT_PATCH_BLOCK
    if (local) {
        bft_accumulate_patch(row, flip, geometric, p, q, r);
        return;
    }
#endif
    bft_accumulate_global(g, row, flip, geometric, p, q, r);
}

// The point of owner-frame parameter t along local edge ge (edge e runs v_e -> v_(e+1)) as
// (u, v), the weights of v1 and v2.
vec2 bft_edge_point(uint ge, float t) {
    return ge == 0u ? vec2(t, 0.0) : (ge == 1u ? vec2(1.0 - t, t) : vec2(0.0, 1.0 - t));
}

// Where tess coordinate b (weights of v0, v1, v2) of `face` is evaluated: the face g that owns
// the point (its own unless b is on an edge or corner another face owns) and the point (u, v)
// in g's frame; which corner and edge of `face` b lies on (-1: none); on an edge, the
// parameter t along the owner's edge, in the owner's direction.
void bft_locate(uint face, vec3 b, out uint g, out vec2 uv, out int corner, out int edge, out float t) {
    g = face;
    uv = b.yz;
    t = 0.0;
    corner = b.x == 1.0 ? 0 : (b.y == 1.0 ? 1 : (b.z == 1.0 ? 2 : -1));
    edge = b.z == 0.0 ? 0 : (b.x == 0.0 ? 1 : (b.y == 0.0 ? 2 : -1));
    if (corner >= 0) {
        uint o = PATCH(face).corner_owner[corner];
        g = owner_face(o);
        uint c = owner_local(o);
        uv = vec2(c == 1u ? 1.0 : 0.0, c == 2u ? 1.0 : 0.0);
    } else if (edge >= 0) {
        t = edge == 0 ? b.y : (edge == 1 ? b.z : b.x);
        uint o = PATCH(face).edge_owner[edge];
        g = owner_face(o);
        if (g != face) t = 1.0 - t;
        uv = bft_edge_point(owner_local(o), t);
    }
}

// The limit point at (u, v) of face g (local: g is this patch, its ring gathered into the patch
// block, and the point interior): grid points with a row exactly; any other point by linear
// interpolation on the level-L lattice (the paper's virtual mesh at maximum level: fractional
// factors morph linearly). Returns whether the point was a table point.
bool bft_eval_at(uint g, bool local, vec2 uv, bool geometric, out vec3 p, out vec3 n) {
    float u = uv.x, v = uv.y;
    float grid = float(table.grid);
    float nseg = float(table.segments);
    vec2 ga = vec2(u, v) * grid;
    vec2 ra = floor(ga + 0.5);
    vec3 q, r;
#ifdef SPACING_EQUAL
    // Equal spacing: the factors are powers of two (bft.tesc), so every point is a table point
    // and the virtual-mesh interpolation below is not compiled (lavapipe runs both sides of a
    // branch, masked: the interpolation's three rows cost three times the one row). A point
    // without a row (none is made; validate() proves every dyadic point has one) takes the
    // first row (a finite point, flagged inexact) rather than paying a second lookup per vertex.
    bool flip;
    uint row = bft_row_at(g, local, uint(ra.x), uint(ra.y), flip);
    bool exact = row != NO_ROW && all(lessThan(abs(ga - ra), vec2(0.02)));
    if (row == NO_ROW) row = 0u;
    bft_accumulate(g, local, row, flip, geometric, p, q, r);
    n = geometric ? cross(q, r) : q;
    return exact;
#else
    if (all(lessThan(abs(ga - ra), vec2(0.02)))) {
        bool flip;
        uint row = bft_row_at(g, local, uint(ra.x), uint(ra.y), flip);
        if (row != NO_ROW) {
            bft_accumulate(g, local, row, flip, geometric, p, q, r);
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
        uint row = bft_row_at(g, local, 3u * cs[k].x, 3u * cs[k].y, flip);
        vec3 pk, qk, rk;
        bft_accumulate(g, local, row, flip, geometric, pk, qk, rk);
        sp += w[k] * pk;
        sq += w[k] * qk;
        sr += w[k] * rk;
    }
    p = sp;
    n = geometric ? cross(sq, sr) : sq;
    return false;
#endif
}

// The limit point (and normal source) at tess coordinate b (weights of v0, v1, v2) of `face`.
// Edge and corner points are evaluated by their owner face in the owner's frame (bft_locate);
// the rest is bft_eval_at. Returns whether the point was a table point.
bool bft_eval(uint face, vec3 b, bool geometric, out vec3 p, out vec3 n) {
    uint g;
    vec2 uv;
    int corner, edge;
    float t;
    bft_locate(face, b, g, uv, corner, edge, t);
    // Shared points (edges, corners) always take the global path, also in their owner: one code
    // path for both faces of an edge, so their bits cannot depend on how a compiler schedules
    // two. (NVIDIA's rounds the unrolled patch-block sum differently from the global loop over
    // the same products, which cracked every shared point; a non-unrolled block loop matches
    // there but costs lavapipe a quarter more: docs/benchmarks.md, "Table I on an NVIDIA
    // H100".) Only interior points read the patch block.
    bool local = g == face && corner < 0 && edge < 0 && (tc_head.y & BFT_INFO_GATHERED) != 0u;
    return bft_eval_at(g, local, uv, geometric, p, n);
}

#endif
