#version 450
// Loop limit surface by basis-function tables on the refinement-pattern path: one instance of
// the pattern per level-1 face, bft_eval (bft.glsl, the evaluation stage's function) at the
// pattern vertex's barycentric domain point. Patterns come at uniform power-of-two levels in
// equal spacing, so every pattern vertex is a table point (SPACING_EQUAL: the exact path only).
// Rows are read from the global buffers (no control stage gathers a patch block).
// Built with and without capture and the surface code (glsl/manifest.toml; stage_out.glsl).
#extension GL_EXT_control_flow_attributes : require
#define TECHNIQUE_PUSH_CONSTANTS
#define BFT_PATCH_LOCAL
#define SPACING_EQUAL
#include "frame.glsl"
#include "bft.glsl"
#include "stage_out.glsl"
#include "normals.glsl"
layout(location = 0) in vec3 in_domain;
#ifdef SURFACE_BUILD
layout(location = 5) flat out vec3 out_albedo;
#endif

// Regular, extraordinary, boundary, private-table patches (as bft.tese).
const vec3 KIND_COLOURS[4] = vec3[4](vec3(0.55, 0.75, 0.95), vec3(0.95, 0.45, 0.35), vec3(0.55, 0.85, 0.45), vec3(0.75, 0.5, 0.9));

void main() {
    uint face = bft.first_patch + uint(gl_InstanceIndex);
    tc_head = uvec4(face, 0u, 0u, 0u);
    bool geometric = (bft.options & uint(BFT_OPTION_GEOMETRIC_NORMALS)) != 0u;
    vec3 p, n;
    bool exact = bft_eval(face, in_domain, geometric, p, n);
    uint kind = table_entries[PATCH(face).entry].kind;
#ifdef SURFACE_BUILD
    out_albedo = (bft.options & uint(BFT_OPTION_PATCH_COLOURS)) != 0u ? KIND_COLOURS[min(kind, 3u)] : frame.base_color.rgb;
#endif
    emit_vertex_at(p, safe_normalize(n, vec3(0.0)), face,
        (exact ? uint(CAPTURE_FLAG_EXACT) : 0u) | (kind << CAPTURE_FLAG_KIND_SHIFT), in_domain.xy);
}
