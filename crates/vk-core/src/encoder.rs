//! [`Encoder`]: a primary command buffer in the recording state, with safe methods. This is the
//! boundary where vk-core states its `unsafe` contracts once; crates above it record without
//! `unsafe` (in the spirit of wgpu-hal's `CommandEncoder`, but checked instead of `unsafe fn`).
//!
//! # The invariants vk-core upholds, and why each method is sound
//! 1. **Objects outlive the GPU's use of them.** Everything an encoder records is borrowed for
//!    `'a`. An encoder is only submitted by value ([`Device::submit_once`], which waits, or
//!    [`crate::swapchain::SwapchainFrame::present`], which consumes the frame), so nothing it
//!    recorded can be dropped before its submission is queued. Dropped afterwards, every vk-core
//!    object goes through the device's retire queue ([`crate::retire`]), which destroys it (and
//!    frees its memory) only once every submission handed out before the drop completed.
//!    Descriptor sets keep the buffers and textures written into them, their layout and their
//!    pool alive.
//! 2. **One recorder per command buffer.** An encoder owns its command buffer (and, for
//!    one-shot work, its whole command pool) exclusively and is neither `Send` nor `Sync`, so
//!    Vulkan's external-synchronization rules for command buffers and pools hold. Exchanging two
//!    encoders (`std::mem::swap` on the `&mut`) is detected at submission by identity: both are
//!    then abandoned unsubmitted and the submission returns [`RecordingError::Exchanged`](crate::error::RecordingError::Exchanged).
//! 3. **Commands only where Vulkan allows them.** The encoder tracks the bound pipeline, descriptor
//!    sets, vertex and index buffers, the open rendering scope (and its attachment formats),
//!    active queries and transform feedback, and debug labels, and refuses what would break a
//!    valid-usage rule it can see: a draw without a graphics pipeline or outside a rendering scope,
//!    pipeline formats that differ from the scope's, an index range past the index buffer, a
//!    vertex range past a vertex buffer, a set never written or of another layout, push constants
//!    past the pipeline's range, a buffer without the usage a command needs, a query not reset in
//!    this command buffer or ended in another scope, a scope left open at submission. Methods
//!    that return `Result` report at once; methods that return nothing record the first such
//!    error and the submission returns it instead of submitting (an invalid command buffer never
//!    reaches the queue).
//! 4. **Descriptor sets are not updated while in use.** Binding a set counts it as used by a
//!    recording; [`crate::DescriptorSet::write_buffer`] refuses a set bound in an unsubmitted
//!    recording, and waits for the submissions that used it before writing.
//!
//! What the encoder cannot see is the shaders' behaviour: which bindings a shader reads, and the
//! vertex indices an index buffer holds (a draw_indexed range is checked against the index
//! buffer, not against the vertex buffers the indices address). Those stay the pipeline
//! author's obligation, as with any Vulkan code; vk-core's own shaders' layouts are checked
//! against their SPIR-V in tests.
use crate::buffer::Buffer;
use crate::descriptor::DescriptorSet;
use crate::device::Device;
use crate::error::{RecordingError as E, Result, VkContext, VkError};
use crate::image::transition;
use crate::indirect::{IndirectDraws, IndirectKind};
use crate::pipeline::{Pipeline, Subpass};
use crate::query::QueryPool;
use crate::retire::Retired;
use crate::target::{OffscreenTarget, COLOR_FORMAT, DEPTH_FORMAT};
use crate::texture::Texture;
use ash::vk;
use std::marker::PhantomData;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

static NEXT_ENCODER_ID: AtomicU64 = AtomicU64::new(1);

/// Where the command buffer came from, so submission and abandonment hand it back correctly.
pub(crate) enum Origin {
    /// A one-shot pool taken from the device, owned by the encoder until submitted.
    Once { pool: vk::CommandPool },
    /// As `Once`, handed out by [`Device::encoder`]: submitted without waiting.
    Unwaited { pool: vk::CommandPool },
    /// A swapchain slot's command buffer (the swapchain resets it).
    Frame,
    /// A command buffer a host application owns, begun, ended and submitted by it
    /// ([`Encoder::record_into`]): the encoder only records.
    Host,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum ScopeKind {
    Offscreen(vk::Image),
    Frame,
    Empty,
    /// A rendering scope the host began before handing its command buffer over, and ends
    /// after [`Encoder::finish`]: nothing in vk-core ends it.
    Host,
}

#[derive(Clone, Copy, Debug)]
struct Scope {
    kind: ScopeKind,
    /// (colour, depth); `UNDEFINED` where the scope has no such attachment.
    formats: [vk::Format; 2],
    /// The render pass subpass the scope is; `None` for dynamic rendering.
    subpass: Option<Subpass>,
    id: u32,
}

/// The rendering scope a host application has open when it hands its command buffer to
/// [`Encoder::record_into`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostScope {
    /// Dynamic rendering with these (colour, depth) attachment formats (`UNDEFINED`: none).
    Rendering([vk::Format; 2]),
    /// A subpass of a render pass instance (of `subpass.render_pass` or one compatible with
    /// it), whose colour and depth attachments `formats` describe as for pipelines
    /// ([`crate::pipeline::GraphicsPipelineDesc::subpass`]).
    Subpass {
        subpass: Subpass,
        formats: [vk::Format; 2],
    },
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum QueryState {
    /// Not reset in this command buffer.
    Unknown,
    /// Reset in this command buffer and not used since.
    Reset,
    Active {
        scope: u32,
        stream: Option<u32>,
    },
    Used,
}

struct QueryUse<'a> {
    pool: &'a QueryPool,
    states: Vec<QueryState>,
}

/// A primary command buffer in the recording state. Everything recorded is borrowed for 'a.
pub struct Encoder<'a> {
    device: Device,
    cmd: vk::CommandBuffer,
    origin: Option<Origin>,
    id: u64,
    pipeline: Option<&'a Pipeline>,
    sets: Vec<Option<&'a DescriptorSet>>,
    /// Every set bound, once per bind: each counts as "in a recording" until the encoder ends.
    bound_sets: Vec<&'a DescriptorSet>,
    vertex_buffers: Vec<(u32, &'a Buffer)>,
    index_buffer: Option<&'a Buffer>,
    scope: Option<Scope>,
    scopes_opened: u32,
    queries: Vec<QueryUse<'a>>,
    transform_feedback: bool,
    labels: u32,
    /// The first misuse seen by a method that returns nothing; submission returns it.
    error: Option<VkError>,
    /// Not Send or Sync: the command buffer and its pool are externally synchronized.
    _single_thread: PhantomData<*const ()>,
}

