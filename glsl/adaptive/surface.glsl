// Texture coordinates, the texture reparameterization (seed 003, Eq. 3) and seamless
// displacement for the adaptive TES. Mirrors topology::texcoord (reparameterization) and
// topology::adaptive::CurveOwner::patch_param (owners).
//
// Seamless displacement: a vertex on a patch boundary is displaced along the normal, and by
// the height at the texture coordinate, of the patch that owns its canonical curve (or its
// canonical corner), evaluated from the global vertex buffer by one `precise` function. Both
// sides of an edge therefore compute the same bits even where a texture seam (a `vt`
// discontinuity) runs along it or the patches differ in kind or level.

// Eq. 3: the rational bicubic s(u, v) of the patch's corner blocks; exactly (u, v) where every
// corner is the identity (regular patches, valence 4, boundaries).
vec2 reparameterize(uint rows, vec2 uv) {
    if (rows == 0u) return uv;
    vec3 net[16];
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) net[i + 4 * j] = vec3(float(i) / 3.0, float(j) / 3.0, 1.0);
    for (uint k = 0u; k < 4u; ++k) {
        uint row = (rows >> (8u * k)) & 255u;
        if (row == 0u) continue;
        vec4 a = REPARAM_TABLE[row].a;
        float c0 = a.x, c1 = a.y, c2 = a.z, c3 = a.w, c4 = REPARAM_TABLE[row].b.x;
        bool cu = k == 1u || k == 2u, cv = k >= 2u;
        // Local block (a, b): (0,0) -> (0, 0, c0), (0,1) -> (0, c1, c2), (1,0) -> (c1, 0, c2),
        // (1,1) -> (c3, c3, c4); mirrored into the corner (c -> 1 - c).
        vec3 local[4] = vec3[4](vec3(0.0, 0.0, c0), vec3(c1, 0.0, c2), vec3(0.0, c1, c2), vec3(c3, c3, c4));
        for (int b = 0; b < 2; ++b) {
            for (int a2 = 0; a2 < 2; ++a2) {
                vec3 l = local[a2 + 2 * b];
                int i = cu ? 3 - a2 : a2, j = cv ? 3 - b : b;
                net[i + 4 * j] = vec3(cu ? 1.0 - l.x : l.x, cv ? 1.0 - l.y : l.y, l.z);
            }
        }
    }
    float s = 1.0 - uv.x, t = 1.0 - uv.y;
    vec4 bu = vec4(s * s * s, 3.0 * uv.x * s * s, 3.0 * uv.x * uv.x * s, uv.x * uv.x * uv.x);
    vec4 bv = vec4(t * t * t, 3.0 * uv.y * t * t, 3.0 * uv.y * uv.y * t, uv.y * uv.y * uv.y);
    vec3 acc = vec3(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            vec3 n = net[i + 4 * j];
            float w = bu[i] * bv[j] * n.z;
            acc += vec3(w * n.xy, w);
        }
    return acc.xy / acc.z;
}

bool reparam_on() { return (adaptive.options & uint(ADAPTIVE_OPTION_REPARAM)) != 0u; }

// The pointwise Eq. 1 error of patch `id` at `uv` (over the bbox diagonal), bilinear in its
// lattice (topology::texcoord::ParamErrorLattice, computed on the CPU for the rest pose), for
// the current reparameterization setting. 0 outside the buffer (not built).
float param_error(uint id, vec2 uv) {
    const uint side = uint(ADAPTIVE_PARAM_ERROR_SIDE), n = side * side;
    uint base = id * 2u * n + (reparam_on() ? n : 0u);
    if (base + n > arrays.param_error_count) return 0.0;
    vec2 x = clamp(uv, 0.0, 1.0) * float(side - 1u);
    uvec2 i = min(uvec2(x), uvec2(side - 2u));
    vec2 f = x - vec2(i);
    uint k = base + i.x + side * i.y;
    float a = mix(PARAM_ERRORS[k], PARAM_ERRORS[k + 1u], f.x);
    float b = mix(PARAM_ERRORS[k + side], PARAM_ERRORS[k + side + 1u], f.x);
    return mix(a, b, f.y);
}

