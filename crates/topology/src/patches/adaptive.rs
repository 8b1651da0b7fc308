//! Feature-adaptive Catmull-Clark plan (Nießner et al. 2012, OpenSubdiv's `RefineAdaptive` +
//! `PatchTableFactory`): which faces to refine, level by level, the stencils of every refined
//! vertex, the patches that cover the limit surface and the canonical boundary curves that
//! make shared patch edges bit-identical on the GPU. CPU only: indices are `u32`, weights `f64`;
//! packing for a device is the technique's business.
//!
//! # Design decisions
//! * **One refiner.** Level 0 is [`LevelTopology::from_mesh`] with every tagged crease and
//!   corner sharpness multiplied by [`AdaptiveOptions::sharpness_scale`] (an infinite tag,
//!   ≥ 10, counts as 10, so it stays infinite at scales ≥ 1 and softens below; boundary edges
//!   are infinitely sharp as always). Each step is
//!   [`crate::refine::refine_sparse_region`] of the selected faces with
//!   [`SparseRegion::SelectedCorners`]: level L + 1 holds their children and, of their
//!   one-ring, only the children at the selected faces' corners, which is all the one-rings of
//!   the selected faces' children need (the rest of the one-ring's children were most of a
//!   level and were refined only to be thrown away). Only children of selected faces are
//!   *complete* (their own one-ring is present with exact points), so only complete faces are
//!   selected again or become patches.
//!   Complete faces partition the surface: a complete face is either selected (its children
//!   cover it) or a patch.
//! * **Irregular vertices** (of a complete face): any incident non-quad face; interior valence
//!   ≠ 4; any positive vertex sharpness or sharp incident edge, except three *regular sharp*
//!   cases the B-spline patch reproduces with phantom points (seed §3.7): (a) a boundary vertex
//!   of valence 3 whose interior edge is smooth, (b) a boundary vertex of valence 2 with
//!   infinite vertex sharpness (the corner rule of "edges and corners"), (c) an interior vertex
//!   of valence 4 with two opposite infinitely sharp edges, the other two smooth, and vertex
//!   sharpness 0 (a regular crease, handled in the patch as a boundary).
//! * **Selection** at level L < isolation: the complete, non-hole faces with an irregular
//!   corner. At level 0 that includes every non-quad face and every face sharing a vertex (so
//!   also an edge) with one, because their corners see a non-quad: the n-gon's level-2
//!   children can therefore never border a level-0 patch. Feature-adaptive isolation of a
//!   vertex feature keeps neighbours within one level by itself (the children of a refined
//!   face along an unrefined neighbour's edge have only regular corners there); the plan still
//!   checks it and returns [`TopologyError::AdaptiveUnbalanced`] instead of emitting a crack.
//! * **Patches.** A complete non-selected face is a Regular patch (16 control points gathered
//!   around its corners, rows across a boundary or infinitely sharp edge replaced by phantom
//!   points `2·P_edge − P_inner`, the corner by `4·P − 2·E₀ − 2·E₁ + F`, as OpenSubdiv does).
//!   At the isolation level an irregular complete face is an end cap: Gregory (the 20 points
//!   of [`crate::patches::gregory::gregory_basis`] on that level, its four `P` replaced by the
//!   canonical corners below, which are the same limit points) or bilinear. Semi-sharp
//!   sharpness still positive at the isolation level is treated as infinite there, for the
//!   classification, the phantoms, the Gregory points and the corner masks alike (as the seed
//!   does): a regular crease becomes a crease patch, anything else an end cap. This is the one
//!   approximation besides the end caps; it vanishes once the isolation level reaches the
//!   sharpness. Holes make no patches and are never selected.
//! * **Parameterisation.** Each patch knows its base face (and sub-quad of a non-quad base
//!   face, numbered as [`crate::limit::eval::LocalMesh::evaluate_subface`] does) and the square
//!   `origin + size·[0,1]²` of that (sub-)face's domain it covers. Its corners are rotated so
//!   that patch corner 0 is the corner at the square's `(0, 0)` and the corners run in the
//!   base face's orientation.
//! * **Transitions.** Each patch edge knows whether the neighbour across it is at the same
//!   level ([`EdgeKind::Plain`]), one level finer ([`EdgeKind::Coarse`]: the neighbour was
//!   refined) or one level coarser ([`EdgeKind::Fine`]: the neighbour's parent is a patch).
//! * **Canonical corners and curves** (what makes shared edges bit-identical on a GPU): every
//!   distinct limit point used as a patch corner is one local point, keyed by the coarsest
//!   vertex-vertex ancestor of the vertex, so a vertex at level L and its child at L + 1 share
//!   it. Its limit stencil is the Catmull-Clark limit mask ([`crate::limit::masks`]) at the first
//!   (coarsest) level where it is a patch corner (where its whole ring is present). Every
//!   distinct patch edge at the finest level where it exists (a transition edge is the union of
//!   its two fine halves) is one cubic Bézier curve `[c0, b1, b2, c3]`, `c0 < c3` the canonical
//!   corner ids; `b1`, `b2` come from one owner patch, chosen Regular before Gregory before
//!   Bilinear, then by lowest patch index (a Regular owner of a half takes it by de Casteljau
//!   from its own edge). A patch's own boundary equals its curves mathematically (a Gregory
//!   edge next to a regular patch has regular ends, where the Gregory boundary is the
//!   B-spline's); a bilinear end cap is the Coons patch of its four curves.
//! * **One global vertex buffer.** Base vertices first, then one [`StencilBlock`] per level (its
//!   rows read only the previous level), then one block of local points (phantoms, Gregory
//!   points, the canonical corners first met on an end cap) that reads only refined vertices,
//!   so each block can run as one parallel kernel. Then two runs of points that no stencil
//!   computes, each a fixed combination of its owner patch's control points, which the device
//!   evaluates every frame: the canonical corners first met on a regular patch
//!   ([`AdaptivePlan::regular_corner_point`]), then the curves' inner points, two per curve
//!   ([`AdaptivePlan::curve_inner_point`]). Dropping their stencil rows made most of the
//!   drop of catmark_car's plan from 1,444 M to 1,086 M instructions (docs/benchmarks.md,
//!   "The CPU plan against OpenSubdiv's far_perf"). Local points are not shared between patches except the canonical corners
//!   and curves (two boundary patches each have their own phantoms).
//! * **Size bound.** Every vertex of a triangle mesh is extraordinary under Catmull-Clark (and
//!   so is every face centre of level 1), so isolation refines nearly everything at every
//!   level: a 1M-triangle grid at isolation 4 is tens of millions of refined faces and
//!   aborted on allocation at 5–7 GB. Before each refinement step the plan projects the
//!   refined faces it will hold, those made so far plus the selected faces' children times the
//!   levels left to the isolation level (the selection of an irregular mesh does not shrink
//!   from level to level), and returns [`TopologyError::AdaptiveTooLarge`] (mesh size,
//!   isolation, estimate) when that exceeds the bound, [`MAX_REFINED_FACES`] by default
//!   ([`plan_adaptive_within`] takes another). The projection is taken before the step's
//!   allocation, so the plan never holds more than the bound's refined faces.
//! * **Cost.** Faces are drafted in parallel per level, canonical corner and curve stencils in
//!   parallel chunks appended in order, so the plan is the same with any thread count. Most of
//!   the remaining time is the sparse refinement itself and first-touch page faults of the
//!   stencil tables.

