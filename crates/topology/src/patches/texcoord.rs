//! Texture coordinates of the limit surface: the OBJ's face-varying `vt` data, interpolated
//! bilinearly on each face (OpenSubdiv's `FVAR_LINEAR_ALL`), at a patch's parameter or — on
//! Gregory patches — at the reparameterized parameter `s(u, v)` of seed 003 ([`crate::patches::reparam`]).
//!
//! Design decisions:
//! - **Linear face-varying data.** A quad's coordinate is the bilinear blend of its four
//!   corners; sub-quad `k` of an `n`-gon (the parameterization of [`crate::limit::eval`]:
//!   `[v_k, e_{k,k+1}, face point, e_{k−1,k}]`) blends the corner's coordinate, the two edge
//!   midpoints and the face's centroid. Texture seams (a vertex with several `vt`) stay seams,
//!   and a patch's coordinates are the bilinear blend of its own four corners' (a patch covers
//!   an axis-aligned square of its (sub)face's parameter), so the GPU needs four pairs per patch.
//! - **Reparameterization per corner valence** ([`crate::patches::adaptive::AdaptivePatch::reparam_valences`]):
//!   the table's row at valences 3–16 (4 is the identity), the valence-16 row above it (measured
//!   in docs/approximations.md: still 8–10× below no reparameterization up to valence 64), the
//!   identity where the valence is 0 (boundary, crease and corner vertices; regular and ACC-1
//!   patches).
use crate::limit::eval::{EvalError, LimitScheme, LocalMesh};
use crate::mesh::ControlMesh;
use crate::patches::adaptive::{AdaptivePatch, AdaptivePlan};
use crate::patches::reparam::{
    control_net, corner_block, reparameterize, IDENTITY_BLOCK, TABLE_VALENCES,
};
use rayon::prelude::*;

/// The corner block of Eq. 3 that a patch corner of reparameterization valence `valence`
/// gets (see the module docs): `None` is the identity.
pub fn reparam_block(valence: u8) -> Option<[f64; 5]> {
    match valence as u32 {
        0 | 4 => None,
        v if v < *TABLE_VALENCES.start() => None,
        v => corner_block(v.min(*TABLE_VALENCES.end())),
    }
}

/// Row of the GPU's reparameterization table for a corner (0: the identity; row `v − 2` for
/// valence `v` in 3..=16, the valence-16 row above).
pub fn reparam_row(valence: u8) -> u32 {
    match reparam_block(valence) {
        None => 0,
        Some(_) => (valence as u32).min(*TABLE_VALENCES.end()) - 2,
    }
}

/// The GPU's reparameterization table: row 0 the identity, row `v − 2` valence `v` (3..=16).
pub fn reparam_rows() -> Vec<[f64; 5]> {
    let mut rows = vec![IDENTITY_BLOCK];
    for v in TABLE_VALENCES {
        rows.push(if v == 4 {
            IDENTITY_BLOCK
        } else {
            corner_block(v).unwrap_or(IDENTITY_BLOCK)
        });
    }
    rows
}

/// Whether the mesh has a `vt` per face corner.
pub fn has_texcoords(mesh: &ControlMesh) -> bool {
    mesh.uvs
        .as_ref()
        .is_some_and(|uvs| uvs.len() == mesh.face_vertices.len())
}

/// The coordinate at parameter `(u, v)` of sub-face `sub` of `face` (sub is 0 for quads), or
/// `None` without `vt` data or out of range.
pub fn face_texcoord(
    mesh: &ControlMesh,
    face: usize,
    sub: usize,
    u: f64,
    v: f64,
) -> Option<[f64; 2]> {
    let corners = subface_corners(mesh, face, sub)?;
    Some(bilinear(&corners, u, v))
}

