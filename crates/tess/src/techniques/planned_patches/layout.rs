//! The adaptive technique's GPU data: every storage buffer `glsl/adaptive/adaptive.glsl` reads,
//! as named `#[repr(C)]` + `Pod` structs, and the packing of `topology`'s plan
//! ([`AdaptivePlan`]: stencil blocks, patches, canonical curves) into them.
//!
//! Design decisions:
//! - **One global vertex buffer** (`vec4`): base vertices, then each level's refined vertices,
//!   then the local points (phantom points, Gregory points, limit corners with rows), then
//!   the limit corners of regular patches, then the curves' inner Bezier points.
//!   Every stencil row is over global vertices, so the stencil evaluator ([`crate::stencil`])
//!   applies every block in place; a block's rows read only earlier blocks, so each block is
//!   one pass. The regular corners and the curve points have no rows: the canonical kernel
//!   evaluates them from their owner patches' control points (corner owners, `CurveOwner`),
//!   in that order, last.
//! - **Patches in array order** (regular, Gregory, bilinear): a patch's record index is its
//!   frame-wide id, what the TES captures and [`crate::Technique::face_point`] maps back.
//! - **Checked before upload**: [`GpuPlan::new`] proves every index a shader can form is
//!   in range and every row reads only earlier blocks, so a bad plan fails here, not as an
//!   out-of-bounds read on the device.
use crate::gpu::bindings::{
    ADAPTIVE_EDGE_COARSE, ADAPTIVE_EDGE_FINE, ADAPTIVE_EDGE_PLAIN, ADAPTIVE_FVAR_MAX_DEPTH,
    ADAPTIVE_KIND_BILINEAR, ADAPTIVE_KIND_GREGORY, ADAPTIVE_KIND_GREGORY_TRIANGLE,
    ADAPTIVE_KIND_REGULAR,
};
use crate::stencil::{GpuStencils, StencilBlock, StencilError, StencilVertex};
use bytemuck::{Pod, Zeroable};
use std::mem::size_of;
use topology::patches::adaptive::{AdaptivePatch, AdaptivePlan, EdgeKind, PatchKind};
use topology::patches::fvar::{FVarPatches, FVAR_EMPTY, FVAR_MAX_DEPTH};
use topology::ControlMesh;

/// `AdaptivePatch` of `adaptive.glsl`: one patch.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct PatchRecord {
    /// First control-point index in the control-point buffer.
    pub cp_offset: u32,
    /// `kind | level << 4 | boundary mask << 8 | transition mask << 12`.
    pub info: u32,
    /// Per edge `i`, four bits at `4i`: edge kind (2 bits), `reversed[0]`, `reversed[1]`.
    pub edge_info: u32,
    pub pad: u32,
    /// Edge `i`: `curves[2i]`, `curves[2i + 1]`.
    pub curves: [u32; 8],
}

/// `PatchSurface` of `adaptive.glsl`: what a patch's texture look-ups need.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PatchSurface {
    /// Texture coordinates at corners (0,0), (1,0), (1,1), (0,1): the OBJ's `vt`, or the
    /// (sub)face parameter when the mesh has none. A triangle patch (corners (0,0), (1,0),
    /// (0,1)) stores `t1 + t2 − t0` at (1,1): the bilinear blend of that parallelogram is the
    /// triangle's linear interpolation, so one formula serves both.
    pub uv: [[f32; 2]; 4],
    /// Per corner `i`, 8 bits at `8i`: its row of the reparameterization table (0 = identity).
    pub reparam_rows: u32,
    /// ACC-1 patches: per corner `i`, 8 bits at `8i`, its valence for the tangent patches
    /// (`topology::patches::acc::tangent_normal`); 0 on every other patch.
    pub tangent_valences: u32,
    /// Smooth texture coordinates: the root entry, in the face-varying array
    /// ([`fvar_words`]), of the patch's (sub-)face, whose parameter `uv` then holds (a
    /// triangle patch's: its barycentric parallelogram); `FVAR_EMPTY`: `uv` are the texture
    /// coordinates.
    pub fvar_root: u32,
    pub pad: u32,
}

