//! Exact Doo-Sabin limit evaluation at any point of a control mesh, with the limit normal.
//!
//! # The domain
//!
//! A domain point is `(f, i, u, v)`: base face `f`, its corner `i` (in the face's vertex order)
//! and `(u, v) ∈ [0, 1]²` in the *corner quad* of that corner, the quad of `f` with corners
//!
//! - `(0, 0)`: the corner's vertex `v_i`,
//! - `(1, 0)`: the midpoint of the edge leaving it, `v_i v_{i+1}`,
//! - `(1, 1)`: the centre of `f`,
//! - `(0, 1)`: the midpoint of the edge entering it, `v_{i−1} v_i`,
//!
//! (the sub-quad `i` of a Catmull-Clark face, [`crate::limit::face_domain::subface_domain`]).
//! After one Doo-Sabin step ([`crate::refine::doo_sabin::refine_dual`]) the child `w` of corner
//! `(f, i)` has valence 4 and its four faces are centred on these four points: the v-face of
//! `v_i` (or its strip face) at `(0, 0)`, the e-face (or strip quad) of the leaving edge at
//! `(1, 0)`, the f-face of `f` at `(1, 1)`, the e-face of the entering edge at `(0, 1)`. That
//! square is `w`'s *domain square*: the limit surface over it depends on `w`'s four faces alone.
//! Shared sides of two corner quads are one curve of the limit surface: `(f, i, 1, t)` is
//! `(f, i+1, t, 1)`, and `(f, i, t, 0)` is `(g, j, 0, t)` with `g` the face across the leaving
//! edge and `j` the corner of `v_i` in `g`.
//!
//! # The steps
//!
//! 1. Refine the control mesh once, globally (linear in its size, done once per evaluator).
//! 2. Take the *ring* of `w`: its four faces, each listed from `w` in its orientation, in fan
//!    order, face `j` centred on corner `j` of the square (`(0,0)`, `(1,0)`, `(1,1)`, `(0,1)`).
//! 3. If every face of the ring is a quad, the ring is a 3×3 grid and the limit over the square
//!    is the uniform biquadratic B-spline of that grid (Doo-Sabin on quads is the tensor product
//!    of Chaikin's rule), its corners the centroids of the four faces. A quad holding boundary
//!    points (a strip quad `[r_0, r_1, b_R, b_L]`) is first completed by point reflection,
//!    `b → 2b − r` with `r` the real corner next to `b`: the boundary rule of
//!    [`crate::rules::doo_sabin`] is Doo-Sabin on that reflected net (its real children are
//!    the strip mask's, its reflected children are the reflections of the next level about the
//!    Chaikin points), so the patch is exact there too, and its boundary row is the uniform
//!    quadratic B-spline of the boundary points.
//! 4. Otherwise the ring holds an *extraordinary* face (a non-quad: the f-face of a non-quad
//!    base face, the v-face of a vertex of valence other than 4, or a strip face of a boundary
//!    vertex with other than two faces). If `(u, v)` is that face's corner of the square exactly,
//!    the limit is the face's centre ([`crate::limit::doo_sabin::face_limit`]: the centroid and
//!    the normal of its mode-1 plane; a strip face's centre is the midpoint of its boundary edge,
//!    on the Chaikin curve, where no normal is given). Else refine the ring one Doo-Sabin step
//!    by the masks of [`crate::rules::doo_sabin`] (the refiner's, strip masks included): the
//!    square splits into four quadrants, the one holding `(u, v)` is owned by `w`'s child in the
//!    face at that corner, whose ring is that face's f-face, the e-faces of its two edges at `w`
//!    and `w`'s v-face. Repeat from 3. After one local step at most one face is extraordinary,
//!    so the loop ends as soon as the point leaves the quadrant at that face (about
//!    `log2(1 / distance)` steps); it stops after [`MAX_DEPTH`] steps and returns the corner's
//!    limit for points within `2^−MAX_DEPTH` of an extraordinary centre.
//!
//! Each step costs one ring (four faces) of arithmetic; an evaluation is `O(depth)` after the
//! global first step. Each step first moves the ring by minus its vertex (added back at the
//! end), so rounding stays relative to the ring's size rather than the mesh's: a normal
//! `2^−39` from an extraordinary centre is still within `2e-12` of the centre's.
//!
//! Derivatives are parametric in the corner quad's `(u, v)` (the patch's, times `2^depth`);
//! the normal is `du × dv` normalized, or the face's normal at an interior extraordinary
//! centre. At an extraordinary centre no derivatives are given.

