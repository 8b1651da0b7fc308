//! The context every technique draws through: frame uniforms (set 0 of every pipeline), the
//! one pipeline cache, per-technique descriptor-set layouts, and the recording of a frame —
//! pre-pass, shaded pass, wireframe overlay, capture pass — the same for every technique.
//!
//! Pipelines are built on first use from a technique's [`PatchPipeline`] and keyed by
//! [`PipelineKey`] (technique, patch type, spacing, pass, builds). Both draw paths go through
//! the same cache and the same pass styles: tessellated patches (`PATCH_LIST`, the evaluation
//! stage built per spacing, since spacing is a layout qualifier and selects a SPIR-V variant)
//! and vertex-stage triangles (`TRIANGLE_LIST`, the vertex stage last before rasterization).
//!
//! Drop order (field order): pipelines, set layouts, frame sets, device handle.
use crate::error::{Result, TessError};
use crate::gpu::bindings::FRAME_UNIFORMS_BINDING;
use crate::gpu::FrameUniforms;
use crate::shaders::{self, Variant};
use crate::technique::{
    DrawCounts, DrawSplit, FactorPolicy, FrameParams, Geometry, Pass, PatchPipeline, PatchType,
    Technique, TechniqueId,
};
use crate::tessellator::{Spacing, MAX_LEVEL};
use std::collections::HashMap;
use std::mem::size_of;
use vk_core::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use vk_core::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage, Subpass, TessellationDesc};
use vk_core::query::{PipelineStatistics, QueryPool};
use vk_core::target::{OffscreenTarget, Rgba8, COLOR_FORMAT, DEPTH_FORMAT};
use vk_core::workarounds::WorkaroundId;
use vk_core::{vk, Buffer, BufferDesc, DescriptorSet, Device, Encoder, MemoryLocation};

/// Selects one pipeline of the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub technique: TechniqueId,
    pub patch: PatchType,
    pub spacing: Spacing,
    pub pass: Pass,
    /// The evaluation stage's surface build ([`crate::Technique::surface_build`]).
    pub surface: bool,
    /// The technique's own axes ([`crate::technique::PatchPipeline::axes`]): two builds of one
    /// technique may differ in them.
    pub axes: Variant,
}

impl PipelineKey {
    /// The pipeline `technique` draws `patch` with in `pass` of a frame of `params`. Spacing
    /// keys only tessellated pipelines (the vertex-stage path has no tessellator).
    pub fn of(
        technique: &dyn Technique,
        patch: PatchType,
        params: &FrameParams,
        pass: Pass,
    ) -> Self {
        let pp = technique.patch_pipeline(patch);
        Self {
            technique: technique.id(),
            patch,
            spacing: if pp.geometry.is_tessellated() {
                params.spacing
            } else {
                Spacing::Equal
            },
            pass,
            surface: technique.surface_build(params),
            axes: pp.axes,
        }
    }
}

/// Set 0 of every pipeline: one uniform buffer and descriptor set per frame slot.
/// Drop order: sets (they keep their pool alive), pool, layout, buffers.
struct FrameSets {
    slots: Vec<(DescriptorSet, Buffer)>,
    _pool: DescriptorPool,
    layout: DescriptorSetLayout,
}

