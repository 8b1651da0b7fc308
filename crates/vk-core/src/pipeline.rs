//! Graphics pipelines with tessellation stages, and compute pipelines. All go through the
//! device's pipeline cache (kept on disk when the device was given a directory:
//! [`crate::pipeline_cache`]).
//!
//! A pipeline remembers what an [`crate::Encoder`] needs to check commands against it: its bind
//! point, layout, set layouts, push-constant range, attachment formats and the render pass
//! subpass it was made for (if any), vertex bindings, and whether its shaders write transform
//! feedback (the SPIR-V's Xfb execution mode).
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext, VkError};
use crate::retire::Retired;
use ash::vk;
use std::sync::Arc;

/// A shader stage: SPIR-V words plus optional specialization constants `(id, bytes)`.
#[derive(Clone, Copy)]
pub struct ShaderStage<'a> {
    pub stage: vk::ShaderStageFlags,
    pub spirv: &'a [u32],
    pub specialization: Option<(&'a [vk::SpecializationMapEntry], &'a [u8])>,
}

impl<'a> ShaderStage<'a> {
    pub fn new(stage: vk::ShaderStageFlags, spirv: &'a [u32]) -> Self {
        Self {
            stage,
            spirv,
            specialization: None,
        }
    }
}

/// Tessellation state: control points per patch and where the domain origin lies.
#[derive(Clone, Copy, Debug)]
pub struct TessellationDesc {
    pub patch_control_points: u32,
    pub domain_origin: vk::TessellationDomainOrigin,
}

/// A subpass of a render pass (render-pass rendering, the alternative to dynamic rendering a
/// host application may use): a pipeline made for it draws only inside that subpass of that
/// render pass, or of one compatible with it (Vulkan's render pass compatibility).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Subpass {
    pub render_pass: vk::RenderPass,
    pub index: u32,
    /// The subpass's sample count (its attachments'): pipelines rasterize with it.
    pub samples: vk::SampleCountFlags,
}

impl Subpass {
    /// "dynamic rendering" for `None`, else the subpass and its render pass, for messages.
    pub fn describe(subpass: Option<Subpass>) -> String {
        match subpass {
            None => "dynamic rendering".into(),
            Some(s) => format!(
                "subpass {} of render pass {:?} ({:?})",
                s.index, s.render_pass, s.samples
            ),
        }
    }
}

#[derive(Clone)]
pub struct GraphicsPipelineDesc<'a> {
    pub name: &'a str,
    pub stages: Vec<ShaderStage<'a>>,
    pub vertex_bindings: Vec<vk::VertexInputBindingDescription>,
    pub vertex_attributes: Vec<vk::VertexInputAttributeDescription>,
    pub topology: vk::PrimitiveTopology,
    pub tessellation: Option<TessellationDesc>,
    pub polygon_mode: vk::PolygonMode,
    pub cull_mode: vk::CullModeFlags,
    pub front_face: vk::FrontFace,
    pub depth_test: bool,
    pub depth_write: bool,
    pub depth_compare: vk::CompareOp,
    /// Constant and slope factors; pushes filled geometry back behind its wireframe overlay.
    pub depth_bias: Option<(f32, f32)>,
    pub color_format: vk::Format,
    pub depth_format: vk::Format,
    /// `None`: dynamic rendering with the formats above. `Some`: that subpass of a render
    /// pass, whose colour attachment (one, or none when `color_format` is `UNDEFINED`) and
    /// depth attachment (none when `depth_format` is `UNDEFINED`) the formats describe.
    pub subpass: Option<Subpass>,
    /// No rasterization: for passes that only capture TES output (transform feedback or storage
    /// buffers). Such a pipeline needs no fragment stage; give `vk::Format::UNDEFINED` as both
    /// formats to render into a scope without attachments.
    pub rasterizer_discard: bool,
    pub set_layouts: Vec<vk::DescriptorSetLayout>,
    pub push_constant_bytes: u32,
}

impl<'a> GraphicsPipelineDesc<'a> {
    /// Defaults: triangle list, filled, back faces culled (CCW front), depth test LESS.
    pub fn new(name: &'a str, color_format: vk::Format, depth_format: vk::Format) -> Self {
        Self {
            name,
            stages: Vec::new(),
            vertex_bindings: Vec::new(),
            vertex_attributes: Vec::new(),
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            tessellation: None,
            polygon_mode: vk::PolygonMode::FILL,
            cull_mode: vk::CullModeFlags::NONE,
            front_face: vk::FrontFace::COUNTER_CLOCKWISE,
            depth_test: true,
            depth_write: true,
            depth_compare: vk::CompareOp::LESS,
            depth_bias: None,
            color_format,
            depth_format,
            subpass: None,
            rasterizer_discard: false,
            set_layouts: Vec::new(),
            push_constant_bytes: 0,
        }
    }
}