use crate::error::TopologyError;
use crate::limit::basis::catmark_regular_weights;
use crate::limit::masks::catmark_smooth_position_weights;
use crate::mesh::{ControlMesh, Topology, INVALID};
use crate::refine::stencil::StencilTable;
use crate::refine::{refine_sparse_region, ChildMaps, ChildOrigin, LevelTopology, SparseRegion};
use crate::rules::{is_infinite, vertex_rule, Rule, Scheme, SHARPNESS_INFINITE};
use rayon::prelude::*;

/// Default bound on the refined faces of an adaptive plan (summed over its levels), 2²³: a
/// few GB of levels, stencils and patches (not measured per face; the 1M-triangle grid that
/// aborted at 5–7 GB had refined past it). A 1M-quad grid at isolation 4 refines only around
/// its four corners; a 1M-triangle grid at isolation 4 projects 12M (3M children × 4 levels)
/// before its first step and is refused there.
pub const MAX_REFINED_FACES: u64 = 1 << 23;

/// How faces still irregular at the isolation level are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum EndCap {
    /// Gregory patch (20 points), as OpenSubdiv does by default.
    #[default]
    Gregory,
    /// Coons patch of the four canonical boundary curves (the seed's bilinear choice).
    Bilinear,
}

/// Options of [`plan_adaptive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveOptions {
    /// Deepest refinement level, `1..=8`.
    pub isolation: u32,
    pub end_cap: EndCap,
    /// Multiplies every tagged edge and vertex sharpness before planning (finite, ≥ 0); an
    /// infinite tag (≥ 10) counts as 10, so 0 makes every tag smooth and 0.5 makes an infinite
    /// one 5; boundary edges stay infinitely sharp.
    pub sharpness_scale: f32,
    /// Follow semi-sharp creases and corners past the isolation level until their sharpness
    /// has decayed, then isolate the irregular vertices that carried them `isolation` more
    /// levels, as every other irregular vertex is, so the surface beside them is exact and its
    /// end caps converge with the isolation level; and isolate the vertices whose end caps
    /// converge slowly (cones, darts, valence 6 and up) a few levels deeper, so every cap is as
    /// close to the limit as the isolation level promises elsewhere (at most level 14 in all).
    /// Off, leftover sharpness at the isolation level is treated as infinite and every end cap
    /// sits at the isolation level (OpenSubdiv's and the seed's behaviour).
    pub follow_semi_sharp: bool,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        AdaptiveOptions {
            isolation: 4,
            end_cap: EndCap::Gregory,
            sharpness_scale: 1.0,
            follow_semi_sharp: true,
        }
    }
}

