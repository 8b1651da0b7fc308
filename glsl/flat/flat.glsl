// Flat tessellation: a base face's own plane at a domain point, what the evaluation stages
// (tessellation path) and the pattern vertex stages (refinement-pattern path) share, so both
// paths compute the same bits at the same domain point.
//
// Written out and `precise`, not mix(): mix's rounding is the driver's (NVIDIA's is
// x + a (y - x), not y at a = 1), and contraction to fused multiply-adds depends on operand
// order. So every quad edge point is a (1 - t) + b t from whichever side, the same two products
// summed, and both quads of an edge emit the same bits; on a triangle edge the third weight is
// 0 and the other two products sum to the same bits in either patch's corner order.

// The bilinear point at (u, v); corners v0 (0,0), v1 (1,0), v2 (1,1), v3 (0,1).
vec3 flat_quad(vec3 c[4], float u, float v) {
    precise vec3 p = (c[0] * (1.0 - u) + c[1] * u) * (1.0 - v) + (c[3] * (1.0 - u) + c[2] * u) * v;
    return p;
}

// The planar point at barycentric b (the weights of corners 0, 1, 2).
vec3 flat_triangle(vec3 c[3], vec3 b) {
    precise vec3 p = b.x * c[0] + b.y * c[1] + b.z * c[2];
    return p;
}
