//! Loop limit surfaces on the tessellation stage through basis-function tables (Holländer &
//! Boubekeur, the paper's Fig. 2):
//!
//! 1. **Initial GPU subdivision step** (the pre-pass, every frame): level-1 positions as
//!    stencils over the base positions (`glsl/bft/subdivide.comp`), then level-1 limit normals
//!    from the limit tangent masks (`glsl/bft/normals.comp`). An animated base mesh costs one
//!    upload of its positions per frame; stencils, patch records and tables never change.
//! 2. **Main pass**: one patch (one control point carrying the face index) per level-1 face.
//!    `bft.tesc` sets power-of-two (or fractional) edge factors from each edge's two endpoints
//!    only; `bft.tese` evaluates the table row of each tess coordinate (see
//!    `glsl/bft/bft.glsl`, mirrored in f32 by [`layout::GpuBft::eval_tess`]).
//!
//! The GPU data (named structs for every buffer, bindings, packing, validation, and the f32
//! mirror of the TES) is [`layout`].
//!
//! Polygons are fan-triangulated first (Loop needs triangles); captured points map back into
//! the input's polygons, so callers never see the triangulation.
use crate::capture::{face_corner_uv, FacePoint};
use crate::context::Context;
use crate::error::{Result, TessError};
pub mod layout;

use super::shared::{check_adaptive_policy, factor_fields, storage, storage_binding};
use crate::gpu::bindings::{
    BFT_BASE_POSITIONS_BINDING, BFT_LEVEL1_NORMALS_BINDING, BFT_LEVEL1_POSITIONS_BINDING,
    BFT_LOCAL_SIZE, BFT_OPTION_FRACTIONAL, BFT_OPTION_GEOMETRIC_NORMALS, BFT_OPTION_PATCH_COLOURS,
};
use crate::gpu::BftPush;
use crate::shaders::{self, Stage, Variant};
use crate::technique::{
    for_each_draw, number_arrays, DrawCounts, FactorPolicy, FrameParams, Pass, PatchArray,
    PatchPipeline, PatchType, Technique, TechniqueId,
};
use crate::tessellator::{uniform_triangle_count, uniform_vertex_count, Domain, Spacing};
use layout::{BasePosition, GpuBft, STORAGE_BINDINGS};
use topology::bft::{prepare_loop_bft, LoopBft};
use topology::ControlMesh;
use vk_core::descriptor::{BindingDesc, DescriptorPool};
use vk_core::pipeline::{Pipeline, ShaderStage};
use vk_core::{vk, Buffer, BufferDesc, DescriptorSet, Encoder, MemoryLocation};

/// Default maximum table level: 32 segments per level-1 edge, 64 per base edge.
pub const DEFAULT_TABLE_LEVEL: u32 = 5;

/// Set 1 of every BFT pipeline: the storage buffers of [`STORAGE_BINDINGS`].
static SET_BINDINGS: [BindingDesc; STORAGE_BINDINGS.len()] = {
    let mut out = [storage_binding(0); STORAGE_BINDINGS.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = storage_binding(STORAGE_BINDINGS[i]);
        i += 1;
    }
    out
};

/// `bit` when `on`.
fn flag(on: bool, bit: u32) -> u32 {
    if on {
        bit
    } else {
        0
    }
}

/// Base positions as the `BasePositions` buffer holds them.
fn as_base_positions(positions: &[[f32; 3]]) -> &[u8] {
    bytemuck::cast_slice::<BasePosition, u8>(bytemuck::cast_slice::<[f32; 3], BasePosition>(
        positions,
    ))
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
}

impl Default for BftOptions {
    fn default() -> Self {
        Self {
            table_level: DEFAULT_TABLE_LEVEL,
            tangents: false,
            name: "mesh".into(),
        }
    }
}

/// One base mesh on the GPU with everything the BFT pipeline reads. Drop order: pipelines,
/// sets (they keep their pool alive), pool, buffers.
pub struct Bft {
    subdivide: Pipeline,
    normals: Pipeline,
    /// One set per frame slot (they differ only in the base-position buffer).
    sets: Vec<DescriptorSet>,
    _pool: DescriptorPool,
    base: Vec<Buffer>,
    _static: Vec<Buffer>,
    arrays: Vec<PatchArray>,
    pub gpu: GpuBft,
    pub bft: LoopBft,
    /// Per Loop triangle: its input face, the face's side count and its fan index (corners
    /// 0, j + 1, j + 2); identity for a triangle mesh.
    fans: Vec<(u32, u32, u32)>,
    /// The triangle mesh Loop subdivides (the input, or its fan triangulation): the positions
    /// [`Technique::update_base`] replaces.
    pub loop_mesh: ControlMesh,
    /// Base positions as last uploaded (the CPU reference).
    pub base_positions: Vec<[f32; 3]>,
    /// Bounds of the rest pose: an animated surface keeps its camera framing.
    rest_bbox: ([f32; 3], [f32; 3]),
    /// How the input was taken (fan triangulation), for the caller to show.
    pub notes: Vec<String>,
}