/// `CurveOwner` of `adaptive.glsl`: the patch whose evaluation along a canonical curve gives
/// both sides its normals and texture coordinates (`topology::patches::adaptive::CurveOwner`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct CurveOwner {
    /// Frame-wide patch id.
    pub patch: u32,
    /// `edge | part << 2 | forward << 4 | triangle << 5` (a triangle owner's edges run
    /// `topology::patches::adaptive::edge_param`'s way).
    pub info: u32,
}

/// `ReparamRow` of `adaptive.glsl`: one corner block `c0..c4` of Eq. 3 (padded to two `vec4`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ReparamRow {
    pub c: [f32; 8],
}

const _: () = {
    assert!(ADAPTIVE_FVAR_MAX_DEPTH == FVAR_MAX_DEPTH);
    assert!(size_of::<PatchRecord>() == 48);
    assert!(size_of::<PatchSurface>() == 48);
    assert!(size_of::<CurveOwner>() == 8);
    assert!(size_of::<ReparamRow>() == 32);
};

/// The GPU's reparameterization table (`topology::patches::texcoord::reparam_rows`).
pub fn reparam_rows() -> Vec<ReparamRow> {
    topology::patches::texcoord::reparam_rows()
        .iter()
        .map(|r| {
            let mut c = [0.0f32; 8];
            for (o, &x) in c.iter_mut().zip(r) {
                *o = x as f32;
            }
            ReparamRow { c }
        })
        .collect()
}

/// The face-varying patches as the one `uint` array `glsl/adaptive/fvar.glsl` reads: a
/// header (the first word of the nodes, of the leaves and of the points, then 0), the tree
/// nodes (four entries each), the leaves (`1` for a Gregory triangle else `0`, first point)
/// and the points (two `f32` bit patterns each). Without patches, the header alone (nothing
/// reads it: every patch's root is `ADAPTIVE_FVAR_NONE`).
pub fn fvar_words(fvar: Option<&FVarPatches>) -> Vec<u32> {
    let Some(f) = fvar else {
        return vec![4, 4, 4, 0];
    };
    let node_base = 4usize;
    let leaf_base = node_base + 4 * f.nodes.len();
    let point_base = leaf_base + 2 * f.patches.len();
    let mut out = Vec::with_capacity(point_base + 2 * f.points.len());
    out.extend([node_base as u32, leaf_base as u32, point_base as u32, 0]);
    out.extend(f.nodes.iter().flatten());
    for p in &f.patches {
        out.extend([u32::from(p.is_triangle()), p.first_point]);
    }
    for p in &f.points {
        out.extend([(p[0] as f32).to_bits(), (p[1] as f32).to_bits()]);
    }
    out
}