impl<'a> Encoder<'a> {
    /// Begins recording into `cmd`.
    ///
    /// # Safety
    /// `cmd` is a primary command buffer of `device` in the initial state, handed over with its
    /// pool as `origin` says: no one else records into, resets or frees either while the encoder
    /// lives, and a `Once`/`Unwaited` pool is the encoder's to recycle.
    pub(crate) unsafe fn begin(
        device: &Device,
        cmd: vk::CommandBuffer,
        origin: Origin,
    ) -> Result<Self> {
        // SAFETY: the caller's contract.
        unsafe {
            device.raw.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )
        }
        .ctx("vkBeginCommandBuffer")?;
        Ok(Self::recording(device, cmd, origin))
    }

    /// Records into `cmd`, a command buffer a host application owns and submits itself (the
    /// C ABI's host-owned mode): the encoder neither begins, ends, submits nor resets it, and
    /// is closed with [`Encoder::finish`]. With `scope`, the host has begun a rendering scope
    /// (dynamic rendering of those formats, or a render pass instance in that subpass), which
    /// draws are checked against; the host also set the viewport and scissor (every vk-core
    /// pipeline takes them as dynamic state).
    ///
    /// # Safety
    /// - `cmd` is a primary command buffer of `device`, in the recording state, that nothing
    ///   else records into, resets or frees until the encoder is finished or dropped.
    /// - With `scope`, `cmd` is inside the rendering scope it describes, viewport and scissor
    ///   set: [`HostScope::Rendering`], a scope begun with dynamic rendering with exactly those
    ///   attachment formats (`UNDEFINED` where there is no attachment);
    ///   [`HostScope::Subpass`], a render pass instance, begun with contents
    ///   `VK_SUBPASS_CONTENTS_INLINE`, of a render pass compatible with `subpass.render_pass`,
    ///   in subpass `subpass.index`, whose attachments `formats` and `subpass.samples`
    ///   describe. Without `scope`, `cmd` is outside any rendering scope.
    /// - Everything the recording references stays alive until the GPU finished executing
    ///   `cmd`. vk-core cannot see the host's submissions, so its retire queue does not cover
    ///   them: the caller destroys what it recorded only after the host waited for them.
    pub unsafe fn record_into(
        device: &Device,
        cmd: vk::CommandBuffer,
        scope: Option<HostScope>,
    ) -> Self {
        let mut e = Self::recording(device, cmd, Origin::Host);
        let (what, formats, subpass) = match scope {
            Some(HostScope::Rendering(formats)) => ("host rendering scope", formats, None),
            Some(HostScope::Subpass { subpass, formats }) => {
                ("host render pass instance", formats, Some(subpass))
            }
            None => return e,
        };
        if e.open_scope(what, ScopeKind::Host, formats) {
            if let Some(s) = e.scope.as_mut() {
                s.subpass = subpass;
            }
        }
        e
    }

    /// Closes an encoder of [`Encoder::record_into`]: the host's scope (if any) is left open
    /// for the host to end. Returns the first misuse recorded, or what was left open inside
    /// (a query, transform feedback, a label, a scope of vk-core's own).
    pub fn finish(mut self) -> Result<()> {
        if !matches!(self.origin, Some(Origin::Host)) {
            return Err(VkError::recording("finish", E::Exchanged));
        }
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.scope.is_some_and(|s| s.kind == ScopeKind::Host) {
            if self.transform_feedback {
                return Err(VkError::recording(
                    "finish",
                    E::Unclosed {
                        open: "transform feedback",
                    },
                ));
            }
            self.scope = None;
        }
        match self.take_unready() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn recording(device: &Device, cmd: vk::CommandBuffer, origin: Origin) -> Self {
        Self {
            device: device.clone(),
            cmd,
            origin: Some(origin),
            id: NEXT_ENCODER_ID.fetch_add(1, Ordering::Relaxed),
            pipeline: None,
            sets: Vec::new(),
            bound_sets: Vec::new(),
            vertex_buffers: Vec::new(),
            index_buffer: None,
            scope: None,
            scopes_opened: 0,
            queries: Vec::new(),
            transform_feedback: false,
            labels: 0,
            error: None,
            _single_thread: PhantomData,
        }
    }

    pub(crate) fn id(&self) -> u64 {
        self.id
    }

    pub fn device(&self) -> &Device {
        &self.device
    }

    /// Remembers the first misuse of a method that cannot return it.
    fn defer(&mut self, command: &'static str, problem: E) {
        if self.error.is_none() {
            self.error = Some(VkError::recording(command, problem));
        }
    }

    fn outside_rendering(&self, command: &'static str) -> Result<()> {
        match self.scope {
            Some(_) => Err(VkError::recording(command, E::InsideRendering)),
            None => Ok(()),
        }
    }

    fn needs_usage(
        command: &'static str,
        buffer: &Buffer,
        usage: vk::BufferUsageFlags,
    ) -> Result<()> {
        if buffer.usage().contains(usage) {
            Ok(())
        } else {
            Err(VkError::recording(
                command,
                E::BufferUsage {
                    buffer: buffer.name().to_owned(),
                    needed: usage,
                },
            ))
        }
    }

    /// `buffer` holds at least `bytes` (a copy's source or destination).
    fn needs_size(command: &'static str, buffer: &Buffer, bytes: u64) -> Result<()> {
        if buffer.size() >= bytes {
            Ok(())
        } else {
            Err(VkError::recording(
                command,
                E::BufferTooSmall {
                    buffer: buffer.name().to_owned(),
                    needed: bytes,
                    size: buffer.size(),
                },
            ))
        }
    }

    pub fn begin_label(&mut self, name: &str) {
        self.labels += 1;
        if let (Some(du), Ok(name)) = (&self.device.debug_utils, std::ffi::CString::new(name)) {
            let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
            // SAFETY: the command buffer is recording (invariant 2).
            unsafe { du.cmd_begin_debug_utils_label(self.cmd, &label) };
        }
    }

    pub fn end_label(&mut self) {
        if self.labels == 0 {
            return self.defer("vkCmdEndDebugUtilsLabelEXT", E::NoLabel);
        }
        self.labels -= 1;
        if let Some(du) = &self.device.debug_utils {
            // SAFETY: a label is open on this command buffer (counted above).
            unsafe { du.cmd_end_debug_utils_label(self.cmd) };
        }
    }

    /// Graphics or compute, from the pipeline itself (Pipeline must know its bind point, its layout and its push-constant range size).
    pub fn bind_pipeline(&mut self, pipeline: &'a Pipeline) {
        // SAFETY: the pipeline is borrowed for 'a (invariant 1); its bind point is its own.
        unsafe {
            self.device
                .raw
                .cmd_bind_pipeline(self.cmd, pipeline.bind_point, pipeline.raw)
        };
        self.pipeline = Some(pipeline);
    }

    fn pipeline(&self, command: &'static str) -> Result<&'a Pipeline> {
        self.pipeline
            .ok_or_else(|| VkError::recording(command, E::NoPipeline))
    }

    /// Binds sets first_set.. with the bound pipeline's layout and bind point; error if no pipeline is bound.
    pub fn bind_descriptor_sets(
        &mut self,
        first_set: u32,
        sets: &[&'a DescriptorSet],
    ) -> Result<()> {
        const CMD: &str = "vkCmdBindDescriptorSets";
        let pipeline = self.pipeline(CMD)?;
        let count = pipeline.set_layouts.len() as u32;
        let end = first_set.saturating_add(sets.len() as u32);
        if end > count {
            return Err(VkError::recording(
                CMD,
                E::SetIndex {
                    pipeline: pipeline.name.clone(),
                    first: first_set,
                    end,
                    count,
                },
            ));
        }
        for (i, set) in sets.iter().enumerate() {
            let index = first_set + i as u32;
            if set.layout_raw() != pipeline.set_layouts[index as usize] {
                return Err(VkError::recording(
                    CMD,
                    E::SetLayout {
                        pipeline: pipeline.name.clone(),
                        index,
                        set: set.name().to_owned(),
                    },
                ));
            }
        }
        // Count every set in before recording the bind (invariant 4); bound_sets counts each
        // out again when the encoder ends, so a set refused here is not counted.
        for set in sets {
            if let Err(binding) = set.enter_recording() {
                return Err(VkError::recording(
                    CMD,
                    E::SetIncomplete {
                        set: set.name().to_owned(),
                        binding,
                    },
                ));
            }
            self.bound_sets.push(set);
        }
        let raw: Vec<vk::DescriptorSet> = sets.iter().map(|s| s.raw).collect();
        // SAFETY: the sets are complete, of the layouts the pipeline layout declares at these
        // indices, borrowed for 'a and counted as in use by this recording (invariants 1, 4).
        unsafe {
            self.device.raw.cmd_bind_descriptor_sets(
                self.cmd,
                pipeline.bind_point,
                pipeline.layout,
                first_set,
                &raw,
                &[],
            )
        };
        if self.sets.len() < end as usize {
            self.sets.resize(end as usize, None);
        }
        for (i, set) in sets.iter().enumerate() {
            self.sets[first_set as usize + i] = Some(set);
        }
        Ok(())
    }

    /// Error if no pipeline is bound or T is larger than the bound pipeline's push range.
    pub fn push_constants<T: bytemuck::Pod>(&mut self, data: &T) -> Result<()> {
        const CMD: &str = "vkCmdPushConstants";
        let pipeline = self.pipeline(CMD)?;
        let bytes = bytemuck::bytes_of(data);
        if bytes.is_empty() || bytes.len() & 3 != 0 {
            return Err(VkError::recording(
                CMD,
                E::PushConstantsSize { bytes: bytes.len() },
            ));
        }
        if bytes.len() > pipeline.push_constant_bytes as usize {
            return Err(VkError::recording(
                CMD,
                E::PushConstantsTooLarge {
                    pipeline: pipeline.name.clone(),
                    bytes: bytes.len(),
                    range: pipeline.push_constant_bytes,
                },
            ));
        }
        // SAFETY: the range [0, len) lies inside the layout's range, which covers all stages.
        unsafe {
            self.device.raw.cmd_push_constants(
                self.cmd,
                pipeline.layout,
                vk::ShaderStageFlags::ALL,
                0,
                bytes,
            )
        };
        Ok(())
    }

    pub fn bind_vertex_buffer(&mut self, binding: u32, buffer: &'a Buffer) {
        const CMD: &str = "vkCmdBindVertexBuffers";
        if let Err(VkError::Recording { problem, .. }) =
            Self::needs_usage(CMD, buffer, vk::BufferUsageFlags::VERTEX_BUFFER)
        {
            return self.defer(CMD, problem);
        }
        // SAFETY: the buffer has vertex usage and is borrowed for 'a.
        unsafe {
            self.device
                .raw
                .cmd_bind_vertex_buffers(self.cmd, binding, &[buffer.raw], &[0])
        };
        self.vertex_buffers.retain(|(b, _)| *b != binding);
        self.vertex_buffers.push((binding, buffer));
    }

    pub fn bind_index_buffer_u32(&mut self, buffer: &'a Buffer) {
        const CMD: &str = "vkCmdBindIndexBuffer";
        if let Err(VkError::Recording { problem, .. }) =
            Self::needs_usage(CMD, buffer, vk::BufferUsageFlags::INDEX_BUFFER)
        {
            return self.defer(CMD, problem);
        }
        // SAFETY: the buffer has index usage and is borrowed for 'a.
        unsafe {
            self.device
                .raw
                .cmd_bind_index_buffer(self.cmd, buffer.raw, 0, vk::IndexType::UINT32)
        };
        self.index_buffer = Some(buffer);
    }

    /// The checks every draw and dispatch share: pipeline of `bind_point`, scope, sets.
    fn check_pipeline_state(
        &self,
        command: &'static str,
        bind_point: vk::PipelineBindPoint,
    ) -> Result<&'a Pipeline> {
        let pipeline = self.pipeline(command)?;
        if pipeline.bind_point != bind_point {
            return Err(VkError::recording(
                command,
                E::BindPoint {
                    pipeline: pipeline.name.clone(),
                    bound: pipeline.bind_point,
                    needed: bind_point,
                },
            ));
        }
        if bind_point == vk::PipelineBindPoint::GRAPHICS {
            let scope = self
                .scope
                .ok_or_else(|| VkError::recording(command, E::OutsideRendering))?;
            if scope.subpass != pipeline.subpass {
                return Err(VkError::recording(
                    command,
                    E::Subpass {
                        pipeline: pipeline.name.clone(),
                        pipeline_subpass: Subpass::describe(pipeline.subpass),
                        scope_subpass: Subpass::describe(scope.subpass),
                    },
                ));
            }
            if scope.formats != pipeline.attachment_formats {
                return Err(VkError::recording(
                    command,
                    E::AttachmentFormats {
                        pipeline: pipeline.name.clone(),
                        pipeline_formats: pipeline.attachment_formats,
                        scope_formats: scope.formats,
                    },
                ));
            }
        } else {
            self.outside_rendering(command)?;
        }
        for (index, layout) in pipeline.set_layouts.iter().enumerate() {
            let bound = self.sets.get(index).copied().flatten();
            if bound.map(|s| s.layout_raw()) != Some(*layout) {
                return Err(VkError::recording(
                    command,
                    E::SetMissing {
                        pipeline: pipeline.name.clone(),
                        index: index as u32,
                    },
                ));
            }
        }
        Ok(pipeline)
    }

    /// Every vertex binding of the pipeline has a buffer; `vertices_end` (when the vertex range
    /// is known) fits in each per-vertex binding, `instances_end` (when known) in each
    /// per-instance binding.
    fn check_vertex_buffers(
        &self,
        command: &'static str,
        pipeline: &Pipeline,
        vertices_end: Option<u32>,
        instances_end: Option<u32>,
    ) -> Result<()> {
        for binding in &pipeline.vertex_bindings {
            let buffer = self
                .vertex_buffers
                .iter()
                .find(|(b, _)| *b == binding.binding)
                .map(|(_, buffer)| *buffer)
                .ok_or_else(|| {
                    VkError::recording(
                        command,
                        E::VertexBufferMissing {
                            pipeline: pipeline.name.clone(),
                            binding: binding.binding,
                        },
                    )
                })?;
            let end = if binding.per_vertex {
                vertices_end
            } else {
                instances_end
            };
            let Some(end) = end.filter(|&e| e > 0) else {
                continue;
            };
            let needed = (end as u64 - 1) * binding.stride as u64 + binding.element_bytes as u64;
            if needed > buffer.size() {
                let (buffer, size) = (buffer.name().to_owned(), buffer.size());
                return Err(VkError::recording(
                    command,
                    if binding.per_vertex {
                        E::VertexRange {
                            buffer,
                            end,
                            needed,
                            size,
                        }
                    } else {
                        E::InstanceRange {
                            buffer,
                            end,
                            needed,
                            size,
                        }
                    },
                ));
            }
        }
        Ok(())
    }

    /// The bound index buffer, when `indices_end` indices fit in it.
    fn check_indices(&self, command: &'static str, first: u32, end: u32) -> Result<&'a Buffer> {
        let index_buffer = self
            .index_buffer
            .ok_or_else(|| VkError::recording(command, E::NoIndexBuffer))?;
        let available = index_buffer.size() / 4;
        if first > end || end as u64 > available {
            return Err(VkError::recording(
                command,
                E::IndexRange {
                    buffer: index_buffer.name().to_owned(),
                    first,
                    end,
                    count: available,
                },
            ));
        }
        Ok(index_buffer)
    }

    /// Error unless a graphics pipeline is bound.
    pub fn draw(&mut self, vertices: Range<u32>) -> Result<()> {
        self.draw_instanced(vertices, 0..1)
    }

    /// `vertices` of each of `instances`; per-instance vertex bindings are checked against the
    /// instance range as per-vertex ones are against the vertex range.
    pub fn draw_instanced(&mut self, vertices: Range<u32>, instances: Range<u32>) -> Result<()> {
        const CMD: &str = "vkCmdDraw";
        let pipeline = self.check_pipeline_state(CMD, vk::PipelineBindPoint::GRAPHICS)?;
        self.check_vertex_buffers(CMD, pipeline, Some(vertices.end), Some(instances.end))?;
        let count = vertices.end.saturating_sub(vertices.start);
        let instance_count = instances.end.saturating_sub(instances.start);
        // SAFETY: a graphics pipeline is bound inside a rendering scope of its formats, with
        // every set and vertex buffer it declares bound and large enough (invariant 3).
        unsafe {
            self.device.raw.cmd_draw(
                self.cmd,
                count,
                instance_count,
                vertices.start,
                instances.start,
            )
        };
        Ok(())
    }

    /// Error unless a graphics pipeline and an index buffer are bound and the range lies inside the index buffer.
    pub fn draw_indexed(&mut self, indices: Range<u32>) -> Result<()> {
        self.draw_indexed_instanced(indices, 0..1)
    }

    /// `indices` of each of `instances`, checked as [`Self::draw_indexed`] and
    /// [`Self::draw_instanced`] check theirs.
    pub fn draw_indexed_instanced(
        &mut self,
        indices: Range<u32>,
        instances: Range<u32>,
    ) -> Result<()> {
        const CMD: &str = "vkCmdDrawIndexed";
        let pipeline = self.check_pipeline_state(CMD, vk::PipelineBindPoint::GRAPHICS)?;
        self.check_vertex_buffers(CMD, pipeline, None, Some(instances.end))?;
        self.check_indices(CMD, indices.start, indices.end)?;
        // SAFETY: as for draw, and the index range lies inside the bound index buffer.
        unsafe {
            self.device.raw.cmd_draw_indexed(
                self.cmd,
                indices.end - indices.start,
                instances.end.saturating_sub(instances.start),
                indices.start,
                0,
                instances.start,
            )
        };
        Ok(())
    }

    /// Every draw of `draws` (indexed through the bound index buffer when they are indexed
    /// commands), checked against the extent they promise ([`crate::indirect`]).
    pub fn draw_indirect(&mut self, draws: &'a IndirectDraws) -> Result<()> {
        let indexed = draws.kind() == IndirectKind::DrawIndexed;
        let cmd: &'static str = if indexed {
            "vkCmdDrawIndexedIndirect"
        } else {
            "vkCmdDrawIndirect"
        };
        let pipeline = self.check_pipeline_state(cmd, vk::PipelineBindPoint::GRAPHICS)?;
        Self::needs_usage(cmd, draws.buffer(), vk::BufferUsageFlags::INDIRECT_BUFFER)?;
        let extent = draws.extent();
        let vertices = (!indexed).then_some(extent.vertices);
        self.check_vertex_buffers(cmd, pipeline, vertices, Some(extent.instances))?;
        let (buffer, count, stride) = (draws.buffer().raw, draws.draws(), draws.kind().stride());
        if indexed {
            self.check_indices(cmd, 0, extent.indices)?;
            // SAFETY: as for draw_indexed; every command's indices and instances lie inside
            // the promised extent, checked against the bound buffers above, and the command
            // count was checked against the device's limit when the buffer was made.
            unsafe {
                self.device
                    .raw
                    .cmd_draw_indexed_indirect(self.cmd, buffer, 0, count, stride)
            };
        } else {
            // SAFETY: as for draw, with the extent as the ranges.
            unsafe {
                self.device
                    .raw
                    .cmd_draw_indirect(self.cmd, buffer, 0, count, stride)
            };
        }
        Ok(())
    }

    /// Error unless a compute pipeline is bound.
    pub fn dispatch(&mut self, groups: [u32; 3]) -> Result<()> {
        const CMD: &str = "vkCmdDispatch";
        self.check_pipeline_state(CMD, vk::PipelineBindPoint::COMPUTE)?;
        let max = self.device.info.caps.max_compute_work_group_count;
        if groups.iter().zip(&max).any(|(g, m)| g > m) {
            return Err(VkError::recording(CMD, E::WorkgroupCount { groups, max }));
        }
        // SAFETY: a compute pipeline is bound outside a rendering scope with its sets.
        unsafe {
            self.device
                .raw
                .cmd_dispatch(self.cmd, groups[0], groups[1], groups[2])
        };
        Ok(())
    }

    pub fn memory_barrier(
        &mut self,
        src: (vk::PipelineStageFlags, vk::AccessFlags),
        dst: (vk::PipelineStageFlags, vk::AccessFlags),
    ) {
        const CMD: &str = "vkCmdPipelineBarrier";
        if self.scope.is_some() {
            // Barriers inside dynamic rendering need dynamicRenderingLocalRead; Tessera has none.
            return self.defer(CMD, E::InsideRendering);
        }
        let barrier = vk::MemoryBarrier::default()
            .src_access_mask(src.1)
            .dst_access_mask(dst.1);
        // SAFETY: outside a rendering scope; a global memory barrier references no object.
        unsafe {
            self.device.raw.cmd_pipeline_barrier(
                self.cmd,
                src.0,
                dst.0,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            )
        };
    }

    /// Copies `min(src, dst)` bytes from the start of `src` to the start of `dst`.
    pub fn copy_buffer(&mut self, src: &'a Buffer, dst: &'a Buffer) -> Result<()> {
        const CMD: &str = "vkCmdCopyBuffer";
        self.outside_rendering(CMD)?;
        Self::needs_usage(CMD, src, vk::BufferUsageFlags::TRANSFER_SRC)?;
        Self::needs_usage(CMD, dst, vk::BufferUsageFlags::TRANSFER_DST)?;
        let region = [vk::BufferCopy::default().size(src.size().min(dst.size()))];
        // SAFETY: outside a rendering scope; both buffers have the usages and hold the region.
        unsafe {
            self.device
                .raw
                .cmd_copy_buffer(self.cmd, src.raw, dst.raw, &region)
        };
        Ok(())
    }

    /// Writes `data` into `dst` at `offset` from the command buffer itself (vkCmdUpdateBuffer,
    /// in pieces of at most 65,536 bytes): a small table that changes every frame, without a
    /// staging buffer or a host-visible copy per frame slot. `offset` and the length are
    /// multiples of 4 and the range lies in `dst`; ordering against earlier readers and later
    /// ones is the caller's barrier (a transfer write).
    pub fn update_buffer(&mut self, dst: &'a Buffer, offset: u64, data: &[u8]) -> Result<()> {
        const CMD: &str = "vkCmdUpdateBuffer";
        const PIECE: usize = 65536;
        self.outside_rendering(CMD)?;
        Self::needs_usage(CMD, dst, vk::BufferUsageFlags::TRANSFER_DST)?;
        Self::needs_size(CMD, dst, offset + data.len() as u64)?;
        if !offset.is_multiple_of(4) || !data.len().is_multiple_of(4) {
            return Err(VkError::recording(
                CMD,
                E::UpdateAlignment {
                    offset,
                    bytes: data.len(),
                },
            ));
        }
        for (k, piece) in data.chunks(PIECE).enumerate() {
            // SAFETY: outside a rendering scope; `dst` has TRANSFER_DST and holds the range,
            // whose offset and size are multiples of 4 and at most 65,536 bytes.
            unsafe {
                self.device.raw.cmd_update_buffer(
                    self.cmd,
                    dst.raw,
                    offset + (k * PIECE) as u64,
                    piece,
                )
            };
        }
        Ok(())
    }

    /// Uploads level 0 of `texture` from the start of `staging` (tightly packed texels), blits
    /// the rest of its mip chain from it, and leaves every level in SHADER_READ_ONLY_OPTIMAL.
    /// The previous contents are discarded; earlier work on the queue that samples the texture
    /// is waited for by the barriers.
    pub fn upload_texture(&mut self, staging: &'a Buffer, texture: &'a Texture) -> Result<()> {
        const CMD: &str = "vkCmdCopyBufferToImage";
        self.outside_rendering(CMD)?;
        Self::needs_usage(CMD, staging, vk::BufferUsageFlags::TRANSFER_SRC)?;
        Self::needs_size(CMD, staging, texture.byte_len())?;
        let device = &self.device.raw;
        let (cmd, image, levels) = (self.cmd, texture.raw_image(), texture.levels());
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let write = vk::AccessFlags::TRANSFER_WRITE;
        let sampled = (
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::AccessFlags::SHADER_READ,
        );
        let extent = texture.extent();
        let region = vk::BufferImageCopy::default()
            .image_subresource(color_layers(0))
            .image_extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth: 1,
            });
        // SAFETY: outside a rendering scope; the texture (borrowed for 'a) has TRANSFER_DST
        // usage, `levels` levels, and TRANSFER_SRC usage with blit and linear-filter format
        // features whenever levels > 1 (Texture::new); the staging buffer has TRANSFER_SRC
        // usage and holds level 0 (checked). The first barrier discards the old contents
        // (UNDEFINED) after every earlier command on the queue; each level is written before
        // it is read, and all end in SHADER_READ_ONLY_OPTIMAL, the texture's resting layout.
        unsafe {
            image_barrier(
                device,
                cmd,
                image,
                0..levels,
                (
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                ),
                (
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::AccessFlags::MEMORY_WRITE,
                ),
                (transfer, write),
            );
            device.cmd_copy_buffer_to_image(
                cmd,
                staging.raw,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
            for level in 1..levels {
                image_barrier(
                    device,
                    cmd,
                    image,
                    level - 1..level,
                    (
                        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    ),
                    (transfer, write),
                    (transfer, vk::AccessFlags::TRANSFER_READ),
                );
                let corner = |e: vk::Extent2D| vk::Offset3D {
                    x: e.width as i32,
                    y: e.height as i32,
                    z: 1,
                };
                let blit = vk::ImageBlit::default()
                    .src_subresource(color_layers(level - 1))
                    .src_offsets([
                        vk::Offset3D::default(),
                        corner(texture.level_extent(level - 1)),
                    ])
                    .dst_subresource(color_layers(level))
                    .dst_offsets([vk::Offset3D::default(), corner(texture.level_extent(level))]);
                device.cmd_blit_image(
                    cmd,
                    image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[blit],
                    vk::Filter::LINEAR,
                );
            }
            if levels > 1 {
                image_barrier(
                    device,
                    cmd,
                    image,
                    0..levels - 1,
                    (
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    ),
                    (transfer, write),
                    sampled,
                );
            }
            image_barrier(
                device,
                cmd,
                image,
                levels - 1..levels,
                (
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                ),
                (transfer, write),
                sampled,
            );
        }
        Ok(())
    }

    /// Copies `level` of `texture` (tightly packed) to the start of `buffer`, then makes the
    /// buffer readable by the host; the level returns to SHADER_READ_ONLY_OPTIMAL. For tests.
    #[cfg(test)]
    pub(crate) fn read_texture_level(
        &mut self,
        texture: &'a Texture,
        level: u32,
        buffer: &'a Buffer,
    ) -> Result<()> {
        const CMD: &str = "vkCmdCopyImageToBuffer";
        self.outside_rendering(CMD)?;
        Self::needs_usage(CMD, buffer, vk::BufferUsageFlags::TRANSFER_DST)?;
        let needed = vk::ImageUsageFlags::TRANSFER_SRC;
        if !texture.usage().contains(needed) {
            return Err(VkError::recording(
                CMD,
                E::TextureUsage {
                    texture: texture.name().to_owned(),
                    needed,
                },
            ));
        }
        if level >= texture.levels() {
            return Err(VkError::recording(
                CMD,
                E::MipLevel {
                    texture: texture.name().to_owned(),
                    level,
                    levels: texture.levels(),
                },
            ));
        }
        let extent = texture.level_extent(level);
        let bytes =
            extent.width as u64 * extent.height as u64 * texture.format().bytes_per_texel() as u64;
        Self::needs_size(CMD, buffer, bytes)?;
        let device = &self.device.raw;
        let (cmd, image) = (self.cmd, texture.raw_image());
        let region = vk::BufferImageCopy::default()
            .image_subresource(color_layers(level))
            .image_extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth: 1,
            });
        let transfer = vk::PipelineStageFlags::TRANSFER;
        // SAFETY: outside a rendering scope; the texture (borrowed for 'a) has TRANSFER_SRC
        // usage and the level, which rests in SHADER_READ_ONLY_OPTIMAL; the buffer has
        // TRANSFER_DST usage and holds the level (checked).
        unsafe {
            image_barrier(
                device,
                cmd,
                image,
                level..level + 1,
                (
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                ),
                (
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::AccessFlags::MEMORY_WRITE,
                ),
                (transfer, vk::AccessFlags::TRANSFER_READ),
            );
            device.cmd_copy_image_to_buffer(
                cmd,
                image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer.raw,
                &[region],
            );
            image_barrier(
                device,
                cmd,
                image,
                level..level + 1,
                (
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                ),
                (transfer, vk::AccessFlags::empty()),
                (
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::AccessFlags::SHADER_READ,
                ),
            );
            device.cmd_pipeline_barrier(
                cmd,
                transfer,
                vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[vk::MemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                    .dst_access_mask(vk::AccessFlags::HOST_READ)],
                &[],
                &[],
            );
        }
        Ok(())
    }

    fn query_use(&mut self, pool: &'a QueryPool) -> &mut QueryUse<'a> {
        let i = match self.queries.iter().position(|q| std::ptr::eq(q.pool, pool)) {
            Some(i) => i,
            None => {
                self.queries.push(QueryUse {
                    pool,
                    states: vec![QueryState::Unknown; pool.count as usize],
                });
                self.queries.len() - 1
            }
        };
        &mut self.queries[i]
    }

    pub fn reset_queries(&mut self, pool: &'a QueryPool) {
        const CMD: &str = "vkCmdResetQueryPool";
        if self.scope.is_some() {
            return self.defer(CMD, E::InsideRendering);
        }
        let q = self.query_use(pool);
        if let Some(index) = q
            .states
            .iter()
            .position(|s| matches!(s, QueryState::Active { .. }))
        {
            let problem = E::QueryActive {
                pool: pool.name.clone(),
                index: index as u32,
            };
            return self.defer(CMD, problem);
        }
        q.states.fill(QueryState::Reset);
        // SAFETY: outside a rendering scope, no query of the pool active; borrowed for 'a.
        unsafe {
            self.device
                .raw
                .cmd_reset_query_pool(self.cmd, pool.raw, 0, pool.count)
        };
    }

    /// Checks pool type and index, that the query was reset here and is not in use, and that no
    /// query of the same type (and stream) is active; returns the current scope id.
    fn check_query_begin(
        &mut self,
        call: &'static str,
        pool: &'a QueryPool,
        index: u32,
        types: &[vk::QueryType],
        stream: Option<u32>,
    ) -> Result<u32> {
        if !types.contains(&pool.ty) {
            return Err(VkError::QueryType {
                call,
                pool: pool.name.clone(),
                expected: types[0],
                found: pool.ty,
            });
        }
        pool.check_index(call, index)?;
        let busy = self.queries.iter().any(|q| {
            q.pool.ty == pool.ty
                && q.states
                    .iter()
                    .any(|s| matches!(s, QueryState::Active { stream: st, .. } if *st == stream))
        });
        let scope = self.scope.map_or(0, |s| s.id);
        let state = self.query_use(pool).states[index as usize];
        match state {
            QueryState::Reset if !busy => Ok(scope),
            QueryState::Reset | QueryState::Active { .. } => Err(VkError::recording(
                call,
                E::QueryActive {
                    pool: pool.name.clone(),
                    index,
                },
            )),
            QueryState::Unknown | QueryState::Used => Err(VkError::recording(
                call,
                E::QueryNotReset {
                    pool: pool.name.clone(),
                    index,
                },
            )),
        }
    }

    /// Checks the query is active in the current scope (with `stream`) and marks it used.
    fn check_query_end(
        &mut self,
        call: &'static str,
        pool: &'a QueryPool,
        index: u32,
        stream: Option<u32>,
    ) -> Result<()> {
        pool.check_index(call, index)?;
        let scope = self.scope.map_or(0, |s| s.id);
        let q = self.query_use(pool);
        if q.states[index as usize] != (QueryState::Active { scope, stream }) {
            return Err(VkError::recording(
                call,
                E::QueryNotActive {
                    pool: pool.name.clone(),
                    index,
                },
            ));
        }
        q.states[index as usize] = QueryState::Used;
        Ok(())
    }

    pub fn begin_query(&mut self, pool: &'a QueryPool, index: u32) -> Result<()> {
        const CMD: &str = "vkCmdBeginQuery";
        let types = [vk::QueryType::PIPELINE_STATISTICS, vk::QueryType::OCCLUSION];
        let scope = self.check_query_begin(CMD, pool, index, &types, None)?;
        // SAFETY: the query was reset in this command buffer and no query of its type is active.
        unsafe {
            self.device.raw.cmd_begin_query(
                self.cmd,
                pool.raw,
                index,
                vk::QueryControlFlags::empty(),
            )
        };
        self.query_use(pool).states[index as usize] = QueryState::Active {
            scope,
            stream: None,
        };
        Ok(())
    }

    pub fn end_query(&mut self, pool: &'a QueryPool, index: u32) -> Result<()> {
        self.check_query_end("vkCmdEndQuery", pool, index, None)?;
        // SAFETY: the query is active, begun in the current scope.
        unsafe { self.device.raw.cmd_end_query(self.cmd, pool.raw, index) };
        Ok(())
    }

    pub fn write_timestamp(
        &mut self,
        pool: &'a QueryPool,
        stage: vk::PipelineStageFlags,
        index: u32,
    ) -> Result<()> {
        const CMD: &str = "vkCmdWriteTimestamp";
        self.check_query_begin(CMD, pool, index, &[vk::QueryType::TIMESTAMP], None)?;
        // SAFETY: a timestamp pool, the query reset in this command buffer and unused since.
        unsafe {
            self.device
                .raw
                .cmd_write_timestamp(self.cmd, stage, pool.raw, index)
        };
        self.query_use(pool).states[index as usize] = QueryState::Used;
        Ok(())
    }

    fn xfb_commands(&self) -> Result<&ash::ext::transform_feedback::Device> {
        self.device.transform_feedback()
    }

    /// VK_EXT_transform_feedback: binds `buffers` (whole buffers) at bindings 0.. and begins with counters (see crates/tess/src/capture.rs:721-800 for today's begin/end capture scope and host barrier, which must be expressible with these) ; typed error when the extension is absent.
    pub fn begin_transform_feedback(
        &mut self,
        buffers: &[&'a Buffer],
        counters: &[&'a Buffer],
    ) -> Result<()> {
        let ranges: Vec<_> = buffers.iter().map(|b| (*b, 0, b.size())).collect();
        self.begin_transform_feedback_ranges(&ranges, counters)
    }

    /// As [`Encoder::begin_transform_feedback`], binding `(buffer, offset, size)` regions at
    /// bindings 0.. (several captures into one buffer). Offsets and sizes are multiples of 4.
    pub fn begin_transform_feedback_ranges(
        &mut self,
        ranges: &[(&'a Buffer, u64, u64)],
        counters: &[&'a Buffer],
    ) -> Result<()> {
        const CMD: &str = "vkCmdBeginTransformFeedbackEXT";
        self.xfb_commands()?;
        if self.scope.is_none() {
            return Err(VkError::recording(CMD, E::OutsideRendering));
        }
        if self.transform_feedback {
            return Err(VkError::recording(CMD, E::TransformFeedbackActive));
        }
        let pipeline = self.check_pipeline_state(CMD, vk::PipelineBindPoint::GRAPHICS)?;
        if !pipeline.transform_feedback_output {
            return Err(VkError::recording(
                CMD,
                E::NoTransformFeedbackOutput {
                    pipeline: pipeline.name.clone(),
                },
            ));
        }
        let caps = &self.device.info.caps;
        let max = caps.max_transform_feedback_buffers;
        if ranges.is_empty() || ranges.len() > max as usize || counters.len() > max as usize {
            return Err(VkError::recording(
                CMD,
                E::TransformFeedbackBuffers {
                    count: ranges.len().max(counters.len()),
                    max,
                },
            ));
        }
        for &(buffer, offset, size) in ranges {
            Self::needs_usage(
                CMD,
                buffer,
                vk::BufferUsageFlags::TRANSFORM_FEEDBACK_BUFFER_EXT,
            )?;
            let inside = offset
                .checked_add(size)
                .is_some_and(|end| end <= buffer.size());
            if offset & 3 != 0
                || size & 3 != 0
                || size > caps.max_transform_feedback_buffer_size
                || !inside
            {
                return Err(VkError::recording(
                    CMD,
                    E::TransformFeedbackRange {
                        offset,
                        size,
                        max: caps.max_transform_feedback_buffer_size.min(buffer.size()),
                    },
                ));
            }
        }
        for counter in counters {
            Self::needs_usage(
                CMD,
                counter,
                vk::BufferUsageFlags::TRANSFORM_FEEDBACK_COUNTER_BUFFER_EXT,
            )?;
        }
        let raw: Vec<vk::Buffer> = ranges.iter().map(|r| r.0.raw).collect();
        let offsets: Vec<u64> = ranges.iter().map(|r| r.1).collect();
        let sizes: Vec<u64> = ranges.iter().map(|r| r.2).collect();
        let counter_raw: Vec<vk::Buffer> = counters.iter().map(|c| c.raw).collect();
        let counter_offsets = vec![0u64; counters.len()];
        let xfb = self.xfb_commands()?;
        // SAFETY: the extension is enabled; inside a rendering scope with a graphics pipeline
        // that writes transform feedback; no transform feedback active; the regions lie inside
        // buffers with the usage, aligned and within the device's limits; the counters have
        // the counter usage; the arrays live across the calls and their lengths are passed.
        unsafe {
            (xfb.fp().cmd_bind_transform_feedback_buffers_ext)(
                self.cmd,
                0,
                raw.len() as u32,
                raw.as_ptr(),
                offsets.as_ptr(),
                sizes.as_ptr(),
            );
            (xfb.fp().cmd_begin_transform_feedback_ext)(
                self.cmd,
                0,
                counter_raw.len() as u32,
                counter_raw.as_ptr(),
                counter_offsets.as_ptr(),
            );
        }
        self.transform_feedback = true;
        Ok(())
    }

    pub fn end_transform_feedback(&mut self, counters: &[&'a Buffer]) -> Result<()> {
        const CMD: &str = "vkCmdEndTransformFeedbackEXT";
        let xfb = self.xfb_commands()?;
        if !self.transform_feedback {
            return Err(VkError::recording(CMD, E::TransformFeedbackInactive));
        }
        let max = self.device.info.caps.max_transform_feedback_buffers;
        if counters.len() > max as usize {
            return Err(VkError::recording(
                CMD,
                E::TransformFeedbackBuffers {
                    count: counters.len(),
                    max,
                },
            ));
        }
        for counter in counters {
            Self::needs_usage(
                CMD,
                counter,
                vk::BufferUsageFlags::TRANSFORM_FEEDBACK_COUNTER_BUFFER_EXT,
            )?;
        }
        let counter_raw: Vec<vk::Buffer> = counters.iter().map(|c| c.raw).collect();
        let counter_offsets = vec![0u64; counters.len()];
        // SAFETY: transform feedback is active in this scope; the counters have the usage; the
        // arrays live across the call.
        unsafe {
            (xfb.fp().cmd_end_transform_feedback_ext)(
                self.cmd,
                0,
                counter_raw.len() as u32,
                counter_raw.as_ptr(),
                counter_offsets.as_ptr(),
            )
        };
        self.transform_feedback = false;
        Ok(())
    }

    pub fn begin_query_stream(
        &mut self,
        pool: &'a QueryPool,
        index: u32,
        stream: u32,
    ) -> Result<()> {
        const CMD: &str = "vkCmdBeginQueryIndexedEXT";
        let xfb = self.xfb_commands()?.clone();
        let types = [vk::QueryType::TRANSFORM_FEEDBACK_STREAM_EXT];
        let scope = self.check_query_begin(CMD, pool, index, &types, Some(stream))?;
        let max = self.device.info.caps.max_transform_feedback_streams;
        if stream >= max {
            return Err(VkError::recording(
                CMD,
                E::TransformFeedbackBuffers {
                    count: stream as usize + 1,
                    max,
                },
            ));
        }
        // SAFETY: a stream-query pool of this device, the query reset here and inactive, a
        // stream the device has.
        unsafe {
            (xfb.fp().cmd_begin_query_indexed_ext)(
                self.cmd,
                pool.raw,
                index,
                vk::QueryControlFlags::empty(),
                stream,
            )
        };
        self.query_use(pool).states[index as usize] = QueryState::Active {
            scope,
            stream: Some(stream),
        };
        Ok(())
    }

    pub fn end_query_stream(&mut self, pool: &'a QueryPool, index: u32, stream: u32) -> Result<()> {
        const CMD: &str = "vkCmdEndQueryIndexedEXT";
        let xfb = self.xfb_commands()?.clone();
        self.check_query_end(CMD, pool, index, Some(stream))?;
        // SAFETY: the query is active with this stream, begun in the current scope.
        unsafe { (xfb.fp().cmd_end_query_indexed_ext)(self.cmd, pool.raw, index, stream) };
        Ok(())
    }

    /// Opens a rendering scope (records its begin); `None` and a deferred error inside another.
    fn open_scope(
        &mut self,
        command: &'static str,
        kind: ScopeKind,
        formats: [vk::Format; 2],
    ) -> bool {
        if self.scope.is_some() {
            self.defer(command, E::InsideRendering);
            return false;
        }
        self.scopes_opened += 1;
        self.scope = Some(Scope {
            kind,
            formats,
            subpass: None,
            id: self.scopes_opened,
        });
        true
    }

    /// Dynamic rendering into an offscreen target (clears colour and depth) with full viewport/scissor set.
    pub fn begin_offscreen(&mut self, target: &'a OffscreenTarget, clear: [f32; 4]) {
        let kind = ScopeKind::Offscreen(target.color.raw);
        if self.open_scope("vkCmdBeginRendering", kind, [COLOR_FORMAT, DEPTH_FORMAT]) {
            // SAFETY: outside any scope (checked); the images are borrowed for 'a.
            unsafe {
                record_begin_rendering(
                    &self.device,
                    self.cmd,
                    (target.color.raw, target.color.view),
                    (target.depth.raw, target.depth.view),
                    target.extent,
                    clear,
                )
            };
        }
    }

    /// Records a rendering scope into a swapchain image (see [`crate::swapchain`]).
    ///
    /// # Safety
    /// `color` is an image of `format` and `depth` one of DEPTH_FORMAT, both of `extent` with
    /// their views, alive until this encoder's submission completed; their previous contents may
    /// be discarded.
    pub(crate) unsafe fn begin_frame_scope(
        &mut self,
        color: (vk::Image, vk::ImageView),
        format: vk::Format,
        depth: (vk::Image, vk::ImageView),
        extent: vk::Extent2D,
        clear: [f32; 4],
    ) -> bool {
        let opened = self.open_scope(
            "vkCmdBeginRendering",
            ScopeKind::Frame,
            [format, DEPTH_FORMAT],
        );
        if opened {
            // SAFETY: outside any scope; the caller vouches for the images.
            unsafe { record_begin_rendering(&self.device, self.cmd, color, depth, extent, clear) };
        }
        opened
    }

    /// Closes the open scope when it is of `kind` (any when `None`) and nothing begun inside it
    /// is still active; records the end. False (with a deferred error) otherwise.
    fn close_scope(&mut self, command: &'static str, kind: Option<ScopeKind>) -> bool {
        let Some(scope) = self.scope else {
            self.defer(command, E::OutsideRendering);
            return false;
        };
        // The host's scope is the host's to end (after `finish`).
        if kind.is_some_and(|k| k != scope.kind) || scope.kind == ScopeKind::Host {
            self.defer(command, E::WrongRenderingScope);
            return false;
        }
        if self.transform_feedback {
            self.defer(
                command,
                E::Unclosed {
                    open: "transform feedback",
                },
            );
            return false;
        }
        let active_inside = self.queries.iter().find_map(|q| {
            q.states
                .iter()
                .position(|s| matches!(s, QueryState::Active { scope: id, .. } if *id == scope.id))
                .map(|i| (q.pool.name.clone(), i as u32))
        });
        if let Some((pool, index)) = active_inside {
            self.defer(command, E::QueryActive { pool, index });
            return false;
        }
        // SAFETY: a rendering scope is open, with no query or transform feedback begun inside it.
        unsafe { self.device.raw.cmd_end_rendering(self.cmd) };
        self.scope = None;
        true
    }

    /// The error submission would return before submitting: a deferred misuse, or something
    /// left open. Taken, so check it only right before abandoning or submitting.
    pub(crate) fn take_unready(&mut self) -> Option<VkError> {
        if let Some(e) = self.error.take() {
            return Some(e);
        }
        let open = if self.scope.is_some() {
            Some("a rendering scope")
        } else if self.transform_feedback {
            Some("transform feedback")
        } else if self.queries.iter().any(|q| {
            q.states
                .iter()
                .any(|s| matches!(s, QueryState::Active { .. }))
        }) {
            Some("a query")
        } else if self.labels > 0 {
            Some("a debug label")
        } else {
            None
        };
        open.map(|open| VkError::recording("vkQueueSubmit", E::Unclosed { open }))
    }

    /// Ends rendering, copies colour into `readback` (OffscreenTarget::readback_buffer), with the barriers.
    pub fn end_offscreen_and_copy(&mut self, target: &'a OffscreenTarget, readback: &'a Buffer) {
        const CMD: &str = "vkCmdCopyImageToBuffer";
        let bytes = target.extent.width as u64 * target.extent.height as u64 * 4;
        if let Err(VkError::Recording { problem, .. }) =
            Self::needs_usage(CMD, readback, vk::BufferUsageFlags::TRANSFER_DST)
                .and_then(|()| Self::needs_size(CMD, readback, bytes))
        {
            return self.defer(CMD, problem);
        }
        let kind = ScopeKind::Offscreen(target.color.raw);
        if !self.close_scope("vkCmdEndRendering", Some(kind)) {
            return;
        }
        // SAFETY: the scope that rendered into the target's colour image just ended; the image
        // has TRANSFER_SRC usage (OffscreenTarget::new) and `extent`; the readback buffer has
        // TRANSFER_DST usage and holds width·height·4 bytes (checked above).
        unsafe {
            record_copy_to_buffer(
                &self.device,
                self.cmd,
                target.color.raw,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                target.extent,
                readback.raw,
            );
            self.device.raw.cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[vk::MemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                    .dst_access_mask(vk::AccessFlags::HOST_READ)],
                &[],
                &[],
            );
        }
    }

    /// Ends a rendering scope without copying (attachment-less/capture passes and swapchain frames).
    pub fn end_rendering(&mut self) {
        self.close_scope("vkCmdEndRendering", None);
    }

    /// Rendering scope with no attachments (transform-feedback capture with rasterizer discard): see how capture.rs does it today.
    pub fn begin_rendering_without_attachments(&mut self, extent: vk::Extent2D) {
        let formats = [vk::Format::UNDEFINED, vk::Format::UNDEFINED];
        if !self.open_scope("vkCmdBeginRendering", ScopeKind::Empty, formats) {
            return;
        }
        let extent = vk::Extent2D {
            width: extent.width.max(1),
            height: extent.height.max(1),
        };
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent,
        };
        let rendering = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: extent.width as f32,
            height: extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: outside any scope (checked); a scope without attachments references nothing.
        unsafe {
            self.device.raw.cmd_begin_rendering(self.cmd, &rendering);
            self.device.raw.cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.device.raw.cmd_set_scissor(self.cmd, 0, &[area]);
        }
    }

    /// The raw command buffer and the open scope's (colour, depth) formats, for a vk-core
    /// module that records its own draws inside the scope through ash (the HUD overlay). The
    /// bindings the encoder tracks are forgotten: the caller binds its own pipeline, sets and
    /// buffers, so a later draw through the encoder must bind again.
    pub(crate) fn raw_in_scope(
        &mut self,
        command: &'static str,
    ) -> Result<(vk::CommandBuffer, [vk::Format; 2])> {
        let Some(scope) = self.scope else {
            return Err(VkError::recording(command, E::OutsideRendering));
        };
        if scope.subpass.is_some() {
            // vk-core's own raw draws (the overlay) are made for dynamic rendering.
            return Err(VkError::recording(
                command,
                E::Subpass {
                    pipeline: "HUD overlay".into(),
                    pipeline_subpass: Subpass::describe(None),
                    scope_subpass: Subpass::describe(scope.subpass),
                },
            ));
        }
        self.pipeline = None;
        self.sets.clear();
        self.vertex_buffers.clear();
        self.index_buffer = None;
        Ok((self.cmd, scope.formats))
    }

    /// The raw command buffer, for vk-core's own recording (swapchain transitions).
    pub(crate) fn raw_cmd(&self) -> vk::CommandBuffer {
        self.cmd
    }

    /// Ends the recording and hands it to the queue without waiting (an encoder from
    /// [`Device::encoder`]). Sound because submission takes the encoder by value: what it
    /// borrowed can be dropped only after this returns, and the retire queue then keeps it
    /// until the GPU finished. A recording found invalid is not submitted: its error is returned.
    pub fn submit(mut self) -> Result<Submission> {
        let Some(Origin::Unwaited { pool }) = self.origin.take() else {
            // An encoder of submit_once or of a frame, exchanged into this one's place: it is
            // abandoned here (its own submitter reports the exchange too).
            return Err(VkError::recording("vkQueueSubmit", E::Exchanged));
        };
        self.origin = Some(Origin::Unwaited { pool });
        let device = self.device.clone();
        let cmd = self.cmd;
        // SAFETY: no semaphores or fence; the command buffer's pool is retired below with the
        // serial, so it is recycled only after the submission completed.
        let (serial, _) = unsafe { self.submit_with(&[], &[], vk::Fence::null()) }?;
        device.retire(Retired::CommandPool { pool, cmd });
        Ok(Submission { serial, device })
    }

    /// Ends and submits the recording. Returns the serial and the origin (for the caller to
    /// recycle once the serial completed). A deferred error, or anything left open, returns the
    /// error instead and the encoder is abandoned unsubmitted.
    ///
    /// # Safety
    /// As [`DeviceShared::submit`](crate::DeviceShared) for `wait`, `signal` and `fence`; the
    /// caller keeps whatever it recorded outside the encoder's borrows alive until the serial.
    pub(crate) unsafe fn submit_with(
        mut self,
        wait: &[crate::command::Wait],
        signal: &[vk::Semaphore],
        fence: vk::Fence,
    ) -> Result<(u64, Origin)> {
        if let Some(e) = self.take_unready() {
            return Err(e);
        }
        // SAFETY: recording began in `begin`; nothing is left open.
        unsafe { self.device.raw.end_command_buffer(self.cmd) }.ctx("vkEndCommandBuffer")?;
        // SAFETY: the command buffer is executable and owned by this encoder; what it references
        // is borrowed for 'a, which outlives this call (invariant 1); the caller vouches for the
        // semaphores and fence.
        let serial = unsafe { self.device.submit(&[self.cmd], wait, signal, fence) }?;
        for set in &self.bound_sets {
            set.used_by(serial);
        }
        let origin = self.origin.take().unwrap_or(Origin::Frame);
        Ok((serial, origin))
    }
}

/// A recording handed to the queue by [`Encoder::submit`].
pub struct Submission {
    serial: u64,
    device: Device,
}

impl Submission {
    /// Blocks until the GPU finished this submission (and every earlier one).
    pub fn wait(&self) -> Result<()> {
        self.device.wait_serial(self.serial)?;
        self.device.collect_retired();
        Ok(())
    }

    pub fn is_complete(&self) -> bool {
        self.device.completed_serial() >= self.serial
    }
}

impl Drop for Encoder<'_> {
    fn drop(&mut self) {
        for set in &self.bound_sets {
            set.leave_recording();
        }
        // Still owning a one-shot pool means the recording was never submitted: hand it back.
        if let Some(Origin::Once { pool } | Origin::Unwaited { pool }) = self.origin.take() {
            // SAFETY: never submitted, so not pending.
            unsafe { self.device.recycle_once_pool(pool, self.cmd) };
        }
    }
}

/// The colour aspect of one mip level (layer 0).
fn color_layers(level: u32) -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers::default()
        .aspect_mask(vk::ImageAspectFlags::COLOR)
        .mip_level(level)
        .layer_count(1)
}

/// Records a layout transition of the colour `levels` of `image` with the given scopes.
///
/// # Safety
/// `cmd` is recording outside a rendering scope; `image` is a colour image with those levels,
/// in layout `layouts.0` (or that is UNDEFINED), alive until the submission completed.
unsafe fn image_barrier(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    levels: Range<u32>,
    layouts: (vk::ImageLayout, vk::ImageLayout),
    src: (vk::PipelineStageFlags, vk::AccessFlags),
    dst: (vk::PipelineStageFlags, vk::AccessFlags),
) {
    let barrier = vk::ImageMemoryBarrier::default()
        .image(image)
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .src_access_mask(src.1)
        .dst_access_mask(dst.1)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .subresource_range(
            vk::ImageSubresourceRange::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .base_mip_level(levels.start)
                .level_count(levels.end - levels.start)
                .layer_count(1),
        );
    // SAFETY: the caller's contract.
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            src.0,
            dst.0,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[barrier],
        )
    };
}

