//! Draws a mesh with one of the triangle/quad techniques (flat, Phong, PN triangles), shaded,
//! with an optional wireframe overlay. Pipelines are created on first use, keyed by
//! [`PipelineKey`]; spacing variants are separate TES binaries (a layout qualifier).
use crate::camera::Camera;
use crate::error::{Result, TessError};
use crate::gpu::bindings::FRAME_UNIFORMS_BINDING;
use crate::gpu::{DrawPush, FrameUniforms, Vertex};
use crate::render_mesh::RenderMesh;
use crate::shaders::{spirv, Stage, Variant};
use crate::tessellator::{uniform_vertex_count, Domain, Spacing};
use std::collections::HashMap;
use vk_core::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use vk_core::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage, TessellationDesc};
use vk_core::query::{PipelineStatistics, QueryPool};
use vk_core::target::{OffscreenTarget, Rgba8, COLOR_FORMAT, DEPTH_FORMAT};
use vk_core::{vk, Buffer, BufferDesc, Device, MemoryLocation};

/// The surface technique a draw uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Planar subdivision of each face (quads kept as quad patches).
    #[default]
    Flat,
    /// Phong tessellation (Boubekeur & Alexa 2008) on triangles.
    Phong,
    /// Curved PN triangles with the corrected normal field.
    Pn,
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "flat" => Ok(Method::Flat),
            "phong" => Ok(Method::Phong),
            "pn" => Ok(Method::Pn),
            _ => Err(format!("unknown method '{s}' (flat, phong, pn)")),
        }
    }
}

/// Whether tessellated draws are split for drivers that need it. `Off` exists only so a test can
/// show the driver bug the split works around.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DrawSplit {
    #[default]
    Auto,
    Off,
    /// One patch per draw: the slowest and surest reference.
    PerPatch,
}

/// Everything that decides what one frame shows.
#[derive(Clone, Copy, Debug)]
pub struct DrawParams {
    pub method: Method,
    pub spacing: Spacing,
    /// Outer and inner tessellation level (uniform factors).
    pub level: f32,
    pub wireframe: bool,
    pub camera: Camera,
    /// Phong tessellation shape factor α.
    pub phong_alpha: f32,
    pub split: DrawSplit,
    pub base_color: [f32; 3],
    pub clear_color: [f32; 4],
}

impl Default for DrawParams {
    fn default() -> Self {
        Self {
            method: Method::Flat,
            spacing: Spacing::Equal,
            level: 4.0,
            wireframe: false,
            camera: Camera::default(),
            phong_alpha: 0.75,
            split: DrawSplit::Auto,
            base_color: [0.85, 0.72, 0.55],
            clear_color: [0.12, 0.13, 0.16, 1.0],
        }
    }
}

/// Selects one pipeline: technique, patch domain, spacing, and fill or wireframe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub method: Method,
    pub domain: Domain,
    pub spacing: Spacing,
    pub wireframe: bool,
}

/// A mesh's buffers on the GPU: vertices and one index buffer per patch list.
pub struct GpuMesh {
    pub vertices: Buffer,
    /// All faces as triangles.
    pub triangles: Option<PatchList>,
    /// Quads, and the non-quad faces as triangles, for flat quad tessellation.
    pub quads: Option<PatchList>,
    pub quad_mode_triangles: Option<PatchList>,
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
    pub vertex_count: u32,
}

pub struct PatchList {
    pub indices: Buffer,
    pub patches: u32,
    pub control_points: u32,
}

fn patch_list(
    device: &Device,
    name: &str,
    indices: &[u32],
    control_points: u32,
) -> Result<Option<PatchList>> {
    if indices.is_empty() {
        return Ok(None);
    }
    let buffer = Buffer::with_data(
        device,
        name,
        vk::BufferUsageFlags::INDEX_BUFFER,
        bytemuck::cast_slice(indices),
    )?;
    Ok(Some(PatchList {
        indices: buffer,
        patches: indices.len() as u32 / control_points,
        control_points,
    }))
}