/// What draws need of one vertex binding: its stride, and the bytes its last vertex spans.
#[derive(Clone, Copy, Debug)]
pub(crate) struct VertexBinding {
    pub(crate) binding: u32,
    pub(crate) stride: u32,
    pub(crate) per_vertex: bool,
    pub(crate) element_bytes: u32,
}

/// A pipeline and its layout, destroyed together through the retire queue.
pub struct Pipeline {
    pub(crate) raw: vk::Pipeline,
    pub(crate) layout: vk::PipelineLayout,
    pub bind_point: vk::PipelineBindPoint,
    pub(crate) name: String,
    pub(crate) set_layouts: Vec<vk::DescriptorSetLayout>,
    pub(crate) push_constant_bytes: u32,
    /// (colour, depth) formats; `UNDEFINED` for none (and for compute pipelines).
    pub(crate) attachment_formats: [vk::Format; 2],
    /// The subpass it was made for; `None` for dynamic rendering (and compute).
    pub(crate) subpass: Option<Subpass>,
    pub(crate) vertex_bindings: Vec<VertexBinding>,
    pub(crate) transform_feedback_output: bool,
    device: Arc<DeviceShared>,
}

impl Pipeline {
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Bytes of push constants the layout declares.
    pub fn push_constant_bytes(&self) -> u32 {
        self.push_constant_bytes
    }
}

/// Whether a SPIR-V module declares the Xfb execution mode (it writes transform feedback).
fn writes_transform_feedback(spirv: &[u32]) -> bool {
    const OP_EXECUTION_MODE: u32 = 16;
    const XFB: u32 = 11;
    let mut i = 5; // after the header
    while i < spirv.len() {
        let count = (spirv[i] >> 16) as usize;
        let opcode = spirv[i] & 0xffff;
        if opcode == OP_EXECUTION_MODE && count >= 3 && spirv.get(i + 2) == Some(&XFB) {
            return true;
        }
        i += count.max(1);
    }
    false
}

/// Bytes one attribute of `format` reads (the formats vertex input uses; others count as 16).
fn format_bytes(format: vk::Format) -> u32 {
    use vk::Format as F;
    match format {
        F::R32_SFLOAT | F::R32_UINT | F::R32_SINT | F::R8G8B8A8_UNORM | F::R8G8B8A8_SNORM => 4,
        F::R32G32_SFLOAT | F::R32G32_UINT | F::R32G32_SINT | F::R16G16B16A16_SFLOAT => 8,
        F::R32G32B32_SFLOAT | F::R32G32B32_UINT | F::R32G32B32_SINT => 12,
        _ => 16,
    }
}

/// The rasterization state of `desc`: polygon mode, culling, winding, discard, depth bias.
fn rasterization_state(
    desc: &GraphicsPipelineDesc<'_>,
) -> vk::PipelineRasterizationStateCreateInfo<'static> {
    vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(desc.polygon_mode)
        .cull_mode(desc.cull_mode)
        .front_face(desc.front_face)
        .line_width(1.0)
        .rasterizer_discard_enable(desc.rasterizer_discard)
        .depth_bias_enable(desc.depth_bias.is_some())
        .depth_bias_constant_factor(desc.depth_bias.map(|b| b.0).unwrap_or(0.0))
        .depth_bias_slope_factor(desc.depth_bias.map(|b| b.1).unwrap_or(0.0))
}

/// The depth state of `desc` (no stencil).
fn depth_stencil_state(
    desc: &GraphicsPipelineDesc<'_>,
) -> vk::PipelineDepthStencilStateCreateInfo<'static> {
    vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(desc.depth_test)
        .depth_write_enable(desc.depth_write)
        .depth_compare_op(desc.depth_compare)
}

fn vertex_bindings(desc: &GraphicsPipelineDesc<'_>) -> Vec<VertexBinding> {
    desc.vertex_bindings
        .iter()
        .map(|b| {
            let element_bytes = desc
                .vertex_attributes
                .iter()
                .filter(|a| a.binding == b.binding)
                .map(|a| a.offset + format_bytes(a.format))
                .max()
                .unwrap_or(0);
            VertexBinding {
                binding: b.binding,
                stride: b.stride,
                per_vertex: b.input_rate == vk::VertexInputRate::VERTEX,
                element_bytes,
            }
        })
        .collect()
}