// Log-scale ramp of a relative error: blue <= 1e-5, cyan 1e-4.25, green 1e-3.5, yellow
// 1e-2.75, red >= 1e-2 (a decade per 1.33 colour steps, as a heat map of Fig. 8).
vec3 param_error_colour(float e) {
    float t = clamp((log(max(e, 1e-12)) / log(10.0) + 5.0) / 3.0, 0.0, 1.0) * 4.0;
    const vec3 ramp[5] = vec3[5](vec3(0.15, 0.25, 0.85), vec3(0.1, 0.7, 0.85), vec3(0.2, 0.75, 0.25), vec3(0.95, 0.85, 0.2), vec3(0.9, 0.15, 0.1));
    uint k = min(uint(t), 3u);
    return mix(ramp[k], ramp[k + 1u], t - float(k));
}

#ifdef FACE_VARYING
#include "fvar.glsl"
#endif

// The texture coordinate of a patch with surface record `sf` at texture parameter `st`: the
// corners' bilinear blend, which in the face-varying build (-DFACE_VARYING, for surfaces with
// face-varying patches) is the (sub-)face parameter they are looked up at (fvar.glsl).
vec2 texcoord_at(PatchSurface sf, vec2 st) {
    vec2 blend = mix(mix(sf.uv[0], sf.uv[1], st.x), mix(sf.uv[3], sf.uv[2], st.x), st.y);
#ifdef FACE_VARYING
    if (sf.fvar_root != FVAR_EMPTY) return fvar_texcoord(sf.fvar_root, blend, blend);
#endif
    return blend;
}

// The texture coordinate patch `id` shows at its (u, v).
vec2 patch_texcoord(uint id, vec2 uv) {
    PatchSurface sf = SURFACES[id];
    vec2 st = reparam_on() ? reparameterize(sf.reparam_rows, uv) : uv;
    return texcoord_at(sf, st);
}

// Height at a texture coordinate: the height map's red channel (level 0, so both sides of an
// edge read the same texels), or a procedural bump pattern.
float surface_height(vec2 tex) {
    if ((adaptive.options & uint(ADAPTIVE_OPTION_HEIGHT_MAP)) != 0u) return textureLod(height_map, tex, 0.0).r;
    vec2 w = 6.2831853 * 8.0 * tex;
    return 0.5 + 0.25 * (sin(w.x) + sin(w.y));
}

void bernstein3(float t, out vec4 b, out vec4 d) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    d = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}

// Uniform cubic B-spline basis and its derivative.
void bspline3(float t, out vec4 b, out vec4 d) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * t * t - 6.0 * t * t + 4.0, -3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0, t * t * t) / 6.0;
    d = vec4(-3.0 * s * s, 9.0 * t * t - 12.0 * t, -9.0 * t * t + 6.0 * t + 3.0, 3.0 * t * t) / 6.0;
}

