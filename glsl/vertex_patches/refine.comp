#version 450
// One Doo-Sabin step of every vertex patch, depth d -> d + 1 (Fan and Cheng §2;
// `tess::techniques::vertex_patches`, the layout of `topology::patches::doo_sabin`). Each patch
// is a one-dimensional array in its own region of one buffer; a work item is one point of a
// patch's inner layers (the regular quad it starts, and its corner quad when it is a corner
// point), or one side j (the v-face's child j and outer corner face j with its copies). Every
// index is the seed's arithmetic: the layer l = floor(sqrt(floor(i / n))), the corner points
// C(l, j) = l^2 n + j (2l + 1), the partner offsets D(l, j) = (2l + 1) n + 2j + 1, and the step
// maps (offset k -> 2k + 1 in layer 2l + 1). Flags (present, boundary) come per element from
// the host; a face is refined when its corners are present, by the strip mask when it holds
// boundary points. A child is summed from its own corner round the face, anchored and
// `precise`, so every patch holding a shared face writes its children with the same bits.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "bindings.glsl"
layout(local_size_x = VERTEX_PATCHES_LOCAL_SIZE) in;

struct VertexPatchRecord {
    uint valence;
    uint sizes;
    uint source;
    uint destination;
    uint first_item;
};

layout(buffer_reference, std430, buffer_reference_align = 16) buffer VertexPatchPoints { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer VertexPatchFlags { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer VertexPatchRecords { VertexPatchRecord v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer VertexPatchWords { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer VertexPatchWeights { float v[]; };

// `tess::gpu::VertexPatchStep`.
layout(push_constant) uniform VertexPatchStep {
    uvec2 points;
    uvec2 flags;
    uvec2 records;
    uvec2 sizes;
    uvec2 weights;
    uvec2 weight_starts;
    uint patch_count;
    uint items;
    uint first_item;
    uint depth;
} step;

#define points VertexPatchPoints(step.points).v
#define flags VertexPatchFlags(step.flags).v
#define records VertexPatchRecords(step.records).v
#define size_sums VertexPatchWords(step.sizes).v
#define weights VertexPatchWeights(step.weights).v
#define weight_starts VertexPatchWords(step.weight_starts).v

const uint NONE = 0xffffffffu;

// The patch being refined.
uint n;
uint source;
uint destination;
uint size_base;

uint corner_point(uint l, uint j) { return l * l * n + j * (2u * l + 1u); }
uint delta(uint l, uint j) { return (2u * l + 1u) * n + 2u * j + 1u; }
uint outer_layer(uint d) { return 1u << (d - 1u); }
uint layer_points(uint d) { uint l = outer_layer(d) + 1u; return l * l * n; }
uint corner_size(uint j) { return size_sums[size_base + j + 1u] - size_sums[size_base + j]; }
uint slot(uint d, uint j) { return layer_points(d) + size_sums[size_base + j]; }

// The point after (or before) point i of layer l, cyclically.
uint next_in_layer(uint l, uint i, bool back) {
    uint start = l * l * n;
    uint count = (2u * l + 1u) * n;
    uint k = i - start;
    return start + (back ? (k + count - 1u) % count : (k + 1u) % count);
}

// A face's corners (source slots) and, per corner, where its child goes (destination slots:
// the child's place, then one copy or NONE).
uint m;
uint corners[VERTEX_PATCHES_MAX_FACE];
uint targets[VERTEX_PATCHES_MAX_FACE];
uint copies[VERTEX_PATCHES_MAX_FACE];

vec3 corner(uint k) { return points[source + corners[k]].xyz; }

// Refines the face in `corners` when all its corners are present; children i in [first, last).
void refine_face(uint first, uint last) {
    uint boundary = 0u;
    for (uint k = 0u; k < m; ++k) {
        uint f = flags[source + corners[k]];
        if ((f & VERTEX_PATCH_PRESENT) == 0u) return;
        if ((f & VERTEX_PATCH_BOUNDARY) != 0u) boundary |= 1u << k;
    }
    // The strip's boundary edge starts at corner p (the host checked there is at most one).
    uint p = NONE;
    for (uint k = 0u; k < m && boundary != 0u; ++k) {
        if ((boundary >> k & 1u) != 0u && (boundary >> ((k + 1u) % m) & 1u) != 0u) p = k;
    }
    for (uint i = first; i < last; ++i) {
        uint w = weight_starts[m] + (p == NONE ? 0u : m + ((i + m - p) % m) * m);
        vec3 anchor = corner(i);
        precise vec3 d = vec3(0.0);
        for (uint k = 1u; k < m; ++k) {
            d += weights[w + k] * (corner((i + k) % m) - anchor);
        }
        precise vec3 q = anchor + d;
        points[destination + targets[i]] = vec4(q, 1.0);
        if (copies[i] != NONE) points[destination + copies[i]] = vec4(q, 1.0);
    }
}

void set_quad(uint c0, uint c1, uint c2, uint c3, uint t0, uint t1, uint t2, uint t3) {
    m = 4u;
    corners[0] = c0; corners[1] = c1; corners[2] = c2; corners[3] = c3;
    targets[0] = t0; targets[1] = t1; targets[2] = t2; targets[3] = t3;
    for (uint k = 0u; k < 4u; ++k) copies[k] = NONE;
}

// The faces inner point i starts: its regular quad, and its corner quad below layer L - 1.
void point_faces(uint i, uint d) {
    uint l = uint(sqrt(float(i / n)));
    while ((l + 1u) * (l + 1u) * n <= i) ++l;
    while (l * l * n > i) --l;
    uint r = i - l * l * n;
    uint j = r / (2u * l + 1u);
    uint k = r % (2u * l + 1u);
    uint dl = delta(l, j);
    uint child = corner_point(2u * l + 1u, j) + 2u * k + 1u;
    uint dc = delta(2u * l + 1u, j);
    set_quad(i, i + dl, i + dl + 1u, next_in_layer(l, i, false),
             child, child + dc, child + dc + 1u, child + 1u);
    refine_face(0u, 4u);
    if (k == 0u && l + 1u < outer_layer(d)) {
        uint c = corner_point(l + 1u, j);
        uint cc = corner_point(2u * l + 2u, j);
        set_quad(corner_point(l, j), next_in_layer(l + 1u, c, true), c, next_in_layer(l + 1u, c, false),
                 corner_point(2u * l + 1u, j), next_in_layer(2u * l + 2u, cc, true), cc,
                 next_in_layer(2u * l + 2u, cc, false));
        refine_face(0u, 4u);
    }
}

// Side j: the v-face's child j, and outer corner face j (into its corner slots at d + 1 and
// the layer points they coincide with).
void side_faces(uint j, uint d) {
    m = n;
    for (uint k = 0u; k < n; ++k) {
        corners[k] = k;
        targets[k] = k;
        copies[k] = NONE;
    }
    refine_face(j, j + 1u);
    uint size = corner_size(j);
    if (size == 0u) return;
    m = size;
    uint s = slot(d, j);
    uint s_next = slot(d + 1u, j);
    uint outer = outer_layer(d + 1u);
    uint c = corner_point(outer, j);
    for (uint k = 0u; k < m; ++k) {
        corners[k] = s + k;
        targets[k] = s_next + k;
        copies[k] = NONE;
    }
    copies[0] = corner_point(outer - 1u, j);
    copies[1] = next_in_layer(outer, c, true);
    copies[m - 1u] = next_in_layer(outer, c, false);
    if (m == 4u) copies[2] = c;
    refine_face(0u, m);
}

void main() {
    uint item = step.first_item + gl_GlobalInvocationID.x;
    if (item >= step.items) return;
    // The patch whose items hold this one: the last record starting at or before it.
    uint lo = 0u;
    uint hi = step.patch_count;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (records[mid].first_item <= item) lo = mid; else hi = mid;
    }
    VertexPatchRecord r = records[lo];
    n = r.valence;
    source = r.source;
    destination = r.destination;
    size_base = r.sizes;
    uint local = item - r.first_item;
    uint l = outer_layer(step.depth);
    uint inner = l * l * n;
    if (local < inner) {
        point_faces(local, step.depth);
    } else {
        side_faces(local - inner, step.depth);
    }
}
