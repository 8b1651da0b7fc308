//! Texture reparameterization of Gregory patches (seed 003, Eq. 1–3 and Table 1): a rational
//! bicubic `s(u, v)` that maps a Gregory patch's parameter to the parameter the exact
//! Catmull-Clark patch gives the same point, so textures and displacement sampled at `s(u, v)`
//! land where they would on the limit surface. The geometry is not changed.
//!
//! Design decisions:
//! - **Geometry independence.** As in the paper, the fit is made once per valence on the
//!   characteristic map: the planar control mesh of a single extraordinary vertex of valence
//!   `n` whose limit surface is the subdominant eigenfunction of the subdivision matrix. We
//!   compute it by power iteration through the crate's own refiner (one uniform step of a star
//!   of [`STAR_RINGS`] rings, the central star read back from the child level by the
//!   refiner's documented numbering, recentred and rescaled), so it follows exactly the rules
//!   that draw the surface, including OpenSubdiv's Catmull-Clark masks.
//! - **Correspondence (Eq. 2).** The paper matches a 17² grid of the exact patch to the nearest
//!   of 5000² Gregory points. The characteristic map is planar, so the nearest point is the
//!   Gregory patch's preimage of the exact point; we solve for it with projected Gauss-Newton
//!   (the closest point of the square when the exact point lies outside the Gregory patch's
//!   image), which is the 5000² search's limit without its discretization.
//! - **The 2×2 corner block of Eq. 3.** Five numbers `c0..c4` per valence; valence 4 is the
//!   identity `(1, 1/3, 1, 1/3, 1)`. A face combines the blocks of its four corners mirrored
//!   (the paper's `c̄ = 1 − c`, §3.2). The table ([`REPARAM_TABLE`]) is generated offline by
//!   `crates/topology/examples/reparam_fit.rs` (Levenberg–Marquardt on Eq. 2) and committed.
//! - **The pointwise error (Eq. 1, the paper's Fig. 8).** The paper's Eq. 1 composes `g ∘ s`
//!   while Eq. 2 and §3 make `s` map a Gregory parameter to a texture (exact-patch) parameter.
//!   We measure what a texture shows: the Gregory point `g(u, v)` displays the texel of the
//!   exact point `p(s(u, v))`, so its error is `|p(s(u, v)) − g(u, v)|` (without
//!   reparameterization `|p(u, v) − g(u, v)|`), relative to the patch's diameter.
use crate::limit::basis::bezier_curve_weights;
use crate::limit::eval::EvalError;
use crate::limit::eval::{LimitScheme, LocalMesh};
use crate::mesh::ControlMesh;
use crate::patches::gregory::{gregory_basis, gregory_weights};
use crate::refine::stencil::Stencil;
use crate::refine::{refine_uniform, Level};
use crate::rules::Scheme;

/// Rings of quads per sector in the characteristic-map control mesh: the patch at the
/// extraordinary vertex and the one-rings of its corners reach ring 2; one more ring keeps the
/// star's boundary out of every mask the patch reads.
pub const STAR_RINGS: usize = 3;

/// Eq. 2's lattice on the exact patch (the paper's 17²).
pub const FIT_GRID: usize = 17;

/// Valences the committed table covers (valence 4 included, as the identity).
pub const TABLE_VALENCES: std::ops::RangeInclusive<u32> = 3..=16;

/// The identity block: valence 4, where the Gregory patch is the exact bicubic patch.
pub const IDENTITY_BLOCK: [f64; 5] = [1.0, 1.0 / 3.0, 1.0, 1.0 / 3.0, 1.0];

include!("reparam_table.rs");

/// Table 1 of the paper (valences 3–10), for comparison with ours.
pub const PAPER_TABLE_1: [(u32, [f64; 5]); 8] = [
    (3, [0.0759, 0.1014, 0.6548, 0.2105, 0.9240]),
    (4, [1.0000, 0.3333, 1.0000, 0.3333, 1.0000]),
    (5, [0.3296, 0.0850, 0.7913, 0.3223, 0.8958]),
    (6, [0.4188, 0.0759, 0.8259, 0.3636, 0.8768]),
    (7, [0.4830, 0.0686, 0.8487, 0.3949, 0.8595]),
    (8, [0.5293, 0.0629, 0.8645, 0.4189, 0.8451]),
    (9, [0.5634, 0.0586, 0.8757, 0.4372, 0.8335]),
    (10, [0.5890, 0.0553, 0.8840, 0.4515, 0.8242]),
];