// ACC-1 shading normal from the two tangent patches (Loop & Schaefer 2008); mirrors
// topology::acc::tangent_normal (see there for the construction). `c`: the patch's 28 points,
// the Gregory form of the Bezier net (20), then per corner the limit-tangent points Ep, Em.
// `valences`: 8 bits per corner.
vec3 acc_tangent_normal(vec3 c[28], uint valences, vec2 uv) {
    vec3 b[16];  // b[i + 4 j], i along u
    b[0] = c[0];  b[1] = c[1];  b[4] = c[2];  b[5] = c[3];
    b[3] = c[5];  b[7] = c[6];  b[2] = c[7];  b[6] = c[8];
    b[15] = c[10]; b[14] = c[11]; b[11] = c[12]; b[10] = c[13];
    b[12] = c[15]; b[8] = c[16]; b[13] = c[17]; b[9] = c[18];
    // Limit tangents as derivatives along +u / +v at corners 00, 10, 11, 01.
    vec3 tu00 = 3.0 * (c[20] - c[0]), tv00 = 3.0 * (c[21] - c[0]);
    vec3 tv10 = 3.0 * (c[22] - c[5]), tu10 = -3.0 * (c[23] - c[5]);
    vec3 tu11 = -3.0 * (c[24] - c[10]), tv11 = -3.0 * (c[25] - c[10]);
    vec3 tv01 = -3.0 * (c[26] - c[15]), tu01 = 3.0 * (c[27] - c[15]);
    vec4 cs;
    for (uint k = 0u; k < 4u; ++k) {
        float n = float((valences >> (8u * k)) & 255u);
        cs[k] = n == 0.0 ? 0.0 : cos(6.28318530718 / n);
    }
    float c00 = cs.x, c10 = cs.y, c11 = cs.z, c01 = cs.w;
    // u-tangent patch U[i][j] (quadratic in u), v-tangent patch V[i][j] (quadratic in v).
    vec3 U[12], V[12];  // U[i + 3 j], V[i + 4 j]
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) U[i + 3 * j] = 3.0 * (b[i + 1 + 4 * j] - b[i + 4 * j]);
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) V[i + 4 * j] = 3.0 * (b[i + 4 * (j + 1)] - b[i + 4 * j]);
    U[0] = tu00; U[2] = tu10; U[9] = tu01; U[11] = tu11;
    V[0] = tv00; V[8] = tv01; V[3] = tv10; V[11] = tv11;
    // Half of lambda T's inner control vectors: (-c1 T0 + 2 c0 T1) / 3, (-2 c1 T1 + c0 T2) / 3.
    vec3 m;
    m = 3.0 * (b[8] - b[4]);
    U[3] += (-c01 * tv00 + 2.0 * c00 * m) / 3.0;  U[6] += (-2.0 * c01 * m + c00 * tv01) / 3.0;
    m = 3.0 * (b[11] - b[7]);
    U[5] -= (-c11 * tv10 + 2.0 * c10 * m) / 3.0;  U[8] -= (-2.0 * c11 * m + c10 * tv11) / 3.0;
    m = 3.0 * (b[2] - b[1]);
    V[1] += (-c10 * tu00 + 2.0 * c00 * m) / 3.0;  V[2] += (-2.0 * c10 * m + c00 * tu10) / 3.0;
    m = 3.0 * (b[14] - b[13]);
    V[9] -= (-c11 * tu01 + 2.0 * c01 * m) / 3.0;  V[10] -= (-2.0 * c11 * m + c01 * tu11) / 3.0;
    float u = uv.x, v = uv.y, su = 1.0 - u, sv = 1.0 - v;
    vec3 qu = vec3(su * su, 2.0 * u * su, u * u), qv = vec3(sv * sv, 2.0 * v * sv, v * v);
    vec4 cu = vec4(su * su * su, 3.0 * u * su * su, 3.0 * u * u * su, u * u * u);
    vec4 cv = vec4(sv * sv * sv, 3.0 * v * sv * sv, 3.0 * v * v * sv, v * v * v);
    // precise: owner_frame returns this, and every TES must get the same bits.
    precise vec3 du = vec3(0.0), dv = vec3(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) du += (qu[i] * cv[j]) * U[i + 3 * j];
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) dv += (cu[i] * qv[j]) * V[i + 4 * j];
    return safe_normalize(cross(du, dv), vec3(0.0, 0.0, 1.0));
}

// (a F + b G) / (a + b) and its derivatives by a and by b (the mean, 0 where a + b vanishes).
void tri_blend(float a, float b, vec3 f, vec3 g, out vec3 x, out vec3 dx_da, out vec3 dx_db) {
    precise float d = a + b;
    if (d < 1e-7) {
        x = 0.5 * (f + g);
        dx_da = vec3(0.0);
        dx_db = vec3(0.0);
        return;
    }
    precise vec3 r = (a * f + b * g) / d;
    x = r;
    dx_da = b * (f - g) / (d * d);
    dx_db = a * (g - f) / (d * d);
}

float ipow(float x, int n) {
    float r = 1.0;
    for (int k = 0; k < n; ++k) r *= x;
    return r;
}

