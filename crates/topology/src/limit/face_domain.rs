//! Exact limit evaluation in the face domains of capture's `# p` lines.
//!
//! [`LocalMesh`] evaluates the limit surface in its patch domains (Loop: the
//! triangle with corners 0, 1, 2 at (0, 0), (1, 0), (0, 1); Catmull-Clark: the unit square, and
//! sub-quads after one refinement for other faces). What `tessera export` writes, and what a
//! host reads back from a capture, is a point of a **base face** in the domain of
//! [`face_corner_uv`]: triangles with corners 0, 1, 2 at (1, 0), (0, 1), (0, 0);
//! quads the unit square; n-gons the regular n-gon in the unit square's circle.
//! [`LimitEvaluator`] takes points in that convention, for any face of the control mesh, and
//! evaluates the exact limit there:
//!
//! - **Loop**: on the mesh's fan triangulation (what the Loop techniques draw); a point of
//!   polygon `f` falls in fan triangle `j` (corners 0, j+1, j+2), whose barycentric weights of
//!   corners 1 and 2 are the patch parameters.
//! - **Catmull-Clark**: quads directly; any other face through its sub-quads, each mapping
//!   bilinearly into the face's domain as the adaptive technique maps them (corner, edge
//!   midpoint, centre, edge midpoint), inverted here (Newton, to rounding).
//! - **Doo-Sabin** ([`LimitEvaluator::doo_sabin`]): every face through the same sub-quads,
//!   which are [`crate::limit::doo_sabin_eval`]'s corner quads. At the centre of a non-quad
//!   face the limit has no parametric derivatives: `du` and `dv` are zero there and the normal
//!   is the centre's.
//!
//! Derivatives are with respect to the face domain's `u` and `v` (the chain rule through those
//! maps); the normal is `du × dv`, normalized (outward, as [`crate::limit::eval`] orients it).
//! Points may lie up to [`DOMAIN_TOLERANCE`] outside a face's domain (captured coordinates are
//! `f32`) and are moved onto it; farther, or NaN, is a
//! [`EvalError::ParamOutOfRange`].
//!
//! An evaluator holds only immutable data: one may be shared by any number of threads.
use crate::limit::doo_sabin_eval::DooSabinEvaluator;
use crate::limit::eval::{normal_of, EvalError, LimitSample, LimitScheme, LocalMesh};
use crate::mesh::ControlMesh;
use crate::rules::Scheme;
use std::collections::BTreeMap;

/// Where corner `k` of an `n`-sided face sits in the face's (u, v) domain, the convention of
/// every point Tessera reports on a base mesh (captures, `# p` lines of exports):
/// - triangles: corner 0 (1, 0), corner 1 (0, 1), corner 2 (0, 0), so (u, v) are the
///   barycentric weights of corners 0 and 1 (= `gl_TessCoord.xy` of a triangle patch);
/// - quads: (0, 0), (1, 0), (1, 1), (0, 1), the bilinear domain of the quad TES;
/// - n-gons, n ≥ 5: the regular n-gon inscribed in the unit square's circle,
///   (½ + ½ cos 2πk/n, ½ + ½ sin 2πk/n).
///
/// A Catmull-Clark non-quad is evaluated on its sub-quads ([`LocalMesh::evaluate_subface`]);
/// sub-quad `k` maps bilinearly onto (corner k, midpoint of edge k, centre, midpoint of edge
/// k − 1) of this domain ([`subface_domain`]).
pub fn face_corner_uv(n: u32, k: u32) -> [f64; 2] {
    match (n, k % n.max(1)) {
        (3, 0) => [1.0, 0.0],
        (3, 1) => [0.0, 1.0],
        (3, _) => [0.0, 0.0],
        (4, 0) => [0.0, 0.0],
        (4, 1) => [1.0, 0.0],
        (4, 2) => [1.0, 1.0],
        (4, _) => [0.0, 1.0],
        (n, k) => {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            [0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin()]
        }
    }
}

