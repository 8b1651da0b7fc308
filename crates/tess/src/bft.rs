//! Loop limit surfaces on the tessellation stage through basis-function tables (Holländer &
//! Boubekeur, the paper's Fig. 2):
//!
//! 1. **Initial GPU subdivision step** (compute, every frame): level-1 positions as stencils over
//!    the base positions (`bft/subdivide.comp`), then level-1 limit normals from the limit
//!    tangent masks (`bft/normals.comp`). An animated base mesh costs one upload of its
//!    positions per frame; stencils, patch records and tables never change.
//! 2. **Main pass**: one patch (one control point carrying the face index) per level-1 face.
//!    `bft.tesc` sets power-of-two (or fractional) edge factors from each edge's two endpoints
//!    only; `bft.tese` evaluates the table row of each tess coordinate (see
//!    `glsl/bft/bft.glsl`, mirrored in f32 by [`GpuBft::eval_tess`]).
//!
//! The GPU data (named structs for every buffer, bindings, packing, validation) is
//! [`crate::techniques::bft::layout`], re-exported here.
use crate::capture::{
    begin_capture_scope, capture_to_host_barrier, end_capture_scope, CaptureRecord, CapturedSoup,
    FacePoint, CAPTURE_STRIDE,
};
use crate::error::{Result, TessError};
use crate::gpu::bindings::{
    BFT_BASE_POSITIONS_BINDING, BFT_FACTORS_DISTANCE, BFT_FACTORS_SCREEN, BFT_FACTORS_UNIFORM,
    BFT_LEVEL1_NORMALS_BINDING, BFT_LEVEL1_POSITIONS_BINDING, BFT_OPTION_FRACTIONAL,
    BFT_OPTION_GEOMETRIC_NORMALS, BFT_OPTION_PATCH_COLOURS,
};
use crate::gpu::BftPush;
use crate::renderer::{set_pass_style, DrawCounts, DrawSplit, Renderer};
use crate::shaders::{spirv, Stage, Variant};
use crate::tessellator::{uniform_vertex_count, Domain, Spacing};
use std::collections::HashMap;
use topology::bft::{prepare_loop_bft, LoopBft};

pub use crate::techniques::bft::layout::*;
use topology::ControlMesh;
use vk_core::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use vk_core::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage, TessellationDesc};
use vk_core::query::{PipelineStatistics, QueryPool};
use vk_core::target::{OffscreenTarget, Rgba8};
use vk_core::workarounds::WorkaroundId;
use vk_core::{vk, Buffer, BufferDesc, Device, MemoryLocation};

/// Default maximum table level: 32 segments per level-1 edge, 64 per base edge.
pub const DEFAULT_TABLE_LEVEL: u32 = 5;

/// How a BFT draw chooses its tessellation factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FactorPolicy {
    /// `S` segments per base edge (`S/2` per level-1 edge), `S ∈ {2, 4, …, 2^(L+1)}`.
    Uniform { segments: u32 },
    /// Edge factor = projected edge length / `pixels` per segment.
    Screen { pixels: f32 },
    /// An edge at `reference` distance from the eye gets the maximum level; the factor halves
    /// each time the distance doubles.
    Distance { reference: f32 },
}

impl Default for FactorPolicy {
    fn default() -> Self {
        FactorPolicy::Uniform { segments: 16 }
    }
}

/// What one BFT frame shows, beyond the shared [`crate::DrawParams`] (camera, colours,
/// wireframe, draw split).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BftParams {
    pub factors: FactorPolicy,
    /// Fractional factors (fractional-even spacing) morphing linearly on the level-`L` virtual
    /// mesh, instead of power-of-two factors.
    pub fractional: bool,
    /// Normals from the tangent tables (`du × dv`) instead of subdivision shading.
    pub geometric_normals: bool,
    /// Colour patches by kind: regular, extraordinary, boundary.
    pub patch_colours: bool,
}