/// Transitions colour and depth into attachment layouts (discarding their contents), begins
/// dynamic rendering with clears, and sets a full-extent viewport (y flipped so +y is up) and
/// scissor.
///
/// # Safety
/// `cmd` is recording outside a rendering scope; the images live until its submission completed;
/// `color` has a colour view and `depth` a depth view of at least `extent`.
pub(crate) unsafe fn record_begin_rendering(
    device: &Device,
    cmd: vk::CommandBuffer,
    (color, color_view): (vk::Image, vk::ImageView),
    (depth, depth_view): (vk::Image, vk::ImageView),
    extent: vk::Extent2D,
    clear: [f32; 4],
) {
    // SAFETY: the caller's contract; from UNDEFINED, whatever layout the images were in.
    unsafe {
        transition(
            &device.raw,
            cmd,
            color,
            vk::ImageAspectFlags::COLOR,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        );
        transition(
            &device.raw,
            cmd,
            depth,
            vk::ImageAspectFlags::DEPTH,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        );
    }
    let color_att = [vk::RenderingAttachmentInfo::default()
        .image_view(color_view)
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            color: vk::ClearColorValue { float32: clear },
        })];
    let depth_att = vk::RenderingAttachmentInfo::default()
        .image_view(depth_view)
        .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::DONT_CARE)
        .clear_value(vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: 1.0,
                stencil: 0,
            },
        });
    let area = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    };
    let info = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(1)
        .color_attachments(&color_att)
        .depth_attachment(&depth_att);
    let viewport = vk::Viewport {
        x: 0.0,
        y: extent.height as f32,
        width: extent.width as f32,
        height: -(extent.height as f32),
        min_depth: 0.0,
        max_depth: 1.0,
    };
    // SAFETY: the caller's contract; the attachments are in the layouts named above.
    unsafe {
        device.raw.cmd_begin_rendering(cmd, &info);
        device.raw.cmd_set_viewport(cmd, 0, &[viewport]);
        device.raw.cmd_set_scissor(cmd, 0, &[area]);
    }
}

/// Transitions a colour image from `from` to TRANSFER_SRC and copies it whole (tightly packed
/// 4-byte texels) into `buffer`: offscreen readbacks and swapchain screenshots.
///
/// # Safety
/// `cmd` is recording outside a rendering scope; `image` has TRANSFER_SRC usage, `extent`, and is
/// in layout `from`; `buffer` has TRANSFER_DST usage and holds `extent.width · extent.height · 4`
/// bytes; both live until the submission completed.
pub(crate) unsafe fn record_copy_to_buffer(
    device: &Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    from: vk::ImageLayout,
    extent: vk::Extent2D,
    buffer: vk::Buffer,
) {
    // SAFETY: the caller's contract.
    unsafe {
        transition(
            &device.raw,
            cmd,
            image,
            vk::ImageAspectFlags::COLOR,
            from,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        )
    };
    let region = vk::BufferImageCopy::default()
        .image_subresource(
            vk::ImageSubresourceLayers::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .layer_count(1),
        )
        .image_extent(vk::Extent3D {
            width: extent.width,
            height: extent.height,
            depth: 1,
        });
    // SAFETY: the caller's contract.
    unsafe {
        device.raw.cmd_copy_image_to_buffer(
            cmd,
            image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer,
            &[region],
        )
    };
}
