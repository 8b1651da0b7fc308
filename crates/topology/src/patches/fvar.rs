//! Face-varying patches: the texture coordinates of a planned surface, smooth as OpenSubdiv's
//! face-varying patches make them (OpenSubdiv 3.1+), for the adaptive and single-pass plans.
//!
//! # Design decisions
//! - **The value mesh, planned as the surface is.** The texture layout is a control mesh of
//!   its own ([`crate::refine::fvar::texcoord_mesh`]), planned with the surface's own plan
//!   (feature-adaptive to the same isolation, or single-pass), so each of its patches is the
//!   face-varying patch over its square of a base face: exact B-spline where the layout is
//!   regular, a Gregory patch at the isolation level around its irregular values (always
//!   Gregory, whatever the surface's end caps: a texture coordinate needs no watertight
//!   Coons boundary), a Gregory triangle on a single-pass triangle.
//! - **Looked up by the base-face parameter.** Seams and pinned values make the layout's
//!   irregular places differ from the surface's, so its patches need not cover the surface's
//!   squares one to one. Each base (sub-)face has a quadtree of the layout's patches over its
//!   domain; a surface patch names the root of its (sub-)face and its square, and a point
//!   descends from the root, halving the square, to the leaf patch, whose own parameter the
//!   descent has computed. No refinement level of the two plans needs to agree. A triangle
//!   patch of a single-pass plan covers its whole triangle in both plans: its root is the
//!   layout's triangle patch, evaluated at the same barycentric parameter.
//! - **One patch form.** Every leaf is stored as a 20-point Gregory patch (a B-spline patch
//!   converted to its Bézier net, whose interior points are each corner's pair `Fp = Fm`) or
//!   a 15-point Gregory triangle, in `f32` on the device; `glsl/adaptive/fvar.glsl` mirrors
//!   [`FVarPatches::texcoord`].
//! - **Static.** Texture coordinates do not move with an animated base: the points are made
//!   once, on the CPU.
//!
//! Approximation: a Gregory triangle's edge next to a split face (a transition edge of the
//! single-pass plan) follows the triangle's own cubic, not the neighbour's two halves.
use crate::error::TopologyError;
use crate::mesh::ControlMesh;
use crate::patches::adaptive::single_pass::{plan_single_pass, SinglePassOptions};
use crate::patches::adaptive::{
    plan_adaptive, AdaptiveOptions, AdaptivePatch, AdaptivePlan, EndCap, PatchKind,
};
use crate::patches::gregory::{gregory_triangle_weights, gregory_weights};
use crate::refine::fvar::{texcoord_mesh, ValueMesh};
use crate::rules::{Scheme, SHARPNESS_INFINITE};

/// A tree entry naming a leaf patch: `FVAR_LEAF | patch`.
pub const FVAR_LEAF: u32 = 1 << 31;
/// A tree entry naming nothing (a hole of the layout).
pub const FVAR_EMPTY: u32 = u32::MAX;
/// The deepest descent a look-up makes (plans refine at most 14 levels, a single-pass
/// plan's split one more).
pub const FVAR_MAX_DEPTH: u32 = 16;
/// Points of a quad leaf (the Gregory form) and of a triangle leaf.
pub const FVAR_QUAD_POINTS: usize = 20;
pub const FVAR_TRIANGLE_POINTS: usize = 15;

/// One leaf: the layout plan's patch kind (a triangle is stored as a Gregory triangle, every
/// other kind in the Gregory form) and its first point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FVarPatch {
    pub kind: PatchKind,
    pub first_point: u32,
}

impl FVarPatch {
    /// Stored as a 15-point Gregory triangle (else the 20-point Gregory form).
    pub fn is_triangle(&self) -> bool {
        self.kind == PatchKind::GregoryTriangle
    }
}

/// The face-varying patches of a surface (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FVarPatches {
    /// Inner tree nodes: the entries of the four quadrants, `q = (s ≥ ½) + 2·(t ≥ ½)`; an
    /// entry is a node index, `FVAR_LEAF | patch` or [`FVAR_EMPTY`].
    pub nodes: Vec<[u32; 4]>,
    /// Per base face `f`, the root entries of its sub-faces from `root_offsets[f]` (one for
    /// quads and single-pass triangles, `n` for an `n`-gon).
    pub roots: Vec<u32>,
    pub root_offsets: Vec<u32>,
    pub patches: Vec<FVarPatch>,
    pub points: Vec<[f64; 2]>,
}