/// Rows computing a contiguous range of global vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StencilBlock {
    /// Row `r` computes global vertex `first_vertex + r`.
    pub first_vertex: u32,
    /// Indices are global vertex ids, all below `first_vertex`.
    pub table: StencilTable,
}

/// Patch counts of one level (the seed's Fig. 5.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelStats {
    pub regular: u32,
    pub end_caps: u32,
    /// Faces held at this level: the children of the level above's selection and, of its
    /// one-ring, the children at the selection's corners.
    pub faces: u32,
    /// Faces of a uniform refinement to this level.
    pub uniform_faces: u64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchKind {
    Regular,
    Gregory,
    Bilinear,
    /// A Gregory triangle patch ([`crate::patches::gregory::gregory_triangle_weights`]) on a triangle
    /// base face (single-pass plans): three corners and edges, barycentric `(u, v)`,
    /// `u + v ≤ 1`.
    GregoryTriangle,
}

impl PatchKind {
    /// Corners (and edges) of the patch's domain.
    pub fn corners(self) -> usize {
        if self == PatchKind::GregoryTriangle {
            3
        } else {
            4
        }
    }
}

/// Patch parameter at `t` along edge `edge` (in the patch's edge direction) of a patch with
/// `corners` corners: the square's edges run (0,0) → (1,0) → (1,1) → (0,1); the triangle's
/// (0,0) → (1,0) → (0,1).
pub fn edge_param(corners: usize, edge: usize, t: f64) -> [f64; 2] {
    if corners == 3 {
        return match edge {
            0 => [t, 0.0],
            1 => [1.0 - t, t],
            _ => [0.0, 1.0 - t],
        };
    }
    match edge {
        0 => [t, 0.0],
        1 => [1.0, t],
        2 => [1.0 - t, 1.0],
        _ => [0.0, 1.0 - t],
    }
}

/// Parameter of patch corner `corner` (see [`edge_param`]).
pub fn corner_param(corners: usize, corner: usize) -> [f64; 2] {
    edge_param(corners, corner, 0.0)
}

/// The sub-quad parameter of a point of a triangle's barycentric domain `(u, v)`: sub-quad
/// `k` (of [`crate::limit::eval::LocalMesh::evaluate_subface`]) is the third of the triangle nearest
/// corner `k`, `[corner, edge midpoint, centroid, edge midpoint]`, mapped bilinearly from its
/// `(s, t)`. Inverting that map: with `(a, b)` the barycentrics of the next and the previous
/// corner, `a = s/2 − st/6`, `b = t/2 − st/6`. Face-varying data bilinear on the sub-quads is
/// thereby linear on the triangle.
pub fn triangle_subquad_param(u: f64, v: f64) -> (u8, f64, f64) {
    let l = [1.0 - u - v, u, v];
    // The nearest corner (ties to the lower index, both sides agree there anyway).
    let k = if l[0] >= l[1] && l[0] >= l[2] {
        0
    } else if l[1] >= l[2] {
        1
    } else {
        2
    };
    let (a, b) = (l[(k + 1) % 3], l[(k + 2) % 3]);
    // s − t = 2(a − b); t² + (2(a − b) − 3) t + 6b = 0, the root in [0, 1].
    let d = 2.0 * (a - b);
    let p = 3.0 - d;
    let t = (p - (p * p - 24.0 * b).max(0.0).sqrt()) * 0.5;
    let s = t + d;
    (k as u8, s.clamp(0.0, 1.0), t.clamp(0.0, 1.0))
}

/// Level of the neighbour across a patch edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EdgeKind {
    /// Same level (or no neighbour).
    Plain,
    /// The neighbour is one level finer: two curves, one per half.
    Coarse,
    /// The neighbour is one level coarser: this edge is half of its edge.
    Fine,
}

