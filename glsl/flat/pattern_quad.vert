#version 450
// Flat quads on the refinement-pattern path: the bilinear point at the pattern vertex's domain
// point (flat.glsl, as quad.tese computes it at the tessellator's).
#define PATTERN_QUAD
#include "frame.glsl"
#include "sine.glsl"
#include "stage_out.glsl"
#include "pattern_in.glsl"
#include "flat.glsl"
void main() {
    vec3 p[4] = vec3[4](in_p0, in_p1, in_p2, in_p3);
    vec3 n[4] = vec3[4](in_n0, in_n1, in_n2, in_n3);
    float u = in_domain.x, v = in_domain.y;
    vec3 m = flat_quad(n, u, v);
    emit_vertex_at(displace_sine(flat_quad(p, u, v), m), m, pattern_patch_id(), 0u, in_domain.xy);
}