/// The corners of sub-quad `k` of an `n`-gon in the face's domain ([`face_corner_uv`]):
/// corner k, midpoint of edge k, centre, midpoint of edge k − 1.
pub fn subface_domain(n: u32, k: u32) -> [[f64; 2]; 4] {
    let c = |i: u32| face_corner_uv(n, i % n);
    let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) * 0.5, (a[1] + b[1]) * 0.5];
    let centre = (0..n).fold([0.0, 0.0], |s, i| {
        let p = c(i);
        [s[0] + p[0] / n as f64, s[1] + p[1] / n as f64]
    });
    let (corner, next, prev) = (c(k), c(k + 1), c(k + n - 1));
    [corner, mid(corner, next), centre, mid(prev, corner)]
}

/// The bilinear map of `quad` at (s, t): weights (1−s)(1−t), s(1−t), st, (1−s)t.
pub fn bilinear(quad: &[[f64; 2]; 4], s: f64, t: f64) -> [f64; 2] {
    let w = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
    let mut out = [0.0; 2];
    for (p, w) in quad.iter().zip(w) {
        out[0] += w * p[0];
        out[1] += w * p[1];
    }
    out
}

/// How far (domain units) a point may lie outside its face's domain and still be evaluated
/// (on the domain's nearest point).
pub const DOMAIN_TOLERANCE: f64 = 1e-5;

/// The limit surface at one point: position, derivatives along the face domain's `u` and `v`,
/// and the unit normal `du × dv` (zero where both derivatives are parallel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceSample {
    pub position: [f64; 3],
    pub du: [f64; 3],
    pub dv: [f64; 3],
    pub normal: [f64; 3],
}

/// A point a batch could not evaluate: its index in the batch and why.
#[derive(Debug, thiserror::Error)]
#[error("point {point} (face {face}, u {u}, v {v}): {source}")]
pub struct PointError {
    pub point: usize,
    pub face: u32,
    pub u: f64,
    pub v: f64,
    #[source]
    pub source: Box<EvalError>,
}

/// Where a face-domain point is evaluated: a face of the evaluated mesh (a fan triangle of the
/// base face for Loop), an optional Catmull-Clark sub-quad, its patch parameters, and the
/// Jacobian `∂(patch parameters)/∂(u, v)` (rows: the two patch parameters).
#[derive(Clone, Copy, Debug)]
struct PatchPoint {
    face: usize,
    sub: Option<usize>,
    param: [f64; 2],
    inverse_jacobian: [[f64; 2]; 2],
}

