#version 450
// Phong tessellation on the refinement-pattern path, at the pattern vertex's barycentric
// domain point (phong.glsl, as tri.tese computes it at the tessellator's).
#include "frame.glsl"
#include "sine.glsl"
#include "stage_out.glsl"
#include "pattern_in.glsl"
#include "phong.glsl"
void main() {
    vec3 c[3] = vec3[3](in_p0, in_p1, in_p2);
    vec3 n[3] = vec3[3](in_n0, in_n1, in_n2);
    vec3 m = phong_normal(n, in_domain);
    emit_vertex_at(displace_sine(phong_point(c, n, in_domain, frame.tess.z), m), m,
        pattern_patch_id(), 0u, in_domain.xy);
}