/// Curves of one patch edge; see [`EdgeKind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchEdge {
    pub kind: EdgeKind,
    /// Plain: both the edge's curve. Coarse: first and second half in the patch's edge
    /// direction. Fine: this edge's curve, then its sibling half.
    pub curves: [u32; 2],
    /// The patch's edge direction runs from the curve's point 3 to its point 0.
    pub reversed: [bool; 2],
}

/// The patch that owns a canonical curve: the curve is `part` (0 whole, 1 first half, 2 second
/// half, in the patch's edge direction) of its edge `edge`, running with the edge's direction
/// from point 0 to point 3 when `forward`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CurveOwner {
    pub patch: u32,
    pub edge: u8,
    pub part: u8,
    pub forward: bool,
    /// The owner is a [`PatchKind::GregoryTriangle`] (its edges run as [`edge_param`]'s).
    pub triangle: bool,
}

impl CurveOwner {
    /// The owner's patch parameter at curve parameter `s`.
    pub fn patch_param(&self, s: f64) -> [f64; 2] {
        let e = if self.forward { s } else { 1.0 - s };
        let t = match self.part {
            1 => 0.5 * e,
            2 => 0.5 + 0.5 * e,
            _ => e,
        };
        edge_param(if self.triangle { 3 } else { 4 }, self.edge as usize, t)
    }
}

/// A patch's control-point ids, inline up to a regular patch's 16: tens of thousands of
/// patches per plan, each with a heap block of its own, cost catmark_car's plan ~9 % of its
/// instructions in `malloc` and `free` and ~3 MB of fresh pages. End caps (20 to 28) spill.
pub type ControlPoints = smallvec::SmallVec<[u32; 16]>;

/// One patch of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptivePatch {
    pub kind: PatchKind,
    pub level: u8,
    /// Global vertex ids. Regular: 16, row-major 4×4 as [`crate::limit::basis`] (phantoms
    /// substituted); Gregory: 20, per corner `P, Ep, Em, Fp, Fm`; Bilinear: the 4 canonical
    /// corners; GregoryTriangle: 27, per corner `P, Ep, Em, Fp, Fm` (15), then per edge the
    /// inner points of its two level-1 halves in the edge's direction (12; the curves of a
    /// triangle's edges where it owns them).
    pub control_points: ControlPoints,
    pub base_face: u32,
    /// Sub-quad of a non-quad base face; 0 for quads and for triangle patches (which cover
    /// their whole triangle, [`AdaptivePatch::base_param`]).
    pub sub_face: u8,
    /// Patch `(u, v)` covers `(sub)face parameter origin + size·(u, v)`.
    pub origin: [f64; 2],
    pub size: f64,
    /// Bit `i`: edge `i` is a boundary or infinitely sharp crease handled in the patch (for
    /// end caps too, where it only informs: their points already account for it).
    pub boundary_mask: u8,
    /// Bit `i`: the neighbour across edge `i` is one level finer.
    pub transition_mask: u8,
    /// Edge 0: v0→v1 (v = 0), 1: v1→v2 (u = 1), 2: v2→v3 (v = 1), 3: v3→v0 (u = 0). A triangle
    /// patch: 0: v0→v1 (v = 0), 1: v1→v2 (u + v = 1), 2: v2→v0 (u = 0), edge 3 unused.
    pub edges: [PatchEdge; 4],
    /// Per corner: the valence whose texture-reparameterization block applies
    /// ([`crate::patches::reparam`]), 0 for the identity (regular and ACC-1 patches, boundary, crease and
    /// corner vertices). Gregory patches only: the table is fitted to them.
    pub reparam_valences: [u8; 4],
    /// ACC-1 patches (Gregory kind, 28 control points: the net's 20, then per corner the limit
    /// tangent points `Ep, Em` of [`crate::patches::gregory`]): each corner's valence, for the tangent
    /// patches that shade them ([`crate::patches::acc::tangent_normal`]); `[0; 4]` on every other patch.
    pub tangent_valences: [u8; 4],
}

impl AdaptivePatch {
    /// Corners (and edges) of the patch.
    pub fn corners(&self) -> usize {
        self.kind.corners()
    }

    /// The base-face parameter of patch parameter `(u, v)`: `(sub-face, s, t)`, the sub-face 0
    /// on quads. A triangle patch maps its barycentric domain onto the triangle's three
    /// sub-quads ([`triangle_subquad_param`]).
    pub fn base_param(&self, u: f64, v: f64) -> (u8, f64, f64) {
        if self.kind == PatchKind::GregoryTriangle {
            return triangle_subquad_param(u, v);
        }
        (
            self.sub_face,
            self.origin[0] + self.size * u,
            self.origin[1] + self.size * v,
        )
    }
}

