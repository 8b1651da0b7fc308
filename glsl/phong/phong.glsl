// Phong tessellation (Boubekeur & Alexa 2008): the linear point projected onto each corner's
// tangent plane, the projections blended barycentrically, then mixed with the linear point by
// the shape factor alpha. What the evaluation stage and the pattern vertex stage share, so
// both paths compute the same bits at the same domain point.
//
// `precise` barycentric sums (flat.glsl): both patches of an edge get the same bits. Each
// projection depends on its corner alone, so it is the same in either patch.

vec3 phong_project(vec3 q, vec3 p, vec3 n) {
    return q - dot(q - p, n) * n;
}

// The Phong point at barycentric b of corners c (normals n), shape factor alpha.
vec3 phong_point(vec3 c[3], vec3 n[3], vec3 b, float alpha) {
    precise vec3 p = b.x * c[0] + b.y * c[1] + b.z * c[2];
    precise vec3 phong = b.x * phong_project(p, c[0], n[0]) + b.y * phong_project(p, c[1], n[1])
        + b.z * phong_project(p, c[2], n[2]);
    precise vec3 blended = (1.0 - alpha) * p + alpha * phong;
    return blended;
}

// Normals are interpolated linearly.
vec3 phong_normal(vec3 n[3], vec3 b) {
    precise vec3 m = b.x * n[0] + b.y * n[1] + b.z * n[2];
    return m;
}
