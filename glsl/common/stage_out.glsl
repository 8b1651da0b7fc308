// What the last stage before rasterization (an evaluation stage, or a vertex stage on the
// vertex-stage path) hands to the fragment stage, and the clip-space write.
//
// Capture contract (`tess::gpu::CaptureRecord`): that stage compiled with `-DCAPTURE` (the
// manifest's capture axis) also records, through transform feedback, one record per emitted
// triangle corner, in the order the primitive assembler sees them: world position, normal (as
// shaded), patch id, flags (technique-defined, 0 = none) and the domain coordinate (what the
// technique maps back to the base mesh: the tessellator's gl_TessCoord.xy in an evaluation
// stage). Buffer, stride and offsets come from bindings.glsl; a test reads them back from the
// SPIR-V against the Rust struct.
// The patch id is the index of the patch in the frame's patch numbering, draw splits included.
#include "bindings.glsl"
#ifdef CAPTURE
#define XFB_AT(off) , xfb_buffer = CAPTURE_XFB_BUFFER, xfb_stride = CAPTURE_XFB_STRIDE, xfb_offset = off
#else
#define XFB_AT(off)
#endif
layout(location = 0 XFB_AT(CAPTURE_OFFSET_POSITION)) out vec3 out_world;
layout(location = 1 XFB_AT(CAPTURE_OFFSET_NORMAL)) out vec3 out_normal;
#ifdef CAPTURE
layout(location = 2 XFB_AT(CAPTURE_OFFSET_PATCH)) flat out uvec2 out_patch_flags;
layout(location = 3 XFB_AT(CAPTURE_OFFSET_DOMAIN)) out vec2 out_domain;
#endif

void emit_vertex_at(vec3 p, vec3 n, uint patch_id, uint flags, vec2 domain) {
    out_world = p;
    out_normal = n;
#ifdef CAPTURE
    out_patch_flags = uvec2(patch_id, flags);
    out_domain = domain;
#endif
    gl_Position = frame.view_proj * vec4(p, 1.0);
}