impl GpuMesh {
    pub fn upload(device: &Device, mesh: &RenderMesh) -> Result<Self> {
        let n = mesh.vertices.len() as u32;
        // Indices were validated by RenderMesh; assert the invariant before anything reaches the GPU.
        let in_range = |l: &[u32]| l.iter().all(|&i| i < n);
        let tri: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let quad: Vec<u32> = mesh.quads.iter().flatten().copied().collect();
        let qtri: Vec<u32> = mesh.quad_mode_triangles.iter().flatten().copied().collect();
        if !(in_range(&tri) && in_range(&quad) && in_range(&qtri)) {
            return Err(TessError::Invalid(
                "patch index out of range of the vertex buffer".into(),
            ));
        }
        let vertices = Buffer::with_data(
            device,
            "mesh vertices",
            vk::BufferUsageFlags::VERTEX_BUFFER,
            bytemuck::cast_slice(&mesh.vertices),
        )?;
        Ok(Self {
            vertices,
            triangles: patch_list(device, "triangle patches", &tri, 3)?,
            quads: patch_list(device, "quad patches", &quad, 4)?,
            quad_mode_triangles: patch_list(device, "quad-mode triangle patches", &qtri, 3)?,
            bbox_min: mesh.bbox_min,
            bbox_max: mesh.bbox_max,
            vertex_count: n,
        })
    }
}

/// Set 0 of every pipeline that includes `frame.glsl`: one uniform buffer and descriptor set
/// per frame slot, with their layout. Drop order: pool (frees the sets), layout, buffers.
pub(crate) struct FrameSets {
    _pool: DescriptorPool,
    layout: DescriptorSetLayout,
    slots: Vec<(Buffer, vk::DescriptorSet)>,
}

impl FrameSets {
    /// `slots` uniform buffers and sets, named after `name` (for debuggers).
    pub(crate) fn new(device: &Device, name: &str, slots: usize) -> Result<Self> {
        let layout = DescriptorSetLayout::new(
            device,
            &format!("{name} frame set layout"),
            &[BindingDesc {
                binding: FRAME_UNIFORMS_BINDING,
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                stages: vk::ShaderStageFlags::ALL_GRAPHICS,
            }],
        )?;
        let pool = DescriptorPool::new(
            device,
            &format!("{name} frame descriptor pool"),
            &layout,
            slots as u32,
        )?;
        let mut out = Vec::with_capacity(slots);
        for i in 0..slots {
            let uniforms = Buffer::new(
                device,
                &BufferDesc {
                    name: &format!("{name} frame uniforms {i}"),
                    size: std::mem::size_of::<FrameUniforms>() as u64,
                    usage: vk::BufferUsageFlags::UNIFORM_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?;
            let set = pool.allocate(&layout)?;
            pool.write_buffers(
                set,
                &[(
                    FRAME_UNIFORMS_BINDING,
                    vk::DescriptorType::UNIFORM_BUFFER,
                    uniforms.descriptor(),
                )],
            );
            out.push((uniforms, set));
        }
        Ok(Self {
            _pool: pool,
            layout,
            slots: out,
        })
    }

    pub(crate) fn layout(&self) -> vk::DescriptorSetLayout {
        self.layout.raw
    }

    /// The set of slot `slot`, or a typed error for a slot that does not exist.
    pub(crate) fn set(&self, slot: usize) -> Result<vk::DescriptorSet> {
        self.slots
            .get(slot)
            .map(|s| s.1)
            .ok_or_else(|| TessError::Invalid(format!("no frame slot {slot}")))
    }

    pub(crate) fn write(&mut self, slot: usize, uniforms: &FrameUniforms) -> Result<()> {
        let s = self
            .slots
            .get_mut(slot)
            .ok_or_else(|| TessError::Invalid(format!("no frame slot {slot}")))?;
        s.0.write(0, bytemuck::bytes_of(uniforms))?;
        Ok(())
    }
}

/// Owns pipelines and per-frame uniforms. Drop order: pipelines, frame sets, then the device
/// handle.
pub struct Renderer {
    pipelines: HashMap<PipelineKey, Pipeline>,
    frames: FrameSets,
    color_format: vk::Format,
    depth_format: vk::Format,
    device: Device,
}

/// How many draws and patches one recorded frame issued (for tests of the draw split).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawCounts {
    pub draws: u32,
    pub patches: u32,
}

impl Renderer {
    pub fn new(
        device: &Device,
        color_format: vk::Format,
        depth_format: vk::Format,
        frames_in_flight: usize,
    ) -> Result<Self> {
        Ok(Self {
            pipelines: HashMap::new(),
            frames: FrameSets::new(device, "renderer", frames_in_flight)?,
            color_format,
            depth_format,
            device: device.clone(),
        })
    }