impl BftParams {
    fn spacing(&self) -> Spacing {
        if self.fractional {
            Spacing::FractionalEven
        } else {
            Spacing::Equal
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct BftPipelineKey {
    spacing: Spacing,
    wireframe: bool,
}

/// One base mesh on the GPU with everything the BFT pipeline reads. Drop order: pipelines,
/// descriptor pool, set layout, buffers, device handle.
pub struct BftSurface {
    pipelines: HashMap<BftPipelineKey, Pipeline>,
    capture_pipelines: HashMap<Spacing, Pipeline>,
    subdivide: Pipeline,
    normals: Pipeline,
    _pool: DescriptorPool,
    set_layout: DescriptorSetLayout,
    /// One descriptor set per frame slot (they differ only in the base-position buffer).
    sets: Vec<vk::DescriptorSet>,
    base: Vec<Buffer>,
    _static: Vec<Buffer>,
    pub gpu: GpuBft,
    pub bft: LoopBft,
    /// Base positions as last uploaded (for the bounding box and the CPU reference).
    pub base_positions: Vec<[f32; 3]>,
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
    color_format: vk::Format,
    depth_format: vk::Format,
    device: Device,
}

fn storage(device: &Device, name: &str, bytes: &[u8]) -> Result<Buffer> {
    // Zero-length storage buffers are invalid; pad empty arrays to one word.
    let pad = [0u8; 4];
    let data = if bytes.is_empty() { &pad[..] } else { bytes };
    Ok(Buffer::with_data(
        device,
        name,
        vk::BufferUsageFlags::STORAGE_BUFFER,
        data,
    )?)
}

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

/// The base positions of `mesh` in f32.
pub fn base_positions(mesh: &ControlMesh) -> Vec<[f32; 3]> {
    mesh.positions
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect()
}

impl BftSurface {
    /// Prepares `mesh` (refines once on the CPU for the topology, builds stencils, patch records
    /// and the tables at `table_level`) and uploads it; `frames_in_flight` base-position
    /// buffers let frame `k + 1` upload while frame `k` renders.
    pub fn new(
        renderer: &Renderer,
        mesh: &ControlMesh,
        name: &str,
        table_level: u32,
        tangents: bool,
        frames_in_flight: usize,
    ) -> Result<Self> {
        let device = renderer.device().clone();
        let max_level = device.info.caps.max_tessellation_generation_level;
        if (1u32 << table_level) > max_level {
            return Err(TessError::Invalid(format!(
                "table level {table_level} needs tessellation level {} but the device allows {max_level}",
                1u32 << table_level
            )));
        }
        let bft = prepare_loop_bft(mesh, table_level, tangents)
            .map_err(|e| TessError::Invalid(format!("{name}: {e}")))?;
        let gpu = GpuBft::new(&bft)?;
        let stages = vk::ShaderStageFlags::COMPUTE
            | vk::ShaderStageFlags::VERTEX
            | vk::ShaderStageFlags::TESSELLATION_CONTROL
            | vk::ShaderStageFlags::TESSELLATION_EVALUATION
            | vk::ShaderStageFlags::FRAGMENT;
        let bindings: Vec<BindingDesc> = STORAGE_BINDINGS
            .iter()
            .map(|&binding| BindingDesc {
                binding,
                ty: vk::DescriptorType::STORAGE_BUFFER,
                stages,
            })
            .collect();
        let set_layout = DescriptorSetLayout::new(&device, "bft set layout", &bindings)?;
        let pool = DescriptorPool::new(
            &device,
            "bft descriptor pool",
            &set_layout,
            frames_in_flight as u32,
        )?;
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
        let base_positions = base_positions(mesh);
        let mut base = Vec::new();
        let mut sets = Vec::new();
        for i in 0..frames_in_flight {
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
            let set = pool.allocate(&set_layout)?;
            let mut writes = vec![(
                BFT_BASE_POSITIONS_BINDING,
                vk::DescriptorType::STORAGE_BUFFER,
                buf.descriptor(),
            )];
            for (binding, s) in &statics {
                writes.push((*binding, vk::DescriptorType::STORAGE_BUFFER, s.descriptor()));
            }
            pool.write_buffers(set, &writes);
            base.push(buf);
            sets.push(set);
        }
        let layouts = [renderer.frame_set_layout(), set_layout.raw];
        let push = std::mem::size_of::<BftPush>() as u32;
        let subdivide = Pipeline::compute(
            &device,
            "bft subdivide",
            ShaderStage::new(
                vk::ShaderStageFlags::COMPUTE,
                spirv(Stage::BftSubdivideComp, Variant::default())?,
            ),
            &layouts,
            push,
        )?;
        let normals = Pipeline::compute(
            &device,
            "bft normals",
            ShaderStage::new(
                vk::ShaderStageFlags::COMPUTE,
                spirv(Stage::BftNormalsComp, Variant::default())?,
            ),
            &layouts,
            push,
        )?;
        let (bbox_min, bbox_max) = bbox(&base_positions);
        let (color_format, depth_format) = renderer.formats();
        Ok(Self {
            pipelines: HashMap::new(),
            capture_pipelines: HashMap::new(),
            subdivide,
            normals,
            _pool: pool,
            set_layout,
            sets,
            base,
            _static: statics.into_iter().map(|(_, b)| b).collect(),
            gpu,
            bft,
            base_positions,
            bbox_min,
            bbox_max,
            color_format,
            depth_format,
            device,
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

    /// Uploads new base positions into frame slot `slot` (same vertex count).
    pub fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        if positions.len() != self.base_positions.len() {
            return Err(TessError::Invalid(format!(
                "{} base positions given, the mesh has {}",
                positions.len(),
                self.base_positions.len()
            )));
        }
        let buf = self
            .base
            .get_mut(slot)
            .ok_or_else(|| TessError::Invalid(format!("no frame slot {slot}")))?;
        buf.write(0, as_base_positions(positions))?;
        self.base_positions = positions.to_vec();
        Ok(())
    }

    fn pipeline(&mut self, renderer: &Renderer, key: BftPipelineKey) -> Result<&Pipeline> {
        if !self.pipelines.contains_key(&key) {
            let p = self.build_pipeline(renderer, key)?;
            self.pipelines.insert(key, p);
        }
        Ok(&self.pipelines[&key])
    }

    fn build_pipeline(&self, renderer: &Renderer, key: BftPipelineKey) -> Result<Pipeline> {
        let variant = Variant {
            spacing: Some(key.spacing),
            capture: false,
        };
        let name = format!(
            "bft {:?}{}",
            key.spacing,
            if key.wireframe { " wireframe" } else { "" }
        );
        let mut desc = GraphicsPipelineDesc::new(&name, self.color_format, self.depth_format);
        desc.stages = [
            Stage::BftBftVert,
            Stage::BftBftTesc,
            Stage::BftBftTese,
            Stage::BftBftFrag,
        ]
        .into_iter()
        .map(|s| Ok(ShaderStage::new(s.vk_stage(), spirv(s, variant)?)))
        .collect::<Result<_>>()?;
        desc.topology = vk::PrimitiveTopology::PATCH_LIST;
        desc.tessellation = Some(TessellationDesc {
            patch_control_points: 1,
            domain_origin: vk::TessellationDomainOrigin::UPPER_LEFT,
        });
        desc.set_layouts = vec![renderer.frame_set_layout(), self.set_layout.raw];
        desc.push_constant_bytes = std::mem::size_of::<BftPush>() as u32;
        set_pass_style(&mut desc, key.wireframe);
        Ok(Pipeline::graphics(&self.device, &desc)?)
    }

    fn push(&self, params: &BftParams, mode: u32) -> BftPush {
        let max_level = self.gpu.table.segments as f32;
        let (factor_mode, uniform_level, pixels, reference) = match params.factors {
            FactorPolicy::Uniform { segments } => {
                (BFT_FACTORS_UNIFORM, segments as f32 * 0.5, 0.0, 0.0)
            }
            FactorPolicy::Screen { pixels } => (BFT_FACTORS_SCREEN, 0.0, pixels.max(0.01), 0.0),
            FactorPolicy::Distance { reference } => {
                (BFT_FACTORS_DISTANCE, 0.0, 0.0, reference.max(1e-6))
            }
        };
        BftPush {
            mode,
            first_patch: 0,
            factor_mode,
            options: flag(params.geometric_normals, BFT_OPTION_GEOMETRIC_NORMALS)
                | flag(params.patch_colours, BFT_OPTION_PATCH_COLOURS)
                | flag(params.fractional, BFT_OPTION_FRACTIONAL),
            uniform_level,
            pixels_per_segment: pixels,
            distance_ref: reference,
            max_level,
            count: self.gpu.level1_vertices,
        }
    }

    /// Checks the factors against the tables: uniform `S` must be a power of two in
    /// `2..=2^(L+1)` unless fractional; geometric normals need tangent tables.
    pub fn check_params(&self, params: &BftParams) -> Result<()> {
        // Without tangent tables the du/dv offsets are u32::MAX: the TES must never read them.
        if params.geometric_normals && !self.bft.tables.tangents {
            return Err(TessError::Invalid(
                "geometric normals need the tangent tables (this surface was built without them)"
                    .into(),
            ));
        }
        let max = 2 * self.gpu.table.segments;
        if let FactorPolicy::Uniform { segments } = params.factors {
            if segments < 2 || segments > max || (!params.fractional && !segments.is_power_of_two())
            {
                return Err(TessError::Invalid(format!(
                    "--segments {segments}: BFT takes a power of two in 2..={max} segments per base edge \
                     (tables at level {}; raise --table-level for more)",
                    self.gpu.table.level
                )));
            }
        }
        Ok(())
    }

    /// Records the initial subdivision step of frame slot `slot`: level-1 positions, then
    /// normals, with the barriers that order them after the previous frame's reads and before
    /// this frame's tessellation stages. Outside any rendering scope.
    pub fn record_compute(&self, cmd: vk::CommandBuffer, renderer: &Renderer, slot: usize) {
        let d = &self.device;
        let push = BftPush {
            count: self.gpu.level1_vertices,
            ..Default::default()
        };
        let groups = self.gpu.level1_vertices.div_ceil(64);
        let tess_stages = vk::PipelineStageFlags::VERTEX_SHADER
            | vk::PipelineStageFlags::TESSELLATION_CONTROL_SHADER
            | vk::PipelineStageFlags::TESSELLATION_EVALUATION_SHADER;
        let set = self.sets[slot.min(self.sets.len() - 1)];
        let frame_set = renderer.frame_set(slot);
        let barrier = |src_stage, src, dst_stage, dst| {
            let m = [vk::MemoryBarrier::default()
                .src_access_mask(src)
                .dst_access_mask(dst)];
            // SAFETY: cmd is recording outside a render pass.
            unsafe {
                d.raw.cmd_pipeline_barrier(
                    cmd,
                    src_stage,
                    dst_stage,
                    vk::DependencyFlags::empty(),
                    &m,
                    &[],
                    &[],
                )
            };
        };
        d.begin_label(cmd, "bft initial subdivision step");
        // The previous frame's tessellation stages read level 1 before we overwrite it; host
        // writes of the base positions are visible at submit.
        barrier(
            tess_stages,
            vk::AccessFlags::SHADER_READ,
            vk::PipelineStageFlags::COMPUTE_SHADER,
            vk::AccessFlags::SHADER_WRITE,
        );
        for (pipeline, last) in [(&self.subdivide, false), (&self.normals, true)] {
            // SAFETY: pipelines, sets and buffers are owned by self/renderer and outlive the
            // submission (callers wait for the frame's fence before dropping them).
            unsafe {
                d.raw
                    .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, pipeline.raw);
                d.raw.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    pipeline.layout,
                    0,
                    &[frame_set, set],
                    &[],
                );
                d.raw.cmd_push_constants(
                    cmd,
                    pipeline.layout,
                    vk::ShaderStageFlags::ALL,
                    0,
                    bytemuck::bytes_of(&push),
                );
                d.raw.cmd_dispatch(cmd, groups.max(1), 1, 1);
            }
            if last {
                barrier(
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_WRITE,
                    tess_stages,
                    vk::AccessFlags::SHADER_READ,
                );
            } else {
                barrier(
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_WRITE,
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_READ,
                );
            }
        }
        d.end_label(cmd);
    }

    /// Patches per draw: all of them, unless a driver workaround limits the vertices one draw
    /// may emit (`vk_core::workarounds`), computed at the largest factor the policy can reach.
    pub fn patches_per_draw(&self, params: &BftParams, split: DrawSplit) -> u32 {
        match split {
            DrawSplit::Off => u32::MAX,
            DrawSplit::PerPatch => 1,
            DrawSplit::Auto => {
                let max = match params.factors {
                    FactorPolicy::Uniform { segments } => segments as f32 * 0.5,
                    _ => self.gpu.table.segments as f32,
                };
                let verts = uniform_vertex_count(Domain::Triangle, params.spacing(), max);
                self.device.workarounds.max_patches_per_draw(verts)
            }
        }
    }

    /// Records the draws of one pass (shaded, or the wireframe overlay) inside a rendering
    /// scope; [`Self::record_compute`] must have run earlier in the frame.
    pub fn record_draw(
        &mut self,
        cmd: vk::CommandBuffer,
        renderer: &Renderer,
        slot: usize,
        params: &BftParams,
        split: DrawSplit,
        wireframe: bool,
    ) -> Result<DrawCounts> {
        self.check_params(params)?;
        let key = BftPipelineKey {
            spacing: params.spacing(),
            wireframe,
        };
        let mut push = self.push(params, wireframe as u32);
        let per_draw = self.patches_per_draw(params, split);
        let set = self.sets[slot.min(self.sets.len() - 1)];
        let frame_set = renderer.frame_set(slot);
        let total = self.gpu.patch_count;
        let device = self.device.clone();
        let pipeline = self.pipeline(renderer, key)?;
        // SAFETY: cmd is recording inside a rendering scope; everything bound is owned by self
        // or the renderer and outlives the submission.
        unsafe {
            device
                .raw
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.raw);
            device.raw.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                pipeline.layout,
                0,
                &[frame_set, set],
                &[],
            );
        }
        // SAFETY: the pipeline and its sets are bound on cmd inside a rendering scope.
        let counts = unsafe {
            record_patch_draws(&device, cmd, pipeline.layout, &mut push, total, per_draw)
        };
        Ok(counts)
    }
}

/// Draws patches `0..total` (one control point each: the level-1 face) in draws of at most
/// `per_draw`, with `push.first_patch` set per draw so patch ids stay frame-wide.
///
/// # Safety
/// A BFT pipeline with `layout` and its sets is bound on `cmd`, inside a rendering scope (or a
/// capture scope); `total` is the validated patch count.
unsafe fn record_patch_draws(
    device: &Device,
    cmd: vk::CommandBuffer,
    layout: vk::PipelineLayout,
    push: &mut BftPush,
    total: u32,
    per_draw: u32,
) -> DrawCounts {
    let mut counts = DrawCounts::default();
    let mut first = 0;
    while first < total {
        let n = per_draw.min(total - first);
        push.first_patch = first;
        // SAFETY: the caller's contract; first..first + n are existing, validated patches.
        unsafe {
            device.raw.cmd_push_constants(
                cmd,
                layout,
                vk::ShaderStageFlags::ALL,
                0,
                bytemuck::bytes_of(push),
            );
            device.raw.cmd_draw(cmd, n, 1, first, 0);
        }
        counts.draws += 1;
        counts.patches += n;
        first += n;
    }
    counts
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

impl BftSurface {
    /// Renders one frame offscreen (compute pass, shaded pass, optional wireframe overlay) and
    /// reads it back; with `statistics`, also the pipeline statistics of the shaded pass (None
    /// where a driver workaround forbids the query).
    pub fn render_offscreen(
        &mut self,
        renderer: &mut Renderer,
        draw: &crate::DrawParams,
        params: &BftParams,
        extent: vk::Extent2D,
        statistics: bool,
    ) -> Result<(Rgba8, Option<PipelineStatistics>, DrawCounts)> {
        self.check_params(params)?;
        let device = self.device.clone();
        let target = OffscreenTarget::new(&device, extent)?;
        let readback = target.readback_buffer(&device)?;
        // See WorkaroundId::LavapipeStatisticsQueryPointPatches: there the query is skipped and
        // the statistics come back as None.
        let statistics = statistics
            && !device
                .workarounds
                .has(WorkaroundId::LavapipeStatisticsQueryPointPatches);
        let query = if statistics {
            Some(QueryPool::statistics(&device, "bft statistics", 1)?)
        } else {
            None
        };
        renderer.update_frame(0, (self.bbox_min, self.bbox_max), draw, extent)?;
        let mut result = Ok(DrawCounts::default());
        device.one_shot(|cmd| {
            if let Some(q) = &query {
                q.cmd_reset(cmd);
            }
            self.record_compute(cmd, renderer, 0);
            target.cmd_begin(&device, cmd, draw.clear_color);
            if let Some(q) = &query {
                // SAFETY: the query was reset above in this command buffer.
                unsafe {
                    device
                        .raw
                        .cmd_begin_query(cmd, q.raw, 0, vk::QueryControlFlags::empty())
                };
            }
            result = self.record_draw(cmd, renderer, 0, params, draw.split, false);
            if let Some(q) = &query {
                // SAFETY: matches the begin above.
                unsafe { device.raw.cmd_end_query(cmd, q.raw, 0) };
            }
            if draw.wireframe && result.is_ok() {
                if let Err(e) = self.record_draw(cmd, renderer, 0, params, draw.split, true) {
                    result = Err(e);
                }
            }
            target.cmd_end_and_copy(&device, cmd, &readback);
        })?;
        let counts = result?;
        let stats = match &query {
            Some(q) => q.statistics_results()?.first().copied(),
            None => None,
        };
        Ok((target.read(&readback)?, stats, counts))
    }
}

impl BftSurface {
    /// The capture pipeline of `spacing` (created on first use): its handle and layout.
    fn capture_pipeline(
        &mut self,
        renderer: &Renderer,
        spacing: Spacing,
    ) -> Result<(vk::Pipeline, vk::PipelineLayout)> {
        if let Some(p) = self.capture_pipelines.get(&spacing) {
            return Ok((p.raw, p.layout));
        }
        let variant = Variant {
            spacing: Some(spacing),
            capture: true,
        };
        let mut desc =
            GraphicsPipelineDesc::new("bft capture", vk::Format::UNDEFINED, vk::Format::UNDEFINED);
        desc.stages = [Stage::BftBftVert, Stage::BftBftTesc, Stage::BftBftTese]
            .into_iter()
            .map(|s| Ok(ShaderStage::new(s.vk_stage(), spirv(s, variant)?)))
            .collect::<Result<_>>()?;
        desc.topology = vk::PrimitiveTopology::PATCH_LIST;
        desc.tessellation = Some(TessellationDesc {
            patch_control_points: 1,
            domain_origin: vk::TessellationDomainOrigin::UPPER_LEFT,
        });
        desc.set_layouts = vec![renderer.frame_set_layout(), self.set_layout.raw];
        desc.push_constant_bytes = std::mem::size_of::<BftPush>() as u32;
        desc.rasterizer_discard = true;
        desc.depth_test = false;
        desc.depth_write = false;
        let p = Pipeline::graphics(&self.device, &desc)?;
        let handles = (p.raw, p.layout);
        self.capture_pipelines.insert(spacing, p);
        Ok(handles)
    }

    /// Captures, through transform feedback, every triangle corner the BFT TES emits for one
    /// frame of `draw` (camera) and `params` (factors), after running the compute pass on the
    /// current base positions. Sized by a first pass's stream query when the factors are
    /// adaptive, so no triangle is dropped.
    pub fn capture(
        &mut self,
        renderer: &mut Renderer,
        draw: &crate::DrawParams,
        params: &BftParams,
        extent: vk::Extent2D,
    ) -> Result<CapturedSoup> {
        self.check_params(params)?;
        let device = self.device.clone();
        let xfb = device.transform_feedback()?.clone();
        let (pipeline, layout) = self.capture_pipeline(renderer, params.spacing())?;
        renderer.update_frame(0, (self.bbox_min, self.bbox_max), draw, extent)?;
        let mut capacity: u64 = match params.factors {
            FactorPolicy::Uniform { segments } => {
                self.gpu.patch_count as u64
                    * crate::tessellator::uniform_triangle_count(
                        Domain::Triangle,
                        params.spacing(),
                        segments as f32 * 0.5,
                    )
            }
            _ => self.gpu.patch_count as u64 * 16,
        };
        let per_draw = self.patches_per_draw(params, draw.split);
        let mut push = self.push(params, 0);
        let total = self.gpu.patch_count;
        let set = self.sets[0];
        let frame_set = renderer.frame_set(0);
        for _pass in 0..2 {
            let bytes = capacity.max(1) * 3 * CAPTURE_STRIDE;
            if bytes > device.info.caps.max_transform_feedback_buffer_size {
                return Err(TessError::Invalid(format!(
                    "capture needs {bytes} bytes, more than the device's transform feedback limit"
                )));
            }
            let buffer = Buffer::new(
                &device,
                &BufferDesc {
                    name: "bft capture records",
                    size: bytes,
                    usage: vk::BufferUsageFlags::TRANSFORM_FEEDBACK_BUFFER_EXT,
                    location: MemoryLocation::GpuToCpu,
                },
            )?;
            let query = QueryPool::transform_feedback_stream(&device, "bft capture", 1)?;
            let mut failure = None;
            device.one_shot(|cmd| {
                query.cmd_reset(cmd);
                self.record_compute(cmd, renderer, 0);
                // SAFETY: pipeline, sets and buffer live until one_shot returns (it waits); the
                // bound region is the whole buffer.
                unsafe {
                    begin_capture_scope(
                        &device,
                        &xfb,
                        cmd,
                        (pipeline, layout),
                        &[frame_set, set],
                        (buffer.raw, 0, bytes),
                    )
                };
                if let Err(e) = query.cmd_begin_stream(cmd, 0, 0) {
                    failure = Some(e);
                }
                // SAFETY: the capture pipeline and its sets are bound in the scope above.
                unsafe { record_patch_draws(&device, cmd, layout, &mut push, total, per_draw) };
                if let Err(e) = query.cmd_end_stream(cmd, 0, 0) {
                    failure = Some(e);
                }
                // SAFETY: the scope was begun above; cmd is then outside any rendering scope.
                unsafe {
                    end_capture_scope(&device, &xfb, cmd);
                    capture_to_host_barrier(&device, cmd);
                }
            })?;
            if let Some(e) = failure {
                return Err(e.into());
            }
            let counts = query.transform_feedback_results()?;
            let c = counts.first().copied().unwrap_or_default();
            if c.primitives_needed > capacity {
                capacity = c.primitives_needed;
                continue;
            }
            let all: Vec<CaptureRecord> = buffer.read()?;
            let n = (c.primitives_written as usize * 3).min(all.len());
            return Ok(CapturedSoup {
                records: all[..n].to_vec(),
            });
        }
        Err(TessError::Invalid(
            "transform feedback overflowed twice".into(),
        ))
    }

    /// Maps a captured (patch, `gl_TessCoord.xy`) to the base face and its domain coordinate in
    /// [`crate::capture::face_corner_uv`]'s convention (weights of the base face's corners 0, 1).
    pub fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        if patch >= self.gpu.patch_count {
            return None;
        }
        let (u, v) = patch_uv(domain);
        let (f, bu, bv) = self.bft.base_domain(patch as usize, u, v);
        Some(FacePoint {
            face: f as u32,
            u: (1.0 - bu - bv) as f32,
            v: bu as f32,
        })
    }
}

/// The patch coordinate `(u, v)` (weights of the patch's `v1`, `v2`) of a captured
/// `gl_TessCoord.xy` (weights of `v0`, `v1`).
pub fn patch_uv(domain: [f32; 2]) -> (f64, f64) {
    let (x, y) = (domain[0] as f64, domain[1] as f64);
    (y, 1.0 - x - y)
}
