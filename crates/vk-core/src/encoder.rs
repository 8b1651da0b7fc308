//! TEMPORARY minimal Encoder (the lead's stand-in until the vk-core branch lands).
use crate::buffer::Buffer;
use crate::descriptor::BindingDesc;
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext, VkError};
use crate::pipeline::Pipeline;
use crate::query::QueryPool;
use crate::target::OffscreenTarget;
use ash::vk;
use std::marker::PhantomData;
use std::sync::Arc;
use crate::transform_feedback::TransformFeedbackCommands;

/// A descriptor set allocated from a pool, with its layout's bindings.
pub struct DescriptorSet {
    pub(crate) raw: vk::DescriptorSet,
    pub(crate) bindings: Vec<BindingDesc>,
    pub(crate) device: Arc<DeviceShared>,
}

impl DescriptorSet {
    pub fn write_buffer(&self, binding: u32, ty: vk::DescriptorType, buffer: &Buffer) -> Result<()> {
        if !self.bindings.iter().any(|b| b.binding == binding && b.ty == ty) {
            return Err(VkError::Invalid(format!("no binding {binding} of type {ty:?}")));
        }
        let info = [buffer.descriptor()];
        let w = [vk::WriteDescriptorSet::default()
            .dst_set(self.raw)
            .dst_binding(binding)
            .descriptor_type(ty)
            .buffer_info(&info)];
        // SAFETY: temporary.
        unsafe { self.device.raw.update_descriptor_sets(&w, &[]) };
        Ok(())
    }
}

pub struct Encoder<'a> {
    device: Device,
    raw: vk::CommandBuffer,
    pipeline: Option<(vk::PipelineBindPoint, vk::PipelineLayout, u32)>,
    index_len: Option<u64>,
    _m: PhantomData<&'a ()>,
}

impl<'a> Encoder<'a> {
    pub fn device(&self) -> &Device {
        &self.device
    }
    pub fn begin_label(&mut self, name: &str) {
        self.device.begin_label(self.raw, name);
    }
    pub fn end_label(&mut self) {
        self.device.end_label(self.raw);
    }
    pub fn bind_pipeline(&mut self, p: &'a Pipeline) {
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_bind_pipeline(self.raw, p.bind_point, p.raw) };
        self.pipeline = Some((p.bind_point, p.layout, p.push_constant_bytes));
    }
    pub fn bind_descriptor_sets(&mut self, first: u32, sets: &[&'a DescriptorSet]) -> Result<()> {
        let (bp, layout, _) = self.pipeline.ok_or(VkError::Invalid("no pipeline".into()))?;
        let raw: Vec<_> = sets.iter().map(|s| s.raw).collect();
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_bind_descriptor_sets(self.raw, bp, layout, first, &raw, &[]) };
        Ok(())
    }
    pub fn push_constants<T: bytemuck::Pod>(&mut self, data: &T) -> Result<()> {
        let (_, layout, size) = self.pipeline.ok_or(VkError::Invalid("no pipeline".into()))?;
        if std::mem::size_of::<T>() as u32 > size {
            return Err(VkError::Invalid("push constants too large".into()));
        }
        // SAFETY: temporary.
        unsafe {
            self.device.raw.cmd_push_constants(
                self.raw,
                layout,
                vk::ShaderStageFlags::ALL,
                0,
                bytemuck::bytes_of(data),
            )
        };
        Ok(())
    }
    pub fn bind_vertex_buffer(&mut self, binding: u32, b: &'a Buffer) {
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_bind_vertex_buffers(self.raw, binding, &[b.raw], &[0]) };
    }
    pub fn bind_index_buffer_u32(&mut self, b: &'a Buffer) {
        // SAFETY: temporary.
        unsafe {
            self.device
                .raw
                .cmd_bind_index_buffer(self.raw, b.raw, 0, vk::IndexType::UINT32)
        };
        self.index_len = Some(b.size / 4);
    }
    pub fn draw(&mut self, v: std::ops::Range<u32>) -> Result<()> {
        self.pipeline.ok_or(VkError::Invalid("no pipeline".into()))?;
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_draw(self.raw, v.len() as u32, 1, v.start, 0) };
        Ok(())
    }
    pub fn draw_indexed(&mut self, i: std::ops::Range<u32>) -> Result<()> {
        let n = self.index_len.ok_or(VkError::Invalid("no index buffer".into()))?;
        if i.end as u64 > n {
            return Err(VkError::Invalid("index range".into()));
        }
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_draw_indexed(self.raw, i.len() as u32, 1, i.start, 0, 0) };
        Ok(())
    }
    pub fn dispatch(&mut self, g: [u32; 3]) -> Result<()> {
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_dispatch(self.raw, g[0], g[1], g[2]) };
        Ok(())
    }
    pub fn memory_barrier(
        &mut self,
        src: (vk::PipelineStageFlags, vk::AccessFlags),
        dst: (vk::PipelineStageFlags, vk::AccessFlags),
    ) {
        let m = [vk::MemoryBarrier::default().src_access_mask(src.1).dst_access_mask(dst.1)];
        // SAFETY: temporary.
        unsafe {
            self.device.raw.cmd_pipeline_barrier(
                self.raw,
                src.0,
                dst.0,
                vk::DependencyFlags::empty(),
                &m,
                &[],
                &[],
            )
        };
    }
    pub fn reset_queries(&mut self, pool: &'a QueryPool) {
        pool.cmd_reset(self.raw);
    }
    pub fn begin_query(&mut self, pool: &'a QueryPool, index: u32) -> Result<()> {
        pool.cmd_begin(self.raw, index)
    }
    pub fn end_query(&mut self, pool: &'a QueryPool, index: u32) -> Result<()> {
        pool.cmd_end(self.raw, index)
    }
    pub fn write_timestamp(
        &mut self,
        pool: &'a QueryPool,
        stage: vk::PipelineStageFlags,
        index: u32,
    ) -> Result<()> {
        pool.cmd_write_timestamp(self.raw, stage, index)
    }
    pub fn begin_query_stream(&mut self, pool: &'a QueryPool, index: u32, stream: u32) -> Result<()> {
        pool.cmd_begin_stream(self.raw, index, stream)
    }
    pub fn end_query_stream(&mut self, pool: &'a QueryPool, index: u32, stream: u32) -> Result<()> {
        pool.cmd_end_stream(self.raw, index, stream)
    }
    pub fn begin_transform_feedback(&mut self, buffers: &[&'a Buffer], _c: &[&'a Buffer]) -> Result<()> {
        let xfb = self.device.transform_feedback()?.clone();
        for (i, b) in buffers.iter().enumerate() {
            // SAFETY: temporary.
            unsafe { xfb.cmd_bind_transform_feedback_buffer(self.raw, i as u32, b.raw, 0, b.size) };
        }
        // SAFETY: temporary.
        unsafe { xfb.cmd_begin_transform_feedback(self.raw) };
        Ok(())
    }
    pub fn end_transform_feedback(&mut self, _c: &[&'a Buffer]) -> Result<()> {
        let xfb = self.device.transform_feedback()?.clone();
        // SAFETY: temporary.
        unsafe { xfb.cmd_end_transform_feedback(self.raw) };
        Ok(())
    }
    pub fn begin_offscreen(&mut self, t: &'a OffscreenTarget, clear: [f32; 4]) {
        t.cmd_begin(&self.device, self.raw, clear);
    }
    pub fn end_offscreen_and_copy(&mut self, t: &'a OffscreenTarget, readback: &'a Buffer) {
        t.cmd_end_and_copy(&self.device, self.raw, readback);
    }
    pub fn end_rendering(&mut self) {
        // SAFETY: temporary.
        unsafe { self.device.raw.cmd_end_rendering(self.raw) };
    }
    pub fn begin_rendering_without_attachments(&mut self, extent: vk::Extent2D) {
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent,
        };
        let rendering = vk::RenderingInfo::default().render_area(area).layer_count(1);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: extent.width as f32,
            height: extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: temporary.
        unsafe {
            self.device.raw.cmd_begin_rendering(self.raw, &rendering);
            self.device.raw.cmd_set_viewport(self.raw, 0, &[viewport]);
            self.device.raw.cmd_set_scissor(self.raw, 0, &[area]);
        }
    }
    /// Temporary: the raw command buffer for the legacy swapchain path.
    pub fn raw(&self) -> vk::CommandBuffer {
        self.raw
    }
    /// # Safety
    /// temporary
    pub unsafe fn from_raw(device: &Device, raw: vk::CommandBuffer) -> Self {
        Self {
            device: device.clone(),
            raw,
            pipeline: None,
            index_len: None,
            _m: PhantomData,
        }
    }
}

