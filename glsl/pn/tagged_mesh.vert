#version 450
// Pass-through of a scalar-tagged PN mesh's corners: position, the side's sharp normal, and
// the corner's two tagged edge control points (w: 1 where the corner is tagged), which the
// control stage reads (tri.tesc, SCALAR_TAGS; tess::gpu::TaggedCorner).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec4 in_b_next;
layout(location = 3) in vec4 in_b_prev;
layout(location = 0) out vec3 out_position;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec4 out_b_next;
layout(location = 3) out vec4 out_b_prev;
void main() {
    out_position = in_position;
    out_normal = in_normal;
    out_b_next = in_b_next;
    out_b_prev = in_b_prev;
}