/// Everything a device needs to draw the feature-adaptive limit surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AdaptivePlan {
    /// Global ids `0..num_base_vertices` are the control mesh's vertices.
    pub num_base_vertices: u32,
    /// Size of the global vertex buffer.
    pub num_vertices: u32,
    /// Refinement levels 1..=isolation, in order.
    pub steps: Vec<StencilBlock>,
    /// Phantom points, Gregory points and the canonical corners first met on an end cap (the
    /// last block).
    pub local_points: StencilBlock,
    pub patches: Vec<AdaptivePatch>,
    /// Canonical boundary curves: cubic Bézier control points (global ids).
    pub curves: Vec<[u32; 4]>,
    /// Global id of curve 0's first inner point. The inner points come last, after the
    /// regular corners, two per curve in curve order (`curves[c][1] = first_curve_point + 2c`), and no
    /// stencil rows compute them: [`AdaptivePlan::curve_inner_point`] does, from the owner's
    /// control points, as the device does every frame.
    pub first_curve_point: u32,
    /// Global id of the first canonical corner that no stencil row computes. The corners
    /// `first_regular_corner..first_curve_point` were first met on a regular patch, their
    /// owner: each is that B-spline patch's value at its corner, a fixed combination of its
    /// 3×3 points there, phantoms included ([`AdaptivePlan::regular_corner_point`]), which the
    /// device evaluates every frame. The corners before it have limit-stencil rows, the
    /// last rows of `local_points`.
    pub first_regular_corner: u32,
    /// Per curve: the patch that computed its inner points, whose evaluation along the curve
    /// defines the curve's normals and texture coordinates for both sides.
    pub curve_owners: Vec<CurveOwner>,
    /// Global id of the first canonical corner (the limit point of a patch corner; corners are
    /// numbered consecutively from here).
    pub first_corner: u32,
    /// Per canonical corner: `[patch, corner]` of the patch whose evaluation at that corner
    /// defines its normal and texture coordinate for every patch around it.
    pub corner_owners: Vec<[u32; 2]>,
    /// Per level 0..=isolation.
    pub level_stats: Vec<LevelStats>,
    pub isolation: u32,
}

/// Position and parametric derivatives of a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchSample {
    pub position: [f64; 3],
    pub du: [f64; 3],
    pub dv: [f64; 3],
}

mod assemble;
mod levels;
mod nets;
pub mod single_pass;
pub use assemble::MAX_LOCAL_TERMS;

/// Plan the feature-adaptive refinement and patches of `mesh` (Catmull-Clark).
///
/// ```
/// use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, EndCap};
/// use topology::ControlMesh;
/// // A cube: eight valence-3 vertices, isolated to level 2.
/// let p = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.],
///          [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
/// let faces = [[0u32, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
/// let mesh = ControlMesh::from_polygons(p.to_vec(), &faces);
/// let opts = AdaptiveOptions { isolation: 2, ..AdaptiveOptions::default() };
/// let plan = plan_adaptive(&mesh, &opts).unwrap();
/// assert_eq!(plan.level_stats[2].end_caps, 24); // three per corner
/// let verts = plan.apply(&mesh.positions);
/// let centre = plan.evaluate(&verts, 0, 0.5, 0.5).position;
/// assert!(centre.iter().all(|x| x.is_finite()));
/// ```
pub fn plan_adaptive(
    mesh: &ControlMesh,
    opts: &AdaptiveOptions,
) -> Result<AdaptivePlan, TopologyError> {
    plan_adaptive_within(mesh, opts, MAX_REFINED_FACES)
}

/// [`plan_adaptive`] under a bound on the refined faces other than [`MAX_REFINED_FACES`]: a
/// plan projected past it is [`TopologyError::AdaptiveTooLarge`], returned before the
/// refinement step that would exceed it.
pub fn plan_adaptive_within(
    mesh: &ControlMesh,
    opts: &AdaptiveOptions,
    max_refined_faces: u64,
) -> Result<AdaptivePlan, TopologyError> {
    if !(1..=8).contains(&opts.isolation) {
        return Err(TopologyError::IsolationOutOfRange {
            isolation: opts.isolation,
        });
    }
    let scale = opts.sharpness_scale;
    if !scale.is_finite() || scale < 0.0 {
        return Err(TopologyError::BadSharpnessScale { scale });
    }
    let scaled = levels::scaled_mesh(mesh, scale)?;
    let levels = levels::build_levels(
        &scaled,
        opts.isolation as usize,
        opts.follow_semi_sharp,
        max_refined_faces,
        false,
    )?;
    assemble::assemble(&scaled, opts, levels, opts.isolation as usize, false, false)
}