impl FrameSets {
    fn new(device: &Device, slots: usize) -> Result<Self> {
        let layout = DescriptorSetLayout::new(
            device,
            "frame set layout",
            &[BindingDesc {
                binding: FRAME_UNIFORMS_BINDING,
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                stages: vk::ShaderStageFlags::ALL_GRAPHICS | vk::ShaderStageFlags::COMPUTE,
            }],
        )?;
        let pool = DescriptorPool::new(device, "frame descriptor pool", &layout, slots as u32)?;
        let mut out = Vec::with_capacity(slots);
        for i in 0..slots {
            let uniforms = Buffer::new(
                device,
                &BufferDesc {
                    name: &format!("frame uniforms {i}"),
                    size: size_of::<FrameUniforms>() as u64,
                    usage: vk::BufferUsageFlags::UNIFORM_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?;
            let set = pool.allocate_set(&layout)?;
            set.write_buffer(
                FRAME_UNIFORMS_BINDING,
                vk::DescriptorType::UNIFORM_BUFFER,
                &uniforms,
            )?;
            out.push((set, uniforms));
        }
        Ok(Self {
            slots: out,
            _pool: pool,
            layout,
        })
    }
}

/// See the module docs.
pub struct Context {
    pipelines: HashMap<PipelineKey, Pipeline>,
    /// Refinement patterns made so far (host data; techniques upload what they draw).
    patterns: crate::pattern::PatternCache,
    set_layouts: HashMap<TechniqueId, DescriptorSetLayout>,
    frames: FrameSets,
    color_format: vk::Format,
    depth_format: vk::Format,
    /// The host's render pass subpass the draw pipelines are made for; `None`: dynamic
    /// rendering ([`Self::for_subpass`]).
    subpass: Option<Subpass>,
    /// The frame block last written and its frame slot ([`Self::frame_view`]).
    view: Option<(usize, FrameUniforms)>,
    device: Device,
}

impl Context {
    /// A context rendering to `color_format`/`depth_format` with `frames_in_flight` frame
    /// slots (frame `k + 1` writes its uniforms while frame `k` renders).
    pub fn new(
        device: &Device,
        color_format: vk::Format,
        depth_format: vk::Format,
        frames_in_flight: usize,
    ) -> Result<Self> {
        if frames_in_flight == 0 {
            return Err(TessError::FrameSlot { slot: 0, slots: 0 });
        }
        Ok(Self {
            pipelines: HashMap::new(),
            patterns: Default::default(),
            set_layouts: HashMap::new(),
            frames: FrameSets::new(device, frames_in_flight)?,
            view: None,
            color_format,
            depth_format,
            subpass: None,
            device: device.clone(),
        })
    }

    /// A context whose draw pipelines render in `subpass` of a host's render pass (whose
    /// colour and depth attachments have these formats; `UNDEFINED` for none) instead of a
    /// dynamic-rendering scope. Capture pipelines still use a scope of their own.
    pub fn for_subpass(
        device: &Device,
        subpass: Subpass,
        color_format: vk::Format,
        depth_format: vk::Format,
        frames_in_flight: usize,
    ) -> Result<Self> {
        let mut ctx = Self::new(device, color_format, depth_format, frames_in_flight)?;
        ctx.subpass = Some(subpass);
        Ok(ctx)
    }

    /// A context for offscreen targets (RGBA8 + D32) and captures, one frame slot.
    pub fn offscreen(device: &Device) -> Result<Self> {
        Self::new(device, COLOR_FORMAT, DEPTH_FORMAT, 1)
    }

    /// The refinement pattern of one patch of `domain` at uniform `level` with `spacing`, made
    /// on first use ([`crate::pattern::make`]) and shared by every surface drawn
    /// through this context.
    pub fn refinement_pattern(
        &mut self,
        domain: crate::tessellator::Domain,
        spacing: Spacing,
        level: f32,
    ) -> Result<std::sync::Arc<crate::pattern::RefinementPattern>> {
        self.refinement_pattern_for(crate::pattern::PatternKey::new(domain, spacing, level))
    }

    /// The refinement pattern of `key` (per-edge levels too), made on first use
    /// ([`crate::pattern::make`]) and shared by every surface drawn through this context.
    pub fn refinement_pattern_for(
        &mut self,
        key: crate::pattern::PatternKey,
    ) -> Result<std::sync::Arc<crate::pattern::RefinementPattern>> {
        if let Some(p) = self.patterns.cached(key) {
            return Ok(p);
        }
        let pattern = std::sync::Arc::new(crate::pattern::make(self, key)?);
        self.patterns.insert(key, pattern.clone());
        Ok(pattern)
    }

    /// Makes `pattern` the one this context draws for its domain at `spacing` and `level` (a
    /// benchmark comparing paths on one pattern); surfaces take it from their next frame.
    pub fn set_refinement_pattern(
        &mut self,
        spacing: Spacing,
        level: f32,
        pattern: std::sync::Arc<crate::pattern::RefinementPattern>,
    ) {
        let key = crate::pattern::PatternKey::new(pattern.domain, spacing, level);
        self.patterns.insert(key, pattern);
    }

    pub fn device(&self) -> &Device {
        &self.device
    }

    pub fn frames_in_flight(&self) -> usize {
        self.frames.slots.len()
    }

    /// Colour and depth formats the pipelines render to.
    pub fn formats(&self) -> (vk::Format, vk::Format) {
        (self.color_format, self.depth_format)
    }

    /// The frame set of `slot`, or a typed error for a slot that does not exist.
    pub fn frame_set(&self, slot: usize) -> Result<&DescriptorSet> {
        self.frames
            .slots
            .get(slot)
            .map(|s| &s.0)
            .ok_or(TessError::FrameSlot {
                slot,
                slots: self.frames.slots.len(),
            })
    }

    /// The set-1 layout of `technique` (made once, from `bindings`): one per technique
    /// type, so pipelines built for one surface serve every surface of that technique.
    pub fn ensure_set_layout(
        &mut self,
        technique: TechniqueId,
        bindings: &[BindingDesc],
    ) -> Result<()> {
        if !self.set_layouts.contains_key(&technique) {
            let layout = DescriptorSetLayout::new(
                &self.device,
                &format!("{technique} set layout"),
                bindings,
            )?;
            self.set_layouts.insert(technique, layout);
        }
        Ok(())
    }

    /// The set-1 layout of `technique`, once [`Self::ensure_set_layout`] made it.
    pub fn set_layout(&self, technique: TechniqueId) -> Result<&DescriptorSetLayout> {
        self.set_layouts
            .get(&technique)
            .ok_or(TessError::Unsupported {
                technique,
                what: "a descriptor set before its layout was made",
            })
    }

    /// Layout of set 0 (the frame uniforms), for pipelines built outside the cache (compute
    /// pre-passes).
    pub fn frame_set_layout(&self) -> &DescriptorSetLayout {
        &self.frames.layout
    }

    /// Writes the frame uniforms of `slot` for `params` on a target of `extent`, framing `bbox`
    /// (a technique's [`Technique::bbox`]).
    pub fn write_frame(
        &mut self,
        slot: usize,
        bbox: ([f32; 3], [f32; 3]),
        params: &FrameParams,
        extent: vk::Extent2D,
    ) -> Result<()> {
        self.write_frame_uniforms(slot, &frame_uniforms(bbox, params, extent))
    }

    /// The frame block last written ([`Self::write_frame`]): the view and viewport adaptive
    /// factors see. A technique that chooses its levels on the host reads it in
    /// [`Technique::prepare_frame`], so every frame writes its block before [`Self::prepare`].
    pub fn frame_view(&self) -> Option<&FrameUniforms> {
        self.view.as_ref().map(|(_, u)| u)
    }

    /// Writes the frame uniforms of `slot` as given (see [`frame_uniforms_with`]).
    pub fn write_frame_uniforms(&mut self, slot: usize, uniforms: &FrameUniforms) -> Result<()> {
        self.view = Some((slot, *uniforms));
        let slots = self.frames.slots.len();
        let (_, buffer) = self
            .frames
            .slots
            .get_mut(slot)
            .ok_or(TessError::FrameSlot { slot, slots })?;
        buffer.write(0, bytemuck::bytes_of(uniforms))?;
        Ok(())
    }

    /// Checks `params` (what the technique's registry entry says it does not take, then its
    /// own [`Technique::check`]), lets `technique` do the host work of the frame
    /// ([`Technique::prepare_frame`]) and builds the pipelines `passes` need. Must precede
    /// recording (which borrows the context and the technique immutably for the encoder's
    /// lifetime).
    pub fn prepare(
        &mut self,
        technique: &mut dyn Technique,
        params: &FrameParams,
        passes: &[Pass],
    ) -> Result<()> {
        crate::techniques::info(technique.id())
            .features
            .refuse(technique.id(), params)?;
        technique.check(params)?;
        let written = self.view;
        technique.prepare_frame(self, params)?;
        // Making a pattern draws a unit patch through this context (crate::pattern::make),
        // which writes a frame block of its own: the caller's goes back into its slot.
        if let Some((slot, uniforms)) = written {
            let same = self.view.is_some_and(|(s, u)| {
                s == slot && bytemuck::bytes_of(&u) == bytemuck::bytes_of(&uniforms)
            });
            if !same {
                self.write_frame_uniforms(slot, &uniforms)?;
            }
        }
        let technique = &*technique;
        let bindings = technique.set_layout_bindings();
        if !bindings.is_empty() {
            self.ensure_set_layout(technique.id(), bindings)?;
        }
        for array in technique.patch_arrays() {
            for &pass in passes {
                let key = PipelineKey::of(technique, array.patch, params, pass);
                if !self.pipelines.contains_key(&key) {
                    let p = self.build_pipeline(technique, key)?;
                    self.pipelines.insert(key, p);
                }
            }
        }
        Ok(())
    }

    fn build_pipeline(&self, technique: &dyn Technique, key: PipelineKey) -> Result<Pipeline> {
        let pp = technique.patch_pipeline(key.patch);
        let capture = key.pass == Pass::Capture;
        let name = format!(
            "{} {:?} {:?} {:?}",
            key.technique, key.patch, key.spacing, key.pass
        );
        let (color, depth) = if capture {
            (vk::Format::UNDEFINED, vk::Format::UNDEFINED)
        } else {
            (self.color_format, self.depth_format)
        };
        let mut desc = GraphicsPipelineDesc::new(&name, color, depth);
        desc.subpass = if capture { None } else { self.subpass };
        desc.stages = pipeline_stages(&pp, key)?;
        desc.vertex_bindings = pp.vertex_input.bindings.to_vec();
        desc.vertex_attributes = pp.vertex_input.attributes.to_vec();
        match pp.geometry {
            Geometry::Tessellated { control_points, .. } => {
                desc.topology = vk::PrimitiveTopology::PATCH_LIST;
                desc.tessellation = Some(TessellationDesc {
                    patch_control_points: control_points,
                    domain_origin: vk::TessellationDomainOrigin::UPPER_LEFT,
                });
            }
            Geometry::Triangles => desc.topology = vk::PrimitiveTopology::TRIANGLE_LIST,
        }
        desc.set_layouts = vec![self.frames.layout.raw];
        if let Some(l) = self.set_layouts.get(&key.technique) {
            desc.set_layouts.push(l.raw);
        }
        desc.push_constant_bytes = pp.push_constant_bytes;
        set_pass_style(&mut desc, key.pass);
        Ok(Pipeline::graphics(&self.device, &desc)?)
    }

    /// Patches per draw of `array`: all, unless a driver workaround limits the vertices one
    /// draw may emit (`vk_core::workarounds::WorkaroundId::LavapipeTessChunkVertexLimit`,
    /// computed at the largest factor the policy can reach) or the patches whose
    /// `gl_PrimitiveID` it counts right (`LavapipeTessPrimitiveIdRestart`).
    pub fn patches_per_draw(
        &self,
        technique: &dyn Technique,
        params: &FrameParams,
        array: usize,
    ) -> u32 {
        match params.split {
            DrawSplit::Off => u32::MAX,
            DrawSplit::PerPatch => 1,
            DrawSplit::Auto => {
                let pipeline = technique
                    .patch_arrays()
                    .get(array)
                    .map(|a| technique.patch_pipeline(a.patch));
                let Some(pipeline) = pipeline.filter(|p| p.geometry.is_tessellated()) else {
                    // The split works around the tessellator's chunking; a vertex-stage draw
                    // is one draw.
                    return u32::MAX;
                };
                let max = technique.max_vertices_per_patch(params, array);
                self.device
                    .workarounds
                    .max_patches_per_draw(max, pipeline.control_points())
            }
        }
    }

    /// Records the technique's pre-pass for frame slot `slot` (outside any rendering scope).
    pub fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        technique: &'a dyn Technique,
        slot: usize,
    ) -> Result<()> {
        technique.record_pre_pass(enc, self.frame_set(slot)?, slot)
    }

    /// Records one pass of every patch array inside an open rendering (or capture) scope.
    /// [`Self::prepare`] must have built the pass's pipelines.
    pub fn record_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        technique: &'a dyn Technique,
        slot: usize,
        params: &FrameParams,
        pass: Pass,
    ) -> Result<DrawCounts> {
        let mut counts = DrawCounts::default();
        for i in 0..technique.patch_arrays().len() {
            counts += self.record_array(enc, technique, slot, params, pass, i)?;
        }
        Ok(counts)
    }

