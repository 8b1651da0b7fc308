//! Window target: surface + swapchain that survives resize, minimise and out-of-date, with
//! per-frame synchronisation and an optional readback of the presented image (screenshots).
//!
//! Design decisions:
//! - [`Swapchain::acquire`] hands out a [`SwapchainFrame`] that borrows the swapchain mutably and
//!   derefs to an [`Encoder`]: while it lives the swapchain cannot be rebuilt or dropped, so the
//!   images it records into stay alive; [`SwapchainFrame::present`] takes it by value, so what
//!   its encoder borrowed outlives the submission (afterwards the retire queue takes over).
//! - A frame dropped (or a present that fails its checks) is abandoned: its recording is never
//!   submitted, the acquire semaphore is consumed by an empty submission, and the swapchain is
//!   rebuilt before the next frame (the acquired image cannot be presented unrendered). A frame
//!   leaked with `mem::forget` is noticed at the next acquire, which recovers after an idle wait.
//! - Screenshots copy from the swapchain image, which needs TRANSFER_SRC usage: requested when
//!   the surface supports it, and a typed [`VkError::Unsupported`] otherwise.
use crate::buffer::{Buffer, BufferDesc};
use crate::device::Device;
use crate::encoder::{record_copy_to_buffer, Encoder, Origin};
use crate::error::{RecordingError, Result, VkContext, VkError};
use crate::image::{transition, Image, ImageDesc};
use crate::instance::Instance;
use crate::target::{Rgba8, DEPTH_FORMAT};
use ash::vk;
use gpu_allocator::MemoryLocation;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle, RawDisplayHandle, RawWindowHandle};
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
    /// The images have TRANSFER_SRC usage (screenshots possible).
    screenshots: bool,
    /// A frame was acquired and neither presented nor abandoned (it was leaked).
    outstanding: bool,
    loader: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    surface_loader: ash::khr::surface::Instance,
    device: Device,
    /// The window the surface presents to, kept alive until the surface is destroyed (in
    /// `drop`, before the fields); `None` for the legacy constructor.
    _window: Option<Arc<dyn std::any::Any + Send + Sync>>,
    _instance: Arc<Instance>,
}

impl Swapchain {
    /// Device extension a swapchain needs.
    pub const DEVICE_EXTENSION: &'static CStr = ash::khr::swapchain::NAME;

    /// A swapchain presenting to `window`, which it keeps alive as long as its surface.
    pub fn for_window<W>(device: &Device, window: Arc<W>, extent: vk::Extent2D) -> Result<Self>
    where
        W: HasWindowHandle + HasDisplayHandle + Send + Sync + 'static,
    {
        let display = window
            .display_handle()
            .map_err(|e| VkError::Surface(e.to_string()))?
            .as_raw();
        let handle = window
            .window_handle()
            .map_err(|e| VkError::Surface(e.to_string()))?
            .as_raw();
        // SAFETY: the handles come from `window`, which the swapchain keeps (as `_window`) until
        // after it destroyed the surface.
        unsafe { Self::create(device, display, handle, extent, Some(window)) }
    }

