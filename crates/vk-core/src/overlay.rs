//! An immediate-mode UI overlay: egui's tessellated output drawn into a frame's open rendering
//! scope by `egui-ash-renderer`, behind safe calls. It knows nothing of what the UI shows.
//!
//! Design decisions:
//! - The renderer is egui-ash-renderer 0.13 (ash 0.38, dynamic rendering) with its own default
//!   memory path, not gpu-allocator: the device's allocator is private to vk-core and behind a
//!   `Mutex`, while the renderer's gpu-allocator path wants an `Arc<Mutex<Allocator>>` of its
//!   own. Its buffers and images are therefore not in [`crate::DeviceShared::allocated_bytes`]
//!   nor its handles in `live_objects`; they are made once (pipeline, layouts, the font
//!   atlas) or grow to the largest UI drawn (vertex and index buffers, one set per frame slot).
//! - Vertex and index buffers: the renderer keeps `frames_in_flight` sets and takes the next on
//!   each non-empty draw. Draws happen at most once per frame and a frame slot's previous
//!   submission has completed before it is recorded again, so the set written now was last read
//!   by a frame at least `frames_in_flight` frames ago, which has completed.
//! - Textures (egui's font atlas; rare after the first frames): the renderer uploads through its
//!   own command buffer, submitted on the device's queue (under vk-core's queue lock) and waited
//!   for with `vkQueueWaitIdle`; that submission takes no timeline serial, which is sound because
//!   it is complete when the call returns. Before any texture change the device is waited idle,
//!   since frames in flight may sample the texture being replaced and the renderer destroys the
//!   replaced image at once. egui's partial updates are applied to a CPU copy of the whole image
//!   and the whole image is uploaded: the renderer's partial update transitions the image from
//!   `UNDEFINED`, which allows a driver to discard the texels outside the patch.
//! - Textures egui frees after a frame are freed at the next [`Overlay::update_textures`] after
//!   an idle wait (the frame that may still sample them is then complete); the retire queue
//!   cannot hold them, as they are the renderer's objects.
//! - Drop waits for the device idle before the renderer destroys its objects.
use crate::device::Device;
use crate::encoder::Encoder;
use crate::error::{Result, VkContext, VkError};
use ash::vk;
use egui::epaint::textures::TexturesDelta;
use egui::epaint::{ClippedPrimitive, ImageData, ImageDelta};
use egui::{ColorImage, TextureId};
use egui_ash_renderer::{DynamicRendering, Options, RenderMode, Renderer};
use std::collections::HashMap;
use std::mem::ManuallyDrop;
use std::sync::Arc;

/// What an [`Overlay`] draws into: the rendering scope's formats and the frames in flight.
#[derive(Clone, Copy, Debug)]
pub struct OverlayDesc {
    /// The colour attachment's format (a `*_UNORM` one: the renderer converts to sRGB itself).
    pub color_format: vk::Format,
    /// The depth attachment's format, when the scope has one (the overlay does not test depth).
    pub depth_format: Option<vk::Format>,
    /// Frames that may be in flight at once (one vertex and index buffer set each).
    pub frames_in_flight: usize,
}

/// egui drawn through vk-core. Drop order: idle wait, renderer, command pool (in `drop`).
pub struct Overlay {
    renderer: ManuallyDrop<Renderer<egui_ash_renderer::allocator::DefaultAllocator>>,
    /// The renderer's texture uploads allocate their command buffers here.
    pool: vk::CommandPool,
    /// The whole image of each egui-managed texture, where partial updates are applied.
    images: HashMap<TextureId, ColorImage>,
    /// Textures egui released after the last frame: freed at the next update.
    to_free: Vec<TextureId>,
    formats: [vk::Format; 2],
    device: Device,
}

