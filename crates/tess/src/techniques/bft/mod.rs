//! Loop limit surfaces on the tessellation stage through basis-function tables (Holländer &
//! Boubekeur, the paper's Fig. 2):
//!
//! 1. **Initial GPU subdivision step** (the pre-pass, every frame): level-1 positions as
//!    stencils over the base positions (the stencil evaluator, [`crate::stencil`], reading the
//!    frame slot's base positions and writing the level-1 positions), then level-1 limit
//!    normals from the limit tangent masks (`glsl/bft/normals.comp`). An animated base mesh
//!    costs one upload of its positions per frame; stencils, patch records and tables never
//!    change.
//! 2. **Main pass**: one patch (one control point carrying the face index) per level-1 face.
//!    `bft.tesc` sets power-of-two (or fractional) edge factors from each edge's two endpoints
//!    only; `bft.tese` evaluates the table row of each tess coordinate (see
//!    `glsl/bft/bft.glsl`, mirrored in f32 by [`layout::GpuBft::eval_tess`]).
//!
//! **Cost on a CPU driver** (lavapipe runs the TES on the CPU, eight vertices a SIMD
//! batch, and executes both sides of every branch, masked): a storage-buffer read indexed by
//! the patch is a per-lane loop there, a patch input one load for the whole patch. So the TCS
//! gathers the patch's header words, mirror permutation and ring (level-1 positions and
//! normals, rings up to 18 slots) into a patch block once, and the TES sums each row from it;
//! only points on an edge or corner owned by another face (and rings past 18 slots) read the
//! global buffers, with the same products in the same order, so shared points keep their bits.
//! The equal-spacing TES variant (power-of-two factors: every point is a table point) compiles
//! out the fractional path's virtual-mesh interpolation, whose three rows it would otherwise
//! run masked for every vertex.
//!
//! The GPU data (named structs for every buffer, bindings, packing, validation, and the f32
//! mirror of the TES) is [`layout`].
//!
//! Polygons are fan-triangulated first (Loop needs triangles); captured points map back into
//! the input's polygons, so callers never see the triangulation.
//!
//! **Buffers beyond `maxStorageBufferRange`** (a 1M-triangle mesh has 4M level-1 faces: 160 MB
//! of patch headers, 190 MB of rings, more than lavapipe's 128 MiB): the stencil evaluator
//! windows its own buffers, the normals pass runs in chunks of level-1 vertices and the draw
//! in chunks of patches, each with its own descriptor set of windows into the shared buffers
//! and its bases in the push constants ([`super::windows`]). A patch's footprint includes its edge and corner owners' headers,
//! rings and ring vertices, since the TES evaluates shared points in the owner's frame. A mesh
//! that fits is one chunk with bases 0: the same draw as before. The basis-function tables
//! (header and entries, mirror permutations, row maps, weights) are not windowed: a shared
//! table serves patches anywhere in the mesh, so every chunk may read any of them. The shaders
//! read them by device address (`GL_EXT_buffer_reference`, the addresses in the uniform block
//! [`BftTableArrays`]), so no range limits them either; tables are refused only past what
//! their 32-bit weight offsets address. A device without `bufferDeviceAddress` (a host's) is
//! refused by name.
use crate::capture::{face_corner_uv, FacePoint};
use crate::context::Context;
use crate::error::{Param, ParamError, Result, TablesTooLarge, TessError};
pub mod layout;
mod patterns;

use super::host_view::HostView;
use super::shared::{
    check_adaptive_policy, compute_pipeline, factor_fields, storage, storage_binding, upload_base,
    STAGES,
};
use super::windows::{self, Chunk, Limits, Member, Space};
use crate::animation::base_positions;
use crate::bench::usage::Laps;
use crate::gpu::bindings::{
    BFT_LEVEL1_NORMALS_BINDING, BFT_LEVEL1_POSITIONS_BINDING, BFT_LOCAL_SIZE,
    BFT_OPTION_FRACTIONAL, BFT_OPTION_GEOMETRIC_NORMALS, BFT_OPTION_PATCH_COLOURS,
    BFT_PATCH_HEADERS_BINDING, BFT_PATCH_RINGS_BINDING, BFT_TABLE_ARRAYS_BINDING,
    BFT_TANGENT_OFFSETS_BINDING, BFT_TANGENT_TERMS_BINDING,
};
use crate::gpu::{BftPush, BftTableArrays};
use crate::shaders::{Stage, Variant};
use crate::stencil::{self, GpuStencils, StencilBlock, StencilEvaluator, StencilVertices};
use crate::technique::{
    for_each_draw, number_arrays, DeviceAllocation, DrawCounts, DrawPath, FactorPolicy, Features,
    FrameParams, Pass, PatchArray, PatchPipeline, PatchType, PipelineChoice, Technique,
    TechniqueId,
};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};
use crate::tessellator::{uniform_triangle_count, uniform_vertex_count, Domain, Spacing};
use layout::{PackedTables, PatchHeader, TangentTerm, STORAGE_BINDINGS};
use patterns::{BftPatterns, Piece};
use std::ops::Range;
use topology::patches::bft::{
    build_patch_records, face_rotations, level1_base_domain, loop_level1, loop_tables,
    loop_tangent_stencils, table_weight_count,
};
use topology::ControlMesh;
use vk_core::descriptor::{BindingDesc, DescriptorPool};
use vk_core::pipeline::Pipeline;
use vk_core::{vk, Buffer, BufferDesc, DescriptorSet, Encoder, MemoryLocation};

impl TechniqueId {
    pub const BFT: TechniqueId = TechniqueId::new("bft");
}

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::BFT,
    help: "exact Loop limit surface from basis-function tables (Holländer & Boubekeur)",
    features: Features {
        adaptive_factors: true,
        spacings: [true, true, false],
        animation: true,
        patch_colours: true,
        geometric_normals: true,
        phong_alpha: false,
        table_level: true,
        triangles_only: true,
        isolation: false,
        surface: false,
        single_pass: false,
        sine_displacement: true,
        paths: &[DrawPath::Tessellation, DrawPath::Pattern],
    },
    scheme: Some(topology::Scheme::Loop),
    default_for_scheme: true,
    shader_folder: "bft",
    abi_code: 4,
    legend: &[
        ([0.55, 0.75, 0.95], "regular"),
        ([0.95, 0.45, 0.35], "extraordinary"),
        ([0.55, 0.85, 0.45], "boundary"),
        ([0.75, 0.5, 0.9], "private table"),
    ],
    build: build_registered,
    check_options: |build, params| check_frame(build.table_level, params),
};

/// The registry's constructor: [`Bft::new`] with the build options BFT takes.
fn build_registered(
    ctx: &mut Context,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    let b = Bft::new(
        ctx,
        mesh,
        &BftOptions {
            table_level: options.table_level,
            tangents: options.tangents,
            name: options.name.clone(),
            patch_block: None,
            pipeline: options.pipeline,
        },
    )?;
    let notes = b.notes.clone();
    Ok(Built {
        technique: Box::new(b),
        notes,
    })
}

