#version 450
// The canonical points of a feature-adaptive frame that have no stencil rows, after the stencil
// evaluator (crates/tess/src/stencil) has written the levels and the local points: `mode`
// ADAPTIVE_CANONICAL_MODE_CORNERS evaluates the limit corners of regular patches, then
// ADAPTIVE_CANONICAL_MODE_CURVES the canonical curves' inner Bezier points, each from its
// owner patch's control points (a fixed combination per patch kind and corner or edge). Items
// `first_item .. first_item + count` per dispatch; the vertex buffer is read and written by address.
#define ADAPTIVE_WRITES_VERTICES
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
layout(local_size_x = ADAPTIVE_LOCAL_SIZE) in;

// Per regular patch edge: the slots of the four B-spline points along it (edge direction) and
// the slot step across it (`topology::adaptive::nets::REGULAR_EDGE_LINES`).
const uvec4 REGULAR_EDGE_LINE[4] = uvec4[4](uvec4(4u, 5u, 6u, 7u), uvec4(2u, 6u, 10u, 14u), uvec4(11u, 10u, 9u, 8u), uvec4(13u, 9u, 5u, 1u));
const uint REGULAR_EDGE_STEP[4] = uint[4](4u, 1u, 4u, 1u);

vec3 cp_vtx(AdaptivePatch p, uint k) { return vtx(CONTROL_POINTS[p.cp_offset + k]); }

// Curve point `i` (curve i / 2, inner point 1 + i % 2): its owner's edge as a cubic Bezier
// curve B0..B3 in the edge's direction (a regular patch's B-spline edge, a Gregory patch's
// P, Ep, Em, P', a bilinear end cap's straight line), or the half of it the curve is, at
// point k of the segment in the curve's direction (`AdaptivePlan::curve_inner_point`). The
// sums are offsets from one of the points read (as the rows are), so the f32 rounding is
// relative to the patch's size, not to the coordinates' magnitude.
vec3 curve_inner_point(uint i) {
    uint c = i >> 1u;
    uint slot = 1u + (i & 1u);
    CurveOwner o = CURVE_OWNERS[c];
    AdaptivePatch p = PATCHES[o.patch_id];
    uint e = o.info & 3u;
    uint part = (o.info >> 2u) & 3u;
    uint k = ((o.info >> 4u) & 1u) != 0u ? slot : 3u - slot;
    uint kind = patch_kind(p);
    if (kind == ADAPTIVE_KIND_GREGORY_TRIANGLE && part != 0u) {
        return cp_vtx(p, 15u + 4u * e + 2u * (part - 1u) + (k - 1u));
    }
    uint n = kind == ADAPTIVE_KIND_GREGORY_TRIANGLE ? 3u : 4u;
    uint e1 = (e + 1u) % n;
    vec3 anchor;
    vec3 b[4];
    if (kind == ADAPTIVE_KIND_REGULAR) {
        uvec4 line = REGULAR_EDGE_LINE[e];
        uint step = REGULAR_EDGE_STEP[e];
        anchor = cp_vtx(p, line[1]);
        vec3 q[4];
        for (uint j = 0u; j < 4u; ++j) {
            q[j] = ((cp_vtx(p, line[j] - step) - anchor) + 4.0 * (cp_vtx(p, line[j]) - anchor) + (cp_vtx(p, line[j] + step) - anchor)) / 6.0;
        }
        b[0] = (1.0 / 6.0) * q[0] + (4.0 / 6.0) * q[1] + (1.0 / 6.0) * q[2];
        b[1] = (2.0 / 3.0) * q[1] + (1.0 / 3.0) * q[2];
        b[2] = (1.0 / 3.0) * q[1] + (2.0 / 3.0) * q[2];
        b[3] = (1.0 / 6.0) * q[1] + (4.0 / 6.0) * q[2] + (1.0 / 6.0) * q[3];
    } else if (kind == ADAPTIVE_KIND_BILINEAR) {
        anchor = cp_vtx(p, e);
        vec3 d = cp_vtx(p, e1) - anchor;
        b = vec3[4](vec3(0.0), d / 3.0, 2.0 * d / 3.0, d);
    } else {
        anchor = cp_vtx(p, 5u * e);
        b = vec3[4](vec3(0.0), cp_vtx(p, 5u * e + 1u) - anchor, cp_vtx(p, 5u * e1 + 2u) - anchor, cp_vtx(p, 5u * e1) - anchor);
    }
    vec3 d;
    if (part == 0u) {
        d = b[k];
    } else if (part == 1u) {
        // de Casteljau at 1/2: the first half's points 1 and 2, or the second half's.
        d = k == 1u ? 0.5 * b[0] + 0.5 * b[1] : 0.25 * b[0] + 0.5 * b[1] + 0.25 * b[2];
    } else {
        d = k == 1u ? 0.25 * b[1] + 0.5 * b[2] + 0.25 * b[3] : 0.5 * b[2] + 0.5 * b[3];
    }
    return anchor + d;
}

// Canonical corner `k` (global vertex first_corner + k), owned by a regular patch: the
// smooth valence-4 limit mask over the patch's 3x3 points around that corner, as offsets from
// the corner's own point (`AdaptivePlan::regular_corner_point`).
const ivec2 CORNER_POS[4] = ivec2[4](ivec2(0, 0), ivec2(1, 0), ivec2(1, 1), ivec2(0, 1));
vec3 regular_corner_point(uint k) {
    uvec2 o = CORNER_OWNERS[k];
    AdaptivePatch p = PATCHES[o.x];
    ivec2 c = CORNER_POS[o.y & 3u];
    // slot(a, b) = 4 (b + 1) + (a + 1)
    uint s = uint(4 * (c.y + 1) + (c.x + 1));
    vec3 anchor = cp_vtx(p, s);
    vec3 e = (cp_vtx(p, s + 1u) - anchor) + (cp_vtx(p, s + 4u) - anchor) + (cp_vtx(p, s - 1u) - anchor) + (cp_vtx(p, s - 4u) - anchor);
    vec3 f = (cp_vtx(p, s - 3u) - anchor) + (cp_vtx(p, s + 5u) - anchor) + (cp_vtx(p, s + 3u) - anchor) + (cp_vtx(p, s - 5u) - anchor);
    return anchor + ((1.0 / 9.0) * e + (1.0 / 36.0) * f);
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= adaptive.count) return;
    if (adaptive.mode == ADAPTIVE_CANONICAL_MODE_CORNERS) {
        uint k = adaptive.first_item + i;
        VERTICES[adaptive.first_corner + k] = vec4(regular_corner_point(k), 1.0);
        return;
    }
    uint pi = adaptive.first_item + i;
    uvec4 curve = CURVES[pi >> 1u];
    VERTICES[(pi & 1u) == 0u ? curve.y : curve.z] = vec4(curve_inner_point(pi), 1.0);
}
