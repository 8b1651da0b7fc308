// Normalisation that stays finite for every finite vector (no NaN out of finite input).
// normalize(v) is v * inversesqrt(dot(v, v)): NaN for a zero vector (a degenerate patch, a
// collapsed face, cancelling normals), and for v beyond about 1.8e19 (the cross product of
// tangents of a mesh near topology::MAX_COORDINATE) dot(v, v) overflows, while for tiny v it
// underflows to zero. Dividing by the largest component first brings v to [-1, 1] without
// changing its direction, so the dot product neither overflows nor underflows.
#ifndef NORMALS_GLSL
#define NORMALS_GLSL
// Both are `precise` and written out (no dot(), no contraction), so every stage that evaluates
// the same vector gets the same bits: the adaptive TES variants evaluate a shared point's
// owner frame each on its own.
// The unit vector along v, or `fallback` when v is zero.
vec3 safe_normalize(vec3 v, vec3 fallback) {
    precise float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    if (!(m > 0.0)) return fallback;
    precise vec3 s = v / m;
    precise float d = s.x * s.x + s.y * s.y + s.z * s.z;
    precise vec3 r = s * inversesqrt(d);
    return r;
}

// |v|, finite for every finite v (length() overflows beyond about 1.8e19).
float safe_length(vec3 v) {
    precise float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    if (!(m > 0.0)) return 0.0;
    precise vec3 s = v / m;
    precise float d = s.x * s.x + s.y * s.y + s.z * s.z;
    precise float r = m * sqrt(d);
    return r;
}
#endif