    /// Records one pass of one patch array: [`Self::bind_array`], then its draws.
    pub fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        technique: &'a dyn Technique,
        slot: usize,
        params: &FrameParams,
        pass: Pass,
        array: usize,
    ) -> Result<DrawCounts> {
        self.bind_array(enc, technique, slot, params, pass, array)?;
        self.draw_array(enc, technique, slot, params, pass, array)
    }

    /// Binds the pipeline and sets of one pass of one patch array (a capture begins transform
    /// feedback after this: Vulkan wants the pipeline bound first).
    pub fn bind_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        technique: &'a dyn Technique,
        slot: usize,
        params: &FrameParams,
        pass: Pass,
        array: usize,
    ) -> Result<()> {
        let a = technique
            .patch_arrays()
            .get(array)
            .ok_or(TessError::NoPatchArray { array })?;
        let key = PipelineKey::of(technique, a.patch, params, pass);
        let pipeline = self
            .pipelines
            .get(&key)
            .ok_or(TessError::PipelineNotPrepared {
                technique: key.technique,
                pass,
            })?;
        enc.bind_pipeline(pipeline);
        let frame_set = self.frame_set(slot)?;
        match technique.descriptor_set(slot) {
            Some(set) => enc.bind_descriptor_sets(0, &[frame_set, set])?,
            None => enc.bind_descriptor_sets(0, &[frame_set])?,
        }
        Ok(())
    }

    /// The draws of one pass of one patch array for frame slot `slot`, after
    /// [`Self::bind_array`].
    pub fn draw_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        technique: &'a dyn Technique,
        slot: usize,
        params: &FrameParams,
        pass: Pass,
        array: usize,
    ) -> Result<DrawCounts> {
        let a = technique
            .patch_arrays()
            .get(array)
            .ok_or(TessError::NoPatchArray { array })?;
        enc.begin_label(&format!("{} {:?} {:?}", technique.id(), a.patch, pass));
        let per_draw = self.patches_per_draw(technique, params, array);
        let counts = technique.record_array(enc, array, slot, params, pass, per_draw)?;
        enc.end_label();
        Ok(counts)
    }

    /// Records a whole frame's passes inside an open rendering scope: shaded, then the
    /// wireframe overlay when `params.wireframe`.
    pub fn record_frame<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        technique: &'a dyn Technique,
        slot: usize,
        params: &FrameParams,
    ) -> Result<DrawCounts> {
        let mut counts = self.record_pass(enc, technique, slot, params, Pass::Shaded)?;
        if params.wireframe {
            counts += self.record_pass(enc, technique, slot, params, Pass::Wireframe)?;
        }
        Ok(counts)
    }

    /// The passes a frame of `params` draws.
    pub fn frame_passes(params: &FrameParams) -> &'static [Pass] {
        if params.wireframe {
            &[Pass::Shaded, Pass::Wireframe]
        } else {
            &[Pass::Shaded]
        }
    }

    /// Renders one frame of `technique` offscreen (pre-pass, shaded pass, optional wireframe
    /// overlay) and reads it back.
    pub fn render_offscreen(
        &mut self,
        technique: &mut dyn Technique,
        params: &FrameParams,
        extent: vk::Extent2D,
    ) -> Result<Rgba8> {
        Ok(self
            .render_offscreen_stats(technique, params, extent, false)?
            .image)
    }

    /// [`Self::render_offscreen`]; with `statistics`, also the pipeline statistics of the
    /// shaded pass (None where a driver workaround forbids the query for these patches).
    pub fn render_offscreen_stats(
        &mut self,
        technique: &mut dyn Technique,
        params: &FrameParams,
        extent: vk::Extent2D,
        statistics: bool,
    ) -> Result<OffscreenFrame> {
        self.write_frame(0, technique.bbox(), params, extent)?;
        self.prepare(technique, params, Self::frame_passes(params))?;
        let technique = &*technique;
        let device = self.device.clone();
        let target = OffscreenTarget::new(&device, extent)?;
        let readback = target.readback_buffer(&device)?;
        let statistics = statistics && statistics_query_safe(&device, technique);
        let query = if statistics {
            Some(QueryPool::statistics(&device, "pipeline statistics", 1)?)
        } else {
            None
        };
        let this = &*self;
        let counts = device.submit_once(|enc| -> Result<DrawCounts> {
            if let Some(q) = &query {
                enc.reset_queries(q);
            }
            this.record_pre_pass(enc, technique, 0)?;
            enc.begin_offscreen(&target, params.clear_color);
            if let Some(q) = &query {
                enc.begin_query(q, 0)?;
            }
            let mut counts = this.record_pass(enc, technique, 0, params, Pass::Shaded)?;
            if let Some(q) = &query {
                enc.end_query(q, 0)?;
            }
            if params.wireframe {
                counts += this.record_pass(enc, technique, 0, params, Pass::Wireframe)?;
            }
            enc.end_offscreen_and_copy(&target, &readback);
            Ok(counts)
        })??;
        let statistics = match &query {
            Some(q) => q.statistics_results()?.first().copied(),
            None => None,
        };
        Ok(OffscreenFrame {
            image: target.read(&readback)?,
            statistics,
            counts,
        })
    }
}