/// The corner block for a vertex of `valence`: the table's row, or `None` beyond it (callers
/// then fall back to the identity and say so).
pub fn corner_block(valence: u32) -> Option<[f64; 5]> {
    if valence == 4 {
        return Some(IDENTITY_BLOCK);
    }
    TABLE_VALENCES
        .contains(&valence)
        .then(|| REPARAM_TABLE[(valence - TABLE_VALENCES.start()) as usize])
}

/// The 4×4 rational control net of Eq. 3 (`(u, v, w)` per point, `[i][j]` = Bernstein index `i`
/// in `u`, `j` in `v`) of a face whose corners (0 at `(0,0)`, 1 at `(1,0)`, 2 at `(1,1)`, 3 at
/// `(0,1)`, the domain of [`crate::limit::basis`]) carry `blocks`.
pub fn control_net(blocks: &[[f64; 5]; 4]) -> [[[f64; 3]; 4]; 4] {
    let mut net = [[[0.0; 3]; 4]; 4];
    for (i, row) in net.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            *p = [i as f64 / 3.0, j as f64 / 3.0, 1.0];
        }
    }
    // Corner (U, V) ∈ {0,1}²: the block's local point (a, b) ∈ {0,1}² sits at net index
    // (a or 3−a, b or 3−b), its coordinates mirrored the same way (c̄ = 1 − c).
    for (corner, &(cu, cv)) in [(0, 0), (1, 0), (1, 1), (0, 1)].iter().enumerate() {
        let [c0, c1, c2, c3, c4] = blocks[corner];
        let local = [
            [(0.0, 0.0, c0), (0.0, c1, c2)],
            [(c1, 0.0, c2), (c3, c3, c4)],
        ];
        for (a, row) in local.iter().enumerate() {
            for (b, &(lu, lv, w)) in row.iter().enumerate() {
                let i = if cu == 0 { a } else { 3 - a };
                let j = if cv == 0 { b } else { 3 - b };
                let u = if cu == 0 { lu } else { 1.0 - lu };
                let v = if cv == 0 { lv } else { 1.0 - lv };
                net[i][j] = [u, v, w];
            }
        }
    }
    net
}

/// Eq. 3: the texture parameter of the Gregory point at `(u, v)` under the net `net`.
pub fn reparameterize(net: &[[[f64; 3]; 4]; 4], u: f64, v: f64) -> [f64; 2] {
    let (bu, bv) = (bezier_curve_weights(u).0, bezier_curve_weights(v).0);
    let (mut x, mut y, mut w) = (0.0, 0.0, 0.0);
    for i in 0..4 {
        for j in 0..4 {
            let b = bu[i] * bv[j] * net[i][j][2];
            x += b * net[i][j][0];
            y += b * net[i][j][1];
            w += b;
        }
    }
    [x / w, y / w]
}

/// The characteristic map of Catmull-Clark at a vertex of valence `n`, with the patch that
/// has the extraordinary vertex at its `(0, 0)` corner.
#[derive(Clone, Debug)]
pub struct CharacteristicMap {
    pub valence: u32,
    /// Planar control mesh (z = 0): a star of [`STAR_RINGS`] rings, the vertex at index 0.
    pub mesh: ControlMesh,
    /// Power iterations until the star stopped changing.
    pub iterations: usize,
    exact: LocalMesh,
    gregory: [Stencil; 20],
}

/// Index of star vertex `(i, j)` of sector `s` (spoke `s` holds `(k, 0)`, spoke `s + 1` holds
/// `(0, k)`).
fn star_index(n: usize, m: usize, s: usize, i: usize, j: usize) -> usize {
    let spoke = |s: usize, k: usize| 1 + (s % n) * m + (k - 1);
    match (i, j) {
        (0, 0) => 0,
        (i, 0) => spoke(s, i),
        (0, j) => spoke(s + 1, j),
        (i, j) => 1 + n * m + s * m * m + (i - 1) * m + (j - 1),
    }
}

fn star_faces(n: usize, m: usize) -> Vec<[u32; 4]> {
    let mut faces = Vec::with_capacity(n * m * m);
    for s in 0..n {
        for i in 0..m {
            for j in 0..m {
                let q = |i, j| star_index(n, m, s, i, j) as u32;
                faces.push([q(i, j), q(i + 1, j), q(i + 1, j + 1), q(i, j + 1)]);
            }
        }
    }
    faces
}

