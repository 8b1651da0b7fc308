#version 450
// Loop limit surface by basis-function tables: one level-1 face per patch. gl_TessCoord
// (weights of the face's v0, v1, v2) names a table point (exact limit) or, for fractional
// factors, a point of the level-L virtual mesh. Normals by subdivision shading (the same
// weights over the level-1 limit normals, then normalised) or from the tangent tables.
// Built in every spacing, with and without capture (glsl/manifest.toml; tese_out.glsl).
#extension GL_EXT_control_flow_attributes : require
#define TECHNIQUE_PUSH_CONSTANTS
#define BFT_PATCH_IN
#include "frame.glsl"
#include "bft.glsl"
#include "tese_out.glsl"
#include "normals.glsl"
#ifdef SURFACE_BUILD
#include "sine.glsl"
#endif
layout(triangles, SPACING, ccw) in;
#ifdef SURFACE_BUILD
// Only with patch colours (Technique::surface_build): a varying costs lavapipe's rasterizer on
// every triangle (docs/benchmarks.md, "varyings are frame time").
layout(location = 5) flat out vec3 out_albedo;
#endif

// Regular, extraordinary, boundary, private-table patches.
const vec3 KIND_COLOURS[4] = vec3[4](vec3(0.55, 0.75, 0.95), vec3(0.95, 0.45, 0.35), vec3(0.55, 0.85, 0.45), vec3(0.75, 0.5, 0.9));

void main() {
    uint face = tc_head.x;
    bool geometric = (bft.options & uint(BFT_OPTION_GEOMETRIC_NORMALS)) != 0u;
    vec3 p, n;
    bool exact = bft_eval(face, gl_TessCoord, geometric, p, n);
    uint kind = tc_head.y >> BFT_INFO_KIND_SHIFT;
#ifdef SURFACE_BUILD
    out_albedo = (bft.options & uint(BFT_OPTION_PATCH_COLOURS)) != 0u ? KIND_COLOURS[min(kind, 3u)] : frame.base_color.rgb;
    // The seed's sine displacement along the normal: shared points have their owner's position
    // and normal bits on both faces, so they move to the same bits.
    p = displace_sine(p, n);
#endif
    emit_sample(p, safe_normalize(n, vec3(0.0)), face, (exact ? uint(CAPTURE_FLAG_EXACT) : 0u) | (kind << CAPTURE_FLAG_KIND_SHIFT));
}
