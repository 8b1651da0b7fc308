// The evaluation stages' output: `common/stage_out.glsl` (the capture contract is there) at the
// tessellator's domain coordinate. The triangle/quad techniques pass
// `draw.first_patch + uint(gl_PrimitiveID)` as the patch id.
#include "stage_out.glsl"

void emit_sample(vec3 p, vec3 n, uint patch_id, uint flags) {
    emit_vertex_at(p, n, patch_id, flags, gl_TessCoord.xy);
}
