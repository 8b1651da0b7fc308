#version 450
// Shading of adaptive surfaces: as common/shade.frag, with the per-patch albedo (patch colours).
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
#include "shading.glsl"
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
#ifdef SURFACE_BUILD
// Smooth: constant per patch for patch colours, a field for the parameterization views.
layout(location = 5) in vec3 in_albedo;
layout(location = 6) in vec2 in_texcoord;
#endif
layout(location = 0) out vec4 out_color;
void main() {
#ifdef SURFACE_BUILD
    vec3 albedo = in_albedo;
    if ((adaptive.options & uint(ADAPTIVE_OPTION_TEXTURE)) != 0u) albedo = texture(surface_texture, in_texcoord).rgb;
#else
    // The plain build (tese_main.glsl): no texture, no patch colours.
    vec3 albedo = frame.base_color.rgb;
#endif
    out_color = adaptive.mode == DRAW_MODE_WIREFRAME ? vec4(frame.wire_color.rgb, 1.0) : shade(in_world, in_normal, albedo);
}