/// The base positions of `mesh` in f32.
pub fn base_positions(mesh: &ControlMesh) -> Vec<[f32; 3]> {
    mesh.positions
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect()
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

impl Bft {
    /// Prepares `mesh` (fan-triangulated first when it has polygons; refined once on the CPU
    /// for the topology; stencils, patch records and the tables at `options.table_level`) and
    /// uploads it, with one base-position buffer per frame slot of `ctx`.
    pub fn new(ctx: &mut Context, mesh: &ControlMesh, options: &BftOptions) -> Result<Self> {
        let device = ctx.device().clone();
        let table_level = options.table_level;
        let max_level = device.info.caps.max_tessellation_generation_level;
        if !(1..=6).contains(&table_level) || (1u32 << table_level) > max_level {
            return Err(TessError::TableLevel {
                level: table_level,
                max_tessellation_level: max_level,
            });
        }
        let (loop_mesh, fans, note) = loop_control_mesh(mesh, &options.name);
        let bft = prepare_loop_bft(&loop_mesh, table_level, options.tangents).map_err(|e| {
            TessError::Mesh {
                name: options.name.clone(),
                source: e.into(),
            }
        })?;
        let gpu = GpuBft::new(&bft)?;
        let frames = ctx.frames_in_flight();
        ctx.ensure_set_layout(TechniqueId::Bft, &SET_BINDINGS)?;
        let set_layout = ctx.set_layout(TechniqueId::Bft)?;
        let pool = DescriptorPool::new(&device, "bft descriptor pool", set_layout, frames as u32)?;
        let level1_bytes = gpu.level1_bytes();
        let level1 = |binding: u32, name: &str| -> Result<(u32, Buffer)> {
            let desc = BufferDesc {
                name,
                size: level1_bytes,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
            };
            Ok((binding, Buffer::new(&device, &desc)?))
        };
        let mut statics = vec![
            level1(BFT_LEVEL1_POSITIONS_BINDING, "bft level-1 positions")?,
            level1(BFT_LEVEL1_NORMALS_BINDING, "bft level-1 normals")?,
        ];
        for (binding, name, bytes) in gpu.static_buffers() {
            statics.push((binding, storage(&device, name, &bytes)?));
        }
        let base_positions = base_positions(&loop_mesh);
        let mut base = Vec::new();
        let mut sets = Vec::new();
        for i in 0..frames {
            let mut buf = Buffer::new(
                &device,
                &BufferDesc {
                    name: &format!("bft base positions {i}"),
                    size: (std::mem::size_of::<BasePosition>() * base_positions.len().max(1))
                        as u64,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?;
            buf.write(0, as_base_positions(&base_positions))?;
            let set = pool.allocate_set(set_layout)?;
            set.write_buffer(
                BFT_BASE_POSITIONS_BINDING,
                vk::DescriptorType::STORAGE_BUFFER,
                &buf,
            )?;
            for (binding, s) in &statics {
                set.write_buffer(*binding, vk::DescriptorType::STORAGE_BUFFER, s)?;
            }
            base.push(buf);
            sets.push(set);
        }
        let layouts = [ctx.frame_set_layout().raw, set_layout.raw];
        let push = std::mem::size_of::<BftPush>() as u32;
        let compute = |name: &str, stage: Stage| -> Result<Pipeline> {
            Ok(Pipeline::compute(
                &device,
                name,
                ShaderStage::new(
                    vk::ShaderStageFlags::COMPUTE,
                    shaders::spirv(stage, Variant::default())?,
                ),
                &layouts,
                push,
            )?)
        };
        let subdivide = compute("bft subdivide", Stage::BftSubdivideComp)?;
        let normals = compute("bft normals", Stage::BftNormalsComp)?;
        let arrays = number_arrays(&[(PatchType::LoopBft, gpu.patch_count, 1)]);
        Ok(Self {
            subdivide,
            normals,
            sets,
            _pool: pool,
            base,
            _static: statics.into_iter().map(|(_, b)| b).collect(),
            arrays,
            gpu,
            bft,
            fans,
            loop_mesh,
            rest_bbox: bbox(&base_positions),
            base_positions,
            notes: note.into_iter().collect(),
        })
    }

    /// Bytes of basis-function tables on the GPU ([`GpuBft::table_bytes`]).
    pub fn table_bytes(&self) -> usize {
        self.gpu.table_bytes()
    }

    /// Level-1 faces: patches per frame.
    pub fn patch_count(&self) -> u32 {
        self.gpu.patch_count
    }

    /// Segments per level-1 edge the tables reach (`2^L`).
    fn max_level(&self) -> u32 {
        self.gpu.table.segments
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
            count: self.gpu.level1_vertices,
        }
    }
}

impl Technique for Bft {
    fn id(&self) -> TechniqueId {
        TechniqueId::Bft
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.rest_bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    /// Uniform `S` must be a power of two in `2..=2^(L+1)` unless fractional; spacing equal or
    /// fractional even (the linear geomorph between dyadic levels); geometric normals need
    /// tangent tables (without them their offsets are `u32::MAX`: the TES must never read them).
    fn check(&self, params: &FrameParams) -> Result<()> {
        if params.geometric_normals && !self.bft.tables.tangents {
            return Err(TessError::NeedsTangentTables);
        }
        if params.spacing == Spacing::FractionalOdd {
            return Err(TessError::Unsupported {
                technique: TechniqueId::Bft,
                what: "--spacing fractional-odd (it morphs between dyadic levels: use --fractional, i.e. fractional-even)",
            });
        }
        let fractional = params.spacing == Spacing::FractionalEven;
        let max = 2 * self.max_level();
        if let FactorPolicy::Uniform { segments } = params.factors {
            let whole = segments.fract() == 0.0 && segments >= 1.0;
            let s = segments as u32;
            if !whole || s < 2 || s > max || (!fractional && !s.is_power_of_two()) {
                return Err(TessError::BftSegments {
                    segments,
                    max,
                    table_level: self.gpu.table.level,
                });
            }
        }
        check_adaptive_policy(params)
    }

    fn patch_pipeline(&self, _patch: PatchType) -> PatchPipeline {
        PatchPipeline {
            vertex: Stage::BftBftVert,
            control: Stage::BftBftTesc,
            evaluation: Stage::BftBftTese,
            fragment: Stage::BftBftFrag,
            control_points: 1,
            mesh_vertex_input: false,
            push_constant_bytes: std::mem::size_of::<BftPush>() as u32,
        }
    }

    fn set_layout_bindings(&self) -> &'static [BindingDesc] {
        &SET_BINDINGS
    }

    fn descriptor_set(&self, slot: usize) -> Option<&DescriptorSet> {
        self.sets.get(slot.min(self.sets.len().saturating_sub(1)))
    }

    /// At the largest factor the policy can reach.
    fn max_vertices_per_patch(&self, params: &FrameParams, _array: usize) -> u64 {
        let max = match params.factors {
            FactorPolicy::Uniform { segments } => segments * 0.5,
            _ => self.max_level() as f32,
        };
        uniform_vertex_count(Domain::Triangle, params.spacing, max)
    }

    fn triangles(&self, params: &FrameParams, _array: usize) -> Option<u64> {
        match params.factors {
            FactorPolicy::Uniform { segments } => Some(
                self.gpu.patch_count as u64
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
        if positions.len() != self.base_positions.len() {
            return Err(TessError::BasePositionCount {
                given: positions.len(),
                expected: self.base_positions.len(),
            });
        }
        let slots = self.base.len();
        let buf = self
            .base
            .get_mut(slot)
            .ok_or(TessError::FrameSlot { slot, slots })?;
        buf.write(0, as_base_positions(positions))?;
        self.base_positions = positions.to_vec();
        Ok(())
    }

    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        let push = BftPush {
            count: self.gpu.level1_vertices,
            ..Default::default()
        };
        let groups = self.gpu.level1_vertices.div_ceil(BFT_LOCAL_SIZE).max(1);
        let tess_stages = vk::PipelineStageFlags::VERTEX_SHADER
            | vk::PipelineStageFlags::TESSELLATION_CONTROL_SHADER
            | vk::PipelineStageFlags::TESSELLATION_EVALUATION_SHADER;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let set = self
            .descriptor_set(slot)
            .ok_or(TessError::FrameSlot { slot, slots: 0 })?;
        enc.begin_label("bft initial subdivision step");
        // The previous frame's tessellation stages read level 1 before we overwrite it; host
        // writes of the base positions are visible at submit.
        enc.memory_barrier(
            (tess_stages, vk::AccessFlags::SHADER_READ),
            (compute, vk::AccessFlags::SHADER_WRITE),
        );
        for (pipeline, next) in [
            (&self.subdivide, (compute, vk::AccessFlags::SHADER_READ)),
            (&self.normals, (tess_stages, vk::AccessFlags::SHADER_READ)),
        ] {
            enc.bind_pipeline(pipeline);
            enc.bind_descriptor_sets(0, &[frame_set, set])?;
            enc.push_constants(&push)?;
            enc.dispatch([groups, 1, 1])?;
            enc.memory_barrier((compute, vk::AccessFlags::SHADER_WRITE), next);
        }
        enc.end_label();
        Ok(())
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        params: &FrameParams,
        pass: Pass,
        per_draw: u32,
    ) -> Result<DrawCounts> {
        let a = *self
            .arrays
            .get(array)
            .ok_or(TessError::NoPatchArray { array })?;
        let mut push = self.push(params, pass.mode());
        for_each_draw(a.patches, per_draw, |first, n| {
            push.first_patch = a.first_patch + first;
            enc.push_constants(&push)?;
            enc.draw(first..first + n)?;
            Ok(())
        })
    }

    /// The level-1 face's point in its base triangle, then (for a fan-triangulated polygon)
    /// linearly into the polygon's domain, as the other techniques map fan triangles.
    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        if patch >= self.gpu.patch_count {
            return None;
        }
        let (u, v) = patch_uv(domain);
        let (t, bu, bv) = self.bft.base_domain(patch as usize, u, v);
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

    fn report_notes(&self) -> Vec<String> {
        let g = &self.gpu;
        vec![format!(
            "BFT tables {} bytes at level {} (the valences and cases present in the mesh), \
             patch records {} bytes, base-to-level-1 stencils {} bytes",
            self.table_bytes(),
            g.table.level,
            g.patch_bytes(),
            g.stencil_bytes()
        )]
    }
}

/// The patch coordinate `(u, v)` (weights of the patch's `v1`, `v2`) of a captured
/// `gl_TessCoord.xy` (weights of `v0`, `v1`).
pub fn patch_uv(domain: [f32; 2]) -> (f64, f64) {
    let (x, y) = (domain[0] as f64, domain[1] as f64);
    (y, 1.0 - x - y)
}

/// Axis-aligned bounds of points.
pub fn bbox(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if points.is_empty() {
        ([0.0; 3], [0.0; 3])
    } else {
        (lo, hi)
    }
}

/// Per-vertex unit normals of the base mesh (area-weighted face normals), the directions the
/// animation moves vertices along.
pub fn base_normals(mesh: &ControlMesh) -> Vec<[f32; 3]> {
    let mut n = vec![glam::DVec3::ZERO; mesh.positions.len()];
    for f in mesh.faces() {
        let p = |i: usize| glam::DVec3::from(mesh.positions[f[i] as usize]);
        for k in 1..f.len().saturating_sub(1) {
            let c = (p(k) - p(0)).cross(p(k + 1) - p(0));
            for &v in f {
                n[v as usize] += c;
            }
        }
    }
    n.iter()
        .map(|v| v.normalize_or_zero().as_vec3().to_array())
        .collect()
}

/// The `--animate` deformation (a travelling wave along the vertex normals, as in the Doo-Sabin
/// paper's §3): base position + `amplitude · sin(2π(k·p/diag − t))` along the normal. Only these
/// positions are uploaded per frame.
pub fn wave(
    base: &[[f32; 3]],
    normals: &[[f32; 3]],
    bbox_min: [f32; 3],
    bbox_max: [f32; 3],
    time: f32,
) -> Vec<[f32; 3]> {
    let lo = glam::Vec3::from(bbox_min);
    let hi = glam::Vec3::from(bbox_max);
    let diag = (hi - lo).length().max(1e-6);
    let dir = glam::Vec3::new(0.6, 0.8, 0.0);
    let amplitude = 0.03 * diag;
    base.iter()
        .zip(normals)
        .map(|(p, n)| {
            let p = glam::Vec3::from(*p);
            let phase = 2.0 * std::f32::consts::PI * (2.0 * dir.dot(p - lo) / diag - 0.5 * time);
            (p + glam::Vec3::from(*n) * amplitude * phase.sin()).to_array()
        })
        .collect()
}

/// The `--animate` wave at time `t` applied to the rest pose of a mesh: what is uploaded.
/// Works for any technique that takes [`Technique::update_base`].
pub struct Wave {
    rest: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    bbox: ([f32; 3], [f32; 3]),
}

impl Wave {
    pub fn new(mesh: &ControlMesh) -> Self {
        let rest = base_positions(mesh);
        let bbox = bbox(&rest);
        Self {
            normals: base_normals(mesh),
            rest,
            bbox,
        }
    }

    pub fn at(&self, t: f32) -> Vec<[f32; 3]> {
        wave(&self.rest, &self.normals, self.bbox.0, self.bbox.1, t)
    }
}
