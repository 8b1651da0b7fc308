//! VK_EXT_transform_feedback commands. ash 0.38 loads the extension's function pointers
//! (`ash::ext::transform_feedback::Device`) but wraps none of them; this trait gives them the
//! same shape as ash's own wrappers (values instead of count + pointer) so callers never touch
//! the raw pointers.
use ash::vk;

// LEGACY: removed once tess records through Encoder (Encoder::begin_transform_feedback etc.).
#[doc(hidden)]
pub trait TransformFeedbackCommands {
    /// `vkCmdBindTransformFeedbackBuffersEXT` for one binding (all Tessera captures use one).
    ///
    /// # Safety
    /// `cmd` is recording; `buffer` was created with TRANSFORM_FEEDBACK_BUFFER_EXT usage and
    /// `offset + size` lies inside it.
    unsafe fn cmd_bind_transform_feedback_buffer(
        &self,
        cmd: vk::CommandBuffer,
        binding: u32,
        buffer: vk::Buffer,
        offset: vk::DeviceSize,
        size: vk::DeviceSize,
    );

    /// `vkCmdBeginTransformFeedbackEXT` with no counter buffers (capture starts at offset 0).
    ///
    /// # Safety
    /// `cmd` is recording inside a render pass instance, no transform feedback is active, and
    /// buffers are bound for every binding the pipeline writes.
    unsafe fn cmd_begin_transform_feedback(&self, cmd: vk::CommandBuffer);

    /// `vkCmdEndTransformFeedbackEXT` with no counter buffers.
    ///
    /// # Safety
    /// Transform feedback is active on `cmd`, begun inside the same render pass instance.
    unsafe fn cmd_end_transform_feedback(&self, cmd: vk::CommandBuffer);

    /// `vkCmdBeginQueryIndexedEXT`.
    ///
    /// # Safety
    /// `cmd` is recording, the query was reset and is not active, `index` is a valid stream.
    unsafe fn cmd_begin_query_indexed(
        &self,
        cmd: vk::CommandBuffer,
        pool: vk::QueryPool,
        query: u32,
        flags: vk::QueryControlFlags,
        index: u32,
    );

    /// `vkCmdEndQueryIndexedEXT`.
    ///
    /// # Safety
    /// The query is active on `cmd` with the same `index`.
    unsafe fn cmd_end_query_indexed(
        &self,
        cmd: vk::CommandBuffer,
        pool: vk::QueryPool,
        query: u32,
        index: u32,
    );
}

impl TransformFeedbackCommands for ash::ext::transform_feedback::Device {
    unsafe fn cmd_bind_transform_feedback_buffer(
        &self,
        cmd: vk::CommandBuffer,
        binding: u32,
        buffer: vk::Buffer,
        offset: vk::DeviceSize,
        size: vk::DeviceSize,
    ) {
        // SAFETY: one-element arrays that live across the call; the caller upholds the
        // command's usage rules.
        unsafe {
            (self.fp().cmd_bind_transform_feedback_buffers_ext)(
                cmd, binding, 1, &buffer, &offset, &size,
            )
        }
    }

    unsafe fn cmd_begin_transform_feedback(&self, cmd: vk::CommandBuffer) {
        // SAFETY: zero counter buffers, so the null arrays are never read.
        unsafe {
            (self.fp().cmd_begin_transform_feedback_ext)(
                cmd,
                0,
                0,
                std::ptr::null(),
                std::ptr::null(),
            )
        }
    }

    unsafe fn cmd_end_transform_feedback(&self, cmd: vk::CommandBuffer) {
        // SAFETY: as above.
        unsafe {
            (self.fp().cmd_end_transform_feedback_ext)(
                cmd,
                0,
                0,
                std::ptr::null(),
                std::ptr::null(),
            )
        }
    }

    unsafe fn cmd_begin_query_indexed(
        &self,
        cmd: vk::CommandBuffer,
        pool: vk::QueryPool,
        query: u32,
        flags: vk::QueryControlFlags,
        index: u32,
    ) {
        // SAFETY: plain handles and values; the caller upholds the query rules.
        unsafe { (self.fp().cmd_begin_query_indexed_ext)(cmd, pool, query, flags, index) }
    }

    unsafe fn cmd_end_query_indexed(
        &self,
        cmd: vk::CommandBuffer,
        pool: vk::QueryPool,
        query: u32,
        index: u32,
    ) {
        // SAFETY: as above.
        unsafe { (self.fp().cmd_end_query_indexed_ext)(cmd, pool, query, index) }
    }
}