use crate::error::TopologyError;
use crate::limit::doo_sabin::face_limit;
use crate::limit::eval::EvalError;
use crate::mesh::{ControlMesh, Topology};
use crate::refine::doo_sabin::{boundary_vertices, fan, refine_dual};
use crate::refine::Level;
use crate::rules::doo_sabin::{corner_weights, strip_edge};
use crate::rules::Scheme;

/// The most local refinement steps of one evaluation.
pub const MAX_DEPTH: usize = 64;

/// The corners of a domain square, in ring order.
const CORNERS: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

/// A point of a refined level in a ring: its position and whether it is a boundary point.
#[derive(Clone, Copy, Debug)]
struct Point {
    p: [f64; 3],
    boundary: bool,
}

/// The four faces around a real valence-4 vertex `w` of a refined level, each listed from `w`
/// in its orientation, in fan order (each across the previous one's edge entering `w`): face
/// `j` is centred on corner `CORNERS[j]` of `w`'s domain square.
#[derive(Clone, Debug)]
struct Ring {
    faces: [Vec<Point>; 4],
}

/// The limit at a domain point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DooSabinSample {
    pub position: [f64; 3],
    /// `∂/∂u` and `∂/∂v` in the corner quad's coordinates; `None` at an extraordinary centre.
    pub derivatives: Option<([f64; 3], [f64; 3])>,
    /// The unit normal (`du × dv`); `None` where it degenerates and at a boundary
    /// extraordinary centre.
    pub normal: Option<[f64; 3]>,
}

/// Exact Doo-Sabin limit evaluation on a control mesh (see the module doc).
#[derive(Clone, Debug)]
pub struct DooSabinEvaluator {
    /// The base mesh's face sizes (for range checks and the level-1 numbering).
    base_offsets: Vec<u32>,
    /// The level-1 mesh.
    level: Level,
    /// Its boundary points.
    boundary: Vec<bool>,
}

impl DooSabinEvaluator {
    /// The evaluator of `mesh`: its first Doo-Sabin step (names the vertex or edge the dual
    /// refiner refuses: non-manifold vertices, edges of more than two faces).
    pub fn new(mesh: &ControlMesh) -> Result<Self, EvalError> {
        let base = Level::from_mesh(mesh, Scheme::DooSabin)?;
        let step = refine_dual(&base, true)?;
        let boundary = boundary_vertices(&step.level.topology);
        Ok(DooSabinEvaluator {
            base_offsets: base.face_offsets().to_vec(),
            level: step.level,
            boundary,
        })
    }

    /// The number of base faces.
    pub fn num_faces(&self) -> usize {
        self.base_offsets.len() - 1
    }

    /// The number of corners of base face `face` (0 when out of range).
    pub fn face_size(&self, face: usize) -> usize {
        match (self.base_offsets.get(face), self.base_offsets.get(face + 1)) {
            (Some(&a), Some(&b)) => (b - a) as usize,
            _ => 0,
        }
    }

    /// The limit at `(face, corner, u, v)` (module doc).
    pub fn evaluate(
        &self,
        face: usize,
        corner: usize,
        u: f64,
        v: f64,
    ) -> Result<DooSabinSample, EvalError> {
        let count = self.num_faces();
        if face >= count {
            return Err(EvalError::FaceOutOfRange { face, count });
        }
        let size = self.face_size(face);
        if corner >= size {
            return Err(EvalError::CornerOutOfRange { face, corner, size });
        }
        if !((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)) {
            return Err(EvalError::ParamOutOfRange { u, v });
        }
        evaluate_ring(self.ring(face, corner)?, u, v)
    }