    /// # Safety
    /// `display` and `window` are handles of a live window that outlives the swapchain (or is
    /// kept alive by `keep`).
    unsafe fn create(
        device: &Device,
        display: RawDisplayHandle,
        window: RawWindowHandle,
        extent: vk::Extent2D,
        keep: Option<Arc<dyn std::any::Any + Send + Sync>>,
    ) -> Result<Self> {
        let instance = device.instance.clone();
        // SAFETY: the caller's contract on the handles.
        let surface = unsafe {
            ash_window::create_surface(&instance.entry, &instance.raw, display, window, None)
        }
        .ctx("vkCreate*SurfaceKHR")?;
        device.created(1);
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
            device.destroyed(1);
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
        device.created(1);
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
            device.created(2);
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
            screenshots: false,
            outstanding: false,
            loader,
            surface,
            surface_loader,
            device: device.clone(),
            _window: keep,
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
        self.device
            .destroyed((self.views.len() + self.render_finished.len()) as u64);
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
        self.screenshots = caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_SRC);
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
        self.device.created(1);
        if self.raw != vk::SwapchainKHR::null() {
            // SAFETY: the device is idle; the old swapchain's images are no longer used.
            unsafe { self.loader.destroy_swapchain(self.raw, None) };
            self.device.destroyed(1);
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
            self.device.created(1);
            // SAFETY: device live.
            self.render_finished.push(
                unsafe {
                    self.device
                        .raw
                        .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                }
                .ctx("vkCreateSemaphore")?,
            );
            self.device.created(1);
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

    /// Waits for the slot's previous frame and acquires an image. `None` when there is nothing
    /// to draw into now (minimised, or rebuilt: try next frame). Shared by the frame API and the
    /// legacy one; the slot's fence is left signalled, for whoever submits to reset.
    fn acquire_image(&mut self) -> Result<Option<(usize, u32)>> {
        if self.outstanding {
            self.recover_leaked_frame()?;
        }
        if self.needs_rebuild && !self.rebuild(self.extent)? {
            return Ok(None);
        }
        let slot = self.frame_index % FRAMES_IN_FLIGHT;
        let sync = &self.frames[slot];
        // SAFETY: the fence belongs to this device.
        unsafe {
            self.device
                .raw
                .wait_for_fences(&[sync.in_flight], true, u64::MAX)
        }
        .ctx("vkWaitForFences")?;
        // SAFETY: swapchain and semaphore are live; the semaphore is unsignalled (its last wait
        // completed with the fence, or it was never used).
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
        // SAFETY: the fence wait above guarantees the command buffer is not pending; the pool
        // is used by this swapchain only, which `&mut self` holds.
        unsafe {
            self.device
                .raw
                .reset_command_buffer(sync.cmd, vk::CommandBufferResetFlags::empty())
        }
        .ctx("vkResetCommandBuffer")?;
        Ok(Some((slot, image_index)))
    }

    /// A frame was leaked (`mem::forget`) after its acquire: its semaphore may still be pending.
    /// After an idle wait, every acquire semaphore is replaced and the swapchain rebuilt (which
    /// releases the acquired image).
    fn recover_leaked_frame(&mut self) -> Result<()> {
        self.device.wait_idle();
        for f in &mut self.frames {
            // SAFETY: device live.
            let fresh = unsafe {
                self.device
                    .raw
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }
            .ctx("vkCreateSemaphore")?;
            let old = std::mem::replace(&mut f.image_available, fresh);
            // SAFETY: the device is idle, so no queue operation waits on the old semaphore.
            unsafe { self.device.raw.destroy_semaphore(old, None) };
        }
        self.outstanding = false;
        self.needs_rebuild = true;
        Ok(())
    }

    /// Whether [`SwapchainFrame::present`] can take a screenshot (the surface allows copying
    /// from its images).
    pub fn supports_screenshots(&self) -> bool {
        self.screenshots
    }

    /// Waits for the slot's previous frame, acquires an image and begins recording a frame into
    /// it. `None` when there is nothing to draw into now (minimised, or rebuilt: try again).
    pub fn acquire(&mut self) -> Result<Option<SwapchainFrame<'_>>> {
        let Some((slot, image_index)) = self.acquire_image()? else {
            return Ok(None);
        };
        let cmd = self.frames[slot].cmd;
        self.outstanding = true;
        // SAFETY: the slot's command buffer was reset by acquire_image (not pending: its fence
        // was waited for); its pool is this swapchain's, which the frame borrows mutably.
        let encoder = match unsafe { Encoder::begin(&self.device, cmd, Origin::Frame) } {
            Ok(e) => e,
            Err(e) => {
                self.abandon(slot);
                return Err(e);
            }
        };
        let extent = self.extent;
        Ok(Some(SwapchainFrame {
            encoder_id: encoder.id(),
            encoder,
            guard: FrameGuard {
                swapchain: self,
                slot,
                image_index,
                done: false,
            },
            extent,
            rendered: false,
        }))
    }

    /// Gives up the frame in `slot`: its recording is never submitted; an empty submission
    /// consumes the acquire semaphore, and the swapchain is rebuilt before the next frame.
    fn abandon(&mut self, slot: usize) {
        let sync = &self.frames[slot];
        // SAFETY: the fence is signalled (waited for in acquire_image, reset nowhere since); the
        // submission waits on the semaphore the acquire will signal and has no command buffers.
        let consumed = unsafe {
            self.device
                .raw
                .reset_fences(&[sync.in_flight])
                .ctx("vkResetFences")
                .and_then(|()| {
                    self.device.submit(
                        &[],
                        &[(
                            sync.image_available,
                            vk::PipelineStageFlags::ALL_COMMANDS,
                            0,
                        )],
                        &[],
                        sync.in_flight,
                    )
                })
        };
        if let Err(e) = consumed {
            log::error!("abandoned frame not retired cleanly: {e}");
        }
        self.outstanding = false;
        self.needs_rebuild = true;
    }