fn bezier(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * s * t,
            6.0 * s * t - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

fn axpy(out: &mut [f64; 3], w: f64, x: &[f64; 3]) {
    out[0] += w * x[0];
    out[1] += w * x[1];
    out[2] += w * x[2];
}

/// Adds the `N` control points `cp(k)` weighted by `w` to `s` (position and derivatives).
fn add_weighted<'a, const N: usize>(
    s: &mut PatchSample,
    w: &crate::limit::basis::PatchWeights<N>,
    cp: impl Fn(usize) -> &'a [f64; 3],
) {
    for k in 0..N {
        axpy(&mut s.position, w.point[k], cp(k));
        axpy(&mut s.du, w.du[k], cp(k));
        axpy(&mut s.dv, w.dv[k], cp(k));
    }
}

impl AdaptivePlan {
    /// The whole global vertex buffer from the base positions (`num_base_vertices` of them).
    pub fn apply(&self, base: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut verts = Vec::with_capacity(self.num_vertices as usize);
        verts.extend_from_slice(&base[..(self.num_base_vertices as usize).min(base.len())]);
        verts.resize(self.num_base_vertices as usize, [0.0; 3]);
        for block in self.steps.iter().chain(std::iter::once(&self.local_points)) {
            verts.resize(block.first_vertex as usize, [0.0; 3]);
            let rows = block.table.apply(&verts);
            verts.extend_from_slice(&rows);
        }
        verts.resize(self.first_regular_corner as usize, [0.0; 3]);
        for id in self.first_regular_corner..self.first_curve_point {
            let p = self.regular_corner_point(&verts, id);
            verts.push(p);
        }
        verts.resize(self.first_curve_point as usize, [0.0; 3]);
        for c in 0..self.curves.len() {
            for slot in 1..=2 {
                let p = self.curve_inner_point(&verts, c, slot);
                verts.push(p);
            }
        }
        verts
    }

