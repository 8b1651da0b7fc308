//! 2D images with one view, for render targets and depth.
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext};
use crate::retire::Retired;
use ash::vk;
use gpu_allocator::vulkan::Allocation;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct ImageDesc<'a> {
    pub name: &'a str,
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub usage: vk::ImageUsageFlags,
    pub aspect: vk::ImageAspectFlags,
}

/// An image with one view; view, image and memory are destroyed together through the retire
/// queue.
pub struct Image {
    pub view: vk::ImageView,
    pub raw: vk::Image,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub aspect: vk::ImageAspectFlags,
    allocation: Option<Allocation>,
    device: Arc<DeviceShared>,
}

impl Image {
    pub fn new(device: &Device, desc: &ImageDesc<'_>) -> Result<Self> {
        Self::with_levels(device, desc, 1)
    }

    /// As [`Image::new`] with `levels` mip levels, all covered by the view (textures).
    pub(crate) fn with_levels(device: &Device, desc: &ImageDesc<'_>, levels: u32) -> Result<Self> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent.width.max(1),
                height: desc.extent.height.max(1),
                depth: 1,
            })
            .mip_levels(levels.max(1))
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: device live; info valid.
        let raw = unsafe { device.raw.create_image(&info, None) }.ctx("vkCreateImage")?;
        device.created(1);
        // SAFETY: raw just created.
        let requirements = unsafe { device.raw.get_image_memory_requirements(raw) };
        let bind = |memory, offset| {
            // SAFETY: raw is unbound; allocate_bound passes memory made for its requirements.
            unsafe { device.raw.bind_image_memory(raw, memory, offset) }.ctx("vkBindImageMemory")
        };
        let allocation = match device.allocate_bound(
            desc.name,
            requirements,
            MemoryLocation::GpuOnly,
            false,
            bind,
        ) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: raw is unused.
                unsafe { device.raw.destroy_image(raw, None) };
                device.destroyed(1);
                return Err(e);
            }
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(desc.format)
            .subresource_range(subresource_range(desc.aspect).level_count(levels.max(1)));
        // SAFETY: image is bound to memory.
        let view = match unsafe { device.raw.create_image_view(&view_info, None) }
            .ctx("vkCreateImageView")
        {
            Ok(v) => {
                device.created(1);
                v
            }
            Err(e) => {
                // SAFETY: raw has no view and was never used.
                unsafe { device.raw.destroy_image(raw, None) };
                device.destroyed(1);
                device.free(allocation);
                return Err(e);
            }
        };
        device.set_name(raw, desc.name);
        device.set_name(view, &format!("{} view", desc.name));
        Ok(Self {
            view,
            raw,
            format: desc.format,
            extent: desc.extent,
            aspect: desc.aspect,
            allocation: Some(allocation),
            device: device.shared.clone(),
        })
    }
}

pub fn subresource_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(aspect)
        .level_count(1)
        .layer_count(1)
}

impl Drop for Image {
    fn drop(&mut self) {
        self.device.retire(Retired::Image {
            view: self.view,
            raw: self.raw,
            allocation: self.allocation.take(),
        });
    }
}

/// Records a whole-image layout transition with a conservative all-commands barrier.
///
/// # Safety
/// `cmd` is recording outside a rendering scope; `image` lives until the submission completed,
/// has `aspect`, and is in layout `from` (or `from` is UNDEFINED).
pub(crate) unsafe fn transition(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    from: vk::ImageLayout,
    to: vk::ImageLayout,
) {
    let barrier = vk::ImageMemoryBarrier::default()
        .image(image)
        .old_layout(from)
        .new_layout(to)
        .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
        .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .subresource_range(subresource_range(aspect));
    // SAFETY: the caller's contract.
    unsafe {
        device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[barrier],
        )
    };
}