    /// A renderer for offscreen targets (RGBA8 + D32), one frame slot.
    pub fn offscreen(device: &Device) -> Result<Self> {
        Self::new(device, COLOR_FORMAT, DEPTH_FORMAT, 1)
    }

    pub fn device(&self) -> &Device {
        &self.device
    }

    /// Layout of set 0 (the frame uniforms), shared by every technique's pipelines.
    pub fn frame_set_layout(&self) -> vk::DescriptorSetLayout {
        self.frames.layout()
    }

    /// Set 0 of frame slot `slot` (clamped to the slots there are).
    pub fn frame_set(&self, slot: usize) -> vk::DescriptorSet {
        let last = self.frames.slots.len() - 1;
        self.frames.slots[slot.min(last)].1
    }

    /// Colour and depth formats the pipelines render to.
    pub fn formats(&self) -> (vk::Format, vk::Format) {
        (self.color_format, self.depth_format)
    }

    fn pipeline(&mut self, key: PipelineKey) -> Result<&Pipeline> {
        if !self.pipelines.contains_key(&key) {
            let p = self.build_pipeline(key)?;
            self.pipelines.insert(key, p);
        }
        Ok(&self.pipelines[&key])
    }

    fn build_pipeline(&self, key: PipelineKey) -> Result<Pipeline> {
        let (tesc, tese, cp) = technique_stages(key.method, key.domain, key.spacing, false)?;
        let name = format!(
            "{:?} {:?} {:?}{}",
            key.method,
            key.domain,
            key.spacing,
            if key.wireframe { " wireframe" } else { "" }
        );
        let mut desc = GraphicsPipelineDesc::new(&name, self.color_format, self.depth_format);
        desc.stages = vec![
            ShaderStage::new(
                vk::ShaderStageFlags::VERTEX,
                spirv(Stage::CommonMeshVert, Variant::default())?,
            ),
            ShaderStage::new(vk::ShaderStageFlags::TESSELLATION_CONTROL, tesc),
            ShaderStage::new(vk::ShaderStageFlags::TESSELLATION_EVALUATION, tese),
            ShaderStage::new(
                vk::ShaderStageFlags::FRAGMENT,
                spirv(Stage::CommonShadeFrag, Variant::default())?,
            ),
        ];
        set_patch_input(&mut desc, cp, self.frames.layout());
        set_pass_style(&mut desc, key.wireframe);
        Ok(Pipeline::graphics(&self.device, &desc)?)
    }

    /// Writes the frame uniforms of slot `slot` for `params` and a target of `extent`.
    pub fn update_uniforms(
        &mut self,
        slot: usize,
        mesh: &GpuMesh,
        params: &DrawParams,
        extent: vk::Extent2D,
    ) -> Result<()> {
        self.update_frame(slot, (mesh.bbox_min, mesh.bbox_max), params, extent)
    }

    /// Writes the frame uniforms of slot `slot` for a scene framed by `bbox`.
    pub fn update_frame(
        &mut self,
        slot: usize,
        bbox: ([f32; 3], [f32; 3]),
        params: &DrawParams,
        extent: vk::Extent2D,
    ) -> Result<()> {
        self.frames
            .write(slot, &frame_uniforms_for(bbox, params, extent))
    }

    /// Records the draws of one frame inside an active rendering scope.
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        slot: usize,
        mesh: &GpuMesh,
        params: &DrawParams,
    ) -> Result<DrawCounts> {
        let passes: &[bool] = if params.wireframe {
            &[false, true]
        } else {
            &[false]
        };
        self.record_passes(cmd, slot, mesh, params, passes)
    }