/// Why a plan cannot go to the GPU.
#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    #[error("adaptive plan: {what} {index} is out of range of {len}")]
    Index {
        what: &'static str,
        index: u64,
        len: u64,
    },
    #[error("adaptive plan: stencil row of vertex {vertex} reads vertex {reads}, which its own block (from {block_start}) writes")]
    BlockOrder {
        vertex: u32,
        reads: u32,
        block_start: u32,
    },
    #[error("adaptive plan: {what} ({value}) does not fit the GPU layout")]
    TooLarge { what: &'static str, value: u64 },
    #[error("adaptive plan: {0}")]
    Stencil(#[from] StencilError),
}

/// The GPU kind of a patch.
pub fn kind_code(kind: PatchKind) -> u32 {
    match kind {
        PatchKind::Regular => ADAPTIVE_KIND_REGULAR,
        PatchKind::Gregory => ADAPTIVE_KIND_GREGORY,
        PatchKind::Bilinear => ADAPTIVE_KIND_BILINEAR,
        PatchKind::GregoryTriangle => ADAPTIVE_KIND_GREGORY_TRIANGLE,
    }
}

/// Control points of a patch kind.
pub fn control_point_count(kind: PatchKind) -> usize {
    match kind {
        PatchKind::Regular => 16,
        PatchKind::Gregory => 20,
        PatchKind::Bilinear => 4,
        // 15 Gregory points, then per edge the inner points of its two level-1 halves (which
        // the patch owns on a boundary or next to another triangle).
        PatchKind::GregoryTriangle => 27,
    }
}

/// Everything the adaptive buffers hold, packed.
pub struct GpuPlan {
    pub num_base_vertices: u32,
    pub num_vertices: u32,
    /// One row per refined vertex up to the regular corners (row `r`: global vertex
    /// `num_base_vertices + r`), over global vertices.
    pub stencils: GpuStencils,
    /// One per non-empty block: the levels in order, then the local points.
    pub blocks: Vec<StencilBlock>,
    /// Records in array order (see [`GpuPlan::order`]).
    pub patches: Vec<PatchRecord>,
    pub control_points: Vec<u32>,
    pub curves: Vec<[u32; 4]>,
    /// Frame-wide patch id → index in the plan's patches.
    pub order: Vec<u32>,
    /// Patches per kind: regular, Gregory, bilinear.
    pub counts: [u32; 4],
    /// Per curve, its owner patch (frame-wide id).
    pub curve_owners: Vec<CurveOwner>,
    /// Global id of the first canonical corner.
    pub first_corner: u32,
    /// Global id of curve 0's first inner point (two per curve follow, after the blocks and
    /// the regular corners).
    pub first_curve_point: u32,
    /// Global id of the first canonical corner the kernel evaluates from its owner's points
    /// (up to `first_curve_point`).
    pub first_regular_corner: u32,
    /// Per canonical corner: `[frame-wide patch id, corner]` of its owner.
    pub corner_owners: Vec<[u32; 2]>,
}

fn check(what: &'static str, index: u64, len: u64) -> Result<(), LayoutError> {
    if index < len {
        Ok(())
    } else {
        Err(LayoutError::Index { what, index, len })
    }
}

fn edge_code(kind: EdgeKind) -> u32 {
    match kind {
        EdgeKind::Plain => ADAPTIVE_EDGE_PLAIN,
        EdgeKind::Coarse => ADAPTIVE_EDGE_COARSE,
        EdgeKind::Fine => ADAPTIVE_EDGE_FINE,
    }
}

/// The plan's levels and local points as one stencil table and its blocks, which must tile
/// the refined part of the vertex buffer in order and read only earlier vertices; returns the
/// first vertex after them.
fn stencil_blocks(
    plan: &AdaptivePlan,
) -> Result<(GpuStencils, Vec<StencilBlock>, u32), LayoutError> {
    let nb = plan.num_base_vertices;
    let mut stencils = GpuStencils::default();
    let mut blocks = Vec::new();
    let mut next = nb;
    for block in plan.steps.iter().chain(std::iter::once(&plan.local_points)) {
        if block.first_vertex != next {
            return Err(LayoutError::Index {
                what: "stencil block start",
                index: block.first_vertex as u64,
                len: next as u64,
            });
        }
        let t = &block.table;
        let rows = t.len() as u32;
        for r in 0..t.len() {
            let (idx, w) = t.stencil(r);
            if let Some(&i) = idx.iter().find(|&&i| i >= block.first_vertex) {
                return Err(LayoutError::BlockOrder {
                    vertex: block.first_vertex + r as u32,
                    reads: i,
                    block_start: block.first_vertex,
                });
            }
            stencils.push_row(idx, w)?;
        }
        if rows > 0 {
            let first = block.first_vertex - nb;
            blocks.push(StencilBlock {
                rows: first..first + rows,
                destination: block.first_vertex,
            });
        }
        next = block.first_vertex + rows;
    }
    Ok((stencils, blocks, next))
}

/// After the blocks (ending at `next`) come the canonical corners of regular patches (computed
/// from their owner's 3×3 points), then the curves' inner points, two per curve in curve order:
/// the kernel writes point `i` to `curves[i / 2][1 + i % 2]`, so those must be exactly that run
/// of the buffer (no two curves write one vertex, nothing else is overwritten), ending the
/// buffer. Returns the number of regular corners.
fn check_point_runs(plan: &AdaptivePlan, next: u32) -> Result<u32, LayoutError> {
    if next != plan.first_regular_corner || plan.first_regular_corner < plan.first_corner {
        return Err(LayoutError::Index {
            what: "first regular corner",
            index: plan.first_regular_corner as u64,
            len: next as u64,
        });
    }
    let regular_corners = plan
        .first_curve_point
        .checked_sub(plan.first_regular_corner)
        .ok_or(LayoutError::Index {
            what: "first curve point",
            index: plan.first_curve_point as u64,
            len: plan.first_regular_corner as u64,
        })?;
    let next = plan.first_curve_point;
    for (c, curve) in plan.curves.iter().enumerate() {
        let first = next as u64 + 2 * c as u64;
        if curve[1] as u64 != first || curve[2] as u64 != first + 1 {
            return Err(LayoutError::Index {
                what: "curve inner point",
                index: curve[1] as u64,
                len: first,
            });
        }
    }
    let end = next as u64 + 2 * plan.curves.len() as u64;
    if end != plan.num_vertices as u64 {
        return Err(LayoutError::Index {
            what: "vertex count",
            index: end,
            len: plan.num_vertices as u64,
        });
    }
    for c in &plan.curves {
        for &v in c {
            check("curve point", v as u64, plan.num_vertices as u64)?;
        }
    }
    Ok(regular_corners)
}

/// Patch records, their control points, and the patches per kind.
type PatchRecords = (Vec<PatchRecord>, Vec<u32>, [u32; 4]);

/// The patch records and control points in array `order`, and the patches per kind.
fn patch_records(plan: &AdaptivePlan, order: &[u32]) -> Result<PatchRecords, LayoutError> {
    let mut counts = [0u32; 4];
    let mut patches = Vec::with_capacity(order.len());
    let mut control_points = Vec::new();
    for &pi in order {
        let p = &plan.patches[pi as usize];
        counts[kind_code(p.kind) as usize] += 1;
        let cp_offset = control_points.len() as u32;
        push_control_points(plan, p, &mut control_points)?;
        patches.push(patch_record(p, cp_offset, plan.curves.len() as u64)?);
    }
    Ok((patches, control_points, counts))
}

/// Appends `p`'s control points, checked: as many as its kind has (ACC-1 patches carry 8
/// limit-tangent points past their 20), each before the curve points, which the kernel computes
/// from them in one dispatch (a control point among them would be read while written).
fn push_control_points(
    plan: &AdaptivePlan,
    p: &AdaptivePatch,
    out: &mut Vec<u32>,
) -> Result<(), LayoutError> {
    let tangents = p.kind == PatchKind::Gregory && p.tangent_valences != [0; 4];
    let need = control_point_count(p.kind) + if tangents { 8 } else { 0 };
    if p.control_points.len() != need {
        return Err(LayoutError::Index {
            what: "control points of a patch",
            index: p.control_points.len() as u64,
            len: need as u64,
        });
    }
    for &c in &p.control_points {
        check("control point", c as u64, plan.first_curve_point as u64)?;
        out.push(c);
    }
    Ok(())
}

/// `p`'s record: kind, level, boundary and transition masks, and per edge its kind, the
/// direction of its curves and the curves (a triangle's fourth edge is zeros).
fn patch_record(
    p: &AdaptivePatch,
    cp_offset: u32,
    ncurves: u64,
) -> Result<PatchRecord, LayoutError> {
    let mut edge_info = 0u32;
    let mut curves = [0u32; 8];
    for (e, edge) in p.edges.iter().enumerate().take(p.corners()) {
        let bits =
            edge_code(edge.kind) | (edge.reversed[0] as u32) << 2 | (edge.reversed[1] as u32) << 3;
        edge_info |= bits << (4 * e);
        for h in 0..2 {
            check("curve", edge.curves[h] as u64, ncurves)?;
            curves[2 * e + h] = edge.curves[h];
        }
    }
    if p.level > 15 {
        return Err(LayoutError::TooLarge {
            what: "patch level",
            value: p.level as u64,
        });
    }
    Ok(PatchRecord {
        cp_offset,
        info: kind_code(p.kind)
            | (p.level as u32) << 4
            | ((p.boundary_mask & 15) as u32) << 8
            | ((p.transition_mask & 15) as u32) << 12,
        edge_info,
        pad: 0,
        curves,
    })
}

/// Per curve, its owner patch by frame-wide id (`frame_id`) and the owner's edge, part and
/// direction. The curve kernel reads the owner's control points of that edge: an edge past the
/// owner's corners (a triangle's fourth) would read past its points.
fn curve_owners(plan: &AdaptivePlan, frame_id: &[u32]) -> Result<Vec<CurveOwner>, LayoutError> {
    if plan.curve_owners.len() != plan.curves.len() {
        return Err(LayoutError::Index {
            what: "curve owners",
            index: plan.curve_owners.len() as u64,
            len: plan.curves.len() as u64,
        });
    }
    let patches = frame_id.len() as u64;
    let mut owners = Vec::with_capacity(plan.curve_owners.len());
    for o in &plan.curve_owners {
        check("curve owner", o.patch as u64, patches)?;
        let owner = &plan.patches[o.patch as usize];
        check("curve owner edge", o.edge as u64, owner.corners() as u64)?;
        check("curve owner part", o.part as u64, 3)?;
        if o.triangle != (owner.kind == PatchKind::GregoryTriangle) {
            return Err(LayoutError::Index {
                what: "curve owner kind",
                index: o.patch as u64,
                len: patches,
            });
        }
        owners.push(CurveOwner {
            patch: frame_id[o.patch as usize],
            info: o.edge as u32
                | (o.part as u32) << 2
                | (o.forward as u32) << 4
                | (o.triangle as u32) << 5,
        });
    }
    Ok(owners)
}

/// Per canonical corner, `[frame-wide owner patch, corner]` (corner 4 + e of a triangle patch:
/// the midpoint of its edge e). The canonical corners are one run up to the curve points: rows,
/// then the `regular_corners` the kernel evaluates from the 3×3 points around corner `c` of
/// their owner, a regular patch whose points (phantoms included) all come earlier. The TES
/// reads `corner_owners[end - first_corner]` at every curve end.
fn corner_owners(
    plan: &AdaptivePlan,
    frame_id: &[u32],
    regular_corners: u32,
) -> Result<Vec<[u32; 2]>, LayoutError> {
    let mut owners = Vec::with_capacity(plan.corner_owners.len());
    for &[pi, c] in &plan.corner_owners {
        check("corner owner", pi as u64, frame_id.len() as u64)?;
        check("corner owner corner", c as u64, 8)?;
        owners.push([frame_id[pi as usize], c]);
    }
    let first_regular = (plan.first_regular_corner - plan.first_corner) as usize;
    if first_regular as u64 + regular_corners as u64 != plan.corner_owners.len() as u64 {
        return Err(LayoutError::Index {
            what: "regular corner owners",
            index: plan.first_curve_point as u64,
            len: plan.first_corner as u64 + plan.corner_owners.len() as u64,
        });
    }
    for &[pi, c] in &plan.corner_owners[first_regular..] {
        let owner = &plan.patches[pi as usize];
        if owner.kind != PatchKind::Regular || c >= 4 {
            return Err(LayoutError::Index {
                what: "regular corner owner",
                index: pi as u64,
                len: plan.patches.len() as u64,
            });
        }
        for &cp in &owner.control_points {
            check(
                "regular corner point",
                cp as u64,
                plan.first_regular_corner as u64,
            )?;
        }
    }
    for c in &plan.curves {
        for v in [c[0], c[3]] {
            check(
                "curve end (canonical corner)",
                (v as u64).wrapping_sub(plan.first_corner as u64),
                owners.len() as u64,
            )?;
        }
    }
    check(
        "last canonical corner",
        plan.first_corner as u64 + owners.len() as u64,
        plan.num_vertices as u64 + 1,
    )?;
    Ok(owners)
}

impl GpuPlan {
    /// The curves' inner points, which the stencil kernel's last dispatches compute.
    pub fn curve_points(&self) -> u32 {
        2 * self.curves.len() as u32
    }

    /// The canonical corners the kernel evaluates from their owners' points (after the blocks).
    pub fn regular_corners(&self) -> u32 {
        self.first_curve_point - self.first_regular_corner
    }

    /// Lays `plan` out for the GPU, in the order the module doc names: the stencil blocks,
    /// the runs of canonical points after them, the patch records in array order, then the
    /// curve and corner owners, each checked so the GPU never indexes out of bounds.
    pub fn new(plan: &AdaptivePlan) -> Result<GpuPlan, LayoutError> {
        let (stencils, blocks, next) = stencil_blocks(plan)?;
        let regular_corners = check_point_runs(plan, next)?;
        let mut order: Vec<u32> = (0..plan.patches.len() as u32).collect();
        order.sort_by_key(|&i| kind_code(plan.patches[i as usize].kind));
        let (patches, control_points, counts) = patch_records(plan, &order)?;
        let mut frame_id = vec![0u32; order.len()];
        for (id, &pi) in order.iter().enumerate() {
            frame_id[pi as usize] = id as u32;
        }
        let curve_owners = curve_owners(plan, &frame_id)?;
        let corner_owners = corner_owners(plan, &frame_id, regular_corners)?;
        Ok(GpuPlan {
            first_curve_point: plan.first_curve_point,
            first_regular_corner: plan.first_regular_corner,
            curve_owners,
            first_corner: plan.first_corner,
            corner_owners,
            num_base_vertices: plan.num_base_vertices,
            num_vertices: plan.num_vertices,
            stencils,
            blocks,
            patches,
            control_points,
            curves: plan.curves.clone(),
            order,
            counts,
        })
    }

    /// Per frame-wide patch: texture coordinates at its corners and its reparameterization
    /// rows (`topology::patches::texcoord`); with face-varying patches `fvar` (made for this
    /// plan), its (sub-)face parameter and its root among them instead.
    pub fn surfaces(
        &self,
        plan: &AdaptivePlan,
        mesh: &ControlMesh,
        fvar: Option<&FVarPatches>,
    ) -> Vec<PatchSurface> {
        let f32x2 = |p: [f64; 2]| [p[0] as f32, p[1] as f32];
        let domain = |p: &AdaptivePatch| {
            if p.corners() == 3 {
                // Barycentric (u, v) stands in; (1, 1) completes the parallelogram.
                return [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
            }
            let [u0, v0] = p.origin;
            let h = p.size;
            [[u0, v0], [u0 + h, v0], [u0 + h, v0 + h], [u0, v0 + h]]
        };
        self.order
            .iter()
            .map(|&pi| {
                let p = &plan.patches[pi as usize];
                let root = fvar.map_or(FVAR_EMPTY, |f| f.root_of(p));
                let (uv, fvar_root) = if root != FVAR_EMPTY {
                    (domain(p), root)
                } else {
                    let uv = topology::patches::texcoord::patch_corners(mesh, p)
                        .unwrap_or_else(|| domain(p));
                    (uv, FVAR_EMPTY)
                };
                let mut rows = 0u32;
                for (i, &v) in p.reparam_valences.iter().enumerate() {
                    rows |= topology::patches::texcoord::reparam_row(v) << (8 * i);
                }
                // Tangent patches read 8 points past the 20 (checked in `new`).
                let mut tangent_valences = 0u32;
                if p.control_points.len() == 28 {
                    for (i, &v) in p.tangent_valences.iter().enumerate() {
                        tangent_valences |= (v as u32) << (8 * i);
                    }
                }
                PatchSurface {
                    uv: uv.map(f32x2),
                    reparam_rows: rows,
                    tangent_valences,
                    fvar_root,
                    pad: 0,
                }
            })
            .collect()
    }

    /// The Eq. 1 error lattice (`--show param-error`) in array order: per record, the
    /// identity's lattice then the reparameterized one.
    pub fn param_errors(
        &self,
        lattice: &topology::patches::texcoord::ParamErrorLattice,
    ) -> Vec<f32> {
        let mut out = Vec::with_capacity(lattice.errors.len());
        for &pi in &self.order {
            out.extend_from_slice(lattice.patch(pi as usize, false));
            out.extend_from_slice(lattice.patch(pi as usize, true));
        }
        out
    }

    /// Bytes of tables on the GPU (stencils, patch records, control points, curves), without
    /// the vertex buffer.
    pub fn table_bytes(&self) -> usize {
        self.stencils.bytes() as usize
            + self.patches.len() * size_of::<PatchRecord>()
            + self.control_points.len() * 4
            + self.curves.len() * (16 + size_of::<CurveOwner>())
            + self.corner_owners.len() * 8
            + self.patches.len() * size_of::<PatchSurface>()
    }

    /// Bytes of the global vertex buffer.
    pub fn vertex_bytes(&self) -> u64 {
        self.num_vertices.max(1) as u64 * size_of::<StencilVertex>() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use topology::patches::fvar::FVAR_LEAF;

    /// `glsl/adaptive/fvar.glsl` writes the tree's leaf and empty entries in hex (a `#define`
    /// cannot carry the high bit): they are `topology`'s.
    #[test]
    fn fvar_glsl_entries_are_topologys() {
        let glsl = include_str!("../../../../../glsl/adaptive/fvar.glsl");
        for line in [
            format!("const uint FVAR_LEAF = {FVAR_LEAF:#x}u;"),
            format!("const uint FVAR_EMPTY = {FVAR_EMPTY:#x}u;"),
        ] {
            assert!(glsl.contains(&line), "fvar.glsl lacks '{line}'");
        }
    }

    /// Without face-varying patches the array is its header; with them, every section
    /// starts where the header says and holds what the patches hold.
    #[test]
    fn fvar_words_follow_the_header() {
        assert_eq!(fvar_words(None), vec![4, 4, 4, 0]);
        let f = FVarPatches {
            nodes: vec![[FVAR_LEAF, FVAR_EMPTY, FVAR_LEAF | 1, FVAR_EMPTY]],
            roots: vec![0],
            root_offsets: vec![0, 1],
            patches: vec![
                topology::patches::fvar::FVarPatch {
                    kind: PatchKind::Regular,
                    first_point: 0,
                },
                topology::patches::fvar::FVarPatch {
                    kind: PatchKind::GregoryTriangle,
                    first_point: 20,
                },
            ],
            points: (0..35).map(|k| [k as f64, 0.5]).collect(),
        };
        let w = fvar_words(Some(&f));
        let [nodes, leaves, points] = [w[0], w[1], w[2]].map(|x| x as usize);
        assert_eq!(&w[nodes..nodes + 4], &f.nodes[0]);
        assert_eq!(&w[leaves..leaves + 4], &[0, 0, 1, 20]);
        assert_eq!(w.len(), points + 70);
        assert_eq!(f32::from_bits(w[points + 2 * 34]), 34.0);
        assert_eq!(f32::from_bits(w[points + 2 * 34 + 1]), 0.5);
    }
}
