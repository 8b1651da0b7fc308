#version 450
// Flat triangles on the refinement-pattern path: the planar point at the pattern vertex's
// barycentric domain point (flat.glsl, as tri.tese computes it at the tessellator's).
#include "frame.glsl"
#include "sine.glsl"
#include "stage_out.glsl"
#include "pattern_in.glsl"
#include "flat.glsl"
void main() {
    vec3 p[3] = vec3[3](in_p0, in_p1, in_p2);
    vec3 n[3] = vec3[3](in_n0, in_n1, in_n2);
    vec3 m = flat_triangle(n, in_domain);
    emit_vertex_at(displace_sine(flat_triangle(p, in_domain), m), m, pattern_patch_id(), 0u,
        in_domain.xy);
}
