// The refinement-pattern seed's procedural displacement (Boubekeur & Schlick 2005, §4, Fig. 4):
// P + a sin(f |P|) along the unit normal, a = frame.sine.x, f = frame.sine.y; a = 0 leaves P as
// it is, bit for bit. It reads only the point's own position and normal, so two patches that
// emit the same bits at a shared point displace it to the same bits (flat, Phong and PN, on
// both draw paths). The normal is left as shaded.
vec3 displace_sine(vec3 p, vec3 n) {
    if (frame.sine.x == 0.0) {
        return p;
    }
    float len = length(n);
    if (!(len > 0.0)) {
        return p;
    }
    precise float h = frame.sine.x * sin(frame.sine.y * length(p)) / len;
    precise vec3 q = p + h * n;
    return q;
}