/// The four texture coordinates at the corners of the (sub)face's parameter square, in patch
/// corner order ((0,0), (1,0), (1,1), (0,1)).
pub fn subface_corners(mesh: &ControlMesh, face: usize, sub: usize) -> Option<[[f64; 2]; 4]> {
    if !has_texcoords(mesh) || face >= mesh.num_faces() {
        return None;
    }
    let uvs = mesh.uvs.as_ref()?;
    let (s, e) = (
        mesh.face_offsets[face] as usize,
        mesh.face_offsets[face + 1] as usize,
    );
    let t = uvs.get(s..e)?;
    let n = t.len();
    if n == 4 {
        return Some([t[0], t[1], t[2], t[3]]);
    }
    if sub >= n || n < 3 {
        return None;
    }
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let mut centre = [0.0; 2];
    for c in t {
        centre[0] += c[0] / n as f64;
        centre[1] += c[1] / n as f64;
    }
    Some([
        t[sub],
        mid(t[sub], t[(sub + 1) % n]),
        centre,
        mid(t[(sub + n - 1) % n], t[sub]),
    ])
}

/// Bilinear blend of four corner values in patch corner order.
pub fn bilinear(c: &[[f64; 2]; 4], u: f64, v: f64) -> [f64; 2] {
    let w = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
    let mut out = [0.0; 2];
    for (k, p) in c.iter().enumerate() {
        out[0] += w[k] * p[0];
        out[1] += w[k] * p[1];
    }
    out
}

/// The texture coordinates at a plan patch's four corners (patch corner order). A triangle
/// patch (corners `t0, t1, t2` at (0,0), (1,0), (0,1)) gets `[t0, t1, t1 + t2 − t0, t2]`: the
/// bilinear blend of that parallelogram is the linear interpolation on the triangle, which is
/// what the bilinear sub-quads give there (see [`crate::patches::adaptive::triangle_subquad_param`]).
pub fn patch_corners(mesh: &ControlMesh, patch: &AdaptivePatch) -> Option<[[f64; 2]; 4]> {
    if patch.corners() == 3 {
        if !has_texcoords(mesh) {
            return None;
        }
        let f = patch.base_face as usize;
        let uvs = mesh.uvs.as_ref()?;
        let t = uvs.get(mesh.face_offsets[f] as usize..mesh.face_offsets[f + 1] as usize)?;
        if t.len() != 3 {
            return None;
        }
        let fourth = [t[1][0] + t[2][0] - t[0][0], t[1][1] + t[2][1] - t[0][1]];
        return Some([t[0], t[1], fourth, t[2]]);
    }
    let face = subface_corners(mesh, patch.base_face as usize, patch.sub_face as usize)?;
    let [u0, v0] = patch.origin;
    let h = patch.size;
    let at = |a: f64, b: f64| bilinear(&face, u0 + h * a, v0 + h * b);
    Some([at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0), at(0.0, 1.0)])
}

/// The texture parameter a patch shows at its `(u, v)`: `s(u, v)` of Eq. 3 from its corners'
/// blocks when `reparam` (the identity where every corner is), else `(u, v)`.
pub fn patch_parameter(patch: &AdaptivePatch, u: f64, v: f64, reparam: bool) -> [f64; 2] {
    let blocks = patch.reparam_valences.map(reparam_block);
    if !reparam || blocks.iter().all(Option::is_none) {
        return [u, v];
    }
    let net = control_net(&blocks.map(|b| b.unwrap_or(IDENTITY_BLOCK)));
    reparameterize(&net, u, v)
}

/// The texture coordinate patch `index` of `plan` shows at `(u, v)` (see [`patch_parameter`]).
pub fn patch_texcoord(
    mesh: &ControlMesh,
    plan: &AdaptivePlan,
    index: usize,
    u: f64,
    v: f64,
    reparam: bool,
) -> Option<[f64; 2]> {
    let patch = plan.patches.get(index)?;
    let corners = patch_corners(mesh, patch)?;
    let [s, t] = patch_parameter(patch, u, v, reparam);
    Some(bilinear(&corners, s, t))
}