/// Default maximum table level: 32 segments per level-1 edge, 64 per base edge.
pub const DEFAULT_TABLE_LEVEL: u32 = 5;

/// Set 1 of every BFT pipeline: the storage buffers of [`STORAGE_BINDINGS`] (windowed), then
/// the uniform block of the tables' addresses.
static SET_BINDINGS: [BindingDesc; STORAGE_BINDINGS.len() + 1] = {
    let mut out = [storage_binding(0); STORAGE_BINDINGS.len() + 1];
    let mut i = 0;
    while i < STORAGE_BINDINGS.len() {
        out[i] = storage_binding(STORAGE_BINDINGS[i]);
        i += 1;
    }
    out[i] = BindingDesc {
        binding: BFT_TABLE_ARRAYS_BINDING,
        ty: vk::DescriptorType::UNIFORM_BUFFER,
        stages: STAGES,
    };
    out
};

/// The most bytes of table weights: what the entries' 32-bit word offsets address.
const MAX_TABLE_BYTES: u64 = 4 * u32::MAX as u64;

const fn member(stride: usize, extra: u32) -> Member {
    Member {
        stride: stride as u64,
        extra,
    }
}
/// Level-1 positions and normals (`vec4`) and the tangent CSR offsets (one past).
const LEVEL1_MEMBERS: [Member; 2] = [member(16, 0), member(4, 1)];
const LEVEL1: Space = Space {
    name: "level-1 vertex",
    members: &LEVEL1_MEMBERS,
};
const TANGENT: Space = Space {
    name: "tangent term",
    members: &[member(std::mem::size_of::<TangentTerm>(), 0)],
};
const PATCHES: Space = Space {
    name: "patch header",
    members: &[member(std::mem::size_of::<PatchHeader>(), 0)],
};
const RINGS: Space = Space {
    name: "patch ring",
    members: &[member(4, 0)],
};

/// A chunk's window in every space (empty: the chunk's shaders never index that buffer).
#[derive(Clone, Debug, Default)]
struct SetWindows {
    level1: Range<u32>,
    tangent: Range<u32>,
    patches: Range<u32>,
    rings: Range<u32>,
}

impl SetWindows {
    /// The push constants' bases.
    fn apply(&self, push: &mut BftPush) {
        push.level1_base = self.level1.start;
        push.tangent_base = self.tangent.start;
        push.patch_base = self.patches.start;
        push.ring_base = self.rings.start;
    }
}

/// Hull of a non-empty index set.
fn span(indices: impl IntoIterator<Item = u32>) -> Range<u32> {
    let mut it = indices.into_iter();
    let Some(first) = it.next() else { return 0..0 };
    let (lo, hi) = it.fold((first, first), |(lo, hi), x| (lo.min(x), hi.max(x)));
    lo..hi + 1
}

/// Chunks of level-1 vertices for the normals pass: each reads its tangent rows and their
/// level-1 vertices; at most `max_items` per dispatch.
fn plan_normals(
    tangent_offsets: &[u32],
    tangent_terms: &[TangentTerm],
    level1_vertices: u32,
    limits: Limits,
    max_items: u32,
) -> Result<Vec<(Range<u32>, SetWindows)>> {
    let chunks = windows::plan(
        "level-1 vertex",
        level1_vertices,
        &[LEVEL1, TANGENT],
        limits,
        |v| {
            let i = v as usize;
            let (t0, t1) = (tangent_offsets[i], tangent_offsets[i + 1]);
            let tangent = &tangent_terms[t0 as usize..t1 as usize];
            [
                span(std::iter::once(v).chain(tangent.iter().map(|t| t.index))),
                t0..t1,
            ]
        },
    )?;
    let mut out = Vec::new();
    for Chunk { items, windows } in chunks {
        let [level1, tangent] = windows;
        let w = SetWindows {
            level1,
            tangent,
            ..Default::default()
        };
        let mut first = items.start;
        while first < items.end {
            let end = items.end.min(first.saturating_add(max_items.max(1)));
            out.push((first..end, w.clone()));
            first = end;
        }
    }
    Ok(out)
}

/// Chunks of patches for the draw: each reads its header, ring and ring vertices, and those of
/// its edge and corner owners (shared points are evaluated in the owner's frame).
fn plan_draw(
    patches: &[PatchHeader],
    patch_rings: &[u32],
    limits: Limits,
) -> Result<Vec<(Range<u32>, SetWindows)>> {
    let chunks = windows::plan(
        "patch",
        patches.len() as u32,
        &[PATCHES, RINGS, LEVEL1],
        limits,
        |p| {
            let h = &patches[p as usize];
            let faces = std::iter::once(p).chain(
                h.edge_owner
                    .iter()
                    .chain(&h.corner_owner)
                    .map(|&o| layout::owner_face(o)),
            );
            let (mut rings, mut verts) = (0..0, 0..0);
            let mut lo_f = p;
            let mut hi_f = p;
            for f in faces {
                lo_f = lo_f.min(f);
                hi_f = hi_f.max(f);
                let o = &patches[f as usize];
                let r = o.ring_offset..o.ring_offset + o.ring_size;
                let v = span(
                    patch_rings[r.start as usize..r.end as usize]
                        .iter()
                        .copied(),
                );
                rings = if rings.is_empty() {
                    r
                } else {
                    rings.start.min(r.start)..rings.end.max(r.end)
                };
                verts = if verts.is_empty() {
                    v
                } else {
                    verts.start.min(v.start)..verts.end.max(v.end)
                };
            }
            [lo_f..hi_f + 1, rings, verts]
        },
    )?;
    Ok(chunks
        .into_iter()
        .map(|Chunk { items, windows }| {
            let [patches, rings, level1] = windows;
            (
                items,
                SetWindows {
                    level1,
                    patches,
                    rings,
                    ..Default::default()
                },
            )
        })
        .collect())
}

/// Refuses tables whose weights exceed `max_bytes` before evaluating any. The shaders read the
/// tables by device address (a shared table serves patches anywhere in the mesh, so they are
/// not windowed), so no storage-buffer range limits them: `max_bytes` is what the entries'
/// 32-bit word offsets address ([`MAX_TABLE_BYTES`]); device memory is the allocation's to
/// refuse. Counting takes milliseconds; evaluating the tables of a mesh with thousands of
/// private ones takes minutes. The error names the largest level that fits.
fn check_table_range(
    records: &topology::patches::bft::PatchRecords,
    level: u32,
    options: &BftOptions,
    max_bytes: u64,
) -> Result<()> {
    let bytes_at = |l: u32| 4 * table_weight_count(records, l, options.tangents);
    let bytes = bytes_at(level);
    if bytes <= max_bytes {
        return Ok(());
    }
    let fits = (1..level)
        .rev()
        .find(|&l| bytes_at(l) <= max_bytes)
        .map(|l| (l, bytes_at(l)));
    Err(TessError::BftTablesTooLarge(TablesTooLarge {
        name: options.name.clone(),
        level,
        bytes,
        private_faces: records
            .iter()
            .filter(|r| matches!(r.key.case, topology::patches::bft::BftCase::Private { .. }))
            .count(),
        faces: records.len(),
        max: max_bytes,
        fits,
    }))
}