    /// Canonical corner `id` (from [`Self::first_regular_corner`] on), from its owner's points
    /// in `verts` (which must hold every vertex before `first_regular_corner`): the smooth
    /// valence-4 limit mask over the owner's 3×3 points around that corner, summed as offsets
    /// from the corner's own point. With phantoms across a boundary or crease it is the
    /// crease (or corner) limit rule, exactly: the B-spline's value at the patch corner.
    /// `glsl/adaptive/canonical.comp` (corners mode) computes the same.
    pub fn regular_corner_point(&self, verts: &[[f64; 3]], id: u32) -> [f64; 3] {
        let [pi, corner] = self.corner_owners[(id - self.first_corner) as usize];
        let pa = &self.patches[pi as usize];
        let [_, we, wf] = catmark_smooth_position_weights(4);
        let (ox, oy) = nets::POS[corner as usize];
        let cp = |a: i32, b: i32| verts[pa.control_points[nets::slot(ox + a, oy + b)] as usize];
        let anchor = cp(0, 0);
        let mut e = [0.0; 3];
        let mut f = [0.0; 3];
        for (a, b) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            let (x, y) = (cp(a, b), cp(a + b, b - a));
            for k in 0..3 {
                e[k] += x[k] - anchor[k];
                f[k] += y[k] - anchor[k];
            }
        }
        std::array::from_fn(|k| anchor[k] + (we * e[k] + wf * f[k]))
    }

    /// Inner point `slot` (1 or 2) of canonical curve `c`, from its owner's control points in
    /// `verts` (which must hold every vertex before [`Self::first_curve_point`]): the owner's
    /// edge as a cubic Bézier curve `B0..B3` in the edge's direction, or the half of it that
    /// the curve is (de Casteljau), read at point `k` of the segment in the curve's direction.
    /// The edge's Bézier points are the regular patch's B-spline edge, a Gregory patch's
    /// `[P, Ep, Em, P']` or a bilinear end cap's straight line between its corners; a Gregory
    /// triangle's halves are its own points. `glsl/adaptive/canonical.comp` (curves mode)
    /// computes the same, so both sides of an edge read one curve.
    pub fn curve_inner_point(&self, verts: &[[f64; 3]], c: usize, slot: usize) -> [f64; 3] {
        let o = &self.curve_owners[c];
        let pa = &self.patches[o.patch as usize];
        let cp = |k: usize| verts[pa.control_points[k] as usize];
        let (e, part) = (o.edge as usize, o.part as usize);
        let k = if o.forward { slot } else { 3 - slot };
        let n = pa.corners();
        let e1 = (e + 1) % n;
        let b: [[f64; 3]; 4] = match pa.kind {
            PatchKind::GregoryTriangle if part != 0 => {
                return cp(15 + 4 * e + 2 * (part - 1) + (k - 1));
            }
            PatchKind::Regular => nets::regular_edge_bezier(e, cp),
            PatchKind::Gregory | PatchKind::GregoryTriangle => {
                [cp(5 * e), cp(5 * e + 1), cp(5 * e1 + 2), cp(5 * e1)]
            }
            PatchKind::Bilinear => {
                let (c0, c3) = (cp(e), cp(e1));
                let third =
                    |a: [f64; 3], b: [f64; 3]| std::array::from_fn(|x| (2.0 * a[x] + b[x]) / 3.0);
                [c0, third(c0, c3), third(c3, c0), c3]
            }
        };
        if part == 0 {
            return b[k];
        }
        let w = nets::bezier_half(part - 1)[k];
        std::array::from_fn(|x| w[0] * b[0][x] + w[1] * b[1][x] + w[2] * b[2][x] + w[3] * b[3][x])
    }

    /// The parameter of canonical corner `k` in its owner patch (`corner_owners[k]`): a patch
    /// corner, or (corner index `4 + e` of a triangle patch) the midpoint of its edge `e`.
    pub fn corner_owner_param(&self, k: usize) -> [f64; 2] {
        let [pi, c] = self.corner_owners[k];
        let n = self.patches[pi as usize].corners();
        let c = c as usize;
        if c >= 4 {
            edge_param(n, c - 4, 0.5)
        } else {
            corner_param(n, c)
        }
    }

    /// Point and derivative of curve `curve` at `t ∈ [0, 1]` (point 0 at `t = 0`).
    pub fn curve_sample(&self, verts: &[[f64; 3]], curve: usize, t: f64) -> ([f64; 3], [f64; 3]) {
        let (w, d) = bezier(t);
        let mut p = [0.0; 3];
        let mut dp = [0.0; 3];
        for (k, &id) in self.curves[curve].iter().enumerate() {
            axpy(&mut p, w[k], &verts[id as usize]);
            axpy(&mut dp, d[k], &verts[id as usize]);
        }
        (p, dp)
    }

    /// Point of curve `curve` at `t ∈ [0, 1]` (point 0 at `t = 0`).
    pub fn curve_point(&self, verts: &[[f64; 3]], curve: usize, t: f64) -> [f64; 3] {
        self.curve_sample(verts, curve, t).0
    }

    /// Point and derivative (with respect to `t`) of edge `edge` of patch `patch` at `t`
    /// along the patch's edge direction, from its curves.
    pub fn edge_sample(
        &self,
        verts: &[[f64; 3]],
        patch: usize,
        edge: usize,
        t: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let e = &self.patches[patch].edges[edge];
        let (k, local, scale) = match e.kind {
            EdgeKind::Coarse if t > 0.5 => (1, 2.0 * t - 1.0, 2.0),
            EdgeKind::Coarse => (0, 2.0 * t, 2.0),
            _ => (0, t, 1.0),
        };
        let (s, sign) = if e.reversed[k] {
            (1.0 - local, -1.0)
        } else {
            (local, 1.0)
        };
        let (p, d) = self.curve_sample(verts, e.curves[k] as usize, s);
        (p, d.map(|x| x * sign * scale))
    }

    /// The shading normal of patch `patch` at `(u, v)`: from the tangent patches on ACC-1
    /// patches ([`crate::patches::acc::tangent_normal`]), else the unit cross product of the
    /// derivatives of [`Self::evaluate`].
    pub fn shading_normal(&self, verts: &[[f64; 3]], patch: usize, u: f64, v: f64) -> [f64; 3] {
        let pa = &self.patches[patch];
        if pa.tangent_valences != [0; 4] && pa.control_points.len() == 28 {
            let points = std::array::from_fn(|k| verts[pa.control_points[k] as usize]);
            return crate::patches::acc::tangent_normal(&points, pa.tangent_valences, u, v);
        }
        let s = self.evaluate(verts, patch, u, v);
        crate::limit::eval::normal_of(&s.du, &s.dv)
    }

    /// The boundary correction of a Gregory triangle patch on its transition edges (a finer
    /// neighbour: the edge is two half curves of level 1, through the exact limit point of the
    /// edge's midpoint, where the patch's own boundary is one cubic). Edge `p` (corner `p` to
    /// `p + 1`) adds `(λp + λp+1)² · (C(t) − B(t))`, `t = λp+1 / (λp + λp+1)`, with `C` the
    /// canonical halves and `B` the patch's own cubic: it is the whole difference on edge `p`,
    /// and 0 on the other two edges (`C − B` vanishes at the corners, with its derivative,
    /// since both start along the same limit tangent), so the patch's boundary is its
    /// canonical curves exactly. Mirrored by `glsl/adaptive/triangle.tese`.
    fn triangle_transitions(
        &self,
        verts: &[[f64; 3]],
        patch: usize,
        u: f64,
        v: f64,
        s: &mut PatchSample,
    ) {
        let pa = &self.patches[patch];
        let l = [1.0 - u - v, u, v];
        const DL: [[f64; 2]; 3] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
        for p in 0..3 {
            if pa.edges[p].kind != EdgeKind::Coarse {
                continue;
            }
            let q = (p + 1) % 3;
            let sum = l[p] + l[q];
            if sum <= 1e-12 {
                continue;
            }
            let t = l[q] / sum;
            let (c, dc) = self.edge_sample(verts, patch, p, t);
            let cp = |k: usize| verts[pa.control_points[k] as usize];
            let own = [cp(5 * p), cp(5 * p + 1), cp(5 * q + 2), cp(5 * q)];
            let (bw, bd) = bezier(t);
            let mut d = c;
            let mut dd = dc;
            for k in 0..4 {
                axpy(&mut d, -bw[k], &own[k]);
                axpy(&mut dd, -bd[k], &own[k]);
            }
            let w = sum * sum;
            axpy(&mut s.position, w, &d);
            for (axis, out) in [&mut s.du, &mut s.dv].into_iter().enumerate() {
                let ds = DL[p][axis] + DL[q][axis];
                // ∂(w·d(t)) = 2·sum·∂sum·d + d'·(∂λq·sum − λq·∂sum)
                axpy(out, 2.0 * sum * ds, &d);
                axpy(out, DL[q][axis] * sum - l[q] * ds, &dd);
            }
        }
    }

    /// CPU evaluation of patch `patch` at `(u, v) ∈ [0,1]²` (`u + v ≤ 1` on a triangle patch)
    /// on the global vertex buffer `verts` (from [`Self::apply`]): bicubic B-spline, Gregory,
    /// Gregory triangle, or the Coons patch of the four curves of a bilinear end cap.
    pub fn evaluate(&self, verts: &[[f64; 3]], patch: usize, u: f64, v: f64) -> PatchSample {
        let pa = &self.patches[patch];
        let cp = |k: usize| &verts[pa.control_points[k] as usize];
        let mut s = PatchSample {
            position: [0.0; 3],
            du: [0.0; 3],
            dv: [0.0; 3],
        };
        match pa.kind {
            PatchKind::Regular => add_weighted(&mut s, &catmark_regular_weights(u, v), cp),
            PatchKind::Gregory => {
                add_weighted(&mut s, &crate::patches::gregory::gregory_weights(u, v), cp)
            }
            PatchKind::GregoryTriangle => {
                add_weighted(
                    &mut s,
                    &crate::patches::gregory::gregory_triangle_weights(u, v),
                    cp,
                );
                self.triangle_transitions(verts, patch, u, v, &mut s);
            }
            PatchKind::Bilinear => {
                let (b, db) = self.edge_sample(verts, patch, 0, u);
                let (r, dr) = self.edge_sample(verts, patch, 1, v);
                let (tp, dtp) = self.edge_sample(verts, patch, 2, 1.0 - u);
                let (lf, dlf) = self.edge_sample(verts, patch, 3, 1.0 - v);
                let (c00, c10, c11, c01) = (cp(0), cp(1), cp(2), cp(3));
                let terms_p: [(f64, &[f64; 3]); 8] = [
                    (1.0 - v, &b),
                    (v, &tp),
                    (1.0 - u, &lf),
                    (u, &r),
                    (-(1.0 - u) * (1.0 - v), c00),
                    (-u * (1.0 - v), c10),
                    (-u * v, c11),
                    (-(1.0 - u) * v, c01),
                ];
                for (w, x) in terms_p {
                    axpy(&mut s.position, w, x);
                }
                let terms_u: [(f64, &[f64; 3]); 8] = [
                    (1.0 - v, &db),
                    (-v, &dtp),
                    (-1.0, &lf),
                    (1.0, &r),
                    (1.0 - v, c00),
                    (-(1.0 - v), c10),
                    (-v, c11),
                    (v, c01),
                ];
                for (w, x) in terms_u {
                    axpy(&mut s.du, w, x);
                }
                let terms_v: [(f64, &[f64; 3]); 8] = [
                    (-1.0, &b),
                    (1.0, &tp),
                    (-(1.0 - u), &dlf),
                    (u, &dr),
                    (1.0 - u, c00),
                    (u, c10),
                    (-u, c11),
                    (-(1.0 - u), c01),
                ];
                for (w, x) in terms_v {
                    axpy(&mut s.dv, w, x);
                }
            }
        }
        s
    }
}