/// Exact limit positions, derivatives and normals of one control mesh at face-domain points.
pub struct LimitEvaluator {
    scheme: Scheme,
    /// What is evaluated: the control mesh (Catmull-Clark) or its fan triangulation (Loop), or
    /// the Doo-Sabin evaluator of the control mesh.
    surface: Surface,
    /// Corners of each base face.
    sizes: Vec<u32>,
    /// Loop: each base face's first fan triangle.
    first_triangle: Vec<u32>,
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn lerp(a: [f64; 2], b: [f64; 2], t: f64) -> [f64; 2] {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

/// The inverse of a 2×2 matrix (rows), or `None` when singular.
fn inverse(m: [[f64; 2]; 2]) -> Option<[[f64; 2]; 2]> {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    (det.abs() > 1e-300).then(|| {
        [
            [m[1][1] / det, -m[0][1] / det],
            [-m[1][0] / det, m[0][0] / det],
        ]
    })
}

/// Barycentric weights of `p` in the triangle `t` (may be negative outside it).
fn barycentric(t: [[f64; 2]; 3], p: [f64; 2]) -> [f64; 3] {
    let area = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let w1 = cross(sub(p, t[0]), sub(t[2], t[0])) / area;
    let w2 = cross(sub(t[1], t[0]), sub(p, t[0])) / area;
    [1.0 - w1 - w2, w1, w2]
}

/// The surface a [`LimitEvaluator`] evaluates.
enum Surface {
    Local(Box<LocalMesh>),
    /// Doo-Sabin's limit ([`crate::limit::doo_sabin_eval`]): a face-domain point is mapped to
    /// its corner quad, the Catmull-Clark sub-quad of the same corner.
    DooSabin(Box<DooSabinEvaluator>),
}

impl LimitEvaluator {
    /// An evaluator of `mesh`'s Doo-Sabin limit surface (non-manifold meshes through their
    /// manifold split, as [`Self::new`]).
    pub fn doo_sabin(mesh: &ControlMesh) -> Result<Self, EvalError> {
        crate::refine::check_doo_sabin_tags(mesh)?;
        let split = crate::mesh::manifold::ManifoldSplit::of(mesh)?;
        Ok(Self {
            scheme: Scheme::DooSabin,
            surface: Surface::DooSabin(Box::new(DooSabinEvaluator::new(&split.mesh)?)),
            sizes: split.mesh.faces().map(|f| f.len() as u32).collect(),
            first_triangle: Vec::new(),
        })
    }

    /// An evaluator of `mesh`'s limit surface under `scheme`: [`Self::new`], or
    /// [`Self::doo_sabin`]; bilinear has none here.
    pub fn of_scheme(mesh: &ControlMesh, scheme: Scheme) -> Result<Self, EvalError> {
        match scheme {
            Scheme::DooSabin => Self::doo_sabin(mesh),
            other => Self::new(mesh, LimitScheme::try_from(other)?),
        }
    }

    /// An evaluator of `mesh`'s limit surface under `scheme` (any face sizes: Loop evaluates
    /// the fan triangulation). The mesh is validated as every control mesh is; a non-manifold
    /// mesh is evaluated through its manifold split
    /// ([`crate::mesh::manifold::ManifoldSplit`]: same faces, same face domains, OpenSubdiv's
    /// rules for the non-manifold parts).
    pub fn new(mesh: &ControlMesh, scheme: LimitScheme) -> Result<Self, EvalError> {
        let split = crate::mesh::manifold::ManifoldSplit::of(mesh)?;
        let mesh = &split.mesh;
        let sizes: Vec<u32> = mesh.faces().map(|f| f.len() as u32).collect();
        let (local, first_triangle) = match scheme {
            LimitScheme::CatmullClark => (LocalMesh::from_control_mesh(mesh, scheme)?, Vec::new()),
            LimitScheme::Loop => {
                let (triangles, _) = mesh.triangulated();
                let mut first = Vec::with_capacity(sizes.len());
                let mut next = 0u32;
                for &n in &sizes {
                    first.push(next);
                    next += n.saturating_sub(2);
                }
                (LocalMesh::from_control_mesh(&triangles, scheme)?, first)
            }
        };
        Ok(Self {
            scheme: scheme.scheme(),
            surface: Surface::Local(Box::new(local)),
            sizes,
            first_triangle,
        })
    }

    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// Faces of the control mesh (what points name).
    pub fn num_faces(&self) -> usize {
        self.sizes.len()
    }

    /// The limit at `(u, v)` of base face `face`, in the `# p` convention.
    pub fn evaluate(&self, face: u32, u: f64, v: f64) -> Result<FaceSample, EvalError> {
        let p = self.patch_point(face, u, v)?;
        let mesh = match &self.surface {
            Surface::Local(mesh) => mesh,
            Surface::DooSabin(ds) => return doo_sabin_sample(ds, &p),
        };
        let s = match p.sub {
            Some(k) => mesh.evaluate_subface(p.face, k, p.param[0], p.param[1])?,
            None => mesh.evaluate(p.face, p.param[0], p.param[1])?,
        };
        Ok(to_face(&s, &p))
    }

    /// [`Self::evaluate`] of every `(face, [u, v])`, in order. Points on one patch share its
    /// neighbourhood ([`LocalMesh::evaluate_many`]), so a batch costs less than its points one
    /// by one. The first point that cannot be evaluated is named in the error.
    pub fn evaluate_many(&self, points: &[(u32, [f64; 2])]) -> Result<Vec<FaceSample>, PointError> {
        let at = |i: usize, source: EvalError| {
            let (face, [u, v]) = points[i];
            PointError {
                point: i,
                face,
                u,
                v,
                source: Box::new(source),
            }
        };
        let mesh = match &self.surface {
            Surface::Local(mesh) => mesh,
            Surface::DooSabin(_) => {
                return (points.iter().enumerate())
                    .map(|(i, &(face, [u, v]))| self.evaluate(face, u, v).map_err(|e| at(i, e)))
                    .collect();
            }
        };
        let mut patches: BTreeMap<(usize, Option<usize>), Vec<usize>> = BTreeMap::new();
        let mut mapped = Vec::with_capacity(points.len());
        for (i, &(face, [u, v])) in points.iter().enumerate() {
            let p = self.patch_point(face, u, v).map_err(|e| at(i, e))?;
            patches.entry((p.face, p.sub)).or_default().push(i);
            mapped.push(p);
        }
        let mut out = vec![None; points.len()];
        for ((face, sub), members) in patches {
            let params: Vec<[f64; 2]> = members.iter().map(|&i| mapped[i].param).collect();
            let samples = mesh
                .evaluate_many(face, sub, &params)
                .map_err(|e| at(members[0], e))?;
            for (&i, s) in members.iter().zip(&samples) {
                out[i] = Some(to_face(s, &mapped[i]));
            }
        }
        Ok(out.into_iter().flatten().collect())
    }

    /// Distance from `p` to the limit surface near face point `(u, v)` of base face `face`:
    /// [`LocalMesh::nearest_limit_distance`] over the patch holding that point, searched from
    /// it. Says how close an approximation is where it parameterizes the surface differently.
    pub fn nearest_limit_distance(
        &self,
        face: u32,
        u: f64,
        v: f64,
        p: &[f64],
    ) -> Result<f64, EvalError> {
        let at = self.patch_point(face, u, v)?;
        match &self.surface {
            Surface::Local(mesh) => mesh.nearest_limit_distance(at.face, at.sub, at.param, p),
            Surface::DooSabin(_) => Err(EvalError::NoLimitEvaluation {
                scheme: Scheme::DooSabin,
            }),
        }
    }

    /// Where `(u, v)` of base face `face` is evaluated, with the map's inverse Jacobian.
    fn patch_point(&self, face: u32, u: f64, v: f64) -> Result<PatchPoint, EvalError> {
        let Some(&n) = self.sizes.get(face as usize) else {
            return Err(EvalError::FaceOutOfRange {
                face: face as usize,
                count: self.sizes.len(),
            });
        };
        if !(u.is_finite() && v.is_finite()) {
            return Err(EvalError::ParamOutOfRange { u, v });
        }
        let p = [u, v];
        let corners: Vec<[f64; 2]> = (0..n).map(|k| face_corner_uv(n, k)).collect();
        // Inside the (convex, counter-clockwise) face domain, within the tolerance.
        let outside = (0..n as usize).any(|k| {
            let a = corners[k];
            let e = sub(corners[(k + 1) % n as usize], a);
            let len = (e[0] * e[0] + e[1] * e[1]).sqrt();
            cross(e, sub(p, a)) < -DOMAIN_TOLERANCE * len
        });
        if outside {
            return Err(EvalError::ParamOutOfRange { u, v });
        }
        match self.scheme {
            Scheme::Loop => Ok(self.fan_point(face as usize, &corners, p)),
            Scheme::CatmullClark if n == 4 => Ok(PatchPoint {
                face: face as usize,
                sub: None,
                param: [u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)],
                inverse_jacobian: [[1.0, 0.0], [0.0, 1.0]],
            }),
            // Catmull-Clark's other faces, and every Doo-Sabin face: the corner's sub-quad.
            _ => sub_quad_point(face as usize, &corners, p).ok_or(EvalError::NotConverged {
                face: face as usize,
                u,
                v,
            }),
        }
    }

    /// Loop: the fan triangle (0, j+1, j+2) of the polygon holding `p`, and its barycentric
    /// weights of corners 1 and 2 (moved onto the triangle when `p` is just outside).
    fn fan_point(&self, face: usize, corners: &[[f64; 2]], p: [f64; 2]) -> PatchPoint {
        let fans = corners.len() - 2;
        let (j, w) = (0..fans)
            .map(|j| {
                (
                    j,
                    barycentric([corners[0], corners[j + 1], corners[j + 2]], p),
                )
            })
            .max_by(|a, b| {
                let min = |w: &[f64; 3]| w[0].min(w[1]).min(w[2]);
                min(&a.1).total_cmp(&min(&b.1))
            })
            .unwrap_or((0, [1.0, 0.0, 0.0]));
        let w = w.map(|x| x.max(0.0));
        let total = w[0] + w[1] + w[2];
        let w1 = w[1] / total;
        // Rounding must not carry the pair past the triangle's hypotenuse.
        let w2 = (w[2] / total).min(1.0 - w1);
        let (e1, e2) = (
            sub(corners[j + 1], corners[0]),
            sub(corners[j + 2], corners[0]),
        );
        // (u, v) = c0 + w1·e1 + w2·e2, so ∂(w1, w2)/∂(u, v) is the inverse of [e1 e2].
        let m = [[e1[0], e2[0]], [e1[1], e2[1]]];
        PatchPoint {
            face: (self.first_triangle[face] as usize) + j,
            sub: None,
            param: [w1, w2],
            inverse_jacobian: inverse(m).unwrap_or([[0.0; 2]; 2]),
        }
    }
}

/// Catmull-Clark, a face of other than four corners: the sub-quad `k` holding `p` (the sector
/// of the face's centre between the midpoints of the edges before and after corner `k`), and
/// its parameters, by Newton's method on the bilinear map (corner, edge midpoint, centre,
/// edge midpoint); `None` if that does not converge.
fn sub_quad_point(face: usize, corners: &[[f64; 2]], p: [f64; 2]) -> Option<PatchPoint> {
    let n = corners.len();
    let quads: Vec<[[f64; 2]; 4]> = (0..n as u32).map(|k| subface_domain(n as u32, k)).collect();
    // Sub-quad k spans the sector of the centre between the midpoints of edges k − 1 and k.
    let d = sub(p, quads[0][2]);
    let k = (0..n)
        .find(|&k| {
            let q = &quads[k];
            cross(sub(q[3], q[2]), d) >= 0.0 && cross(d, sub(q[1], q[2])) >= 0.0
        })
        .unwrap_or(0);
    let q = quads[k];
    let map = |s: f64, t: f64| bilinear(&q, s, t);
    // ∂(u, v)/∂(s, t), columns s and t.
    let jacobian = |s: f64, t: f64| {
        let ds = lerp(sub(q[1], q[0]), sub(q[2], q[3]), t);
        let dt = lerp(sub(q[3], q[0]), sub(q[2], q[1]), s);
        [[ds[0], dt[0]], [ds[1], dt[1]]]
    };
    let (mut s, mut t) = (0.5, 0.5);
    for _ in 0..64 {
        let r = sub(map(s, t), p);
        if r[0].abs().max(r[1].abs()) < 1e-15 {
            break;
        }
        let inv = inverse(jacobian(s, t))?;
        s -= inv[0][0] * r[0] + inv[0][1] * r[1];
        t -= inv[1][0] * r[0] + inv[1][1] * r[1];
        if !(s.is_finite() && t.is_finite()) {
            return None;
        }
    }
    let r = sub(map(s, t), p);
    if r[0].abs().max(r[1].abs()) > 1e-9 {
        return None;
    }
    let (s, t) = (s.clamp(0.0, 1.0), t.clamp(0.0, 1.0));
    Some(PatchPoint {
        face,
        sub: Some(k),
        param: [s, t],
        inverse_jacobian: inverse(jacobian(s, t))?,
    })
}

/// The Doo-Sabin limit at the corner-quad point `p` (its sub-quad is the corner quad): at an
/// extraordinary face's centre, where the limit has no parametric derivatives, `du` and `dv`
/// are zero and the normal is the centre's (zero where none is given).
fn doo_sabin_sample(ds: &DooSabinEvaluator, p: &PatchPoint) -> Result<FaceSample, EvalError> {
    let corner = p.sub.unwrap_or(0);
    let s = ds.evaluate(p.face, corner, p.param[0], p.param[1])?;
    let normal = s.normal.unwrap_or([0.0; 3]);
    let Some((du, dv)) = s.derivatives else {
        return Ok(FaceSample {
            position: s.position,
            du: [0.0; 3],
            dv: [0.0; 3],
            normal,
        });
    };
    let sample = LimitSample {
        position: s.position.to_vec(),
        du: du.to_vec(),
        dv: dv.to_vec(),
    };
    Ok(to_face(&sample, p))
}

/// A patch sample in the face domain: derivatives through the inverse Jacobian.
fn to_face(s: &LimitSample, p: &PatchPoint) -> FaceSample {
    let j = p.inverse_jacobian;
    let along = |col: usize| -> [f64; 3] {
        std::array::from_fn(|c| s.du[c] * j[0][col] + s.dv[c] * j[1][col])
    };
    let (du, dv) = (along(0), along(1));
    FaceSample {
        position: [s.position[0], s.position[1], s.position[2]],
        du,
        dv,
        normal: normal_of(&du, &dv),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limit::eval::limit_point;

    /// A quad, a triangle and a pentagon sharing edges: every face size the mappings treat.
    fn mixed() -> ControlMesh {
        let text = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0.3\nv 2 1 0\nv 1 2 0\n\
                    v 0 2 0.2\nv 2 2 0.1\nf 1 2 5 4\nf 2 3 6\nf 2 6 9 7 5\nf 4 5 7 8\n";
        crate::mesh::obj::parse_obj(text, "mixed").unwrap()
    }

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
    }

    #[test]
    fn quads_and_loop_triangles_are_topologys_points_in_the_export_convention() {
        let mesh = mixed();
        let cc = LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap();
        let want = limit_point(&mesh, LimitScheme::CatmullClark, 0, 0.25, 0.6).unwrap();
        let got = cc.evaluate(0, 0.25, 0.6).unwrap();
        assert_eq!(got.position, want.position);
        assert_eq!((got.du, got.dv), (want.du, want.dv));
        // Loop on a triangle mesh: (u, v) weigh corners 0 and 1, topology's (u', v') weigh
        // corners 1 and 2.
        let (tri, _) = mesh.triangulated();
        let lp = LimitEvaluator::new(&tri, LimitScheme::Loop).unwrap();
        let (u, v) = (0.2, 0.5);
        let want = limit_point(&tri, LimitScheme::Loop, 3, v, 1.0 - u - v).unwrap();
        let got = lp.evaluate(3, u, v).unwrap();
        assert!(close(got.position, want.position, 1e-15));
        assert!(close(got.normal, want.normal, 1e-12));
        // d/du = -d/dv', d/dv = d/du' - d/dv'.
        let du: [f64; 3] = std::array::from_fn(|c| -want.dv[c]);
        assert!(close(got.du, du, 1e-12), "{:?} {:?}", got.du, du);
    }

    #[test]
    fn corners_and_edges_of_every_face_size_meet_their_neighbours() {
        let mesh = mixed();
        for scheme in [LimitScheme::CatmullClark, LimitScheme::Loop] {
            let e = LimitEvaluator::new(&mesh, scheme).unwrap();
            // Shared vertex 5 (index 4) is corner 2 of the quad, corner 4 of the pentagon and
            // corner 1 of the last quad; shared edge 2–6 is edge 2 (6 to 2) of the triangle and
            // edge 0 (2 to 6) of the pentagon.
            let at = |f: u32, n: u32, k: u32| {
                let c = face_corner_uv(n, k);
                e.evaluate(f, c[0], c[1]).unwrap().position
            };
            let v5 = at(0, 4, 2);
            assert!(close(v5, at(2, 5, 4), 1e-12), "{scheme:?}");
            assert!(close(v5, at(3, 4, 1), 1e-12), "{scheme:?}");
            let mid = |f: u32, n: u32, k: u32| {
                let (a, b) = (face_corner_uv(n, k), face_corner_uv(n, k + 1));
                let m = lerp(a, b, 0.3);
                e.evaluate(f, m[0], m[1]).unwrap()
            };
            // The same edge runs the other way round in the pentagon: 0.3 there is 0.7 here.
            let a = mid(1, 3, 2).position;
            let (x, y) = (face_corner_uv(5, 0), face_corner_uv(5, 1));
            let m = lerp(x, y, 0.7);
            let b = e.evaluate(2, m[0], m[1]).unwrap().position;
            assert!(close(a, b, 1e-12), "{scheme:?}: {a:?} {b:?}");
        }
    }

    #[test]
    fn face_derivatives_match_finite_differences() {
        let mesh = mixed();
        for scheme in [LimitScheme::CatmullClark, LimitScheme::Loop] {
            let e = LimitEvaluator::new(&mesh, scheme).unwrap();
            for (face, u, v) in [(1u32, 0.3, 0.25), (2, 0.45, 0.6), (0, 0.4, 0.7)] {
                let s = e.evaluate(face, u, v).unwrap();
                let h = 1e-6;
                let fd = |du: f64, dv: f64| -> [f64; 3] {
                    let a = e.evaluate(face, u + du, v + dv).unwrap().position;
                    let b = e.evaluate(face, u - du, v - dv).unwrap().position;
                    std::array::from_fn(|c| (a[c] - b[c]) / (2.0 * h))
                };
                assert!(close(s.du, fd(h, 0.0), 1e-5), "{scheme:?} {face}");
                assert!(close(s.dv, fd(0.0, h), 1e-5), "{scheme:?} {face}");
            }
        }
    }

    #[test]
    fn bad_faces_and_parameters_are_named() {
        let mesh = mixed();
        let e = LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap();
        assert!(matches!(
            e.evaluate(4, 0.5, 0.5),
            Err(EvalError::FaceOutOfRange { face: 4, count: 4 })
        ));
        for (face, u, v) in [
            (0, 1.1, 0.5),
            (0, f64::NAN, 0.5),
            (1, 0.7, 0.7),
            (2, 0.0, 0.0),
            (0, 0.5, f64::INFINITY),
        ] {
            assert!(
                matches!(
                    e.evaluate(face, u, v),
                    Err(EvalError::ParamOutOfRange { .. })
                ),
                "face {face} ({u}, {v})"
            );
        }
        // Just outside by f32 rounding: evaluated on the edge.
        let on = e.evaluate(1, 0.5, 0.5).unwrap().position;
        let off = e.evaluate(1, 0.5, 0.5 + 1e-7).unwrap().position;
        assert!(close(on, off, 1e-6));
        let err = e
            .evaluate_many(&[(0, [0.5, 0.5]), (9, [0.5, 0.5])])
            .unwrap_err();
        assert_eq!(err.point, 1);
        assert!(err.to_string().contains("point 1 (face 9"), "{err}");
    }

    #[test]
    fn batches_equal_single_points() {
        let mesh = mixed();
        for scheme in [LimitScheme::CatmullClark, LimitScheme::Loop] {
            let e = LimitEvaluator::new(&mesh, scheme).unwrap();
            let points: Vec<(u32, [f64; 2])> = (0..40)
                .map(|i| {
                    let face = i * 7 % 4;
                    let n = mesh.face(face as usize).len() as u32;
                    let a = face_corner_uv(n, i % n);
                    let b = face_corner_uv(n, (i + 1) % n);
                    let c = lerp(lerp(a, b, 0.37), [0.5, 0.5], (i % 5) as f64 * 0.2);
                    (face, c)
                })
                .collect();
            let batch = e.evaluate_many(&points).unwrap();
            for (s, &(f, [u, v])) in batch.iter().zip(&points) {
                assert_eq!(*s, e.evaluate(f, u, v).unwrap());
            }
        }
    }
}