    /// Records the shaded (`false`) and/or wireframe (`true`) passes.
    fn record_passes(
        &mut self,
        cmd: vk::CommandBuffer,
        slot: usize,
        mesh: &GpuMesh,
        params: &DrawParams,
        passes: &[bool],
    ) -> Result<DrawCounts> {
        let mut counts = DrawCounts::default();
        let set = self.frames.set(slot)?;
        let lists = draw_lists(mesh, params.method);
        let device = self.device.clone();
        device.begin_label(cmd, &format!("{:?} level {}", params.method, params.level));
        for &wire in passes {
            for draw in &lists {
                let key = PipelineKey {
                    method: params.method,
                    domain: draw.domain,
                    spacing: params.spacing,
                    wireframe: wire,
                };
                let pipeline = self.pipeline(key)?;
                // SAFETY: cmd is recording inside a rendering scope; the pipeline and set are
                // live and owned by self, which outlives the submission (callers wait).
                unsafe {
                    device.raw.cmd_bind_pipeline(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        pipeline.raw,
                    );
                    device.raw.cmd_bind_descriptor_sets(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        pipeline.layout,
                        0,
                        &[set],
                        &[],
                    );
                }
                let per_draw =
                    patches_per_draw(&device, params, draw.domain, draw.list.control_points);
                let c = record_list_draws(
                    &device,
                    cmd,
                    pipeline.layout,
                    mesh,
                    draw,
                    wire as u32,
                    per_draw,
                );
                counts.draws += c.draws;
                counts.patches += c.patches;
            }
        }
        device.end_label(cmd);
        Ok(counts)
    }

    /// Renders one frame offscreen and reads it back.
    pub fn render_offscreen(
        &mut self,
        mesh: &GpuMesh,
        params: &DrawParams,
        extent: vk::Extent2D,
    ) -> Result<Rgba8> {
        Ok(self.render_offscreen_stats(mesh, params, extent, false)?.0)
    }

