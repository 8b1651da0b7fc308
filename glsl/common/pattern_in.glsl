// The refinement-pattern path's vertex inputs (tess::gpu::pattern_input; crate::pattern): the
// pattern vertex's domain point at location 0 (barycentric (u, v, w) on triangles, (u, v, 0)
// on quads), and the instance's patch corners, position and normal each, from location 1 on.
// The patch id is the instance: draw.first_patch + gl_InstanceIndex.
layout(location = 0) in vec3 in_domain;
layout(location = 1) in vec3 in_p0;
layout(location = 2) in vec3 in_n0;
layout(location = 3) in vec3 in_p1;
layout(location = 4) in vec3 in_n1;
layout(location = 5) in vec3 in_p2;
layout(location = 6) in vec3 in_n2;
#ifdef SCALAR_TAGS
// A scalar-tagged PN triangle's corners' edge control points (tess::gpu::pattern_input::
// TAGGED_TRIANGLE): per instance, corner i's next and previous edge points.
layout(location = 7) in vec4 in_bn0;
layout(location = 8) in vec4 in_bp0;
layout(location = 9) in vec4 in_bn1;
layout(location = 10) in vec4 in_bp1;
layout(location = 11) in vec4 in_bn2;
layout(location = 12) in vec4 in_bp2;
#endif
#ifdef PATTERN_QUAD
layout(location = 7) in vec3 in_p3;
layout(location = 8) in vec3 in_n3;
#endif

uint pattern_patch_id() {
    return draw.first_patch + uint(gl_InstanceIndex);
}
