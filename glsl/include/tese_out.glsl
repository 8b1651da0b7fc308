// What every TES hands to the fragment stage, and the clip-space write.
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
void emit(vec3 p, vec3 n) {
    out_world = p;
    out_normal = n;
    gl_Position = frame.view_proj * vec4(p, 1.0);
}
