// Lambert + Blinn-Phong with one directional light, two-sided (open meshes show their back).
// A zero normal (a degenerate patch) is lit as if it faced the eye.
#include "normals.glsl"
vec4 shade(vec3 world, vec3 normal, vec3 albedo) {
    vec3 view_dir = safe_normalize(frame.camera_pos.xyz - world, vec3(0.0, 0.0, 1.0));
    vec3 n = safe_normalize(normal, view_dir);
    if (dot(n, view_dir) < 0.0) n = -n;
    vec3 l = normalize(frame.light_dir.xyz);
    vec3 h = safe_normalize(l + view_dir, n);
    float diffuse = max(dot(n, l), 0.0);
    float specular = pow(max(dot(n, h), 0.0), 48.0) * 0.35;
    vec3 c = 0.18 * albedo + diffuse * albedo + specular * vec3(1.0);
    return vec4(c, 1.0);
}