// Quartic triangle Bezier points b_ijk (weights of corners 0, 1, 2 to the powers i, j, k) in
// the order gregory_triangle fills them, and their multinomial coefficients.
const ivec3 TRI_IJK[15] = ivec3[15](ivec3(4, 0, 0), ivec3(0, 4, 0), ivec3(0, 0, 4),
    ivec3(3, 1, 0), ivec3(2, 2, 0), ivec3(1, 3, 0), ivec3(0, 3, 1), ivec3(0, 2, 2), ivec3(0, 1, 3),
    ivec3(1, 0, 3), ivec3(2, 0, 2), ivec3(3, 0, 1), ivec3(2, 1, 1), ivec3(1, 2, 1), ivec3(1, 1, 2));
const float TRI_COEF[15] = float[15](1.0, 1.0, 1.0, 4.0, 6.0, 4.0, 4.0, 6.0, 4.0, 4.0, 6.0, 4.0, 12.0, 12.0, 12.0);

// Gregory triangle patch (topology::gregory::gregory_triangle_weights): 15 points, per corner
// P, Ep, Em, Fp, Fm; the cubic boundary degree-elevated, interior points blended. `precise`:
// owners are evaluated by every TES and must agree in bits.
void gregory_triangle(vec3 c[15], vec2 uv, out vec3 pos, out vec3 du, out vec3 dv) {
    float l0 = 1.0 - uv.x - uv.y, l1 = uv.x, l2 = uv.y;
    vec3 b[15], bu[15], bv[15];
    for (int k = 0; k < 15; ++k) { bu[k] = vec3(0.0); bv[k] = vec3(0.0); }
    b[0] = c[0]; b[1] = c[5]; b[2] = c[10];
    b[3] = 0.25 * c[0] + 0.75 * c[1];  b[4] = 0.5 * (c[1] + c[7]);   b[5] = 0.75 * c[7] + 0.25 * c[5];
    b[6] = 0.25 * c[5] + 0.75 * c[6];  b[7] = 0.5 * (c[6] + c[12]);  b[8] = 0.75 * c[12] + 0.25 * c[10];
    b[9] = 0.25 * c[10] + 0.75 * c[11]; b[10] = 0.5 * (c[11] + c[2]); b[11] = 0.75 * c[2] + 0.25 * c[0];
    vec3 da, db;
    // b211 = (l1 Fp0 + l2 Fm0) / (l1 + l2); l1 = u, l2 = v.
    tri_blend(l1, l2, c[3], c[4], b[12], da, db);
    bu[12] = da; bv[12] = db;
    // b121 = (l2 Fp1 + l0 Fm1) / (l2 + l0).
    tri_blend(l2, l0, c[8], c[9], b[13], da, db);
    bu[13] = -db; bv[13] = da - db;
    // b112 = (l0 Fp2 + l1 Fm2) / (l0 + l1).
    tri_blend(l0, l1, c[13], c[14], b[14], da, db);
    bu[14] = db - da; bv[14] = -da;
    precise vec3 p = vec3(0.0), pu = vec3(0.0), pv = vec3(0.0);
    for (int k = 0; k < 15; ++k) {
        ivec3 e = TRI_IJK[k];
        float a0 = ipow(l0, e.x), a1 = ipow(l1, e.y), a2 = ipow(l2, e.z);
        float w = TRI_COEF[k] * a0 * a1 * a2;
        float d0 = e.x > 0 ? TRI_COEF[k] * float(e.x) * ipow(l0, e.x - 1) * a1 * a2 : 0.0;
        float d1 = e.y > 0 ? TRI_COEF[k] * float(e.y) * a0 * ipow(l1, e.y - 1) * a2 : 0.0;
        float d2 = e.z > 0 ? TRI_COEF[k] * float(e.z) * a0 * a1 * ipow(l2, e.z - 1) : 0.0;
        p += w * b[k];
        pu += (d1 - d0) * b[k] + w * bu[k];
        pv += (d2 - d0) * b[k] + w * bv[k];
    }
    pos = p; du = pu; dv = pv;
}

