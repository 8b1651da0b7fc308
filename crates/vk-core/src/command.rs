//! Submission: every submission takes the next serial of the device's timeline (see
//! [`crate::retire`]); one-shot recordings (uploads, readbacks, offscreen frames, where latency
//! does not matter) record into a pooled command buffer, submit and wait.
use crate::device::{Device, DeviceShared};
use crate::encoder::{Encoder, Origin};
use crate::error::{Result, VkContext, VkError};
use crate::retire::Retired;
use ash::vk;

/// A semaphore a submission waits for, the stages that wait, and (for a timeline semaphore)
/// the value waited for; binary semaphores ignore the value.
pub(crate) type Wait = (vk::Semaphore, vk::PipelineStageFlags, u64);

impl DeviceShared {
    /// Submits `cmds` (ended command buffers), signalling the timeline with the returned serial
    /// on completion, plus `signal` (binary semaphores) and `fence`, after `wait`.
    ///
    /// # Safety
    /// Every command buffer is executable, was recorded on this device, is not pending, and
    /// everything it references stays alive until the returned serial completed (the retire
    /// queue keeps objects dropped after this call alive long enough). `wait` and `signal` are
    /// semaphores in the states vkQueueSubmit requires (`signal` binary); `fence` is null or
    /// unsignalled.
    pub(crate) unsafe fn submit(
        &self,
        cmds: &[vk::CommandBuffer],
        wait: &[Wait],
        signal: &[vk::Semaphore],
        fence: vk::Fence,
    ) -> Result<u64> {
        let _q = self
            .queue_lock
            .lock()
            .map_err(|_| VkError::LockPoisoned { what: "queue" })?;
        let mut retired = self.retired.lock().map_err(|_| VkError::LockPoisoned {
            what: "retire queue",
        })?;
        let serial = retired.submitted + 1;
        let wait_semaphores: Vec<_> = wait.iter().map(|w| w.0).collect();
        let wait_stages: Vec<_> = wait.iter().map(|w| w.1).collect();
        let mut signal_semaphores = signal.to_vec();
        signal_semaphores.push(self.timeline);
        // Binary semaphores ignore their value; the timeline's comes last.
        let mut signal_values = vec![0u64; signal.len()];
        signal_values.push(serial);
        let wait_values: Vec<_> = wait.iter().map(|w| w.2).collect();
        let mut timeline_info = vk::TimelineSemaphoreSubmitInfo::default()
            .wait_semaphore_values(&wait_values)
            .signal_semaphore_values(&signal_values);
        let submit = [vk::SubmitInfo::default()
            .wait_semaphores(&wait_semaphores)
            .wait_dst_stage_mask(&wait_stages)
            .command_buffers(cmds)
            .signal_semaphores(&signal_semaphores)
            .push_next(&mut timeline_info)];
        // SAFETY: the queue is serialized by queue_lock; the caller guarantees the rest.
        unsafe { self.raw.queue_submit(self.queue, &submit, fence) }.ctx("vkQueueSubmit")?;
        retired.submitted = serial;
        Ok(serial)
    }

    /// Blocks until submission `serial` (and every earlier one) completed.
    pub(crate) fn wait_serial(&self, serial: u64) -> Result<()> {
        let semaphores = [self.timeline];
        let values = [serial];
        let info = vk::SemaphoreWaitInfo::default()
            .semaphores(&semaphores)
            .values(&values);
        // SAFETY: the timeline semaphore lives as long as the device; waiting has no effect on
        // it, and every serial waited for was or will be signalled by a submission.
        unsafe { self.raw.wait_semaphores(&info, u64::MAX) }.ctx("vkWaitSemaphores")
    }

    /// The newest serial known complete (reads the timeline's counter).
    pub(crate) fn completed_serial(&self) -> u64 {
        // SAFETY: the timeline semaphore lives as long as the device.
        unsafe { self.raw.get_semaphore_counter_value(self.timeline) }.unwrap_or(0)
    }

    /// Destroys every retired object whose submissions completed.
    pub fn collect_retired(&self) {
        let completed = self.completed_serial();
        let ready: Vec<Retired> = {
            let Ok(mut q) = self.retired.lock() else {
                return;
            };
            q.completed = q.completed.max(completed);
            let mut ready = Vec::new();
            while q.waiting.front().is_some_and(|(s, _)| *s <= q.completed) {
                if let Some((_, item)) = q.waiting.pop_front() {
                    ready.push(item);
                }
            }
            ready
        };
        for item in ready {
            // SAFETY: every submission that could use the object completed.
            unsafe { self.destroy_retired(item) };
        }
    }

    /// Takes an object whose last owner dropped it: destroyed now when no submission that could
    /// use it is pending, queued for [`DeviceShared::collect_retired`] otherwise.
    pub(crate) fn retire(&self, item: Retired) {
        let item = {
            let Ok(mut q) = self.retired.lock() else {
                // A poisoned queue leaks the object rather than risk destroying it in use.
                return;
            };
            let serial = q.submitted;
            if serial > q.completed {
                q.completed = q.completed.max(self.completed_serial());
            }
            if serial > q.completed {
                q.waiting.push_back((serial, item));
                None
            } else {
                Some(item)
            }
        };
        if let Some(item) = item {
            // SAFETY: every submission handed out so far completed, so none uses the object.
            unsafe { self.destroy_retired(item) };
        }
        self.collect_retired();
    }