/// `bit` when `on`.
fn flag(on: bool, bit: u32) -> u32 {
    if on {
        bit
    } else {
        0
    }
}

/// How a BFT surface is built (the per-frame choices are in [`FrameParams`]).
#[derive(Clone, Debug)]
pub struct BftOptions {
    /// Maximum table level `L`: segments per base edge up to `2^(L+1)`.
    pub table_level: u32,
    /// Build the `du`/`dv` tables, so geometric normals can be drawn.
    pub tangents: bool,
    /// Name for messages (the mesh's file).
    pub name: String,
    /// Gather each patch's ring into a per-patch block that the TES reads instead of the
    /// global buffers (the `patch_block` shader axis). `None`: by device, on for a CPU
    /// implementation (lavapipe), off for a GPU (docs/benchmarks.md, "Table I on an NVIDIA
    /// H100"); there the environment's `TESSERA_BFT_PATCH_BLOCK=1` or `=0` decides instead, for A/B runs.
    pub patch_block: Option<bool>,
    /// The draw path ([`resolve_path`]).
    pub pipeline: PipelineChoice,
}

impl Default for BftOptions {
    fn default() -> Self {
        Self {
            table_level: DEFAULT_TABLE_LEVEL,
            tangents: false,
            name: "mesh".into(),
            patch_block: None,
            pipeline: PipelineChoice::Auto,
        }
    }
}

/// BFT's draw path for `choice` on `device`: `auto` keeps the tessellation stage wherever the
/// device has one (the pattern path costs more there: docs/benchmarks.md) and draws patterns
/// only where it has none.
pub fn resolve_path(choice: PipelineChoice, device: &vk_core::Device) -> Result<DrawPath> {
    match choice {
        PipelineChoice::Auto if device.info.caps.tessellation_shader => Ok(DrawPath::Tessellation),
        choice => choice.resolve(TechniqueId::BFT, INFO.features.paths, device),
    }
}

/// [`BftOptions::patch_block`] left to the device: lavapipe runs the TES on the CPU, where a
/// storage read indexed by the patch is a per-lane gather and a patch input one load; a GPU
/// reads the global buffers through its caches and loses more to the block's 116 per-patch
/// components than it saves.
fn patch_block_for(device: &vk_core::Device) -> bool {
    match std::env::var("TESSERA_BFT_PATCH_BLOCK").as_deref() {
        Ok("1") => true,
        Ok("0") => false,
        _ => device.info.device_type == vk::PhysicalDeviceType::CPU,
    }
}

/// One base mesh on the GPU with everything the BFT pipeline reads. Drop order: pipelines,
/// sets (they keep their pool alive), pool, buffers.
pub struct Bft {
    /// Level-1 positions from the frame slot's base positions (one evaluator target per slot).
    evaluator: StencilEvaluator,
    normals: Pipeline,
    /// One set per normals chunk (the normals never read base positions: shared by every slot).
    normals_sets: Vec<DescriptorSet>,
    /// Level-1 vertices of each normals chunk, and its windows.
    normals_chunks: Vec<(Range<u32>, SetWindows)>,
    /// One set per draw chunk (the draw never reads base positions: shared by every slot).
    draw_sets: Vec<DescriptorSet>,
    /// Patches of each draw chunk, and its windows.
    draw_chunks: Vec<(Range<u32>, SetWindows)>,
    _pool: DescriptorPool,
    base: Vec<Buffer>,
    _static: Vec<Buffer>,
    arrays: Vec<PatchArray>,
    summary: BftSummary,
    /// Per level-1 face, which of its corners its record's `v0` is: all
    /// [`Bft::base_domain`] keeps of the level-1 mesh and records (freed once packed).
    rotations: Vec<u8>,
    /// Per Loop triangle: its input face, the face's side count and its fan index (corners
    /// 0, j + 1, j + 2); identity for a triangle mesh.
    fans: Vec<(u32, u32, u32)>,
    /// Runs of patches drawn: every level-1 face but the four children of a triangle tagged as
    /// a hole (those are still evaluated: their edges and corners may own shared points).
    drawn: Vec<Range<u32>>,
    /// The triangle mesh Loop subdivides (the input, or its fan triangulation): the positions
    /// [`Technique::update_base`] replaces.
    pub loop_mesh: ControlMesh,
    /// Base positions as last uploaded (the CPU reference).
    pub base_positions: Vec<[f32; 3]>,
    /// Bounds of the rest pose: an animated surface keeps its camera framing.
    rest_bbox: ([f32; 3], [f32; 3]),
    /// How the input was taken (fan triangulation), for the caller to show.
    pub notes: Vec<String>,
    /// The patch-block build ([`BftOptions::patch_block`]).
    patch_block: bool,
    /// On the refinement-pattern path: its instances, patterns and host-chosen levels
    /// ([`patterns`]); `None` on the tessellation path.
    patterns: Option<BftPatterns>,
}

/// Maximal runs of the `patches` level-1 faces whose base triangle is not among `holes` (a
/// triangle's four children are faces `4t..4t + 4`).
fn drawn_runs(patches: u32, holes: &[u32]) -> Vec<Range<u32>> {
    let mut hidden = vec![false; patches as usize];
    for &t in holes {
        for f in 4 * t as usize..(4 * t as usize + 4).min(hidden.len()) {
            hidden[f] = true;
        }
    }
    let mut runs: Vec<Range<u32>> = Vec::new();
    for (f, &h) in hidden.iter().enumerate() {
        let f = f as u32;
        match runs.last_mut() {
            _ if h => {}
            Some(r) if r.end == f => r.end = f + 1,
            _ => runs.push(f..f + 1),
        }
    }
    runs
}

/// The control mesh Loop subdivides: `mesh` itself when it is all triangles, else its fan
/// triangulation, with per triangle (input face, side count, fan index) and, when
/// triangulated, a note saying so.
fn loop_control_mesh(
    mesh: &ControlMesh,
    name: &str,
) -> (ControlMesh, Vec<(u32, u32, u32)>, Option<String>) {
    let polygons = mesh.faces().filter(|f| f.len() != 3).count();
    let (tri, origin) = if polygons == 0 {
        (mesh.clone(), (0..mesh.num_faces() as u32).collect())
    } else {
        mesh.triangulated()
    };
    let mut fans: Vec<(u32, u32, u32)> = Vec::with_capacity(origin.len());
    for &o in &origin {
        let j = match fans.last() {
            Some(&(prev, _, j)) if prev == o => j + 1,
            _ => 0,
        };
        fans.push((o, mesh.face(o as usize).len() as u32, j));
    }
    let note = (polygons > 0).then(|| {
        format!(
            "note: {name}: {polygons} of {} faces are not triangles; Loop subdivides their fan \
             triangulation ({} triangles)",
            mesh.num_faces(),
            tri.num_faces()
        )
    });
    (tri, fans, note)
}

