#version 450
// Curved PN triangles on the refinement-pattern path: the patch's coefficients (pn.glsl's
// pn_patch, what the control stage computes once per patch on the tessellation path) and its
// evaluation at the pattern vertex's barycentric domain point, the same functions as tri.tese.
#include "frame.glsl"
#include "sine.glsl"
#include "stage_out.glsl"
#include "pattern_in.glsl"
#include "normals.glsl"
#include "pn.glsl"
void main() {
    vec3 c[3] = vec3[3](in_p0, in_p1, in_p2);
    vec3 n[3] = vec3[3](in_n0, in_n1, in_n2);
    vec3 p, m;
#ifdef SCALAR_TAGS
    vec4 bn[3] = vec4[3](in_bn0, in_bn1, in_bn2);
    vec4 bp[3] = vec4[3](in_bp0, in_bp1, in_bp2);
    PnPatch q = pn_patch_tagged(c, n, bn, bp);
#else
    PnPatch q = pn_patch(c, n);
#endif
    pn_evaluate(c, n, q, in_domain, p, m);
    m = safe_normalize(m, vec3(0.0));
    emit_vertex_at(displace_sine(p, m), m, pattern_patch_id(), 0u, in_domain.xy);
}