    /// # Safety
    /// No pending submission uses the object, and no other owner remains.
    pub(crate) unsafe fn destroy_retired(&self, item: Retired) {
        // SAFETY: the caller's contract; each handle belongs to this device.
        unsafe {
            match item {
                Retired::Buffer { raw, allocation } => {
                    self.raw.destroy_buffer(raw, None);
                    self.destroyed(1);
                    if let Some(a) = allocation {
                        self.free(a);
                    }
                }
                Retired::Image {
                    view,
                    raw,
                    allocation,
                } => {
                    self.raw.destroy_image_view(view, None);
                    self.raw.destroy_image(raw, None);
                    self.destroyed(2);
                    if let Some(a) = allocation {
                        self.free(a);
                    }
                }
                Retired::Pipeline { raw, layout } => {
                    self.raw.destroy_pipeline(raw, None);
                    self.raw.destroy_pipeline_layout(layout, None);
                    self.destroyed(2);
                }
                Retired::Sampler(s) => {
                    self.raw.destroy_sampler(s, None);
                    self.destroyed(1);
                }
                Retired::DescriptorPool(p) => {
                    self.raw.destroy_descriptor_pool(p, None);
                    self.destroyed(1);
                }
                Retired::DescriptorSetLayout(l) => {
                    self.raw.destroy_descriptor_set_layout(l, None);
                    self.destroyed(1);
                }
                Retired::QueryPool(p) => {
                    self.raw.destroy_query_pool(p, None);
                    self.destroyed(1);
                }
                Retired::CommandPool { pool, cmd } => self.recycle_once_pool(pool, cmd),
            }
        }
    }

    /// A command pool with one primary command buffer in the initial state, for one recording.
    pub(crate) fn take_once_pool(&self) -> Result<(vk::CommandPool, vk::CommandBuffer)> {
        let pooled = self
            .once_pools
            .lock()
            .map_err(|_| VkError::LockPoisoned {
                what: "command pools",
            })?
            .pop();
        if let Some(p) = pooled {
            return Ok(p);
        }
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        // SAFETY: the device is live.
        let pool =
            unsafe { self.raw.create_command_pool(&info, None) }.ctx("vkCreateCommandPool")?;
        self.created(1);
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool was just created and is used by this thread only.
        match unsafe { self.raw.allocate_command_buffers(&alloc) } {
            Ok(cmds) => Ok((pool, cmds[0])),
            Err(result) => {
                // SAFETY: the pool has no command buffers.
                unsafe { self.raw.destroy_command_pool(pool, None) };
                self.destroyed(1);
                Err(VkError::Call {
                    call: "vkAllocateCommandBuffers",
                    result,
                })
            }
        }
    }

    /// Resets a pool taken by [`DeviceShared::take_once_pool`] and makes it available again.
    ///
    /// # Safety
    /// The pool's command buffer is not pending (never submitted, or its submission completed).
    pub(crate) unsafe fn recycle_once_pool(&self, pool: vk::CommandPool, cmd: vk::CommandBuffer) {
        // SAFETY: the caller's contract; the pool is owned by the caller until pushed back.
        let reset = unsafe {
            self.raw
                .reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
        };
        match (reset, self.once_pools.lock()) {
            (Ok(()), Ok(mut pools)) => pools.push((pool, cmd)),
            _ => {
                // SAFETY: as above; a pool that cannot be reset or kept is destroyed instead.
                unsafe { self.raw.destroy_command_pool(pool, None) };
                self.destroyed(1);
            }
        }
    }
}

impl Device {
    /// Records with `record`, submits, and waits for completion.
    ///
    /// Sound because everything the encoder borrowed lives for `'a`, which outlives this call,
    /// and the call returns only after the GPU finished. A recording the encoder found invalid
    /// (see [`Encoder`]) is not submitted: its first error is returned.
    pub fn submit_once<'a, R>(&self, record: impl FnOnce(&mut Encoder<'a>) -> R) -> Result<R> {
        let (pool, cmd) = self.take_once_pool()?;
        // SAFETY: the pool was just taken from the free list, so this encoder owns it.
        let mut encoder = match unsafe { Encoder::begin(self, cmd, Origin::Once { pool }) } {
            Ok(e) => e,
            Err(e) => {
                // SAFETY: the command buffer was never submitted.
                unsafe { self.recycle_once_pool(pool, cmd) };
                return Err(e);
            }
        };
        let id = encoder.id();
        let r = record(&mut encoder);
        if encoder.id() != id {
            // The closure exchanged this encoder with another (std::mem::swap): dropping the
            // one we hold abandons it unsubmitted, and whoever holds ours does the same.
            return Err(VkError::recording(
                "vkQueueSubmit",
                crate::error::RecordingError::Exchanged,
            ));
        }
        // SAFETY: no semaphores or fence; the encoder's borrows ('a) outlive this call, which
        // returns only after the wait below (or leaks the pool when the wait fails).
        let (serial, origin) = unsafe { encoder.submit_with(&[], &[], vk::Fence::null()) }?;
        self.wait_serial(serial)?;
        if let Origin::Once { pool } = origin {
            // SAFETY: the submission completed.
            unsafe { self.recycle_once_pool(pool, cmd) };
        }
        self.collect_retired();
        Ok(r)
    }

    /// An encoder whose recording [`Encoder::submit`] hands to the queue without waiting (work
    /// whose results are read later, e.g. through [`crate::encoder::Submission::wait`]).
    pub fn encoder<'a>(&self) -> Result<Encoder<'a>> {
        let (pool, cmd) = self.take_once_pool()?;
        // SAFETY: the pool was just taken from the free list, so the encoder owns it.
        unsafe { Encoder::begin(self, cmd, Origin::Unwaited { pool }) }.inspect_err(|_| {
            // SAFETY: the command buffer was never submitted.
            unsafe { self.recycle_once_pool(pool, cmd) };
        })
    }
}