/// How the surface is planned, so the layout is planned alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FVarPlan {
    Adaptive(AdaptiveOptions),
    SinglePass(SinglePassOptions),
}

/// The face-varying patches of `mesh`'s texture coordinates for a surface planned as
/// `plan`, or `None` when they are bilinear (no texture coordinates, or
/// [`FVarLinearInterpolation::All`](crate::rules::options::FVarLinearInterpolation::All)).
pub fn texcoord_patches(
    mesh: &ControlMesh,
    plan: &FVarPlan,
) -> Option<Result<FVarPatches, TopologyError>> {
    let scale = match plan {
        FVarPlan::Adaptive(o) => o.sharpness_scale,
        FVarPlan::SinglePass(o) => o.sharpness_scale,
    };
    // The tags are scaled before the layout's analysis, so the values it pins stay pinned.
    let scaled = match scaled_tags(mesh, scale) {
        Ok(m) => m,
        Err(e) => return Some(Err(e)),
    };
    let values = match texcoord_mesh(&scaled, Scheme::CatmullClark)? {
        Ok(v) => v,
        Err(e) => return Some(Err(e)),
    };
    Some(plan_values(&values, plan).and_then(|p| FVarPatches::new(&values, &p)))
}

/// `mesh` with its tags multiplied by `scale` as the plans do (an infinite tag counts as 10).
fn scaled_tags(mesh: &ControlMesh, scale: f32) -> Result<ControlMesh, TopologyError> {
    if !scale.is_finite() || scale < 0.0 {
        return Err(TopologyError::BadSharpnessScale { scale });
    }
    let mut out = mesh.clone();
    if scale != 1.0 {
        for c in &mut out.creases {
            c.sharpness = c.sharpness.min(SHARPNESS_INFINITE) * scale;
        }
        for c in &mut out.corners {
            c.sharpness = c.sharpness.min(SHARPNESS_INFINITE) * scale;
        }
    }
    Ok(out)
}

/// The value mesh planned as the surface is (Gregory end caps, tags already scaled).
fn plan_values(values: &ValueMesh, plan: &FVarPlan) -> Result<AdaptivePlan, TopologyError> {
    match *plan {
        FVarPlan::Adaptive(o) => plan_adaptive(
            &values.mesh,
            &AdaptiveOptions {
                end_cap: EndCap::Gregory,
                sharpness_scale: 1.0,
                ..o
            },
        ),
        FVarPlan::SinglePass(o) => plan_single_pass(
            &values.mesh,
            &SinglePassOptions {
                sharpness_scale: 1.0,
                ..o
            },
        ),
    }
}