    /// Records the end of the frame (screenshot copy and transition for presentation), submits
    /// and presents. The encoder must be ready (nothing open, no deferred error).
    fn present_frame(
        &mut self,
        mut encoder: Encoder<'_>,
        (slot, image_index): (usize, u32),
        rendered: bool,
        screenshot: bool,
    ) -> Result<Option<Rgba8>> {
        if let Some(e) = encoder.take_unready() {
            return Err(e);
        }
        if screenshot && !self.screenshots {
            return Err(VkError::Unsupported {
                device: self.device.info.name.clone(),
                what: "TRANSFER_SRC usage on this surface's swapchain images (screenshots)",
            });
        }
        let device = self.device.clone();
        let i = image_index as usize;
        let image = self.images[i];
        let extent = self.extent;
        let from = if rendered {
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
        } else {
            vk::ImageLayout::UNDEFINED
        };
        let cmd = encoder.raw_cmd();
        let readback = if screenshot {
            let buffer = Buffer::new(
                &device,
                &BufferDesc {
                    name: "screenshot readback",
                    size: extent.width as u64 * extent.height as u64 * 4,
                    usage: vk::BufferUsageFlags::TRANSFER_DST,
                    location: MemoryLocation::GpuToCpu,
                },
            )?;
            // SAFETY: outside any scope (the encoder is ready); the image has TRANSFER_SRC
            // usage (checked above), is in `from` and the buffer holds the extent's texels; both
            // live until the wait below.
            unsafe {
                record_copy_to_buffer(&device, cmd, image, from, extent, buffer.raw);
                transition(
                    &device.raw,
                    cmd,
                    image,
                    vk::ImageAspectFlags::COLOR,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    vk::ImageLayout::PRESENT_SRC_KHR,
                );
            }
            Some(buffer)
        } else {
            // SAFETY: outside any scope; the image is in `from` and lives until presented.
            unsafe {
                transition(
                    &device.raw,
                    cmd,
                    image,
                    vk::ImageAspectFlags::COLOR,
                    from,
                    vk::ImageLayout::PRESENT_SRC_KHR,
                )
            };
            None
        };
        let sync = &self.frames[slot];
        // SAFETY: the fence is signalled and no submission uses it (acquire_image waited).
        unsafe { device.raw.reset_fences(&[sync.in_flight]) }.ctx("vkResetFences")?;
        let wait = [(
            sync.image_available,
            vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT,
            0,
        )];
        let signal = [self.render_finished[i]];
        // SAFETY: the acquire semaphore will be signalled by the acquire, the present semaphore
        // is unsignalled (its last present waited on it), the fence was reset above; the
        // swapchain's images live until a rebuild or drop, both of which wait for the device.
        let submitted = unsafe { encoder.submit_with(&wait, &signal, sync.in_flight) };
        // On failure nothing was submitted: the frame stays outstanding and its guard abandons
        // it, which consumes the acquire semaphore and signals the (reset, unused) fence.
        let (serial, _) = submitted?;
        self.outstanding = false;
        self.frame_index += 1;
        let swapchains = [self.raw];
        let indices = [image_index];
        let present = vk::PresentInfoKHR::default()
            .wait_semaphores(&signal)
            .swapchains(&swapchains)
            .image_indices(&indices);
        {
            let _q = device
                .queue_lock
                .lock()
                .map_err(|_| VkError::LockPoisoned { what: "queue" })?;
            // SAFETY: the image was acquired and its rendering submitted above, signalling the
            // semaphore presentation waits on; the queue is serialized by queue_lock.
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
        match readback {
            Some(buffer) => {
                device.wait_serial(serial)?;
                Ok(Some(self.screenshot_pixels(&buffer, extent)?))
            }
            None => Ok(None),
        }
    }

    /// The screenshot buffer as RGBA8 (BGRA swapchain formats swizzled).
    fn screenshot_pixels(&self, buffer: &Buffer, extent: vk::Extent2D) -> Result<Rgba8> {
        let n = extent.width as usize * extent.height as usize * 4;
        let bytes =
            buffer
                .mapped()
                .filter(|b| b.len() >= n)
                .ok_or_else(|| VkError::NotHostVisible {
                    buffer: buffer.name().to_owned(),
                })?;
        let mut pixels = bytes[..n].to_vec();
        if self.format == vk::Format::B8G8R8A8_UNORM || self.format == vk::Format::B8G8R8A8_SRGB {
            for px in pixels.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
        }
        Ok(Rgba8 {
            width: extent.width,
            height: extent.height,
            pixels,
        })
    }
}

/// Abandons the frame when it is dropped unpresented (see the module header).
struct FrameGuard<'a> {
    swapchain: &'a mut Swapchain,
    slot: usize,
    image_index: u32,
    done: bool,
}

