// Normalisation that stays finite for every finite vector (issue 15: no NaN out of finite input).
// normalize(v) is v * inversesqrt(dot(v, v)): NaN for a zero vector (a degenerate patch, a
// collapsed face, cancelling normals), and for v beyond about 1.8e19 (the cross product of
// tangents of a mesh near topology::MAX_COORDINATE) dot(v, v) overflows, while for tiny v it
// underflows to zero. Dividing by the largest component first brings v to [-1, 1] without
// changing its direction, so the dot product neither overflows nor underflows.
#ifndef NORMALS_GLSL
#define NORMALS_GLSL
// The unit vector along v, or `fallback` when v is zero.
vec3 safe_normalize(vec3 v, vec3 fallback) {
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    if (!(m > 0.0)) return fallback;
    vec3 s = v / m;
    return s * inversesqrt(dot(s, s));
}
#endif
