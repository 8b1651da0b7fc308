//! Window target: surface + swapchain that survives resize, minimise and out-of-date, with
//! per-frame synchronisation and an optional readback of the presented image (screenshots).
use crate::buffer::{Buffer, BufferDesc};
use crate::device::Device;
use crate::error::{Result, VkContext, VkError};
use crate::image::{transition, Image, ImageDesc};
use crate::instance::Instance;
use crate::target::{begin_rendering_view, Rgba8, DEPTH_FORMAT};
use ash::vk;
use gpu_allocator::MemoryLocation;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};
use std::ffi::CStr;
use std::sync::Arc;

pub const FRAMES_IN_FLIGHT: usize = 2;

/// Instance extensions needed to present to windows of this display.
pub fn required_surface_extensions(display: RawDisplayHandle) -> Result<Vec<&'static CStr>> {
    let names = ash_window::enumerate_required_extensions(display)
        .map_err(|e| VkError::Surface(e.to_string()))?;
    // SAFETY: ash-window returns pointers to 'static NUL-terminated extension-name constants.
    Ok(names
        .iter()
        .map(|&p| unsafe { CStr::from_ptr(p) })
        .collect())
}

struct FrameSync {
    image_available: vk::Semaphore,
    in_flight: vk::Fence,
    cmd: vk::CommandBuffer,
}

/// What a frame records into: the command buffer, the swapchain image, its extent and slot.
pub struct Frame {
    pub cmd: vk::CommandBuffer,
    pub slot: usize,
    pub image_index: u32,
    pub extent: vk::Extent2D,
}

/// Drop order: wait idle, per-image objects (views, depth, semaphores), swapchain, frame sync,
/// command pool, surface; the instance Arc last.
pub struct Swapchain {
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    render_finished: Vec<vk::Semaphore>,
    depth: Option<Image>,
    frames: Vec<FrameSync>,
    pool: vk::CommandPool,
    frame_index: usize,
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    needs_rebuild: bool,
    loader: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    surface_loader: ash::khr::surface::Instance,
    device: Device,
    _instance: Arc<Instance>,
}

impl Swapchain {
    /// Device extension a swapchain needs.
    pub const DEVICE_EXTENSION: &'static CStr = ash::khr::swapchain::NAME;

