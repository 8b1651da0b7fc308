//! Regular patches: the quartic box spline of a regular Loop triangle (12 control points) and
//! the bicubic uniform B-spline of a regular Catmull-Clark quad (16 control points).
//!
//! # Parametric domains (the one place where they are stated)
//!
//! * **Loop triangle** `(v0, v1, v2)`: `P(u, v) = v0·(1−u−v) + v1·u + v2·v` on the domain
//!   `u, v ≥ 0, u + v ≤ 1`. Derivatives `du`, `dv` are with respect to these `u`, `v`.
//! * **Catmull-Clark quad** `(v0, v1, v2, v3)`: `(u, v) ∈ [0,1]²` with `v0` at `(0,0)`,
//!   `v1` at `(1,0)`, `v2` at `(1,1)`, `v3` at `(0,1)`.
//!
//! # Control-point ordering
//!
//! Loop (same layout as OpenSubdiv's regular triangle); the face is `(3, 6, 7)`, lattice
//! coordinates `(a, b)` mean the point sits at `v0 + a·(v1−v0) + b·(v2−v0)` in the regular
//! triangular lattice:
//!
//! ```text
//!       0 --- 1                 0:(0,-1)  1:(-1,0)
//!      / \   / \                2:(1,-1)  3:(0,0)=v0  4:(-1,1)
//!     2 --- 3 --- 4             5:(2,-1)  6:(1,0)=v1  7:(0,1)=v2  8:(-1,2)
//!    / \   / \   / \            9:(2,0)  10:(1,1)    11:(0,2)
//!   5 --- 6 --- 7 --- 8
//!    \   / \   / \   /
//!     9 --- 10 -- 11
//! ```
//!
//! Catmull-Clark: row-major 4×4 grid, index `4·(b+1) + (a+1)` for lattice `(a, b) ∈ [-1,2]²`
//! in units of the face's edges, so `v0 = 5`, `v1 = 6`, `v2 = 10`, `v3 = 9`.

/// Lattice coordinates `(a, b)` of the 12 box-spline control points (see the module docs).
pub const LOOP_REGULAR_LATTICE: [(i32, i32); 12] = [
    (0, -1),
    (-1, 0),
    (1, -1),
    (0, 0),
    (-1, 1),
    (2, -1),
    (1, 0),
    (0, 1),
    (-1, 2),
    (2, 0),
    (1, 1),
    (0, 2),
];

/// Slots of the three corners `v0, v1, v2` in the 12-point Loop patch.
pub const LOOP_CORNER_SLOTS: [usize; 3] = [3, 6, 7];
/// Slots of the four corners `v0..v3` in the 16-point Catmull-Clark patch.
pub const CATMARK_CORNER_SLOTS: [usize; 4] = [5, 6, 10, 9];

/// Basis weights of a patch at one parameter value: position and the two first derivatives.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchWeights<const N: usize> {
    pub point: [f64; N],
    pub du: [f64; N],
    pub dv: [f64; N],
}

impl<const N: usize> PatchWeights<N> {
    /// Apply the weights to `N` control points of dimension `D`; returns (position, du, dv).
    pub fn apply<const D: usize>(&self, cps: &[[f64; D]; N]) -> ([f64; D], [f64; D], [f64; D]) {
        let mut p = [0.0; D];
        let mut du = [0.0; D];
        let mut dv = [0.0; D];
        for (i, cp) in cps.iter().enumerate() {
            for k in 0..D {
                p[k] += self.point[i] * cp[k];
                du[k] += self.du[i] * cp[k];
                dv[k] += self.dv[i] * cp[k];
            }
        }
        (p, du, dv)
    }
}

/// Value with its two partial derivatives: the box-spline polynomials are written once and
/// differentiated by evaluation, which keeps the derivative weights in lockstep with the values.
#[derive(Clone, Copy, Debug)]
struct Dual {
    v: f64,
    du: f64,
    dv: f64,
}

impl Dual {
    fn c(v: f64) -> Dual {
        Dual {
            v,
            du: 0.0,
            dv: 0.0,
        }
    }
    fn pow(self, n: u32) -> Dual {
        let mut r = Dual::c(1.0);
        for _ in 0..n {
            r = r * self;
        }
        r
    }
}

impl std::ops::Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual {
            v: self.v + o.v,
            du: self.du + o.du,
            dv: self.dv + o.dv,
        }
    }
}

impl std::ops::Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual {
            v: self.v * o.v,
            du: self.du * o.v + self.v * o.du,
            dv: self.dv * o.v + self.v * o.dv,
        }
    }
}

impl std::ops::Mul<Dual> for f64 {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual {
            v: self * o.v,
            du: self * o.du,
            dv: self * o.dv,
        }
    }
}