    /// The ring of the level-1 child of `(face, corner)`.
    fn ring(&self, face: usize, corner: usize) -> Result<Ring, EvalError> {
        let t = &self.level.topology;
        let w = self.base_offsets[face] + corner as u32;
        // The f-face of `face` is level-1 face `face`; its fan is [f, e_in, v, e_out].
        let faces = fan(t, w as usize, face as u32);
        if faces.len() != 4 || t.vertex_faces(w as usize).len() != 4 {
            return Err(EvalError::NoDomainSquare { face, corner });
        }
        let listed = |j: usize| self.listed_from(t, faces[(j + 2) % 4] as usize, w);
        Ok(Ring {
            faces: [listed(0), listed(1), listed(2), listed(3)],
        })
    }

    /// Face `f` of the level-1 mesh, listed from its corner `w`.
    fn listed_from(&self, t: &Topology, f: usize, w: u32) -> Vec<Point> {
        let fv = t.face_vertices(f);
        let at = fv.iter().position(|&x| x == w).unwrap_or(0);
        (0..fv.len())
            .map(|k| {
                let x = fv[(at + k) % fv.len()] as usize;
                Point {
                    p: self.level.positions[x],
                    boundary: self.boundary[x],
                }
            })
            .collect()
    }
}

/// Steps 3 and 4 of the module doc from `ring` at `(u, v)` of its square.
fn evaluate_ring(mut ring: Ring, mut u: f64, mut v: f64) -> Result<DooSabinSample, EvalError> {
    let mut scale = 1.0;
    let mut origin = [0.0; 3];
    let placed = |mut s: DooSabinSample, origin: [f64; 3]| {
        for (p, o) in s.position.iter_mut().zip(origin) {
            *p += o;
        }
        s
    };
    for _ in 0..MAX_DEPTH {
        // Points relative to `w`: rounding stays relative to the ring's size, not the mesh's.
        let w = ring.recentre();
        origin = std::array::from_fn(|c| origin[c] + w[c]);
        if let Some(grid) = ring.regular_grid() {
            let (p, du, dv) = biquadratic(&grid, u, v);
            let (du, dv) = (du.map(|x| x * scale), dv.map(|x| x * scale));
            return Ok(placed(patch_sample(p, du, dv), origin));
        }
        let q = quadrant(u, v);
        if [u, v] == CORNERS[q] && ring.faces[q].len() != 4 {
            return Ok(placed(centre_sample(&ring.faces[q])?, origin));
        }
        ring = ring.refine(q)?;
        u = 2.0 * u - CORNERS[q][0];
        v = 2.0 * v - CORNERS[q][1];
        scale *= 2.0;
    }
    // Within 2^−MAX_DEPTH of an extraordinary centre: its limit.
    Ok(placed(centre_sample(&ring.faces[quadrant(u, v)])?, origin))
}

/// The quadrant of the square holding `(u, v)`, as the index of its corner.
fn quadrant(u: f64, v: f64) -> usize {
    match (u >= 0.5, v >= 0.5) {
        (false, false) => 0,
        (true, false) => 1,
        (true, true) => 2,
        (false, true) => 3,
    }
}

impl Ring {
    /// Moves the ring by `−w` (its vertex), returning `w`.
    fn recentre(&mut self) -> [f64; 3] {
        let w = self.faces[0][0].p;
        for point in self.faces.iter_mut().flatten() {
            point.p = std::array::from_fn(|c| point.p[c] - w[c]);
        }
        w
    }

    /// The 3×3 grid (`P_ab` at `a + 3b`, `a` along `u`) when all four faces are quads, strip
    /// quads completed by reflection.
    fn regular_grid(&self) -> Option<[[f64; 3]; 9]> {
        if self.faces.iter().any(|f| f.len() != 4) {
            return None;
        }
        // Each face is [w, next, opposite, previous].
        let full: Vec<[[f64; 3]; 4]> = self.faces.iter().map(|f| reflected(f)).collect();
        Some([
            full[0][2], // P00
            full[0][3], // P10 (= face 1's next)
            full[1][2], // P20
            full[0][1], // P01 (= face 3's previous)
            full[0][0], // P11 = w
            full[1][3], // P21 (= face 2's next)
            full[3][2], // P02
            full[2][3], // P12 (= face 3's next)
            full[2][2], // P22
        ])
    }

