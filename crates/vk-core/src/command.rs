//! One-shot command submission: record, submit, wait. Used for uploads, readbacks and
//! offscreen frames where latency does not matter.
use crate::device::Device;
use crate::error::{Result, VkContext, VkError};
use ash::vk;

impl Device {
    /// Records commands with `record`, submits them and waits for completion.
    pub fn one_shot<R>(&self, record: impl FnOnce(vk::CommandBuffer) -> R) -> Result<R> {
        let pool = self
            .one_shot_pool
            .lock()
            .map_err(|_| VkError::Invalid("command pool lock poisoned".into()))?;
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(*pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: pool belongs to this device and is externally synchronized by the lock.
        let cmd =
            unsafe { self.raw.allocate_command_buffers(&info) }.ctx("vkAllocateCommandBuffers")?[0];
        let fence_info = vk::FenceCreateInfo::default();
        // SAFETY: device is live.
        let fence = unsafe { self.raw.create_fence(&fence_info, None) }.ctx("vkCreateFence")?;
        let result = (|| {
            // SAFETY: fresh command buffer.
            unsafe {
                self.raw.begin_command_buffer(
                    cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
            }
            .ctx("vkBeginCommandBuffer")?;
            let r = record(cmd);
            // SAFETY: recording started above.
            unsafe { self.raw.end_command_buffer(cmd) }.ctx("vkEndCommandBuffer")?;
            let cmds = [cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            {
                let _q = self.queue_lock.lock();
                // SAFETY: queue access is serialized by queue_lock.
                unsafe { self.raw.queue_submit(self.queue, &submit, fence) }
                    .ctx("vkQueueSubmit")?;
            }
            // SAFETY: fence was submitted above.
            unsafe { self.raw.wait_for_fences(&[fence], true, u64::MAX) }.ctx("vkWaitForFences")?;
            Ok(r)
        })();
        // SAFETY: the submission completed (or never happened), so both objects are idle.
        unsafe {
            self.raw.destroy_fence(fence, None);
            self.raw.free_command_buffers(*pool, &[cmd]);
        }
        result
    }

    /// Opens a debug-utils label region (shown by capture tools and in validation messages).
    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        if let (Some(du), Ok(name)) = (&self.debug_utils, std::ffi::CString::new(name)) {
            let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
            // SAFETY: cmd is recording.
            unsafe { du.cmd_begin_debug_utils_label(cmd, &label) };
        }
    }

    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(du) = &self.debug_utils {
            // SAFETY: matched with begin_label on the same command buffer.
            unsafe { du.cmd_end_debug_utils_label(cmd) };
        }
    }
}