impl Overlay {
    pub fn new(device: &Device, desc: &OverlayDesc) -> Result<Self> {
        let depth = desc.depth_format.unwrap_or(vk::Format::UNDEFINED);
        let info = vk::CommandPoolCreateInfo::default()
            .flags(vk::CommandPoolCreateFlags::TRANSIENT)
            .queue_family_index(device.queue_family);
        // SAFETY: the device is live; the pool is destroyed in drop after an idle wait.
        let pool =
            unsafe { device.raw.create_command_pool(&info, None) }.ctx("vkCreateCommandPool")?;
        device.set_name(pool, "HUD overlay uploads");
        let renderer = Renderer::with_default_allocator(
            &device.instance.raw,
            device.physical,
            device.raw.clone(),
            RenderMode::DynamicRendering(DynamicRendering {
                color_attachment_format: desc.color_format,
                depth_attachment_format: desc.depth_format,
                stencil_attachment_format: None,
            }),
            Options {
                in_flight_frames: desc.frames_in_flight.max(1),
                enable_depth_test: false,
                enable_depth_write: false,
                srgb_framebuffer: false,
            },
        );
        let renderer = match renderer {
            Ok(r) => r,
            Err(e) => {
                // SAFETY: the pool was made above and nothing was allocated from it.
                unsafe { device.raw.destroy_command_pool(pool, None) };
                return Err(e.into());
            }
        };
        Ok(Self {
            renderer: ManuallyDrop::new(renderer),
            pool,
            images: HashMap::new(),
            to_free: Vec::new(),
            formats: [desc.color_format, depth],
            device: device.clone(),
        })
    }

    /// Applies egui's texture changes of the frame about to be recorded (call before acquiring
    /// it); the delta is emptied, as egui requires of a delta handled. Waits for the device idle
    /// when anything changes or was freed (see the module header).
    pub fn update_textures(&mut self, delta: &mut TexturesDelta) -> Result<()> {
        let set = std::mem::take(&mut delta.set);
        let freed = std::mem::take(&mut delta.free);
        if !set.is_empty() || !self.to_free.is_empty() {
            self.device.wait_idle();
        }
        for id in std::mem::take(&mut self.to_free) {
            self.images.remove(&id);
            self.renderer.free_texture(id)?;
        }
        for (id, changes) in &set {
            let mut options = None;
            for change in changes {
                self.apply(*id, change);
                options = Some(change.options);
            }
            let (Some(image), Some(options)) = (self.images.get(id), options) else {
                continue;
            };
            let whole = ImageDelta::full(ImageData::Color(Arc::new(image.clone())), options);
            let _queue = self
                .device
                .queue_lock
                .lock()
                .map_err(|_| VkError::LockPoisoned { what: "queue" })?;
            self.renderer
                .set_texture(self.device.queue, self.pool, *id, &whole)?;
        }
        self.to_free.extend(freed);
        Ok(())
    }

    /// `change` applied to the CPU copy of texture `id` (a patch outside it is clipped).
    fn apply(&mut self, id: TextureId, change: &ImageDelta) {
        let ImageData::Color(patch) = &change.image;
        let Some([x0, y0]) = change.pos else {
            self.images.insert(id, (**patch).clone());
            return;
        };
        let Some(whole) = self.images.get_mut(&id) else {
            return;
        };
        let [w, h] = whole.size;
        let [pw, ph] = patch.size;
        for y in 0..ph.min(h.saturating_sub(y0)) {
            let n = pw.min(w.saturating_sub(x0));
            let dst = (y0 + y) * w + x0;
            whole.pixels[dst..dst + n].copy_from_slice(&patch.pixels[y * pw..y * pw + n]);
        }
    }

    /// Records `primitives` (egui's tessellated output, in points) into the encoder's open
    /// rendering scope, which must have the formats the overlay was made for. The encoder's
    /// bindings are forgotten (a later draw through it binds again).
    pub fn draw(
        &mut self,
        encoder: &mut Encoder<'_>,
        extent: vk::Extent2D,
        pixels_per_point: f32,
        primitives: &[ClippedPrimitive],
    ) -> Result<()> {
        const CMD: &str = "vkCmdDrawIndexed (overlay)";
        let (cmd, formats) = encoder.raw_in_scope(CMD)?;
        if formats != self.formats {
            return Err(VkError::recording(
                CMD,
                crate::error::RecordingError::AttachmentFormats {
                    pipeline: "HUD overlay".into(),
                    pipeline_formats: self.formats,
                    scope_formats: formats,
                },
            ));
        }
        self.renderer
            .cmd_draw(cmd, extent, pixels_per_point, primitives)?;
        Ok(())
    }
}

impl Drop for Overlay {
    fn drop(&mut self) {
        self.device.wait_idle();
        // SAFETY: dropped once, here; the device is idle, so no submission uses its objects.
        unsafe { ManuallyDrop::drop(&mut self.renderer) };
        // SAFETY: idle device; the pool's command buffers were freed after each upload.
        unsafe { self.device.raw.destroy_command_pool(self.pool, None) };
    }
}