/// One frame rendered offscreen.
pub struct OffscreenFrame {
    pub image: Rgba8,
    pub statistics: Option<PipelineStatistics>,
    pub counts: DrawCounts,
}

/// The shader stages of `pp` for `key`. The last stage before rasterization (the evaluation
/// stage, or the vertex stage on the vertex-stage path) takes the frame's spacing, capture and
/// surface builds; the fragment stage the surface build (it reads what that stage hands it);
/// captures have no fragment stage.
fn pipeline_stages(pp: &PatchPipeline, key: PipelineKey) -> Result<Vec<ShaderStage<'static>>> {
    let capture = key.pass == Pass::Capture;
    let last = Variant {
        spacing: pp.geometry.is_tessellated().then_some(key.spacing),
        capture,
        surface: key.surface,
        ..key.axes
    };
    let stage = |flags, stage, variant| -> Result<ShaderStage<'static>> {
        Ok(ShaderStage::new(flags, shaders::spirv(stage, variant)?))
    };
    let mut stages = Vec::with_capacity(4);
    match pp.geometry {
        Geometry::Tessellated {
            control,
            evaluation,
            ..
        } => {
            stages.push(stage(
                vk::ShaderStageFlags::VERTEX,
                pp.vertex,
                Variant::default(),
            )?);
            stages.push(stage(
                vk::ShaderStageFlags::TESSELLATION_CONTROL,
                control,
                key.axes,
            )?);
            stages.push(stage(
                vk::ShaderStageFlags::TESSELLATION_EVALUATION,
                evaluation,
                last,
            )?);
        }
        Geometry::Triangles => stages.push(stage(vk::ShaderStageFlags::VERTEX, pp.vertex, last)?),
    }
    if !capture {
        let fragment = Variant {
            surface: key.surface,
            ..Variant::default()
        };
        stages.push(stage(
            vk::ShaderStageFlags::FRAGMENT,
            pp.fragment,
            fragment,
        )?);
    }
    Ok(stages)
}