    /// The ring of `w`'s child in face `q`, owner of quadrant `q` of the square.
    fn refine(&self, q: usize) -> Result<Ring, EvalError> {
        let kids = self
            .faces
            .iter()
            .map(|f| children(f))
            .collect::<Result<Vec<_>, _>>()?;
        let (next, prev) = ((q + 1) % 4, (q + 3) % 4);
        let last = |j: usize| kids[j][kids[j].len() - 1];
        // The e-face of the edge entering `w` in face q (shared with face q + 1) and of the
        // edge leaving it (shared with face q − 1), as the refiner lists them.
        let e_next = vec![kids[q][0], last(q), kids[next][1], kids[next][0]];
        let e_prev = vec![kids[q][0], kids[prev][0], last(prev), kids[q][1]];
        let v_face = (0..4).map(|k| kids[(q + k) % 4][0]).collect();
        let order = [kids[q].clone(), e_next, v_face, e_prev];
        let mut faces: [Vec<Point>; 4] = Default::default();
        for (k, face) in order.into_iter().enumerate() {
            faces[(q + k) % 4] = face;
        }
        Ok(Ring { faces })
    }
}

/// The Doo-Sabin children of a face's corners, by the refiner's masks (a strip face's where it
/// holds boundary points).
fn children(face: &[Point]) -> Result<Vec<Point>, EvalError> {
    let n = face.len();
    let strip = strip_edge(n, |k| face[k].boundary).map_err(|_| {
        EvalError::Topology(TopologyError::UnsupportedScheme {
            scheme: "doo-sabin",
            operation:
                "a refined level whose face holds boundary points that are not one boundary edge",
        })
    })?;
    let mut w = Vec::new();
    Ok((0..n)
        .map(|i| {
            corner_weights(n, strip, i, &mut w);
            let mut p = [0.0; 3];
            for (k, &wk) in w.iter().enumerate() {
                for (pc, qc) in p.iter_mut().zip(face[(i + k) % n].p) {
                    *pc += wk * qc;
                }
            }
            Point {
                p,
                boundary: face[i].boundary,
            }
        })
        .collect())
}

/// A quad's corners, each boundary point `b` replaced by `2b − r` (`r` its real neighbour).
fn reflected(face: &[Point]) -> [[f64; 3]; 4] {
    std::array::from_fn(|k| {
        let b = face[k];
        if !b.boundary {
            return b.p;
        }
        let r = [face[(k + 1) % 4], face[(k + 3) % 4]]
            .into_iter()
            .find(|x| !x.boundary)
            .map_or(b.p, |x| x.p);
        std::array::from_fn(|c| 2.0 * b.p[c] - r[c])
    })
}

/// The uniform quadratic B-spline basis on one segment, and its derivative.
fn quadratic_basis(s: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * (1.0 - s) * (1.0 - s), 0.5 + s - s * s, 0.5 * s * s],
        [s - 1.0, 1.0 - 2.0 * s, s],
    )
}

/// The biquadratic B-spline patch of `grid` at `(u, v)`: point, `∂/∂u`, `∂/∂v`.
fn biquadratic(grid: &[[f64; 3]; 9], u: f64, v: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let (bu, du) = quadratic_basis(u);
    let (bv, dv) = quadratic_basis(v);
    let mut out = [[0.0; 3]; 3];
    for b in 0..3 {
        for a in 0..3 {
            let weights = [bu[a] * bv[b], du[a] * bv[b], bu[a] * dv[b]];
            for (o, w) in out.iter_mut().zip(weights) {
                for c in 0..3 {
                    o[c] += w * grid[a + 3 * b][c];
                }
            }
        }
    }
    (out[0], out[1], out[2])
}

fn patch_sample(position: [f64; 3], du: [f64; 3], dv: [f64; 3]) -> DooSabinSample {
    let n = [
        du[1] * dv[2] - du[2] * dv[1],
        du[2] * dv[0] - du[0] * dv[2],
        du[0] * dv[1] - du[1] * dv[0],
    ];
    let len = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    let scale = du.iter().chain(&dv).map(|x| x * x).sum::<f64>();
    DooSabinSample {
        position,
        derivatives: Some((du, dv)),
        normal: (len > 1e-12 * scale && len.is_finite()).then(|| n.map(|x| x / len)),
    }
}

