// What every TES hands to the fragment stage, and the clip-space write.
//
// Capture contract (`tess::capture`): a TES compiled with `-DCAPTURE` also records, through
// transform feedback (buffer 0, 40-byte stride, one record per emitted triangle corner, in the
// order the primitive assembler sees them):
//   offset  0: vec3 world position      offset 12: vec3 normal (as shaded)
//   offset 24: uint patch id            offset 28: uint flags (technique-defined, 0 = none)
//   offset 32: vec2 domain coordinate (gl_TessCoord.xy, as the tessellator produced it)
// The patch id is the index of the patch in the frame's patch numbering, draw splits included:
// the triangle/quad techniques pass `draw.first_patch + uint(gl_PrimitiveID)`.
#ifdef CAPTURE
#define XFB_AT(off) , xfb_buffer = 0, xfb_stride = 40, xfb_offset = off
#else
#define XFB_AT(off)
#endif
layout(location = 0 XFB_AT(0)) out vec3 out_world;
layout(location = 1 XFB_AT(12)) out vec3 out_normal;
#ifdef CAPTURE
layout(location = 2 XFB_AT(24)) flat out uvec2 out_patch_flags;
layout(location = 3 XFB_AT(32)) out vec2 out_domain;
#endif

void emit_sample(vec3 p, vec3 n, uint patch_id, uint flags) {
    out_world = p;
    out_normal = n;
#ifdef CAPTURE
    out_patch_flags = uvec2(patch_id, flags);
    out_domain = gl_TessCoord.xy;
#endif
    gl_Position = frame.view_proj * vec4(p, 1.0);
}