/// What a [`Bft`] keeps of its packed data once uploaded: counts and byte sizes (the arrays
/// themselves live only on the GPU; tests build their CPU mirror with [`GpuBft::new`](layout::GpuBft::new)).
#[derive(Clone, Debug, PartialEq)]
pub struct BftSummary {
    pub base_vertices: u32,
    pub level1_vertices: u32,
    /// Level-1 faces: patches per frame.
    pub patch_count: u32,
    pub table: layout::TableHeader,
    /// The tables hold `du`/`dv` rows (geometric normals).
    pub tangents: bool,
    pub stencil_terms: u64,
    pub tangent_terms: u64,
    pub ring_slots: u64,
    /// Bytes on the GPU: base → level-1 stencils, tangent stencils, patch headers and rings,
    /// tables.
    pub stencil_bytes: u64,
    pub tangent_bytes: u64,
    pub patch_bytes: u64,
    pub table_bytes: u64,
}

fn bytes_of<T>(v: &[T]) -> u64 {
    std::mem::size_of_val(v) as u64
}

/// A topology error of the mesh `options` name.
fn mesh_error(options: &BftOptions, e: topology::limit::eval::EvalError) -> TessError {
    TessError::Mesh {
        name: options.name.clone(),
        source: e.into(),
    }
}

/// The normals pass's data: the level-1 limit-tangent stencils packed, validated and uploaded
/// (by binding), its chunks, and the terms' count and bytes.
struct NormalsStage {
    buffers: Vec<(u32, Buffer)>,
    chunks: Vec<(Range<u32>, SetWindows)>,
    terms: u64,
    bytes: u64,
}

impl NormalsStage {
    fn new(
        device: &vk_core::Device,
        stencils: topology::patches::bft::TangentStencils,
        level1_vertices: u32,
        limits: Limits,
    ) -> Result<Self> {
        let (offsets, terms) = layout::pack_tangents(stencils);
        layout::validate_tangents(&offsets, &terms, level1_vertices)?;
        let max_groups = device.info.caps.max_compute_work_group_count[0];
        let chunks = plan_normals(
            &offsets,
            &terms,
            level1_vertices,
            limits,
            max_groups.saturating_mul(BFT_LOCAL_SIZE),
        )?;
        let buffers = vec![
            (
                BFT_TANGENT_OFFSETS_BINDING,
                storage(
                    device,
                    "bft tangent offsets",
                    bytemuck::cast_slice(&offsets),
                )?,
            ),
            (
                BFT_TANGENT_TERMS_BINDING,
                storage(device, "bft tangent terms", bytemuck::cast_slice(&terms))?,
            ),
        ];
        Ok(Self {
            buffers,
            chunks,
            terms: terms.len() as u64,
            bytes: bytes_of(&offsets) + bytes_of(&terms),
        })
    }
}

/// The draw's data: patch records and tables built from the level-1 mesh, packed, validated
/// and uploaded (by binding), the draw chunks, each face's rotation, and the counts and bytes
/// of the summary.
struct PatchStage {
    buffers: Vec<(u32, Buffer)>,
    /// The tables' arrays, read at the addresses the [`BFT_TABLE_ARRAYS_BINDING`] block holds.
    tables: [Buffer; 4],
    draw_chunks: Vec<(Range<u32>, SetWindows)>,
    rotations: Vec<u8>,
    count: u32,
    ring_slots: u64,
    bytes: u64,
    table: layout::TableHeader,
    tangents: bool,
    table_bytes: u64,
    /// Each face's corners `v0, v1, v2` when kept (the pattern path's host levels).
    corners: Option<Vec<[u32; 3]>>,
}

impl PatchStage {
    /// Takes the level-1 mesh and frees it once the records and tables are built, and each
    /// product once uploaded; `laps` and `stages` time the records and tables.
    fn new(
        device: &vk_core::Device,
        level1: topology::limit::eval::LocalMesh,
        options: &BftOptions,
        limits: Limits,
        keep_corners: bool,
        laps: &mut Laps,
        stages: &mut Vec<String>,
    ) -> Result<Self> {
        let records = build_patch_records(&level1).map_err(|e| mesh_error(options, e))?;
        check_table_range(&records, options.table_level, options, MAX_TABLE_BYTES)?;
        let tables = loop_tables(&level1, &records, options.table_level, options.tangents)
            .map_err(|e| mesh_error(options, e))?;
        let rotations = face_rotations(&level1, &records);
        let level1_vertices = level1.num_vertices() as u32;
        drop(level1);
        stages.push(laps.lap("records and tables"));
        let packed = PackedTables::new(&tables);
        packed.validate()?;
        let (patches, rings) = layout::pack_patches(records, &tables)?;
        let tangents = tables.tangents;
        drop(tables);
        layout::validate_patches(&patches, &rings, &packed.entries, level1_vertices)?;
        let draw_chunks = plan_draw(&patches, &rings, limits)?;
        let corners = keep_corners.then(|| face_corners(&patches, &rings));
        let (count, ring_slots) = (patches.len() as u32, rings.len() as u64);
        let bytes = bytes_of(&patches) + bytes_of(&rings);
        let mut buffers = vec![(
            BFT_PATCH_HEADERS_BINDING,
            storage(device, "bft patch headers", bytemuck::cast_slice(&patches))?,
        )];
        drop(patches);
        buffers.push((
            BFT_PATCH_RINGS_BINDING,
            storage(device, "bft patch rings", bytemuck::cast_slice(&rings))?,
        ));
        drop(rings);
        let (addresses, tables) = table_buffers(device, &packed)?;
        buffers.push((BFT_TABLE_ARRAYS_BINDING, addresses));
        Ok(Self {
            buffers,
            tables,
            draw_chunks,
            rotations,
            count,
            ring_slots,
            bytes,
            table: packed.table,
            tangents,
            table_bytes: packed.bytes() as u64,
            corners,
        })
    }
}

/// Each face's corners `v0, v1, v2`: the first three slots of its ring.
fn face_corners(patches: &[PatchHeader], rings: &[u32]) -> Vec<[u32; 3]> {
    patches
        .iter()
        .map(|h| {
            let at = |k: u32| {
                rings
                    .get((h.ring_offset + k) as usize)
                    .copied()
                    .unwrap_or(0)
            };
            [at(0), at(1), at(2)]
        })
        .collect()
}

/// A set of the BFT layout: the windowed buffers of `statics` as `w`'s windows, and the
/// uniform block of the tables' addresses.
fn write_set(
    pool: &DescriptorPool,
    layout: &vk_core::descriptor::DescriptorSetLayout,
    statics: &[(u32, Buffer)],
    summary: &BftSummary,
    w: &SetWindows,
) -> Result<DescriptorSet> {
    let set = pool.allocate_set(layout)?;
    let n1 = summary.level1_vertices as u64;
    for (binding, buf) in statics {
        let (m, len, win) = match *binding {
            BFT_LEVEL1_POSITIONS_BINDING | BFT_LEVEL1_NORMALS_BINDING => {
                (LEVEL1_MEMBERS[0], n1, &w.level1)
            }
            BFT_TANGENT_OFFSETS_BINDING => (LEVEL1_MEMBERS[1], n1 + 1, &w.level1),
            BFT_TANGENT_TERMS_BINDING => (TANGENT.members[0], summary.tangent_terms, &w.tangent),
            BFT_PATCH_HEADERS_BINDING => {
                (PATCHES.members[0], summary.patch_count as u64, &w.patches)
            }
            BFT_PATCH_RINGS_BINDING => (RINGS.members[0], summary.ring_slots, &w.rings),
            // BFT_TABLE_ARRAYS_BINDING, the one binding not windowed: a uniform block.
            _ => {
                set.write_buffer(*binding, vk::DescriptorType::UNIFORM_BUFFER, buf)?;
                continue;
            }
        };
        windows::write_window(&set, *binding, buf, m, len, win)?;
    }
    Ok(set)
}