/// The limit at the centre of an extraordinary face: [`face_limit`] for a face without boundary
/// points, the midpoint of the boundary edge for a strip face.
fn centre_sample(face: &[Point]) -> Result<DooSabinSample, EvalError> {
    let n = face.len();
    let strip = strip_edge(n, |k| face[k].boundary).map_err(|_| {
        EvalError::Topology(TopologyError::UnsupportedScheme {
            scheme: "doo-sabin",
            operation:
                "a refined level whose face holds boundary points that are not one boundary edge",
        })
    })?;
    if let Some(p) = strip {
        let (a, b) = (face[p].p, face[(p + 1) % n].p);
        return Ok(DooSabinSample {
            position: std::array::from_fn(|c| 0.5 * (a[c] + b[c])),
            derivatives: None,
            normal: None,
        });
    }
    let corners: Vec<[f64; 3]> = face.iter().map(|x| x.p).collect();
    let centroid = std::array::from_fn(|c| corners.iter().map(|p| p[c]).sum::<f64>() / n as f64);
    let normal = face_limit(&corners).map(|(_, normal)| normal);
    Ok(DooSabinSample {
        position: centroid,
        derivatives: None,
        normal,
    })
}

/// The limit positions of every vertex of a Doo-Sabin level (`refined`: level 1 or deeper,
/// whose boundary vertices are boundary points). A vertex's limit is the limit at the centre of
/// its domain square, where the level's next step centres the face made of its children:
///
/// - an interior vertex: the centroid of its children (its v-face, which holds no boundary
///   point, so its centroid is exact);
/// - a boundary vertex `b` with boundary neighbours `a`, `c`: `3/4 b + 1/8 (a + c)`, the
///   midpoint of its two Chaikin children, the quadratic B-spline of the boundary polygon at `b`;
/// - a vertex of no face keeps its position.
pub fn vertex_limits(level: &Level, refined: bool) -> Result<Vec<[f64; 3]>, EvalError> {
    let t = &level.topology;
    let on_boundary = boundary_vertices(t);
    let flags = if refined {
        on_boundary.clone()
    } else {
        vec![false; t.num_vertices()]
    };
    (0..t.num_vertices())
        .map(|x| {
            if t.vertex_faces(x).is_empty() {
                Ok(level.positions[x])
            } else if on_boundary[x] {
                boundary_limit(level, x)
            } else {
                interior_limit(level, &flags, x)
            }
        })
        .collect()
}

/// `3/4 b + 1/8 (a + c)` for boundary vertex `x` with boundary neighbours `a`, `c`.
fn boundary_limit(level: &Level, x: usize) -> Result<[f64; 3], EvalError> {
    let t = &level.topology;
    let ends: Vec<usize> = t
        .vertex_edges(x)
        .iter()
        .filter(|&&e| t.is_boundary_edge(e as usize))
        .map(|&e| {
            let [a, b] = t.edge_vertices(e as usize);
            if a as usize == x {
                b as usize
            } else {
                a as usize
            }
        })
        .collect();
    let [a, c] = ends[..] else {
        return Err(TopologyError::NonManifoldVertex {
            vertex: x as u32,
            fans: ends.len().div_ceil(2),
        }
        .into());
    };
    let p = &level.positions;
    Ok(std::array::from_fn(|k| {
        0.75 * p[x][k] + 0.125 * (p[a][k] + p[c][k])
    }))
}

/// The centroid of interior vertex `x`'s children (`flags`: the level's boundary points).
fn interior_limit(level: &Level, flags: &[bool], x: usize) -> Result<[f64; 3], EvalError> {
    let t = &level.topology;
    let mut sum = [0.0; 3];
    let faces = t.vertex_faces(x);
    for &f in faces {
        let fv = t.face_vertices(f as usize);
        let at = fv.iter().position(|&y| y as usize == x).unwrap_or(0);
        let face: Vec<Point> = (0..fv.len())
            .map(|k| {
                let y = fv[(at + k) % fv.len()] as usize;
                Point {
                    p: level.positions[y],
                    boundary: flags[y],
                }
            })
            .collect();
        let child = children(&face)?[0].p;
        for c in 0..3 {
            sum[c] += child[c] / faces.len() as f64;
        }
    }
    Ok(sum)
}

#[cfg(test)]
#[path = "doo_sabin_eval_tests.rs"]
mod tests;