/// Whether a pipeline-statistics query may wrap `technique`'s draws on `device`: lavapipe
/// crashes on one around one-control-point patches
/// (`WorkaroundId::LavapipeStatisticsQueryPointPatches`).
pub fn statistics_query_safe(device: &Device, technique: &dyn Technique) -> bool {
    !(device
        .workarounds
        .has(WorkaroundId::LavapipeStatisticsQueryPointPatches)
        && technique
            .patch_arrays()
            .iter()
            .any(|a| a.control_points == 1))
}

/// The frame block for `params` on a target of `extent`, framing `bbox`: camera, light,
/// uniform levels, colours. Shared by every pipeline that includes `frame.glsl` (tessellated
/// or not), so they all see the same view.
pub fn frame_uniforms(
    bbox: ([f32; 3], [f32; 3]),
    params: &FrameParams,
    extent: vk::Extent2D,
) -> FrameUniforms {
    let aspect = extent.width as f32 / extent.height.max(1) as f32;
    let m = params.camera.matrices(bbox.0, bbox.1, aspect);
    frame_uniforms_with(m, bbox, params, extent)
}

/// [`frame_uniforms`] with the view and projection given (a host that owns its camera, such as
/// a C++ engine through the C ABI) instead of derived from `params.camera`; the light follows
/// the eye as it does for Tessera's own camera.
pub fn frame_uniforms_with(
    m: crate::camera::CameraMatrices,
    bbox: ([f32; 3], [f32; 3]),
    params: &FrameParams,
    extent: vk::Extent2D,
) -> FrameUniforms {
    let light =
        (m.eye - glam::Vec3::from(bbox.0).lerp(glam::Vec3::from(bbox.1), 0.5)).normalize_or_zero();
    let light = (light + glam::Vec3::new(0.3, 0.6, 0.2)).normalize_or_zero();
    let level = match params.factors {
        FactorPolicy::Uniform { segments } => segments.clamp(1.0, MAX_LEVEL),
        _ => 1.0,
    };
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
        sine: [params.displace_sine[0], params.displace_sine[1], 0.0, 0.0],
    }
}

/// Shaded pass, wireframe overlay or capture: the overlay draws lines without writing depth,
/// the shaded pass is pushed slightly back so the overlay wins the depth test, the capture
/// pass rasterizes nothing. Every technique's pipelines get this.
pub(crate) fn set_pass_style(desc: &mut GraphicsPipelineDesc<'_>, pass: Pass) {
    match pass {
        Pass::Wireframe => {
            desc.polygon_mode = vk::PolygonMode::LINE;
            desc.depth_compare = vk::CompareOp::LESS_OR_EQUAL;
            desc.depth_write = false;
        }
        Pass::Shaded => desc.depth_bias = Some((1.0, 1.0)),
        Pass::Capture => {
            desc.rasterizer_discard = true;
            desc.depth_test = false;
            desc.depth_write = false;
        }
    }
}