/// The pointwise texture error of Eq. 1 (seed 003) on a lattice of every patch of a plan: at
/// the displayed point `g(u, v)` the texture shows the texel of base parameter `s(u, v)`,
/// whose exact limit point is `p(s(u, v))`; the error is `|p(s(u, v)) − g(u, v)|` over the
/// control mesh's bounding-box diagonal, with (`s` of Eq. 3) and without (`s` the identity)
/// the reparameterization. It counts the patch's geometric deviation too, which no
/// reparameterization removes (0 on exact patches). The rest pose only: an animated mesh
/// moves `g` and `p` but not this table. Drawn by `--show param-error` (the paper's Fig. 8).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamErrorLattice {
    /// Lattice points per side: `(u, v) = (i, j) / (side − 1)`.
    pub side: usize,
    /// Per patch: the identity's lattice, then the reparameterized one, each indexed
    /// `i + side · j`.
    pub errors: Vec<f32>,
    /// Patches with a reparameterized corner (on the others both halves are equal).
    pub reparameterized: usize,
}

/// [`ParamErrorLattice::summary`]: over every lattice point, without (`[0]`) and with (`[1]`)
/// the reparameterization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamErrorSummary {
    pub rms: [f64; 2],
    pub max: [f64; 2],
}

impl ParamErrorLattice {
    /// The error of patch `patch` at lattice point `(i, j)`.
    pub fn at(&self, patch: usize, reparam: bool, i: usize, j: usize) -> f32 {
        let n = self.side * self.side;
        self.errors[patch * 2 * n + usize::from(reparam) * n + i + self.side * j]
    }

    /// RMS and maximum over every patch's lattice, without and with the reparameterization.
    pub fn summary(&self) -> ParamErrorSummary {
        let n = self.side * self.side;
        let (mut sq, mut max) = ([0.0f64; 2], [0.0f64; 2]);
        for (k, chunk) in self.errors.chunks(n).enumerate() {
            for &e in chunk {
                sq[k % 2] += f64::from(e) * f64::from(e);
                max[k % 2] = max[k % 2].max(f64::from(e));
            }
        }
        let count = (self.errors.len() / 2).max(1) as f64;
        ParamErrorSummary {
            rms: sq.map(|s| (s / count).sqrt()),
            max,
        }
    }

    /// The values of one patch and mode, in lattice order.
    pub fn patch(&self, patch: usize, reparam: bool) -> &[f32] {
        let n = self.side * self.side;
        let start = patch * 2 * n + usize::from(reparam) * n;
        &self.errors[start..start + n]
    }
}

/// [`ParamErrorLattice`] of `plan` (made from `mesh`) with `side` points per patch side (at
/// least 2). Exact evaluation of the Catmull-Clark limit at every lattice point (one
/// neighbourhood per patch, patches in parallel): 10-40 µs a point, so seconds on meshes of a
/// few thousand patches.
pub fn param_error_lattice(
    mesh: &ControlMesh,
    plan: &AdaptivePlan,
    side: usize,
) -> Result<ParamErrorLattice, EvalError> {
    let side = side.max(2);
    let exact = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark)?;
    let verts = plan.apply(&mesh.positions);
    let diag = mesh.bbox_diagonal().max(f64::MIN_POSITIVE);
    let step = 1.0 / (side - 1) as f64;
    let per_patch: Vec<(Vec<f32>, bool)> = plan
        .patches
        .par_iter()
        .enumerate()
        .map(|(index, patch)| {
            let lattice: Vec<[f64; 2]> = (0..side * side)
                .map(|k| [(k % side) as f64 * step, (k / side) as f64 * step])
                .collect();
            if patch.corners() == 3 {
                return triangle_lattice(&exact, plan, &verts, index, &lattice, diag);
            }
            let base = |st: [f64; 2]| {
                [
                    (patch.origin[0] + patch.size * st[0]).clamp(0.0, 1.0),
                    (patch.origin[1] + patch.size * st[1]).clamp(0.0, 1.0),
                ]
            };
            let reparameterized = patch
                .reparam_valences
                .iter()
                .any(|&v| reparam_block(v).is_some());
            let mut params: Vec<[f64; 2]> = lattice.iter().map(|&uv| base(uv)).collect();
            if reparameterized {
                params.extend(
                    lattice
                        .iter()
                        .map(|&[u, v]| base(patch_parameter(patch, u, v, true))),
                );
            }
            let face = patch.base_face as usize;
            let sub = (mesh.face(face).len() != 4).then_some(patch.sub_face as usize);
            let limit = exact.evaluate_many(face, sub, &params)?;
            // The displayed points once; the texel's limit point per half.
            let shown: Vec<[f64; 3]> = lattice
                .iter()
                .map(|&[u, v]| plan.evaluate(&verts, index, u, v).position)
                .collect();
            let half = lattice.len();
            let mut out = Vec::with_capacity(2 * half);
            for k in 0..2 * half {
                let g = shown[k % half];
                let p = &limit[if reparameterized { k } else { k % half }].position;
                let d = (0..3).map(|c| (g[c] - p[c]).powi(2)).sum::<f64>().sqrt();
                out.push((d / diag) as f32);
            }
            Ok((out, reparameterized))
        })
        .collect::<Result<_, EvalError>>()?;
    Ok(ParamErrorLattice {
        side,
        reparameterized: per_patch.iter().filter(|p| p.1).count(),
        errors: per_patch.into_iter().flat_map(|p| p.0).collect(),
    })
}