impl CharacteristicMap {
    /// Builds the map for valence `n ≥ 3` (power iteration to a change below 1e-14).
    pub fn new(n: u32) -> Result<Self, EvalError> {
        if n < 3 {
            return Err(EvalError::Valence { valence: n });
        }
        let (nu, m) = (n as usize, STAR_RINGS);
        let faces = star_faces(nu, m);
        let count = 1 + nu * m + nu * m * m;
        // A sector-linear start has a strong first Fourier mode: the subdominant eigenspace.
        let mut points = vec![[0.0; 3]; count];
        let angle = |s: usize| std::f64::consts::TAU * s as f64 / nu as f64;
        for s in 0..nu {
            let (a0, a1) = (angle(s), angle(s + 1));
            for i in 0..=m {
                for j in 0..=m {
                    let (x, y) = (i as f64, j as f64);
                    points[star_index(nu, m, s, i, j)] = [
                        x * a0.cos() + y * a1.cos(),
                        x * a0.sin() + y * a1.sin(),
                        0.0,
                    ];
                }
            }
        }
        let mut iterations = 0;
        for it in 1..=400 {
            iterations = it;
            let mesh = ControlMesh::from_polygons(points.clone(), &faces);
            let r = refine_uniform(&mesh, Scheme::CatmullClark, 1)?;
            let (base, child) = (&r.level(0).topology, &r.level(1));
            let (nv, ne) = (base.num_vertices(), base.num_edges());
            let child_of = |s: usize, i: usize, j: usize| -> usize {
                let p = |i, j| star_index(nu, m, s, i, j) as u32;
                match (i % 2, j % 2) {
                    (0, 0) => p(i / 2, j / 2) as usize,
                    (1, 0) => nv + edge(base, p(i / 2, j / 2), p(i / 2 + 1, j / 2)),
                    (0, 1) => nv + edge(base, p(i / 2, j / 2), p(i / 2, j / 2 + 1)),
                    _ => nv + ne + s * m * m + (i / 2) * m + j / 2,
                }
            };
            let mut next = vec![[0.0; 3]; count];
            for s in 0..nu {
                for i in 0..=m {
                    for j in 0..=m {
                        next[star_index(nu, m, s, i, j)] = child.positions[child_of(s, i, j)];
                    }
                }
            }
            // Remove the constant mode (the vertex's limit moves to the origin) and the
            // eigenvalue (first spoke point at unit distance).
            let c = next[0];
            for p in next.iter_mut() {
                for k in 0..3 {
                    p[k] -= c[k];
                }
            }
            let r1 = next[star_index(nu, m, 0, 1, 0)];
            let scale = 1.0 / (r1[0] * r1[0] + r1[1] * r1[1]).sqrt();
            let mut change: f64 = 0.0;
            for (p, q) in next.iter_mut().zip(&points) {
                for k in 0..3 {
                    p[k] *= scale;
                    change = change.max((p[k] - q[k]).abs());
                }
            }
            points = next;
            if change < 1e-14 {
                break;
            }
        }
        let mesh = ControlMesh::from_polygons(points, &faces);
        let exact = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark)?;
        let level = Level::from_mesh(&mesh, Scheme::CatmullClark)?;
        let gregory = gregory_basis(level.view(), 0, &mesh.options)?;
        Ok(Self {
            valence: n,
            mesh,
            iterations,
            exact,
            gregory,
        })
    }

    /// The exact limit patch at `(u, v)`: position and the two derivatives (planar, x and y).
    pub fn exact(&self, u: f64, v: f64) -> Result<[[f64; 2]; 3], EvalError> {
        let s = self.exact.evaluate(0, u, v)?;
        Ok([
            [s.position[0], s.position[1]],
            [s.du[0], s.du[1]],
            [s.dv[0], s.dv[1]],
        ])
    }

    /// The Gregory patch at `(u, v)`: position and the two derivatives.
    pub fn gregory(&self, u: f64, v: f64) -> [[f64; 2]; 3] {
        let w = gregory_weights(u, v);
        let mut out = [[0.0; 2]; 3];
        for (k, st) in self.gregory.iter().enumerate() {
            let p = st.apply(&self.mesh.positions);
            for d in 0..2 {
                out[0][d] += w.point[k] * p[d];
                out[1][d] += w.du[k] * p[d];
                out[2][d] += w.dv[k] * p[d];
            }
        }
        out
    }

    /// The Gregory parameter of the Gregory patch's nearest point to `target` (its preimage
    /// when it has one): projected Gauss-Newton on the square.
    pub fn gregory_preimage(&self, target: [f64; 2], start: [f64; 2]) -> [f64; 2] {
        let mut q = start;
        for _ in 0..100 {
            let [p, du, dv] = self.gregory(q[0], q[1]);
            let r = [target[0] - p[0], target[1] - p[1]];
            // Normal equations of the 2×2 system (also a least-squares step at a fold).
            let (a, b, d) = (dot(du, du), dot(du, dv), dot(dv, dv));
            let (gu, gv) = (dot(du, r), dot(dv, r));
            let det = a * d - b * b;
            let step = if det.abs() > 1e-300 {
                [(d * gu - b * gv) / det, (a * gv - b * gu) / det]
            } else {
                [0.0, 0.0]
            };
            let next = [
                (q[0] + step[0]).clamp(0.0, 1.0),
                (q[1] + step[1]).clamp(0.0, 1.0),
            ];
            let moved = (next[0] - q[0]).abs().max((next[1] - q[1]).abs());
            q = next;
            if moved < 1e-15 {
                break;
            }
        }
        q
    }

    /// Eq. 2's data: for each point of a `grid`² lattice of the exact patch, its Gregory
    /// parameter and the area weight of its cell (trapezoid weights × |∂p/∂u × ∂p/∂v|).
    pub fn correspondence(&self, grid: usize) -> Result<Vec<Correspondence>, EvalError> {
        let h = 1.0 / (grid - 1) as f64;
        let mut out = Vec::with_capacity(grid * grid);
        for a in 0..grid {
            for b in 0..grid {
                let (u, v) = (a as f64 * h, b as f64 * h);
                let [p, du, dv] = self.exact(u, v)?;
                let edge = |k: usize| if k == 0 || k == grid - 1 { 0.5 } else { 1.0 };
                let area = (du[0] * dv[1] - du[1] * dv[0]).abs() * h * h * edge(a) * edge(b);
                out.push(Correspondence {
                    exact: [u, v],
                    gregory: self.gregory_preimage(p, [u, v]),
                    weight: area,
                });
            }
        }
        Ok(out)
    }

    /// The pointwise texture error at `(u, v)` of the Gregory patch under `net` (identity when
    /// `None`): `|p(s(u, v)) − g(u, v)|`.
    pub fn texture_error(
        &self,
        net: Option<&[[[f64; 3]; 4]; 4]>,
        u: f64,
        v: f64,
    ) -> Result<f64, EvalError> {
        let st = net.map_or([u, v], |n| reparameterize(n, u, v));
        let [p, _, _] = self.exact(st[0].clamp(0.0, 1.0), st[1].clamp(0.0, 1.0))?;
        let [g, _, _] = self.gregory(u, v);
        Ok(((p[0] - g[0]).powi(2) + (p[1] - g[1]).powi(2)).sqrt())
    }

    /// Eq. 1 discretized on the dyadic `(2^k + 1)²` lattice: (RMS, max) texture error relative
    /// to the patch's diameter, for the corner block `block` at the extraordinary corner (the
    /// other three corners are regular).
    pub fn distortion(&self, block: Option<[f64; 5]>, k: u32) -> Result<(f64, f64), EvalError> {
        let net = block.map(|b| control_net(&[b, IDENTITY_BLOCK, IDENTITY_BLOCK, IDENTITY_BLOCK]));
        let grid = (1usize << k) + 1;
        let h = 1.0 / (grid - 1) as f64;
        let diameter = {
            let [p0, _, _] = self.exact(0.0, 0.0)?;
            let [p2, _, _] = self.exact(1.0, 1.0)?;
            ((p2[0] - p0[0]).powi(2) + (p2[1] - p0[1]).powi(2)).sqrt()
        };
        let (mut sum, mut max) = (0.0, 0.0f64);
        for a in 0..grid {
            for b in 0..grid {
                let e = self.texture_error(net.as_ref(), a as f64 * h, b as f64 * h)?;
                sum += e * e;
                max = max.max(e);
            }
        }
        Ok((
            (sum / (grid * grid) as f64).sqrt() / diameter,
            max / diameter,
        ))
    }
}

