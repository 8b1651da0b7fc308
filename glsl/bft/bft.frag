#version 450
// Shading of BFT surfaces: as common/shade.frag, with the per-patch albedo (patch colouring mode).
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "bft.glsl"
#include "shading.glsl"
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
#ifdef SURFACE_BUILD
layout(location = 5) flat in vec3 in_albedo;
#endif
layout(location = 0) out vec4 out_color;
void main() {
#ifdef SURFACE_BUILD
    vec3 albedo = in_albedo;
#else
    // The plain build (bft.tese): no patch colours.
    vec3 albedo = frame.base_color.rgb;
#endif
    out_color = bft.mode == DRAW_MODE_WIREFRAME ? vec4(frame.wire_color.rgb, 1.0) : shade(in_world, in_normal, albedo);
}