// The owner evaluation: the normal of patch `id` at `uv`, from the global vertex buffer, one
// operand order, `precise` (every TES that includes this gets the same bits). Call it from one
// place only (see tese_main.glsl).
// Also its derivatives (the geometry patch's, on ACC-1 nets too, whose normal is the tangent
// patches').
void owner_frame(uint id, vec2 uv, out vec3 n_out, out vec3 du_out, out vec3 dv_out) {
    AdaptivePatch p = PATCHES[id];
    uint kind = patch_kind(p);
    precise vec3 du = vec3(0.0), dv = vec3(0.0);
    float u = uv.x, v = uv.y;
    if (kind == ADAPTIVE_KIND_REGULAR) {
        vec4 bu, bv, du_w, dv_w;
        bspline3(u, bu, du_w);
        bspline3(v, bv, dv_w);
        for (uint j = 0u; j < 4u; ++j)
            for (uint i = 0u; i < 4u; ++i) {
                vec3 c = vtx(CONTROL_POINTS[p.cp_offset + 4u * j + i]);
                du += (du_w[i] * bv[j]) * c;
                dv += (bu[i] * dv_w[j]) * c;
            }
    } else if (kind == ADAPTIVE_KIND_GREGORY_TRIANGLE) {
        // Owners are evaluated on their edges (all of a triangle's are on level-1 halves, which
        // it owns only where its own boundary is those halves) and corners, where the boundary
        // correction of triangle.tese vanishes with its derivatives: the quartic alone.
        vec3 c[15];
        for (uint k = 0u; k < 15u; ++k) c[k] = vtx(CONTROL_POINTS[p.cp_offset + k]);
        vec3 pos;
        gregory_triangle(c, uv, pos, du, dv);
    } else if (kind == ADAPTIVE_KIND_GREGORY) {
        vec3 c[20];
        for (uint k = 0u; k < 20u; ++k) c[k] = vtx(CONTROL_POINTS[p.cp_offset + k]);
        // The interior Bezier points as gregory.tese blends them. Their blend derivatives are
        // left out: they carry B1 or B2 in both directions, which vanish on the patch edges,
        // the only place an owner is evaluated.
        vec3 b[16];
        b[0] = c[0];  b[1] = c[1];  b[2] = c[7];  b[3] = c[5];
        b[7] = c[6];  b[11] = c[12]; b[15] = c[10];
        b[14] = c[11]; b[13] = c[17]; b[12] = c[15];
        b[8] = c[16]; b[4] = c[2];
        float d0 = u + v, d1 = 1.0 - u + v, d2 = 2.0 - u - v, d3 = 1.0 - v + u;
        b[5] = d0 < 1e-7 ? 0.5 * (c[3] + c[4]) : (u * c[3] + v * c[4]) / d0;
        b[6] = d1 < 1e-7 ? 0.5 * (c[9] + c[8]) : ((1.0 - u) * c[9] + v * c[8]) / d1;
        b[10] = d2 < 1e-7 ? 0.5 * (c[14] + c[13]) : ((1.0 - v) * c[14] + (1.0 - u) * c[13]) / d2;
        b[9] = d3 < 1e-7 ? 0.5 * (c[18] + c[19]) : ((1.0 - v) * c[18] + u * c[19]) / d3;
        vec4 bu, bv, du_w, dv_w;
        bernstein3(u, bu, du_w);
        bernstein3(v, bv, dv_w);
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                du += (du_w[i] * bv[j]) * b[i + 4 * j];
                dv += (bu[i] * dv_w[j]) * b[i + 4 * j];
            }
    } else {
        // Bilinear caps: the plane of the canonical corners' cross diagonals.
        vec3 c0 = edge_point(p, 0u, 0.0), c1 = edge_point(p, 1u, 0.0), c2 = edge_point(p, 2u, 0.0), c3 = edge_point(p, 3u, 0.0);
        du = (1.0 - v) * (c1 - c0) + v * (c2 - c3);
        dv = (1.0 - u) * (c3 - c0) + u * (c2 - c1);
    }
    precise vec3 r = safe_normalize(cross(du, dv), vec3(0.0, 0.0, 1.0));
    uint tangent_valences = SURFACES[id].tangent_valences;
    if (tangent_valences != 0u) {
        vec3 c[28];
        for (uint k = 0u; k < 28u; ++k) c[k] = vtx(CONTROL_POINTS[p.cp_offset + k]);
        r = acc_tangent_normal(c, tangent_valences, uv);
    }
    n_out = r;
    du_out = du;
    dv_out = dv;
}


