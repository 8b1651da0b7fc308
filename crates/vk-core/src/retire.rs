//! Deferred destruction: submissions are counted on a timeline semaphore, and an object dropped
//! while a submission that could use it is pending waits in a retire queue until it completes.
//!
//! Design decisions:
//! - Every submission (one-shot, swapchain frame, legacy paths) takes the next serial under the
//!   queue lock and signals the device's timeline semaphore with it when it completes; the
//!   semaphore's counter is therefore "every submission up to here has completed".
//! - An object is tagged with the last serial handed out when its last owner drops it. Objects an
//!   [`crate::Encoder`] uses are borrowed until its submission returned (the submit takes the
//!   encoder by value), so that serial covers every submission that could reference them.
//! - When that serial has already completed (one-shot work, which waits) the object is destroyed
//!   at once, so code that waits sees memory come back immediately; otherwise it is queued and
//!   destroyed by the next [`crate::DeviceShared::collect_retired`] (called on every submission,
//!   every retire, by `allocated_bytes` and `wait_idle`) that finds its serial completed.
//! - Memory (gpu-allocator allocations) is handed back together with its handle.
use ash::vk;
use gpu_allocator::vulkan::Allocation;

/// One object waiting for the GPU to finish with it.
pub(crate) enum Retired {
    Buffer {
        raw: vk::Buffer,
        allocation: Option<Allocation>,
    },
    Image {
        view: vk::ImageView,
        raw: vk::Image,
        allocation: Option<Allocation>,
    },
    Pipeline {
        raw: vk::Pipeline,
        layout: vk::PipelineLayout,
    },
    /// A texture's sampler (its image goes as [`Retired::Image`]).
    Sampler(vk::Sampler),
    DescriptorPool(vk::DescriptorPool),
    DescriptorSetLayout(vk::DescriptorSetLayout),
    QueryPool(vk::QueryPool),
    /// A one-shot command pool whose submission was not waited for: recycled, not destroyed.
    CommandPool {
        pool: vk::CommandPool,
        cmd: vk::CommandBuffer,
    },
}

/// The serials handed out and the objects waiting for them (guarded by the device's lock).
#[derive(Default)]
pub(crate) struct RetireQueue {
    /// The serial of the newest submission (0: none yet).
    pub(crate) submitted: u64,
    /// The newest serial known to have completed (a cache of the semaphore's counter).
    pub(crate) completed: u64,
    /// Objects in the order they were retired, so serials are non-decreasing.
    pub(crate) waiting: std::collections::VecDeque<(u64, Retired)>,
}
