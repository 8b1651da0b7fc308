#version 450
// One patch per level-1 face and one control point per patch: the point carries the face.
layout(location = 0) flat out uint out_face;
void main() {
    out_face = uint(gl_VertexIndex);
}
