// Per-frame uniforms shared by every technique. Mirrors `tess::gpu::FrameUniforms` (std140);
// the Rust side asserts sizes and offsets, and a test reads them back from the SPIR-V.
#include "bindings.glsl"
layout(std140, set = FRAME_SET, binding = FRAME_UNIFORMS_BINDING) uniform Frame {
    mat4 view_proj;
    mat4 view;
    vec4 camera_pos;   // xyz: eye in world space
    vec4 light_dir;    // xyz: direction towards the light, normalised
    vec4 tess;         // x: outer level, y: inner level, z: Phong shape factor alpha
    vec4 base_color;   // rgb: surface albedo
    vec4 wire_color;   // rgb: wireframe overlay
    vec4 viewport;     // xy: size in pixels
    vec4 sine;         // x: amplitude a, y: frequency f of a sin(f |P|) along the normal (0: none)
} frame;

// Push constant: what a draw is for, and where it starts in the frame's patch numbering.
// Mirrors `tess::gpu::DrawPush` (std430 offsets checked against the SPIR-V by a test).
// Techniques with their own push block (bft/bft.glsl, adaptive/adaptive.glsl) define
// TECHNIQUE_PUSH_CONSTANTS first.
#ifndef TECHNIQUE_PUSH_CONSTANTS
layout(push_constant) uniform Draw {
    uint mode;         // DRAW_MODE_SHADED or DRAW_MODE_WIREFRAME
    uint first_patch;  // patch id of this draw's first patch (gl_PrimitiveID restarts per draw)
} draw;
#endif