/// The initial subdivision step's GPU side: per frame slot a base-position buffer (the
/// evaluator's vertices), the level-1 positions, and the stencil evaluator from each slot's
/// base positions to the level-1 positions.
struct InitialStep {
    evaluator: StencilEvaluator,
    base: Vec<Buffer>,
    level1_positions: Buffer,
}

impl InitialStep {
    fn new(
        device: &vk_core::Device,
        stencils: &GpuStencils,
        base_positions: &[[f32; 3]],
        level1_vertices: u32,
        frames: usize,
    ) -> Result<Self> {
        let base_vertices = base_positions.len() as u32;
        let vertices = stencil::vertices(base_positions);
        let mut base = Vec::with_capacity(frames);
        for i in 0..frames {
            let mut buf = Buffer::new(
                device,
                &BufferDesc {
                    name: &format!("bft base positions {i}"),
                    size: stencil::vertex_bytes(base_vertices),
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?;
            buf.write(0, bytemuck::cast_slice(&vertices))?;
            base.push(buf);
        }
        let level1_positions = Buffer::new(
            device,
            &BufferDesc {
                name: "bft level-1 positions",
                size: stencil::vertex_bytes(level1_vertices),
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        let targets: Vec<(&Buffer, &Buffer)> =
            base.iter().map(|b| (b, &level1_positions)).collect();
        let evaluator = StencilEvaluator::new(
            device,
            "bft",
            stencils,
            &[StencilBlock {
                rows: 0..level1_vertices,
                destination: 0,
            }],
            StencilVertices {
                sources: base_vertices,
                destinations: level1_vertices,
                in_place: false,
            },
            &targets,
        )?;
        Ok(Self {
            evaluator,
            base,
            level1_positions,
        })
    }
}

/// The basis-function tables' arrays, read by address (header and entries, mirror
/// permutations, row maps, weights), and the uniform buffer of their addresses
/// ([`BftTableArrays`]).
fn table_buffers(device: &vk_core::Device, t: &PackedTables) -> Result<(Buffer, [Buffer; 4])> {
    let table_header = t.header_bytes();
    let arrays: [(&str, &[u8]); 4] = [
        ("bft tables", &table_header[..]),
        (
            "bft mirror permutations",
            bytemuck::cast_slice(&t.mirror_perms),
        ),
        ("bft row maps", bytemuck::cast_slice(&t.row_maps)),
        ("bft table weights", bytemuck::cast_slice(&t.weights)),
    ];
    // An empty array is padded (zero-length buffers are invalid); nothing indexes it.
    let pad = [0u8; 4];
    let [h, p, m, w] = arrays.map(|(name, bytes)| {
        let data = if bytes.is_empty() { &pad[..] } else { bytes };
        Buffer::with_data(
            device,
            name,
            vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            data,
        )
    });
    let tables = [h?, p?, m?, w?];
    let a = |b: &Buffer| b.device_address();
    let block = BftTableArrays {
        tables: a(&tables[0])?,
        perms: a(&tables[1])?,
        maps: a(&tables[2])?,
        weights: a(&tables[3])?,
    };
    let addresses = Buffer::with_data(
        device,
        "bft table addresses",
        vk::BufferUsageFlags::UNIFORM_BUFFER,
        bytemuck::bytes_of(&block),
    )?;
    Ok((addresses, tables))
}

impl Bft {
    /// Prepares `mesh` (fan-triangulated first when it has polygons; refined once on the CPU
    /// for the topology; stencils, patch records and the tables at `options.table_level`) and
    /// uploads it, with one base-position buffer per frame slot of `ctx`.
    ///
    /// **Stage by stage** (a 1M-triangle mesh's level-1 data is ~1.5 GB on the CPU): each
    /// product is packed into its GPU form, checked, uploaded and freed before the next is
    /// built, and the level-1 mesh is dropped once the records, tables and tangent stencils
    /// are taken from it. Every array is validated before it is uploaded, as
    /// [`GpuBft::validate`](layout::GpuBft::validate) does for the whole.
    pub fn new(ctx: &mut Context, mesh: &ControlMesh, options: &BftOptions) -> Result<Self> {
        let device = ctx.device().clone();
        if !device.info.caps.buffer_device_address {
            return Err(TessError::Unsupported {
                technique: TechniqueId::BFT,
                what: "a device without bufferDeviceAddress enabled (BFT reads its \
                       basis-function tables by address; a host device sets \
                       buffer_device_address)",
            });
        }
        let patch_block = options
            .patch_block
            .unwrap_or_else(|| patch_block_for(&device));
        let table_level = options.table_level;
        let path = resolve_path(options.pipeline, &device)?;
        // Patterns are not bound by the tessellator's level (generated up to 256).
        let max_level = match path {
            DrawPath::Pattern => crate::pattern::MAX_GENERATED_SEGMENTS,
            _ => device.info.caps.max_tessellation_generation_level,
        };
        if !(1..=6).contains(&table_level) || (1u32 << table_level) > max_level {
            return Err(ParamError::refused(
                Param::TableLevel,
                table_level,
                format!(
                    "tables must be at level 1..6 and need tessellation level 2^level (the \
                     device allows {max_level})"
                ),
            ));
        }
        let mut laps = Laps::new();
        let mut stages = Vec::new();
        let (loop_mesh, fans, note) = loop_control_mesh(mesh, &options.name);
        let limits = Limits::of(&device);
        // The level-1 mesh and the base → level-1 stencils, packed at once (f32 terms), handed
        // to the stencil evaluator and freed.
        let (level1, stencils) = loop_level1(&loop_mesh).map_err(|e| mesh_error(options, e))?;
        let base_vertices = loop_mesh.positions.len() as u32;
        let level1_vertices = level1.num_vertices() as u32;
        let stencils = GpuStencils::from_table(stencils);
        stencils
            .validate(level1_vertices, base_vertices)
            .map_err(layout::LayoutError::from)?;
        let base_positions = base_positions(&loop_mesh);
        let step = InitialStep::new(
            &device,
            &stencils,
            &base_positions,
            level1_vertices,
            ctx.frames_in_flight(),
        )?;
        let (stencil_count, stencil_bytes) = (stencils.terms.len() as u64, stencils.bytes());
        // The pattern path keeps them to choose levels on the host.
        let host_stencils = (path == DrawPath::Pattern).then_some(stencils);
        stages.push(laps.lap("level 1"));
        let normals = NormalsStage::new(
            &device,
            loop_tangent_stencils(&level1),
            level1_vertices,
            limits,
        )?;
        stages.push(laps.lap("tangent stencils and upload"));
        let patches = PatchStage::new(
            &device,
            level1,
            options,
            limits,
            path == DrawPath::Pattern,
            &mut laps,
            &mut stages,
        )?;
        let summary = BftSummary {
            base_vertices,
            level1_vertices,
            patch_count: patches.count,
            table: patches.table,
            tangents: patches.tangents,
            stencil_terms: stencil_count,
            tangent_terms: normals.terms,
            ring_slots: patches.ring_slots,
            stencil_bytes,
            tangent_bytes: normals.bytes,
            patch_bytes: patches.bytes,
            table_bytes: patches.table_bytes,
        };
        stages.push(laps.lap("patches and upload"));
        let InitialStep {
            evaluator,
            base,
            level1_positions,
        } = step;
        let mut statics = normals.buffers;
        statics.extend(patches.buffers);
        statics.push((BFT_LEVEL1_POSITIONS_BINDING, level1_positions));
        statics.push((
            BFT_LEVEL1_NORMALS_BINDING,
            Buffer::new(
                &device,
                &BufferDesc {
                    name: "bft level-1 normals",
                    size: stencil::vertex_bytes(level1_vertices),
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
        ));
        ctx.ensure_set_layout(TechniqueId::BFT, &SET_BINDINGS)?;
        let set_layout = ctx.set_layout(TechniqueId::BFT)?;
        let max_sets = normals.chunks.len() + patches.draw_chunks.len();
        let pool =
            DescriptorPool::new(&device, "bft descriptor pool", set_layout, max_sets as u32)?;
        let write = |chunks: &[(Range<u32>, SetWindows)]| -> Result<Vec<DescriptorSet>> {
            chunks
                .iter()
                .map(|(_, w)| write_set(&pool, set_layout, &statics, &summary, w))
                .collect()
        };
        let normals_sets = write(&normals.chunks)?;
        let draw_sets = write(&patches.draw_chunks)?;
        let normals_pipeline = compute_pipeline(
            &device,
            "bft normals",
            Stage::BftNormalsComp,
            &[ctx.frame_set_layout().raw, set_layout.raw],
            std::mem::size_of::<BftPush>(),
        )?;
        let arrays = match path {
            DrawPath::Pattern => {
                number_arrays(&[(PatchType::PatternTriangle, summary.patch_count, 0)])
            }
            _ => number_arrays(&[(PatchType::LoopBft, summary.patch_count, 1)]),
        };
        stages.push(laps.lap("sets and pipelines"));
        log::info!(
            "bft {}: {}; {:?} stencil (dispatches, chunks), {} normals and {} draw chunks",
            options.name,
            stages.join("; "),
            evaluator.counts(),
            normals.chunks.len(),
            patches.draw_chunks.len()
        );
        let drawn = drawn_runs(summary.patch_count, &loop_mesh.holes);
        let patterns = match (host_stencils, patches.corners) {
            (Some(stencils), Some(corners)) => Some(BftPatterns::new(
                &device,
                summary.patch_count,
                stencils,
                corners,
            )?),
            _ => None,
        };
        Ok(Self {
            patch_block,
            evaluator,
            normals: normals_pipeline,
            normals_sets,
            normals_chunks: normals.chunks,
            draw_sets,
            draw_chunks: patches.draw_chunks,
            _pool: pool,
            base,
            _static: statics
                .into_iter()
                .map(|(_, b)| b)
                .chain(patches.tables)
                .collect(),
            arrays,
            summary,
            rotations: patches.rotations,
            fans,
            drawn,
            loop_mesh,
            rest_bbox: crate::framing::drawn_bbox(mesh),
            base_positions,
            notes: note.into_iter().collect(),
            patterns,
        })
    }

    /// Counts and GPU byte sizes of what was uploaded.
    pub fn summary(&self) -> &BftSummary {
        &self.summary
    }

    /// The base face and its domain coordinate `(U, V)` (weights of the base face's corners 1
    /// and 2) of patch coordinate `(u, v)` on level-1 face `patch`
    /// ([`LoopBft::base_domain`](topology::patches::bft::LoopBft::base_domain)); `None` past the last patch.
    pub fn base_domain(&self, patch: u32, u: f64, v: f64) -> Option<(usize, f64, f64)> {
        let rotation = *self.rotations.get(patch as usize)?;
        Some(level1_base_domain(patch as usize, rotation, u, v))
    }

    /// Bytes of basis-function tables on the GPU ([`GpuBft::table_bytes`](layout::GpuBft::table_bytes)).
    pub fn table_bytes(&self) -> usize {
        self.summary.table_bytes as usize
    }

    /// Chunks of the pre-pass and of the draw (one each unless a buffer exceeds the device's
    /// storage-buffer range: see the module header).
    pub fn chunk_counts(&self) -> (usize, usize) {
        let stencil_chunks = self.evaluator.counts().1;
        (
            stencil_chunks.max(self.normals_chunks.len()),
            self.draw_chunks.len(),
        )
    }

    /// Level-1 faces: patches per frame.
    pub fn patch_count(&self) -> u32 {
        self.summary.patch_count
    }

    /// Segments per level-1 edge the tables reach (`2^L`).
    fn max_level(&self) -> u32 {
        self.summary.table.segments
    }

    /// The drawn faces of `faces` by draw chunk: `(chunk, run)` in order, each run within one
    /// chunk and one drawn run.
    fn drawn_pieces(&self, faces: Range<u32>) -> Vec<Piece> {
        let mut pieces = Vec::new();
        for (k, (items, _)) in self.draw_chunks.iter().enumerate() {
            let (start, end) = (items.start.max(faces.start), items.end.min(faces.end));
            for run in &self.drawn {
                let (start, end) = (start.max(run.start), end.min(run.end));
                if start < end {
                    pieces.push((k, start..end));
                }
            }
        }
        pieces
    }

    fn push(&self, params: &FrameParams, mode: u32) -> BftPush {
        let (factor_mode, segments, pixels, reference) = factor_fields(params.factors);
        // The tables count segments per level-1 edge: half a base edge.
        let uniform_level = segments * 0.5;
        BftPush {
            mode,
            first_patch: 0,
            factor_mode,
            options: flag(params.geometric_normals, BFT_OPTION_GEOMETRIC_NORMALS)
                | flag(params.patch_colours, BFT_OPTION_PATCH_COLOURS)
                | flag(
                    params.spacing == Spacing::FractionalEven,
                    BFT_OPTION_FRACTIONAL,
                ),
            uniform_level,
            pixels_per_segment: pixels,
            distance_ref: reference,
            max_level: self.max_level() as f32,
            count: self.summary.level1_vertices,
            // Bases: set per draw chunk.
            ..Default::default()
        }
    }
}

/// What BFT refuses in `params` with tables of level `table_level`, known before any device or
/// mesh exists (so callers check it first, [`crate::techniques::check_options`]): uniform `S`
/// must be a power of two in `2..=2^(L+1)`, or with fractional-even spacing any level in that
/// range; spacing equal or fractional even (the geomorph between dyadic levels).
pub fn check_frame(table_level: u32, params: &FrameParams) -> Result<()> {
    if params.spacing == Spacing::FractionalOdd {
        return Err(TessError::Unsupported {
            technique: TechniqueId::BFT,
            what: "fractional-odd spacing (it morphs between dyadic levels: use fractional-even spacing)",
        });
    }
    let fractional = params.spacing == Spacing::FractionalEven;
    // The tables hold 2^L segments per level-1 edge, half a base edge.
    let max = 1u32.checked_shl(table_level + 1).unwrap_or(u32::MAX);
    if let FactorPolicy::Uniform { segments } = params.factors {
        let in_range = segments.is_finite() && (2.0..=max as f32).contains(&segments);
        let dyadic = segments.fract() == 0.0 && (segments as u32).is_power_of_two();
        if !in_range || (!fractional && !dyadic) {
            return Err(ParamError::raising(
                Param::Segments,
                segments,
                format!(
                    "BFT takes a power of two in 2..={max} segments per base edge, any level in \
                     that range with fractional-even spacing (tables at level {table_level})"
                ),
                Param::TableLevel,
            ));
        }
    }
    check_adaptive_policy(params)
}

impl Technique for Bft {
    fn id(&self) -> TechniqueId {
        TechniqueId::BFT
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.rest_bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    /// Geometric normals need tangent tables (without them their offsets are `u32::MAX`: the
    /// TES must never read them); the rest is [`check_frame`].
    fn check(&self, params: &FrameParams) -> Result<()> {
        if params.geometric_normals && !self.summary.tangents {
            return Err(TessError::NeedsTangentTables);
        }
        check_frame(self.summary.table.level, params)
    }

    /// Patch colours (the albedo varying) and the sine displacement need the surface build.
    fn surface_build(&self, params: &FrameParams) -> bool {
        params.patch_colours || params.displace_sine[0] != 0.0
    }

    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline {
        if patch.path() == DrawPath::Pattern {
            return PatchPipeline {
                vertex_input: crate::gpu::pattern_input::PATCH_IDS,
                push_constant_bytes: std::mem::size_of::<BftPush>() as u32,
                axes: Variant {
                    geomorph: self.patterns.as_ref().is_some_and(BftPatterns::morph),
                    ..Variant::default()
                },
                ..PatchPipeline::triangles(Stage::BftPatternVert, Stage::BftBftFrag)
            };
        }
        PatchPipeline {
            push_constant_bytes: std::mem::size_of::<BftPush>() as u32,
            axes: Variant {
                patch_block: self.patch_block,
                ..Variant::default()
            },
            ..PatchPipeline::tessellated(
                Stage::BftBftVert,
                Stage::BftBftTesc,
                Stage::BftBftTese,
                Stage::BftBftFrag,
                1,
            )
        }
    }

    fn set_layout_bindings(&self) -> &'static [BindingDesc] {
        &SET_BINDINGS
    }

    /// The first draw chunk's set (the same for every slot); the others are bound by
    /// [`Technique::record_array`].
    fn descriptor_set(&self, _slot: usize) -> Option<&DescriptorSet> {
        self.draw_sets.first()
    }

    /// At the largest factor the policy can reach.
    fn max_vertices_per_patch(&self, params: &FrameParams, _array: usize) -> u64 {
        // On the pattern path, the largest of the frame's patterns once prepared.
        if let Some(n) = self.patterns.as_ref().map(BftPatterns::max_vertices) {
            if n > 0 {
                return n;
            }
        }
        let max = match params.factors {
            FactorPolicy::Uniform { segments } => segments * 0.5,
            _ => self.max_level() as f32,
        };
        uniform_vertex_count(Domain::Triangle, params.spacing, max)
    }

    fn triangles(&self, params: &FrameParams, _array: usize) -> Option<u64> {
        // Levels the host chooses per face (the pattern path's screen-space and distance
        // factors, and geomorphing) are known once the frame is prepared.
        let host_levels =
            params.uniform_segments().is_none() || params.spacing == Spacing::FractionalEven;
        if let (Some(p), true) = (&self.patterns, host_levels) {
            return p.triangles();
        }
        // Patterns are the tessellator's where it has one, and equal spacing's lattice
        // otherwise: the same count at the powers of two BFT takes.
        match params.factors {
            FactorPolicy::Uniform { segments } => Some(
                self.drawn
                    .iter()
                    .map(|r| (r.end - r.start) as u64)
                    .sum::<u64>()
                    * uniform_triangle_count(Domain::Triangle, params.spacing, segments * 0.5),
            ),
            _ => None,
        }
    }

    /// Same vertex count as the mesh the surface was built from (its fan triangulation keeps
    /// the input's vertices).
    fn base_mesh(&self) -> Option<&ControlMesh> {
        Some(&self.loop_mesh)
    }

    fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        self.base_positions =
            upload_base(&mut self.base, slot, positions, self.base_positions.len())?;
        Ok(())
    }

    /// On the pattern path, takes the frame's patterns from the context: under uniform factors
    /// one triangle pattern per level-1 face at half the base edge's segments, else (and when
    /// geomorphing) the levels the host chooses for each face (the `patterns` module docs).
    fn prepare_frame(&mut self, ctx: &mut Context, params: &FrameParams) -> Result<()> {
        if self.patterns.is_none() {
            return Ok(());
        }
        let pieces = self.drawn_pieces(0..self.summary.patch_count);
        // The tables count segments per level-1 edge: half a base edge.
        let uniform_level = params.uniform_segments().map(|s| s * 0.5);
        let morph = params.spacing == Spacing::FractionalEven;
        let view = match (uniform_level, morph) {
            (Some(_), false) => None,
            _ => Some(*ctx.frame_view().ok_or(TessError::NoFrameView {
                technique: TechniqueId::BFT,
            })?),
        };
        let max_level = self.max_level() as f32;
        let Some(patterns) = &mut self.patterns else {
            return Ok(());
        };
        let level = uniform_level.unwrap_or(1.0);
        match view {
            None => patterns.prepare_uniform(ctx, level, &pieces),
            Some(view) => {
                let host = HostView::new(&view, params.factors, level, max_level, morph);
                patterns.prepare_host_levels(ctx, &host, &self.base_positions, &pieces)
            }
        }
    }

    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        // The stages that read level 1: the pattern path's vertex stage alone (a device
        // without tessellation shaders may name no tessellation stage in a barrier).
        let tess_stages = match self.patterns {
            Some(_) => vk::PipelineStageFlags::VERTEX_SHADER,
            None => {
                vk::PipelineStageFlags::VERTEX_SHADER
                    | vk::PipelineStageFlags::TESSELLATION_CONTROL_SHADER
                    | vk::PipelineStageFlags::TESSELLATION_EVALUATION_SHADER
            }
        };
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let write = (compute, vk::AccessFlags::SHADER_WRITE);
        enc.begin_label("bft initial subdivision step");
        if let Some(p) = &self.patterns {
            p.record_ids(enc)?;
        }
        // The previous frame's tessellation stages read level 1 before we overwrite it; host
        // writes of the base positions are visible at submit.
        enc.memory_barrier((tess_stages, vk::AccessFlags::SHADER_READ), write);
        self.evaluator.record(enc, slot)?;
        // The normals read the level-1 positions.
        enc.memory_barrier(write, (compute, vk::AccessFlags::SHADER_READ));
        enc.bind_pipeline(&self.normals);
        for (k, ((items, w), set)) in self
            .normals_chunks
            .iter()
            .zip(&self.normals_sets)
            .enumerate()
        {
            // Chunks write disjoint vertices, but their windows overlap (synchronization
            // validation sees whole ranges): order them.
            if k > 0 {
                enc.memory_barrier(write, write);
            }
            let mut push = BftPush {
                count: items.end - items.start,
                first_vertex: items.start,
                ..Default::default()
            };
            w.apply(&mut push);
            enc.bind_descriptor_sets(0, &[frame_set, set])?;
            enc.push_constants(&push)?;
            enc.dispatch([push.count.div_ceil(BFT_LOCAL_SIZE).max(1), 1, 1])?;
        }
        enc.memory_barrier(write, (tess_stages, vk::AccessFlags::SHADER_READ));
        enc.end_label();
        Ok(())
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        _slot: usize,
        params: &FrameParams,
        pass: Pass,
        per_draw: u32,
    ) -> Result<DrawCounts> {
        let a = *self
            .arrays
            .get(array)
            .ok_or(TessError::NoPatchArray { array })?;
        let push = self.push(params, pass.mode());
        if let Some(p) = &self.patterns {
            return p.record(enc, &self.draw_chunks, &self.draw_sets, push);
        }
        let mut push = push;
        let mut counts = DrawCounts::default();
        let mut bound = 0;
        for (k, faces) in self.drawn_pieces(a.first_patch..a.first_patch + a.patches) {
            // The context bound the first chunk's set.
            if k != bound {
                let set = self
                    .draw_sets
                    .get(k)
                    .ok_or(TessError::NoPatchArray { array })?;
                enc.bind_descriptor_sets(1, &[set])?;
                bound = k;
            }
            if let Some((_, w)) = self.draw_chunks.get(k) {
                w.apply(&mut push);
            }
            counts += for_each_draw(faces.end - faces.start, per_draw, |first, n| {
                let first = faces.start - a.first_patch + first;
                push.first_patch = a.first_patch + first;
                enc.push_constants(&push)?;
                enc.draw(first..first + n)?;
                Ok(())
            })?;
        }
        Ok(counts)
    }

    /// The level-1 face's point in its base triangle, then (for a fan-triangulated polygon)
    /// linearly into the polygon's domain, as the other techniques map fan triangles.
    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        if patch >= self.summary.patch_count {
            return None;
        }
        let (u, v) = patch_uv(domain);
        let (t, bu, bv) = self.base_domain(patch, u, v)?;
        let &(face, n, j) = self.fans.get(t)?;
        if n == 3 {
            return Some(FacePoint {
                face,
                u: (1.0 - bu - bv) as f32,
                v: bu as f32,
            });
        }
        // (bu, bv) weigh the triangle's corners 1 and 2.
        let w = [1.0 - bu - bv, bu, bv];
        let mut uv = [0.0f64; 2];
        for (k, corner) in [0, j + 1, j + 2].into_iter().enumerate() {
            let c = face_corner_uv(n, corner);
            uv[0] += w[k] * c[0];
            uv[1] += w[k] * c[1];
        }
        Some(FacePoint {
            face,
            u: uv[0] as f32,
            v: uv[1] as f32,
        })
    }

    /// Per frame slot, the base positions; the tables, patch records, stencils, level-1
    /// vertices and normals; on the pattern path the instances and the frame's patterns (one
    /// entry per kind of buffer).
    fn device_memory(&self) -> Vec<DeviceAllocation> {
        let buffers = self
            .base
            .iter()
            .chain(self.evaluator.buffers())
            .chain(&self._static)
            .chain(self.patterns.iter().flat_map(BftPatterns::buffers))
            .map(DeviceAllocation::of_buffer);
        DeviceAllocation::merged(buffers)
    }

    fn report_notes(&self) -> Vec<String> {
        let g = &self.summary;
        vec![format!(
            "BFT tables {} bytes at level {} (the valences and cases present in the mesh), \
             patch records {} bytes, base-to-level-1 stencils {} bytes",
            g.table_bytes, g.table.level, g.patch_bytes, g.stencil_bytes
        )]
    }
}

/// The patch coordinate `(u, v)` (weights of the patch's `v1`, `v2`) of a captured
/// `gl_TessCoord.xy` (weights of `v0`, `v1`).
pub fn patch_uv(domain: [f32; 2]) -> (f64, f64) {
    let (x, y) = (domain[0] as f64, domain[1] as f64);
    (y, 1.0 - x - y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The early size check refuses by the count alone, names the mesh, the level, the private
    /// faces, the bound and the largest level that fits, and passes what fits. (The bound is
    /// what 32-bit weight offsets address, [`MAX_TABLE_BYTES`]; no storage-buffer range, since
    /// the tables are read by address: `tests/scale.rs` draws them under a range below them.)
    #[test]
    fn tables_beyond_the_bound_are_refused_before_evaluation() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/opensubdiv/shapes/loop_cube_creases1.obj"
        );
        let mesh = topology::load_obj(path).expect("shape");
        let (level1, _) = loop_level1(&mesh).expect("level 1");
        let records = build_patch_records(&level1).expect("records");
        let options = BftOptions {
            name: "loop_cube_creases1.obj".into(),
            ..Default::default()
        };
        let bytes = |l| 4 * table_weight_count(&records, l, false);
        let (at5, at4, at3) = (bytes(5), bytes(4), bytes(3));
        assert!(at5 > at4 && at4 > at3, "{at5} {at4} {at3}");
        check_table_range(&records, 5, &options, at5).expect("exactly the range fits");
        let err = check_table_range(&records, 5, &options, at5 - 1)
            .expect_err("one byte short")
            .to_string();
        for needle in [
            "loop_cube_creases1.obj",
            "at level 5",
            &format!("{at5} bytes"),
            "need a private table",
            &format!(
                "more than the {} bytes their 32-bit weight offsets",
                at5 - 1
            ),
            &format!("at level 4 they take {at4} bytes (table level 4"),
        ] {
            assert!(err.contains(needle), "{needle:?} in {err}");
        }
        let err = check_table_range(&records, 5, &options, at4 - 1)
            .expect_err("level 4 does not fit either")
            .to_string();
        assert!(err.contains("table level 3"), "{err}");
        let err = check_table_range(&records, 5, &options, 1)
            .expect_err("nothing fits")
            .to_string();
        assert!(err.contains("no table level fits"), "{err}");
        check_table_range(&records, 6, &options, MAX_TABLE_BYTES).expect("level 6 is addressed");
    }
}
