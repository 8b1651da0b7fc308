#version 450
// One control point per patch: it carries the patch's frame-wide id.
#define TECHNIQUE_PUSH_CONSTANTS
#include "frame.glsl"
#include "adaptive.glsl"
layout(location = 0) flat out uint out_patch;
void main() {
    out_patch = adaptive.first_patch + uint(gl_VertexIndex);
}
