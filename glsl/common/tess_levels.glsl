// Uniform tessellation levels from the frame block, written once per patch.
void set_uniform_levels_tri() {
    if (gl_InvocationID == 0) {
        gl_TessLevelOuter[0] = frame.tess.x;
        gl_TessLevelOuter[1] = frame.tess.x;
        gl_TessLevelOuter[2] = frame.tess.x;
        gl_TessLevelInner[0] = frame.tess.y;
    }
}

void set_uniform_levels_quad() {
    if (gl_InvocationID == 0) {
        gl_TessLevelOuter[0] = frame.tess.x;
        gl_TessLevelOuter[1] = frame.tess.x;
        gl_TessLevelOuter[2] = frame.tess.x;
        gl_TessLevelOuter[3] = frame.tess.x;
        gl_TessLevelInner[0] = frame.tess.y;
        gl_TessLevelInner[1] = frame.tess.y;
    }
}