    /// Renders offscreen; with `statistics`, also returns the pipeline statistics of the shaded
    /// pass (the wireframe pass, if any, is outside the query).
    pub fn render_offscreen_stats(
        &mut self,
        mesh: &GpuMesh,
        params: &DrawParams,
        extent: vk::Extent2D,
        statistics: bool,
    ) -> Result<(Rgba8, Option<PipelineStatistics>, DrawCounts)> {
        let device = self.device.clone();
        let target = OffscreenTarget::new(&device, extent)?;
        let readback = target.readback_buffer(&device)?;
        let query = if statistics {
            Some(QueryPool::statistics(&device, "pipeline statistics", 1)?)
        } else {
            None
        };
        self.update_uniforms(0, mesh, params, extent)?;
        let mut result = Ok(DrawCounts::default());
        device.one_shot(|cmd| {
            if let Some(q) = &query {
                q.cmd_reset(cmd);
            }
            target.cmd_begin(&device, cmd, params.clear_color);
            if let Some(q) = &query {
                // SAFETY: the query was reset above in this command buffer.
                unsafe {
                    device
                        .raw
                        .cmd_begin_query(cmd, q.raw, 0, vk::QueryControlFlags::empty())
                };
            }
            result = self.record_passes(cmd, 0, mesh, params, &[false]);
            if let Some(q) = &query {
                // SAFETY: matches the begin above.
                unsafe { device.raw.cmd_end_query(cmd, q.raw, 0) };
            }
            if params.wireframe {
                if let Ok(shaded) = result {
                    result =
                        self.record_passes(cmd, 0, mesh, params, &[true])
                            .map(|w| DrawCounts {
                                draws: shaded.draws + w.draws,
                                patches: shaded.patches + w.patches,
                            });
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

/// The frame block for `params` on a target of `extent`: camera, light, uniform levels, colours.
pub(crate) fn frame_uniforms(
    mesh: &GpuMesh,
    params: &DrawParams,
    extent: vk::Extent2D,
) -> FrameUniforms {
    frame_uniforms_for((mesh.bbox_min, mesh.bbox_max), params, extent)
}

/// Frame uniforms for a scene framed by `bbox`; shared by every pipeline that includes
/// `frame.glsl` (tessellated or not), so they all see the same view.
pub fn frame_uniforms_for(
    bbox: ([f32; 3], [f32; 3]),
    params: &DrawParams,
    extent: vk::Extent2D,
) -> FrameUniforms {
    let aspect = extent.width as f32 / extent.height.max(1) as f32;
    let m = params.camera.matrices(bbox.0, bbox.1, aspect);
    let light =
        (m.eye - glam::Vec3::from(bbox.0).lerp(glam::Vec3::from(bbox.1), 0.5)).normalize_or_zero();
    let light = (light + glam::Vec3::new(0.3, 0.6, 0.2)).normalize_or_zero();
    let level = params.level.clamp(1.0, crate::tessellator::MAX_LEVEL);
    FrameUniforms {
        view_proj: (m.proj * m.view).to_cols_array_2d(),
        view: m.view.to_cols_array_2d(),
        camera_pos: [m.eye.x, m.eye.y, m.eye.z, 1.0],
        light_dir: [light.x, light.y, light.z, 0.0],
        tess: [level, level, params.phong_alpha, 0.0],
        base_color: [
            params.base_color[0],
            params.base_color[1],
            params.base_color[2],
            1.0,
        ],
        wire_color: [0.05, 0.05, 0.08, 1.0],
        viewport: [extent.width as f32, extent.height as f32, 0.0, 0.0],
    }
}

/// The TCS, the TES (the `-DCAPTURE` build when `capture`) and the control points per patch of
/// one technique on one patch domain.
pub(crate) fn technique_stages(
    method: Method,
    domain: Domain,
    spacing: Spacing,
    capture: bool,
) -> Result<(&'static [u32], &'static [u32], u32)> {
    // (method, domain) → (TCS, TES, control points per patch); the variant picks the build.
    #[rustfmt::skip]
    const STAGES: [(Method, Domain, Stage, Stage, u32); 4] = [
        (Method::Flat, Domain::Quad, Stage::CommonQuadTesc, Stage::FlatQuadTese, 4),
        (Method::Flat, Domain::Triangle, Stage::CommonTriTesc, Stage::FlatTriTese, 3),
        (Method::Phong, Domain::Triangle, Stage::CommonTriTesc, Stage::PhongTriTese, 3),
        (Method::Pn, Domain::Triangle, Stage::PnTriTesc, Stage::PnTriTese, 3),
    ];
    let &(_, _, tesc, tese, control_points) = STAGES
        .iter()
        .find(|s| s.0 == method && s.1 == domain)
        .ok_or_else(|| TessError::Invalid(format!("{method:?} has no {domain:?} patches")))?;
    let variant = Variant {
        spacing: Some(spacing),
        capture,
    };
    Ok((spirv(tesc, variant)?, spirv(tese, variant)?, control_points))
}

/// Shaded pass or wireframe overlay: the overlay draws lines without writing depth, the shaded
/// pass is pushed slightly back so the overlay wins the depth test. Every technique uses this.
pub(crate) fn set_pass_style(desc: &mut GraphicsPipelineDesc<'_>, wireframe: bool) {
    if wireframe {
        desc.polygon_mode = vk::PolygonMode::LINE;
        desc.depth_compare = vk::CompareOp::LESS_OR_EQUAL;
        desc.depth_write = false;
    } else {
        desc.depth_bias = Some((1.0, 1.0));
    }
}

/// Vertex input of the interleaved [`Vertex`] (position at location 0, normal at 1): what mesh.vert
/// and plain.vert read.
pub(crate) fn set_vertex_input(desc: &mut GraphicsPipelineDesc<'_>) {
    desc.vertex_bindings = vec![Vertex::BINDING];
    desc.vertex_attributes = Vertex::ATTRIBUTES.to_vec();
}

/// Vertex input (the mesh's interleaved [`Vertex`]), patch topology, the frame set and the
/// [`DrawPush`] range: what render and capture pipelines share.
pub(crate) fn set_patch_input(
    desc: &mut GraphicsPipelineDesc<'_>,
    control_points: u32,
    set_layout: vk::DescriptorSetLayout,
) {
    set_vertex_input(desc);
    desc.topology = vk::PrimitiveTopology::PATCH_LIST;
    desc.tessellation = Some(TessellationDesc {
        patch_control_points: control_points,
        domain_origin: vk::TessellationDomainOrigin::UPPER_LEFT,
    });
    desc.set_layouts = vec![set_layout];
    desc.push_constant_bytes = std::mem::size_of::<DrawPush>() as u32;
}

/// One patch list a technique draws, with where its patches start in the frame's numbering.
pub struct DrawList<'a> {
    pub list: &'a PatchList,
    pub domain: Domain,
    /// Patch id of the list's first patch.
    pub first_patch: u32,
}

/// The patch lists `method` draws, in order, numbered frame-wide: flat draws the quads
/// (ids `0..quads`) then the other faces' triangles (ids `quads..`); Phong and PN draw every
/// face's triangles (ids `0..triangles`). The captured patch id is this number, which
/// [`RenderMesh::patch_origins`] maps back to base faces.
pub fn draw_lists(mesh: &GpuMesh, method: Method) -> Vec<DrawList<'_>> {
    let lists: Vec<(Option<&PatchList>, Domain)> = match method {
        Method::Flat => vec![
            (mesh.quads.as_ref(), Domain::Quad),
            (mesh.quad_mode_triangles.as_ref(), Domain::Triangle),
        ],
        Method::Phong | Method::Pn => vec![(mesh.triangles.as_ref(), Domain::Triangle)],
    };
    let mut first_patch = 0;
    let mut out = Vec::new();
    for (list, domain) in lists {
        if let Some(list) = list {
            out.push(DrawList {
                list,
                domain,
                first_patch,
            });
            first_patch += list.patches;
        }
    }
    out
}

/// Binds `list`'s buffers and records its draws, split `per_draw` patches at a time, each with
/// its own [`DrawPush::first_patch`]. The pipeline and descriptor set must be bound.
pub(crate) fn record_list_draws(
    device: &Device,
    cmd: vk::CommandBuffer,
    layout: vk::PipelineLayout,
    mesh: &GpuMesh,
    draw: &DrawList<'_>,
    mode: u32,
    per_draw: u32,
) -> DrawCounts {
    let list = draw.list;
    let mut counts = DrawCounts::default();
    // SAFETY: cmd is recording with a compatible pipeline bound; the buffers are live and owned
    // by mesh, which outlives the submission (callers wait).
    unsafe {
        device
            .raw
            .cmd_bind_vertex_buffers(cmd, 0, &[mesh.vertices.raw], &[0]);
        device
            .raw
            .cmd_bind_index_buffer(cmd, list.indices.raw, 0, vk::IndexType::UINT32);
    }
    let per_draw = per_draw.max(1);
    let mut first = 0;
    while first < list.patches {
        let n = per_draw.min(list.patches - first);
        let push = DrawPush {
            mode,
            first_patch: draw.first_patch + first,
        };
        // SAFETY: the layout has a DrawPush-sized range for all stages; first + n ≤ patches,
        // so the index range lies inside the index buffer.
        unsafe {
            device.raw.cmd_push_constants(
                cmd,
                layout,
                vk::ShaderStageFlags::ALL,
                0,
                bytemuck::bytes_of(&push),
            );
            device.raw.cmd_draw_indexed(
                cmd,
                n * list.control_points,
                1,
                first * list.control_points,
                0,
                0,
            )
        };
        counts.draws += 1;
        counts.patches += n;
        first += n;
    }
    counts
}

/// Patches per draw call: the whole list, unless a driver workaround limits it (see
/// `vk_core::workarounds::WorkaroundId::LavapipeTessChunkVertexLimit`).
pub fn patches_per_draw(
    device: &Device,
    params: &DrawParams,
    domain: Domain,
    _control_points: u32,
) -> u32 {
    match params.split {
        DrawSplit::Off => u32::MAX,
        DrawSplit::PerPatch => 1,
        DrawSplit::Auto => {
            let max_vertices = uniform_vertex_count(
                domain,
                params.spacing,
                params.level.clamp(1.0, crate::tessellator::MAX_LEVEL),
            );
            device.workarounds.max_patches_per_draw(max_vertices)
        }
    }
}