// The owner's patch parameter at curve parameter s (CurveOwner::patch_param).
vec2 owner_param(CurveOwner o, float s) {
    uint edge = o.info & 3u, part = (o.info >> 2) & 3u;
    bool forward = ((o.info >> 4) & 1u) != 0u;
    precise float e = forward ? s : 1.0 - s;
    precise float t = part == 1u ? 0.5 * e : (part == 2u ? 0.5 + 0.5 * e : e);
    if (((o.info >> 5) & 1u) != 0u) {
        // Triangle: (0,0) -> (1,0) -> (0,1) -> (0,0).
        precise float r = 1.0 - t;
        if (edge == 0u) return vec2(t, 0.0);
        if (edge == 1u) return vec2(r, t);
        return vec2(0.0, r);
    }
    if (edge == 0u) return vec2(t, 0.0);
    if (edge == 1u) return vec2(1.0, t);
    if (edge == 2u) return vec2(1.0 - t, 1.0);
    return vec2(0.0, 1.0 - t);
}

const vec2 CORNER_PARAMS[4] = vec2[4](vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(1.0, 1.0), vec2(0.0, 1.0));
// A triangle owner's corners 0..2, then (4 + e) the midpoint of its edge e.
const vec2 TRIANGLE_CORNER_PARAMS[7] = vec2[7](vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(0.0, 1.0),
    vec2(0.0, 0.0), vec2(0.5, 0.0), vec2(0.5, 0.5), vec2(0.0, 0.5));

// A boundary vertex at curve `curve`, parameter `s`, displaced by its owner (see above); `pos`
// is the canonical point.
// The shading normal of the displaced surface p + k h n (k the scale): its derivatives are
// p_u + k h_u n and p_v + k h_v n, dropping the k h n_u terms (the curvature of the undisplaced
// surface times the height: small next to the height's slope). With the base normal `n` (the
// tangent patches' on ACC-1) standing for p_u x p_v / |p_u x p_v|, the cross product is
//   |p_u x p_v| n + k h_v (p_u x n) + k h_u (n x p_v),
// whose direction does not depend on the parameterization, so both sides of an edge agree
// wherever the height is continuous. h_u, h_v: central differences of the height at the
// patch's texture coordinates (one-sided at the patch boundary), taken by tese_main.glsl.
vec3 displaced_normal(vec3 n, vec3 du, vec3 dv, float hu, float hv) {
    float k = adaptive.displace_scale;
    // precise: with canonical normals every TES evaluates this for an owner, to the same bits.
    precise vec3 m = safe_length(cross(du, dv)) * n + (k * hv) * cross(du, n) + (k * hu) * cross(n, dv);
    return safe_normalize(m, n);
}

// The patch that owns the canonical point at curve `curve`, parameter s, and its parameter
// there: the corner's owner at the curve's ends, else the curve's.
void canonical_owner(uint curve, float s, out uint owner, out vec2 ouv) {
    if (s == 0.0 || s == 1.0) {
        uint v = s == 0.0 ? CURVES[curve].x : CURVES[curve].w;
        uvec2 o = CORNER_OWNERS[v - adaptive.first_corner];
        owner = o.x;
        ouv = patch_kind(PATCHES[owner]) == ADAPTIVE_KIND_GREGORY_TRIANGLE ? TRIANGLE_CORNER_PARAMS[min(o.y, 6u)] : CORNER_PARAMS[o.y & 3u];
    } else {
        CurveOwner o = CURVE_OWNERS[curve];
        owner = o.patch_id;
        ouv = owner_param(o, s);
    }
}
