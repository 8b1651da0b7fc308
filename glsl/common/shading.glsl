// Lambert + Blinn-Phong with one directional light, two-sided (open meshes show their back).
vec4 shade(vec3 world, vec3 normal, vec3 albedo) {
    vec3 n = normalize(normal);
    vec3 view_dir = normalize(frame.camera_pos.xyz - world);
    if (dot(n, view_dir) < 0.0) n = -n;
    vec3 l = normalize(frame.light_dir.xyz);
    vec3 h = normalize(l + view_dir);
    float diffuse = max(dot(n, l), 0.0);
    float specular = pow(max(dot(n, h), 0.0), 48.0) * 0.35;
    vec3 c = 0.18 * albedo + diffuse * albedo + specular * vec3(1.0);
    return vec4(c, 1.0);
}