/// [`param_error_lattice`] of a triangle patch (identity parameterization, so both halves are
/// equal): lattice points past the diagonal `u + v = 1` take the value of their projection
/// onto it (the GPU's bilinear look-up reads them next to the diagonal).
fn triangle_lattice(
    exact: &LocalMesh,
    plan: &AdaptivePlan,
    verts: &[[f64; 3]],
    index: usize,
    lattice: &[[f64; 2]],
    diag: f64,
) -> Result<(Vec<f32>, bool), EvalError> {
    let patch = &plan.patches[index];
    let mut half = Vec::with_capacity(lattice.len());
    for &[u, v] in lattice {
        let s = u + v;
        let (u, v) = if s > 1.0 { (u / s, v / s) } else { (u, v) };
        let (sub, a, b) = patch.base_param(u, v);
        let p = exact
            .evaluate_subface(patch.base_face as usize, sub as usize, a, b)?
            .position;
        let g = plan.evaluate(verts, index, u, v).position;
        let d = (0..3).map(|c| (g[c] - p[c]).powi(2)).sum::<f64>().sqrt();
        half.push((d / diag) as f32);
    }
    let mut out = half.clone();
    out.extend_from_slice(&half);
    Ok((out, false))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_cover_the_table_and_the_identity() {
        let rows = reparam_rows();
        assert_eq!(rows.len(), 15);
        assert_eq!(rows[0], IDENTITY_BLOCK);
        assert_eq!(reparam_row(0), 0);
        assert_eq!(reparam_row(4), 0);
        assert_eq!(reparam_row(2), 0);
        assert_eq!(rows[reparam_row(3) as usize], corner_block(3).unwrap());
        assert_eq!(rows[reparam_row(16) as usize], corner_block(16).unwrap());
        assert_eq!(reparam_row(40), reparam_row(16));
    }

    #[test]
    fn subface_corners_of_a_triangle() {
        let mut mesh = ControlMesh::from_polygons(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0u32, 1, 2]],
        );
        mesh.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let c = subface_corners(&mesh, 0, 1).unwrap();
        assert_eq!(c[0], [1.0, 0.0]);
        assert_eq!(c[1], [0.5, 0.5]);
        assert!((c[2][0] - 1.0 / 3.0).abs() < 1e-15 && (c[2][1] - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(c[3], [0.5, 0.0]);
        assert!(subface_corners(&mesh, 0, 3).is_none());
        mesh.uvs = None;
        assert!(face_texcoord(&mesh, 0, 0, 0.5, 0.5).is_none());
    }
}