    pub fn new(
        device: &Device,
        display: RawDisplayHandle,
        window: RawWindowHandle,
        extent: vk::Extent2D,
    ) -> Result<Self> {
        let instance = device.instance.clone();
        // SAFETY: the handles come from a live winit window that outlives this swapchain (the
        // viewer drops the swapchain before the window).
        let surface = unsafe {
            ash_window::create_surface(&instance.entry, &instance.raw, display, window, None)
        }
        .ctx("vkCreate*SurfaceKHR")?;
        let surface_loader = ash::khr::surface::Instance::new(&instance.entry, &instance.raw);
        // SAFETY: surface and physical device are live.
        let supported = unsafe {
            surface_loader.get_physical_device_surface_support(
                device.physical,
                device.queue_family,
                surface,
            )
        }
        .unwrap_or(false);
        if !supported {
            // SAFETY: surface unused.
            unsafe { surface_loader.destroy_surface(surface, None) };
            return Err(VkError::Surface(format!(
                "{} cannot present to this window",
                device.info.name
            )));
        }
        // SAFETY: surface and physical device are live.
        let formats =
            unsafe { surface_loader.get_physical_device_surface_formats(device.physical, surface) }
                .ctx("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        // UNORM, like the offscreen target, so a window screenshot equals an offscreen render.
        let format = formats
            .iter()
            .find(|f| {
                f.format == vk::Format::B8G8R8A8_UNORM || f.format == vk::Format::R8G8B8A8_UNORM
            })
            .or(formats.first())
            .map(|f| f.format)
            .ok_or_else(|| VkError::Surface("the surface offers no format".into()))?;
        let loader = ash::khr::swapchain::Device::new(&instance.raw, &device.raw);
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(device.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: device live.
        let pool = unsafe { device.raw.create_command_pool(&pool_info, None) }
            .ctx("vkCreateCommandPool")?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(FRAMES_IN_FLIGHT as u32);
        // SAFETY: pool live.
        let cmds = unsafe { device.raw.allocate_command_buffers(&alloc) }
            .ctx("vkAllocateCommandBuffers")?;
        let mut frames = Vec::new();
        for (i, cmd) in cmds.into_iter().enumerate() {
            // SAFETY: device live.
            let (image_available, in_flight) = unsafe {
                (
                    device
                        .raw
                        .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                        .ctx("vkCreateSemaphore")?,
                    device
                        .raw
                        .create_fence(
                            &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                            None,
                        )
                        .ctx("vkCreateFence")?,
                )
            };
            device.set_name(cmd, &format!("frame {i} commands"));
            frames.push(FrameSync {
                image_available,
                in_flight,
                cmd,
            });
        }
        let mut sc = Self {
            raw: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            render_finished: Vec::new(),
            depth: None,
            frames,
            pool,
            frame_index: 0,
            extent,
            format,
            needs_rebuild: true,
            loader,
            surface,
            surface_loader,
            device: device.clone(),
            _instance: instance,
        };
        sc.rebuild(extent)?;
        Ok(sc)
    }

    /// Marks the swapchain for rebuilding at `extent` (window resized).
    pub fn resize(&mut self, extent: vk::Extent2D) {
        self.extent = extent;
        self.needs_rebuild = true;
    }

    fn destroy_images(&mut self) {
        // SAFETY: called after wait_idle; the objects belong to this swapchain.
        unsafe {
            for &v in &self.views {
                self.device.raw.destroy_image_view(v, None);
            }
            for &s in &self.render_finished {
                self.device.raw.destroy_semaphore(s, None);
            }
        }
        self.views.clear();
        self.render_finished.clear();
        self.images.clear();
        self.depth = None;
    }

    fn rebuild(&mut self, wanted: vk::Extent2D) -> Result<bool> {
        // SAFETY: surface and device are live.
        let caps = unsafe {
            self.surface_loader
                .get_physical_device_surface_capabilities(self.device.physical, self.surface)
        }
        .ctx("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: wanted
                    .width
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: wanted
                    .height
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            // Minimised: keep the old swapchain until the window has an area again.
            return Ok(false);
        }
        self.device.wait_idle();
        self.destroy_images();
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | (caps.supported_usage_flags & vk::ImageUsageFlags::TRANSFER_SRC);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format)
            .image_color_space(vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true)
            .old_swapchain(self.raw);
        // SAFETY: the old swapchain is retired by this call and destroyed right after.
        let raw =
            unsafe { self.loader.create_swapchain(&info, None) }.ctx("vkCreateSwapchainKHR")?;
        if self.raw != vk::SwapchainKHR::null() {
            // SAFETY: the device is idle; the old swapchain's images are no longer used.
            unsafe { self.loader.destroy_swapchain(self.raw, None) };
        }
        self.raw = raw;
        // SAFETY: raw is live.
        self.images =
            unsafe { self.loader.get_swapchain_images(raw) }.ctx("vkGetSwapchainImagesKHR")?;
        for (i, &image) in self.images.iter().enumerate() {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(self.format)
                .subresource_range(crate::image::subresource_range(vk::ImageAspectFlags::COLOR));
            // SAFETY: image belongs to the swapchain.
            self.views.push(
                unsafe { self.device.raw.create_image_view(&view_info, None) }
                    .ctx("vkCreateImageView")?,
            );
            // SAFETY: device live.
            self.render_finished.push(
                unsafe {
                    self.device
                        .raw
                        .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                }
                .ctx("vkCreateSemaphore")?,
            );
            self.device.set_name(image, &format!("swapchain image {i}"));
        }
        self.depth = Some(Image::new(
            &self.device,
            &ImageDesc {
                name: "swapchain depth",
                extent,
                format: DEPTH_FORMAT,
                usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                aspect: vk::ImageAspectFlags::DEPTH,
            },
        )?);
        self.extent = extent;
        self.needs_rebuild = false;
        Ok(true)
    }

    /// Waits for the slot's previous frame, acquires an image and begins its command buffer.
    /// `None` when there is nothing to draw into now (minimised, or rebuilt: try next frame).
    pub fn begin_frame(&mut self) -> Result<Option<Frame>> {
        if self.needs_rebuild && !self.rebuild(self.extent)? {
            return Ok(None);
        }
        let slot = self.frame_index % FRAMES_IN_FLIGHT;
        let sync = &self.frames[slot];
        // SAFETY: fence belongs to this device.
        unsafe {
            self.device
                .raw
                .wait_for_fences(&[sync.in_flight], true, u64::MAX)
        }
        .ctx("vkWaitForFences")?;
        // SAFETY: swapchain and semaphore are live; the semaphore is unsignaled (its last wait completed with the fence).
        let acquired = unsafe {
            self.loader.acquire_next_image(
                self.raw,
                u64::MAX,
                sync.image_available,
                vk::Fence::null(),
            )
        };
        let image_index = match acquired {
            Ok((i, suboptimal)) => {
                if suboptimal {
                    self.needs_rebuild = true;
                }
                i
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.needs_rebuild = true;
                return Ok(None);
            }
            Err(e) => {
                return Err(VkError::Call {
                    call: "vkAcquireNextImageKHR",
                    result: e,
                })
            }
        };
        // SAFETY: the fence wait above guarantees the command buffer is no longer in use.
        unsafe {
            self.device
                .raw
                .reset_fences(&[sync.in_flight])
                .ctx("vkResetFences")?;
            self.device
                .raw
                .reset_command_buffer(sync.cmd, vk::CommandBufferResetFlags::empty())
                .ctx("vkResetCommandBuffer")?;
            self.device
                .raw
                .begin_command_buffer(
                    sync.cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .ctx("vkBeginCommandBuffer")?;
        }
        Ok(Some(Frame {
            cmd: sync.cmd,
            slot,
            image_index,
            extent: self.extent,
        }))
    }

    /// Begins rendering into the frame's image with a clear.
    pub fn cmd_begin_rendering(&self, frame: &Frame, clear: [f32; 4]) -> Result<()> {
        let depth = self
            .depth
            .as_ref()
            .ok_or_else(|| VkError::Invalid("swapchain has no depth image".into()))?;
        let i = frame.image_index as usize;
        begin_rendering_view(
            &self.device,
            frame.cmd,
            self.images[i],
            self.views[i],
            vk::ImageLayout::UNDEFINED,
            depth,
            frame.extent,
            clear,
        );
        Ok(())
    }

    /// Ends rendering, optionally copies the image for a screenshot, submits and presents.
    /// With a screenshot the frame is waited for and read back.
    pub fn end_frame(&mut self, frame: Frame, screenshot: bool) -> Result<Option<Rgba8>> {
        let device = self.device.clone();
        let i = frame.image_index as usize;
        // SAFETY: rendering was begun by cmd_begin_rendering on this command buffer.
        unsafe { device.raw.cmd_end_rendering(frame.cmd) };
        let readback = if screenshot {
            let buffer = Buffer::new(
                &device,
                &BufferDesc {
                    name: "screenshot readback",
                    size: frame.extent.width as u64 * frame.extent.height as u64 * 4,
                    usage: vk::BufferUsageFlags::TRANSFER_DST,
                    location: MemoryLocation::GpuToCpu,
                },
            )?;
            transition(
                &device.raw,
                frame.cmd,
                self.images[i],
                vk::ImageAspectFlags::COLOR,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            );
            // SAFETY: image in TRANSFER_SRC layout (swapchain created with TRANSFER_SRC when
            // supported); the buffer was sized for the extent above.
            unsafe {
                crate::image::cmd_copy_color_to_buffer(
                    &device.raw,
                    frame.cmd,
                    self.images[i],
                    frame.extent,
                    buffer.raw,
                )
            };
            transition(
                &device.raw,
                frame.cmd,
                self.images[i],
                vk::ImageAspectFlags::COLOR,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                vk::ImageLayout::PRESENT_SRC_KHR,
            );
            Some(buffer)
        } else {
            transition(
                &device.raw,
                frame.cmd,
                self.images[i],
                vk::ImageAspectFlags::COLOR,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::PRESENT_SRC_KHR,
            );
            None
        };
        let sync = &self.frames[frame.slot];
        // SAFETY: recording began in begin_frame.
        unsafe { device.raw.end_command_buffer(frame.cmd) }.ctx("vkEndCommandBuffer")?;
        let wait = [sync.image_available];
        let stages = [vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT];
        let signal = [self.render_finished[i]];
        let cmds = [frame.cmd];
        let submit = [vk::SubmitInfo::default()
            .wait_semaphores(&wait)
            .wait_dst_stage_mask(&stages)
            .command_buffers(&cmds)
            .signal_semaphores(&signal)];
        {
            let _q = device.queue_lock.lock();
            // SAFETY: queue access serialized; all objects live.
            unsafe {
                device
                    .raw
                    .queue_submit(device.queue, &submit, sync.in_flight)
            }
            .ctx("vkQueueSubmit")?;
            let swapchains = [self.raw];
            let indices = [frame.image_index];
            let present = vk::PresentInfoKHR::default()
                .wait_semaphores(&signal)
                .swapchains(&swapchains)
                .image_indices(&indices);
            // SAFETY: the image was acquired in begin_frame and rendered above.
            match unsafe { self.loader.queue_present(device.queue, &present) } {
                Ok(false) => {}
                Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.needs_rebuild = true,
                Err(e) => {
                    return Err(VkError::Call {
                        call: "vkQueuePresentKHR",
                        result: e,
                    })
                }
            }
        }
        self.frame_index += 1;
        match readback {
            Some(buffer) => {
                // SAFETY: fence submitted above.
                unsafe {
                    device
                        .raw
                        .wait_for_fences(&[sync.in_flight], true, u64::MAX)
                }
                .ctx("vkWaitForFences")?;
                let bytes = buffer
                    .mapped()
                    .ok_or_else(|| VkError::Invalid("screenshot buffer not mapped".into()))?;
                let mut pixels =
                    bytes[..(frame.extent.width * frame.extent.height * 4) as usize].to_vec();
                if self.format == vk::Format::B8G8R8A8_UNORM
                    || self.format == vk::Format::B8G8R8A8_SRGB
                {
                    for px in pixels.chunks_exact_mut(4) {
                        px.swap(0, 2);
                    }
                }
                Ok(Some(Rgba8 {
                    width: frame.extent.width,
                    height: frame.extent.height,
                    pixels,
                }))
            }
            None => Ok(None),
        }
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        self.device.wait_idle();
        self.destroy_images();
        // SAFETY: device idle; every object below belongs to this swapchain.
        unsafe {
            self.loader.destroy_swapchain(self.raw, None);
            for f in &self.frames {
                self.device.raw.destroy_semaphore(f.image_available, None);
                self.device.raw.destroy_fence(f.in_flight, None);
            }
            self.device.raw.destroy_command_pool(self.pool, None);
            self.surface_loader.destroy_surface(self.surface, None);
        }
    }
}