/// Quartic box-spline weights of the regular Loop patch at `(u, v)` (domain in the module docs).
pub fn loop_regular_weights(u: f64, v: f64) -> PatchWeights<12> {
    // Barycentrics: s for v0, a for v1 (= u), b for v2 (= v).
    let a = Dual {
        v: u,
        du: 1.0,
        dv: 0.0,
    };
    let b = Dual {
        v,
        du: 0.0,
        dv: 1.0,
    };
    let s = Dual {
        v: 1.0 - u - v,
        du: -1.0,
        dv: -1.0,
    };
    let (s2, s3, s4) = (s.pow(2), s.pow(3), s.pow(4));
    let (a2, a3, a4) = (a.pow(2), a.pow(3), a.pow(4));
    let (b2, b3, b4) = (b.pow(2), b.pow(3), b.pow(4));
    let mut w = [Dual::c(0.0); 12];
    // Points above the corners' far sides (2 terms each).
    w[0] = s4 + 2.0 * s3 * a;
    w[1] = s4 + 2.0 * s3 * b;
    w[8] = b4 + 2.0 * b3 * s;
    w[11] = b4 + 2.0 * b3 * a;
    w[9] = a4 + 2.0 * a3 * b;
    w[5] = a4 + 2.0 * a3 * s;
    // Points across the three edges (9 terms each).
    w[2] = s4
        + 2.0 * s3 * b
        + 6.0 * s3 * a
        + 6.0 * s2 * a * b
        + 12.0 * s2 * a2
        + a4
        + 2.0 * a3 * b
        + 6.0 * a3 * s
        + 6.0 * a2 * s * b;
    w[4] = b4
        + 2.0 * b3 * a
        + 6.0 * b3 * s
        + 6.0 * b2 * s * a
        + 12.0 * b2 * s2
        + s4
        + 2.0 * s3 * a
        + 6.0 * s3 * b
        + 6.0 * s2 * a * b;
    w[10] = a4
        + 2.0 * a3 * s
        + 6.0 * a3 * b
        + 6.0 * a2 * b * s
        + 12.0 * a2 * b2
        + b4
        + 2.0 * b3 * s
        + 6.0 * b3 * a
        + 6.0 * b2 * a * s;
    // The three corners (15 terms each).
    w[3] = a4
        + 6.0 * a3 * b
        + 8.0 * a3 * s
        + 36.0 * a2 * b * s
        + 24.0 * a2 * s2
        + 24.0 * a * s3
        + b4
        + 6.0 * b3 * a
        + 8.0 * b3 * s
        + 36.0 * b2 * a * s
        + 24.0 * b2 * s2
        + 24.0 * b * s3
        + 6.0 * s4
        + 60.0 * s2 * a * b
        + 12.0 * a2 * b2;
    w[6] = b4
        + 6.0 * b3 * s
        + 8.0 * b3 * a
        + 36.0 * b2 * s * a
        + 24.0 * b2 * a2
        + 24.0 * b * a3
        + s4
        + 6.0 * s3 * b
        + 8.0 * s3 * a
        + 36.0 * s2 * a * b
        + 24.0 * s2 * a2
        + 24.0 * s * a3
        + 6.0 * a4
        + 60.0 * a2 * b * s
        + 12.0 * b2 * s2;
    w[7] = s4
        + 6.0 * s3 * a
        + 8.0 * s3 * b
        + 36.0 * s2 * a * b
        + 24.0 * s2 * b2
        + 24.0 * s * b3
        + a4
        + 6.0 * a3 * s
        + 8.0 * a3 * b
        + 36.0 * a2 * s * b
        + 24.0 * a2 * b2
        + 24.0 * a * b3
        + 6.0 * b4
        + 60.0 * b2 * s * a
        + 12.0 * s2 * a2;
    let mut out = PatchWeights {
        point: [0.0; 12],
        du: [0.0; 12],
        dv: [0.0; 12],
    };
    for (i, wi) in w.iter().enumerate() {
        out.point[i] = wi.v / 12.0;
        out.du[i] = wi.du / 12.0;
        out.dv[i] = wi.dv / 12.0;
    }
    out
}

/// Cubic Bernstein basis and its derivative at `t`: the Bézier patches' curve weights (Gregory
/// end caps, ACC-1, the reparameterization of [`crate::patches::reparam`]).
pub fn bezier_curve_weights(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * (1.0 - 3.0 * t),
            3.0 * t * (2.0 - 3.0 * t),
            3.0 * t * t,
        ],
    )
}

/// Uniform cubic B-spline weights and derivatives at `t ∈ [0,1]` (the middle span).
pub fn bspline_curve_weights(t: f64) -> ([f64; 4], [f64; 4]) {
    let t2 = t * t;
    let t3 = t2 * t;
    let w = [
        (1.0 - 3.0 * t + 3.0 * t2 - t3) / 6.0,
        (4.0 - 6.0 * t2 + 3.0 * t3) / 6.0,
        (1.0 + 3.0 * t + 3.0 * t2 - 3.0 * t3) / 6.0,
        t3 / 6.0,
    ];
    let d = [
        -0.5 * t2 + t - 0.5,
        1.5 * t2 - 2.0 * t,
        -1.5 * t2 + t + 0.5,
        0.5 * t2,
    ];
    (w, d)
}

/// Bicubic B-spline weights of the regular Catmull-Clark patch at `(u, v) ∈ [0,1]²`.
pub fn catmark_regular_weights(u: f64, v: f64) -> PatchWeights<16> {
    let (wu, du) = bspline_curve_weights(u);
    let (wv, dv) = bspline_curve_weights(v);
    let mut out = PatchWeights {
        point: [0.0; 16],
        du: [0.0; 16],
        dv: [0.0; 16],
    };
    for r in 0..4 {
        for c in 0..4 {
            out.point[4 * r + c] = wu[c] * wv[r];
            out.du[4 * r + c] = du[c] * wv[r];
            out.dv[4 * r + c] = wu[c] * dv[r];
        }
    }
    out
}

/// Weights of a patch of either scheme, sized at run time.
pub fn regular_weights(quad: bool, u: f64, v: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    if quad {
        let w = catmark_regular_weights(u, v);
        (w.point.to_vec(), w.du.to_vec(), w.dv.to_vec())
    } else {
        let w = loop_regular_weights(u, v);
        (w.point.to_vec(), w.du.to_vec(), w.dv.to_vec())
    }
}