/// One pair of Eq. 2: the exact patch's parameter, the Gregory parameter of the same point, and
/// the area weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Correspondence {
    pub exact: [f64; 2],
    pub gregory: [f64; 2],
    pub weight: f64,
}

fn net_of(c: &[f64; 5]) -> [[[f64; 3]; 4]; 4] {
    control_net(&[*c, IDENTITY_BLOCK, IDENTITY_BLOCK, IDENTITY_BLOCK])
}

fn residuals(data: &[Correspondence], c: &[f64; 5]) -> Vec<f64> {
    let net = net_of(c);
    let mut r = Vec::with_capacity(2 * data.len());
    for d in data {
        let s = reparameterize(&net, d.gregory[0], d.gregory[1]);
        let w = d.weight.sqrt();
        r.push(w * (d.exact[0] - s[0]));
        r.push(w * (d.exact[1] - s[1]));
    }
    r
}

fn cost(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Smallest Jacobian determinant of `s` on a 129² lattice spanning the square to within 1e-4 of
/// its sides (central differences need the margin).
pub fn min_jacobian(c: &[f64; 5]) -> f64 {
    let net = net_of(c);
    let n = 129;
    let h = 1e-6;
    let mut min = f64::INFINITY;
    let at = |k: usize| 1e-4 + (1.0 - 2e-4) * k as f64 / (n - 1) as f64;
    for a in 0..n {
        for b in 0..n {
            let (u, v) = (at(a), at(b));
            let su = sub(
                reparameterize(&net, u + h, v),
                reparameterize(&net, u - h, v),
            );
            let sv = sub(
                reparameterize(&net, u, v + h),
                reparameterize(&net, u, v - h),
            );
            min = min.min((su[0] * sv[1] - su[1] * sv[0]) / (4.0 * h * h));
        }
    }
    min
}

/// The paper's bijection constraint: positive weights, the corner block's boundary points on the
/// square's sides in order (`c1 ≥ 0`, so the sides map onto themselves monotonically) and a
/// positive Jacobian inside.
pub fn admissible(c: &[f64; 5]) -> bool {
    c[0] > 0.0
        && c[2] > 0.0
        && c[4] > 0.0
        && c[1] >= 0.0
        && c[1] < 2.0 / 3.0
        && min_jacobian(c) > 0.0
}

/// Eq. 2 minimized over the corner block of an extraordinary corner (the other three regular):
/// Levenberg–Marquardt from the identity with a forward-difference Jacobian; steps that leave the admissible set
/// are rejected like steps that raise the cost (a bound on `c1` is met by clamping the step).
pub fn fit_corner_block(data: &[Correspondence]) -> ([f64; 5], f64, usize) {
    let mut c = IDENTITY_BLOCK;
    let mut r = residuals(data, &c);
    let mut f = cost(&r);
    let mut mu = 1e-3;
    let mut iterations = 0;
    for it in 0..500 {
        iterations = it + 1;
        let h = 1e-7;
        let cols: Vec<Vec<f64>> = (0..5)
            .map(|k| {
                let mut d = c;
                d[k] += h;
                residuals(data, &d)
                    .iter()
                    .zip(&r)
                    .map(|(a, b)| (a - b) / h)
                    .collect()
            })
            .collect();
        let mut jtj = [[0.0; 5]; 5];
        let mut jtr = [0.0; 5];
        for a in 0..5 {
            for b in 0..5 {
                jtj[a][b] = cols[a].iter().zip(&cols[b]).map(|(x, y)| x * y).sum();
            }
            jtr[a] = cols[a].iter().zip(&r).map(|(x, y)| x * y).sum();
        }
        let mut improved = false;
        for _ in 0..30 {
            let mut m = jtj;
            for (k, row) in m.iter_mut().enumerate() {
                row[k] += mu * jtj[k][k].max(1e-12);
            }
            let Some(step) = solve5(m, jtr.map(|x| -x)) else {
                mu *= 10.0;
                continue;
            };
            let mut next = c;
            for k in 0..5 {
                next[k] += step[k];
            }
            next[1] = next[1].max(0.0);
            let rn = residuals(data, &next);
            let fnext = cost(&rn);
            if fnext < f && admissible(&next) {
                let gain = f - fnext;
                c = next;
                r = rn;
                f = fnext;
                mu = (mu / 3.0).max(1e-12);
                improved = gain > 1e-16 * f.max(1e-300);
                break;
            }
            mu *= 4.0;
        }
        if !improved {
            break;
        }
    }
    (c, f, iterations)
}

/// Gaussian elimination with partial pivoting on a 5×5 system.
fn solve5(mut a: [[f64; 5]; 5], mut b: [f64; 5]) -> Option<[f64; 5]> {
    for col in 0..5 {
        let p = (col..5).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        if a[p][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, p);
        b.swap(col, p);
        for row in col + 1..5 {
            let f = a[row][col] / a[col][col];
            let pivot = a[col];
            for (x, p) in a[row].iter_mut().zip(pivot).skip(col) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 5];
    for row in (0..5).rev() {
        let s: f64 = (row + 1..5).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn edge(t: &crate::mesh::Topology, a: u32, b: u32) -> usize {
    // Not input-dependent: the star joins these two vertices by construction.
    t.find_edge(a, b).expect("star edge present") as usize
}