impl Device {
    pub fn submit_once<'a, R>(&self, record: impl FnOnce(&mut Encoder<'a>) -> R) -> Result<R> {
        self.one_shot(|cmd| {
            // SAFETY: temporary.
            let mut enc = unsafe { Encoder::from_raw(self, cmd) };
            record(&mut enc)
        })
    }
}

impl crate::descriptor::DescriptorPool {
    pub fn allocate_set(&self, layout: &crate::descriptor::DescriptorSetLayout) -> Result<DescriptorSet> {
        let layouts = [layout.raw];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.raw)
            .set_layouts(&layouts);
        // SAFETY: temporary.
        let raw = unsafe { self.device_shared().raw.allocate_descriptor_sets(&info) }
            .ctx("vkAllocateDescriptorSets")?[0];
        Ok(DescriptorSet {
            raw,
            bindings: layout.bindings.clone(),
            device: self.device_shared().clone(),
        })
    }
}

impl crate::swapchain::Swapchain {
    /// Temporary: records `pre` (outside rendering) and `draw` (inside rendering into the
    /// frame's image), then submits and presents.
    pub fn present<'a, E: From<VkError>>(
        &mut self,
        frame: crate::swapchain::Frame,
        screenshot: bool,
        clear: [f32; 4],
        pre: impl FnOnce(&mut Encoder<'a>, usize) -> std::result::Result<(), E>,
        draw: impl FnOnce(&mut Encoder<'a>, usize) -> std::result::Result<(), E>,
    ) -> std::result::Result<Option<crate::target::Rgba8>, E> {
        let device = self.device.clone();
        // SAFETY: temporary.
        let mut enc = unsafe { Encoder::from_raw(&device, frame.cmd) };
        pre(&mut enc, frame.slot)?;
        self.cmd_begin_rendering(&frame, clear)?;
        draw(&mut enc, frame.slot)?;
        Ok(self.end_frame(frame, screenshot)?)
    }
}