/// The Bézier net (`b[i + 4j]`, `i` along `u`) of a bicubic B-spline patch (`p[c + 4r]`).
fn bspline_to_bezier(p: &[[f64; 2]; 16]) -> [[f64; 2]; 16] {
    // Each row of the Bézier points of one uniform cubic B-spline segment.
    const M: [[f64; 4]; 4] = [
        [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
        [0.0, 2.0 / 3.0, 1.0 / 3.0, 0.0],
        [0.0, 1.0 / 3.0, 2.0 / 3.0, 0.0],
        [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
    ];
    let mut out = [[0.0; 2]; 16];
    for j in 0..4 {
        for i in 0..4 {
            for r in 0..4 {
                for c in 0..4 {
                    let w = M[i][c] * M[j][r];
                    out[i + 4 * j][0] += w * p[c + 4 * r][0];
                    out[i + 4 * j][1] += w * p[c + 4 * r][1];
                }
            }
        }
    }
    out
}

/// The 20 Gregory points of a bicubic Bézier net: per corner `P, Ep, Em, Fp, Fm` with the
/// corner's interior Bézier point as both `Fp` and `Fm` (`glsl/adaptive/gregory.tese`'s
/// order).
fn bezier_to_gregory(b: &[[f64; 2]; 16]) -> [[f64; 2]; 20] {
    const SLOTS: [usize; 20] = [
        0, 1, 4, 5, 5, // corner 0 at (0, 0)
        3, 7, 2, 6, 6, // corner 1 at (1, 0)
        15, 14, 11, 10, 10, // corner 2 at (1, 1)
        12, 8, 13, 9, 9, // corner 3 at (0, 1)
    ];
    SLOTS.map(|k| b[k])
}

impl FVarPatches {
    /// The leaves of the layout's plan `plan` (made from `values`), in trees per base
    /// (sub-)face.
    pub fn new(values: &ValueMesh, plan: &AdaptivePlan) -> Result<Self, TopologyError> {
        let base: Vec<[f64; 3]> = values.mesh.positions.clone();
        let verts = plan.apply(&base);
        let uv = |id: u32| {
            let p = verts[id as usize];
            [p[0], p[1]]
        };
        let mut out = FVarPatches::default();
        out.root_offsets.push(0);
        for f in values.mesh.faces() {
            let subs = if f.len() == 4 { 1 } else { f.len() };
            out.roots.extend(std::iter::repeat_n(FVAR_EMPTY, subs));
            out.root_offsets.push(out.roots.len() as u32);
        }
        for p in &plan.patches {
            let index = out.patches.len() as u32;
            out.patches.push(FVarPatch {
                kind: p.kind,
                first_point: out.points.len() as u32,
            });
            out.points.extend(leaf_points(p, &uv));
            out.insert(p, FVAR_LEAF | index)?;
        }
        Ok(out)
    }

    /// Puts leaf entry `leaf` at plan patch `p`'s square in its (sub-)face's tree.
    fn insert(&mut self, p: &AdaptivePatch, leaf: u32) -> Result<(), TopologyError> {
        let face = p.base_face as usize;
        let sub = if p.kind == PatchKind::GregoryTriangle {
            0
        } else {
            p.sub_face as usize
        };
        let bad = || TopologyError::AdaptivePatch {
            level: p.level as u32,
            face,
        };
        let first = *self.root_offsets.get(face).ok_or_else(bad)? as usize;
        let end = *self.root_offsets.get(face + 1).ok_or_else(bad)? as usize;
        if first + sub >= end {
            return Err(bad());
        }
        // Depth from the square's size (a power of two), path from its origin.
        let depth = (-p.size.log2()).round().max(0.0) as u32;
        if depth > FVAR_MAX_DEPTH || p.kind == PatchKind::GregoryTriangle && depth != 0 {
            return Err(bad());
        }
        let mut slot = (None, first + sub);
        for level in 0..depth {
            let entry = self.entry(slot);
            let node = if entry == FVAR_EMPTY {
                self.nodes.push([FVAR_EMPTY; 4]);
                let n = (self.nodes.len() - 1) as u32;
                self.set(slot, n);
                n
            } else if entry & FVAR_LEAF != 0 {
                return Err(bad());
            } else {
                entry
            };
            let h = 0.5f64.powi(level as i32 + 1);
            let qs = ((p.origin[0] / h) as u32) & 1;
            let qt = ((p.origin[1] / h) as u32) & 1;
            slot = (Some(node as usize), (qs + 2 * qt) as usize);
        }
        if self.entry(slot) != FVAR_EMPTY {
            return Err(bad());
        }
        self.set(slot, leaf);
        Ok(())
    }

    fn entry(&self, slot: (Option<usize>, usize)) -> u32 {
        match slot {
            (None, r) => self.roots[r],
            (Some(n), q) => self.nodes[n][q],
        }
    }

    fn set(&mut self, slot: (Option<usize>, usize), value: u32) {
        match slot {
            (None, r) => self.roots[r] = value,
            (Some(n), q) => self.nodes[n][q] = value,
        }
    }

    /// The root entry of base face `face`'s sub-face `sub` (0 for quads and triangle
    /// patches), or [`FVAR_EMPTY`].
    pub fn root(&self, face: u32, sub: u8) -> u32 {
        let f = face as usize;
        match (self.root_offsets.get(f), self.root_offsets.get(f + 1)) {
            (Some(&a), Some(&b)) if (a + sub as u32) < b => self.roots[(a + sub as u32) as usize],
            _ => FVAR_EMPTY,
        }
    }

    /// The root entry a surface patch looks its texture coordinates up from.
    pub fn root_of(&self, patch: &AdaptivePatch) -> u32 {
        let sub = if patch.kind == PatchKind::GregoryTriangle {
            0
        } else {
            patch.sub_face
        };
        self.root(patch.base_face, sub)
    }

    /// The texture coordinate at parameter `st` under root entry `root`: the (sub-)face's
    /// parameter, or a triangle patch's barycentric `(u, v)`. `None` for an empty entry or a
    /// descent deeper than [`FVAR_MAX_DEPTH`]. `glsl/adaptive/fvar.glsl` does the same.
    pub fn texcoord(&self, root: u32, st: [f64; 2]) -> Option<[f64; 2]> {
        self.leaf_at(root, st)
            .map(|(leaf, s, t)| self.evaluate(leaf, s, t))
    }

    /// The leaf under root entry `root` at parameter `st`, and the leaf's own parameter there.
    pub fn leaf_at(&self, root: u32, st: [f64; 2]) -> Option<(&FVarPatch, f64, f64)> {
        let [mut s, mut t] = st;
        let mut entry = root;
        for _ in 0..=FVAR_MAX_DEPTH {
            if entry == FVAR_EMPTY {
                return None;
            }
            if entry & FVAR_LEAF != 0 {
                let leaf = self.patches.get((entry & !FVAR_LEAF) as usize)?;
                return Some((leaf, s, t));
            }
            let node = self.nodes.get(entry as usize)?;
            let (hs, ht) = (s >= 0.5, t >= 0.5);
            entry = node[hs as usize + 2 * ht as usize];
            s = 2.0 * s - f64::from(u8::from(hs));
            t = 2.0 * t - f64::from(u8::from(ht));
        }
        None
    }

    /// Leaf `leaf` at its own parameter.
    fn evaluate(&self, leaf: &FVarPatch, s: f64, t: f64) -> [f64; 2] {
        let first = leaf.first_point as usize;
        let mut out = [0.0; 2];
        let mut add = |w: &[f64], n: usize| {
            for (k, &wk) in w.iter().enumerate().take(n) {
                let p = self.points[first + k];
                out[0] += wk * p[0];
                out[1] += wk * p[1];
            }
        };
        if leaf.is_triangle() {
            add(&gregory_triangle_weights(s, t).point, FVAR_TRIANGLE_POINTS);
        } else {
            add(
                &gregory_weights(s.clamp(0.0, 1.0), t.clamp(0.0, 1.0)).point,
                FVAR_QUAD_POINTS,
            );
        }
        out
    }
}

/// The stored points of layout patch `p`: the Gregory form of a B-spline or Gregory patch
/// (an ACC-1 net's first 20), a Gregory triangle's 15, a bilinear cap's corners as the
/// bilinear patch's Bézier net.
fn leaf_points(p: &AdaptivePatch, uv: &impl Fn(u32) -> [f64; 2]) -> Vec<[f64; 2]> {
    let cp = |k: usize| uv(p.control_points[k]);
    match p.kind {
        PatchKind::Regular => {
            let net: [[f64; 2]; 16] = std::array::from_fn(cp);
            bezier_to_gregory(&bspline_to_bezier(&net)).to_vec()
        }
        PatchKind::Gregory => (0..FVAR_QUAD_POINTS).map(cp).collect(),
        PatchKind::GregoryTriangle => (0..FVAR_TRIANGLE_POINTS).map(cp).collect(),
        PatchKind::Bilinear => {
            let c = [cp(0), cp(1), cp(2), cp(3)];
            let b: [[f64; 2]; 16] = std::array::from_fn(|k| {
                let (x, y) = ((k % 4) as f64 / 3.0, (k / 4) as f64 / 3.0);
                std::array::from_fn(|a| {
                    (1.0 - x) * (1.0 - y) * c[0][a]
                        + x * (1.0 - y) * c[1][a]
                        + x * y * c[2][a]
                        + (1.0 - x) * y * c[3][a]
                })
            });
            bezier_to_gregory(&b).to_vec()
        }
    }
}