fn shader_modules(
    device: &Device,
    name: &str,
    stages: &[ShaderStage<'_>],
) -> Result<Vec<vk::ShaderModule>> {
    let mut modules = Vec::new();
    for s in stages {
        let info = vk::ShaderModuleCreateInfo::default().code(s.spirv);
        // SAFETY: SPIR-V comes from the build-time compiler.
        match unsafe { device.raw.create_shader_module(&info, None) } {
            Ok(m) => {
                device.created(1);
                device.set_name(m, &format!("{name} {:?}", s.stage));
                modules.push(m)
            }
            Err(e) => {
                destroy_modules(device, &modules);
                return Err(VkError::Call {
                    call: "vkCreateShaderModule",
                    result: e,
                });
            }
        }
    }
    Ok(modules)
}

fn destroy_modules(device: &Device, modules: &[vk::ShaderModule]) {
    for &m in modules {
        // SAFETY: modules are only needed during pipeline creation.
        unsafe { device.raw.destroy_shader_module(m, None) };
        device.destroyed(1);
    }
}

fn pipeline_layout(
    device: &Device,
    name: &str,
    sets: &[vk::DescriptorSetLayout],
    push_bytes: u32,
) -> Result<vk::PipelineLayout> {
    let ranges = [vk::PushConstantRange::default()
        .stage_flags(vk::ShaderStageFlags::ALL)
        .size(push_bytes)];
    let mut info = vk::PipelineLayoutCreateInfo::default().set_layouts(sets);
    if push_bytes > 0 {
        info = info.push_constant_ranges(&ranges);
    }
    // SAFETY: set layouts are live.
    let layout =
        unsafe { device.raw.create_pipeline_layout(&info, None) }.ctx("vkCreatePipelineLayout")?;
    device.created(1);
    device.set_name(layout, &format!("{name} layout"));
    Ok(layout)
}

impl Pipeline {
    /// The pipeline object of `raw`, created from `desc` with `layout`.
    fn graphics_from(
        device: &Device,
        desc: &GraphicsPipelineDesc<'_>,
        raw: vk::Pipeline,
        layout: vk::PipelineLayout,
    ) -> Self {
        Self {
            raw,
            layout,
            bind_point: vk::PipelineBindPoint::GRAPHICS,
            name: desc.name.to_owned(),
            set_layouts: desc.set_layouts.clone(),
            push_constant_bytes: desc.push_constant_bytes,
            attachment_formats: [desc.color_format, desc.depth_format],
            subpass: desc.subpass,
            vertex_bindings: vertex_bindings(desc),
            transform_feedback_output: desc
                .stages
                .iter()
                .any(|s| writes_transform_feedback(s.spirv)),
            device: device.shared.clone(),
        }
    }

    pub fn graphics(device: &Device, desc: &GraphicsPipelineDesc<'_>) -> Result<Self> {
        let layout = pipeline_layout(
            device,
            desc.name,
            &desc.set_layouts,
            desc.push_constant_bytes,
        )?;
        let modules = match shader_modules(device, desc.name, &desc.stages) {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: layout unused.
                unsafe { device.raw.destroy_pipeline_layout(layout, None) };
                device.destroyed(1);
                return Err(e);
            }
        };
        let spec_infos: Vec<Option<vk::SpecializationInfo>> = desc
            .stages
            .iter()
            .map(|s| {
                s.specialization.map(|(entries, data)| {
                    vk::SpecializationInfo::default()
                        .map_entries(entries)
                        .data(data)
                })
            })
            .collect();
        let stage_infos: Vec<_> = desc
            .stages
            .iter()
            .zip(&modules)
            .zip(&spec_infos)
            .map(|((s, &m), spec)| {
                let info = vk::PipelineShaderStageCreateInfo::default()
                    .stage(s.stage)
                    .module(m)
                    .name(c"main");
                match spec {
                    Some(spec) => info.specialization_info(spec),
                    None => info,
                }
            })
            .collect();
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&desc.vertex_bindings)
            .vertex_attribute_descriptions(&desc.vertex_attributes);
        let input_assembly =
            vk::PipelineInputAssemblyStateCreateInfo::default().topology(desc.topology);
        let mut domain = vk::PipelineTessellationDomainOriginStateCreateInfo::default()
            .domain_origin(
                desc.tessellation
                    .map(|t| t.domain_origin)
                    .unwrap_or(vk::TessellationDomainOrigin::UPPER_LEFT),
            );
        let tess_state = vk::PipelineTessellationStateCreateInfo::default()
            .patch_control_points(
                desc.tessellation
                    .map(|t| t.patch_control_points)
                    .unwrap_or(1),
            )
            .push_next(&mut domain);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = rasterization_state(desc);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(
            desc.subpass
                .map_or(vk::SampleCountFlags::TYPE_1, |s| s.samples),
        );
        let depth = depth_stencil_state(desc);
        // VK_FORMAT_UNDEFINED as the colour format means no colour attachment at all (capture
        // passes render into nothing), so the attachment count matches the rendering scope.
        let color_count = usize::from(desc.color_format != vk::Format::UNDEFINED);
        let attachments = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA)];
        let blend = vk::PipelineColorBlendStateCreateInfo::default()
            .attachments(&attachments[..color_count]);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let color_formats = [desc.color_format];
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&color_formats[..color_count])
            .depth_attachment_format(desc.depth_format);
        let mut info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stage_infos)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout);
        info = match desc.subpass {
            Some(s) => info.render_pass(s.render_pass).subpass(s.index),
            None => info.push_next(&mut rendering),
        };
        if desc.tessellation.is_some() {
            info = info.tessellation_state(&tess_state);
        }
        // SAFETY: every referenced struct lives until the call returns.
        let result = unsafe {
            device
                .raw
                .create_graphics_pipelines(device.pipeline_cache(), &[info], None)
        };
        destroy_modules(device, &modules);
        match result {
            Ok(p) => {
                device.created(1);
                device.set_name(p[0], desc.name);
                Ok(Self::graphics_from(device, desc, p[0], layout))
            }
            Err((_, e)) => {
                // SAFETY: layout unused.
                unsafe { device.raw.destroy_pipeline_layout(layout, None) };
                device.destroyed(1);
                Err(VkError::Call {
                    call: "vkCreateGraphicsPipelines",
                    result: e,
                })
            }
        }
    }

    pub fn compute(
        device: &Device,
        name: &str,
        stage: ShaderStage<'_>,
        set_layouts: &[vk::DescriptorSetLayout],
        push_constant_bytes: u32,
    ) -> Result<Self> {
        let layout = pipeline_layout(device, name, set_layouts, push_constant_bytes)?;
        let modules = match shader_modules(device, name, &[stage]) {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: the layout was never used.
                unsafe { device.raw.destroy_pipeline_layout(layout, None) };
                device.destroyed(1);
                return Err(e);
            }
        };
        let spec = stage.specialization.map(|(entries, data)| {
            vk::SpecializationInfo::default()
                .map_entries(entries)
                .data(data)
        });
        let mut stage_info = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(modules[0])
            .name(c"main");
        if let Some(spec) = &spec {
            stage_info = stage_info.specialization_info(spec);
        }
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage_info)
            .layout(layout);
        // SAFETY: referenced structs live until return.
        let result = unsafe {
            device
                .raw
                .create_compute_pipelines(device.pipeline_cache(), &[info], None)
        };
        destroy_modules(device, &modules);
        match result {
            Ok(p) => {
                device.created(1);
                device.set_name(p[0], name);
                Ok(Self {
                    raw: p[0],
                    layout,
                    bind_point: vk::PipelineBindPoint::COMPUTE,
                    name: name.to_owned(),
                    set_layouts: set_layouts.to_vec(),
                    push_constant_bytes,
                    attachment_formats: [vk::Format::UNDEFINED; 2],
                    subpass: None,
                    vertex_bindings: Vec::new(),
                    transform_feedback_output: false,
                    device: device.shared.clone(),
                })
            }
            Err((_, e)) => {
                // SAFETY: layout unused.
                unsafe { device.raw.destroy_pipeline_layout(layout, None) };
                device.destroyed(1);
                Err(VkError::Call {
                    call: "vkCreateComputePipelines",
                    result: e,
                })
            }
        }
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        self.device.retire(Retired::Pipeline {
            raw: self.raw,
            layout: self.layout,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xfb_execution_mode_is_found_in_spirv() {
        // Header, then OpExecutionMode %main Xfb (3 words), then OpNop-sized filler.
        let mut words = vec![0x0723_0203, 0x0001_0000, 0, 10, 0];
        words.extend([(3 << 16) | 16, 1, 11]);
        assert!(writes_transform_feedback(&words));
        words[7] = 7; // another mode (OriginUpperLeft)
        assert!(!writes_transform_feedback(&words));
        assert!(!writes_transform_feedback(&words[..5]));
    }
}