impl Drop for FrameGuard<'_> {
    fn drop(&mut self) {
        if !self.done {
            self.swapchain.abandon(self.slot);
        }
    }
}

/// A frame being recorded into an acquired swapchain image: an [`Encoder`] (through `Deref`)
/// plus the image. Present it with [`SwapchainFrame::present`]; dropping it abandons the frame.
pub struct SwapchainFrame<'a> {
    // Field order is drop order: the encoder (never submitted, if still here) before the guard
    // that abandons the frame.
    encoder: Encoder<'a>,
    encoder_id: u64,
    guard: FrameGuard<'a>,
    extent: vk::Extent2D,
    rendered: bool,
}

impl<'a> SwapchainFrame<'a> {
    /// Which of the [`FRAMES_IN_FLIGHT`] slots this frame uses (index per-frame resources).
    pub fn slot(&self) -> usize {
        self.guard.slot
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }

    pub fn encoder(&mut self) -> &mut Encoder<'a> {
        &mut self.encoder
    }

    /// Begins rendering into the frame's image and the swapchain's depth image (both cleared),
    /// with the full viewport and scissor set. End it with [`Encoder::end_rendering`].
    pub fn begin_frame_rendering(&mut self, clear: [f32; 4]) {
        let sc = &*self.guard.swapchain;
        let i = self.guard.image_index as usize;
        let Some(depth) = sc.depth.as_ref() else {
            // rebuild always makes a depth image before a frame can be acquired.
            return;
        };
        // SAFETY: the frame borrows the swapchain mutably until it is presented or abandoned,
        // so neither a rebuild nor a drop can destroy the images before the submission, after
        // which both wait for the device; the image is the frame's acquired one, of the
        // swapchain's format and extent, and the depth image matches.
        let opened = unsafe {
            self.encoder.begin_frame_scope(
                (sc.images[i], sc.views[i]),
                sc.format,
                (depth.raw, depth.view),
                self.extent,
                clear,
            )
        };
        self.rendered |= opened;
    }

    /// Submits the frame and presents it; with `screenshot`, waits and returns the image read
    /// back (a typed [`VkError::Unsupported`] where the surface does not allow it). The frame
    /// must have ended its rendering scope; an invalid recording is abandoned, not submitted.
    pub fn present(self, screenshot: bool) -> Result<Option<Rgba8>> {
        let SwapchainFrame {
            encoder,
            encoder_id,
            mut guard,
            rendered,
            ..
        } = self;
        if encoder.id() != encoder_id {
            // Exchanged with another encoder: dropping both (here) abandons the frame.
            return Err(VkError::recording(
                "vkQueueSubmit",
                RecordingError::Exchanged,
            ));
        }
        let slot = (guard.slot, guard.image_index);
        let result = guard
            .swapchain
            .present_frame(encoder, slot, rendered, screenshot);
        // present_frame either submitted (the frame is done) or failed before submitting, in
        // which case the guard abandons the frame when dropped.
        guard.done = !guard.swapchain.outstanding;
        result
    }
}

impl<'a> std::ops::Deref for SwapchainFrame<'a> {
    type Target = Encoder<'a>;
    fn deref(&self) -> &Encoder<'a> {
        &self.encoder
    }
}

impl std::ops::DerefMut for SwapchainFrame<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.encoder
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
        // The swapchain (when made), the frames' semaphores and fences, the pool, the surface.
        let swapchain = u64::from(self.raw != vk::SwapchainKHR::null());
        self.device
            .destroyed(swapchain + 2 * self.frames.len() as u64 + 2);
    }
}
