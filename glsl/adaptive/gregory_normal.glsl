// ACC-1's tangent patches (gregory.tese); included after tese_main.glsl, whose surface.glsl it
// reads.
#ifdef PATCH_SHADING_NORMAL
// ACC-1 nets (Gregory records with tangent valences) shade with their tangent patches: the
// net's 20 points from the control stage, the 8 limit-tangent points from the buffer.
vec3 patch_shading_normal(uint id, vec2 uv, vec3 n) {
    uint valences = SURFACES[id].tangent_valences;
    if (valences == 0u) return n;
    vec3 c[28];
    for (int k = 0; k < 20; ++k) c[k] = tc_points[k];
    uint o = PATCHES[id].cp_offset;
    for (uint k = 20u; k < 28u; ++k) c[k] = vtx(CONTROL_POINTS[o + k]);
    return acc_tangent_normal(c, valences, uv);
}
#endif
