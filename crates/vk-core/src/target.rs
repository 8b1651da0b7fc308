//! Offscreen render target: RGBA8 color + 32-bit float depth, read back to an RGBA8 image.
use crate::buffer::{Buffer, BufferDesc};
use crate::device::Device;
use crate::error::{Result, VkError};
use crate::image::{transition, Image, ImageDesc};
use ash::vk;
use gpu_allocator::MemoryLocation;

pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// An RGBA8 picture read back from the GPU, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgba8 {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}

impl Rgba8 {
    pub fn save_png(&self, path: &std::path::Path) -> Result<()> {
        let img = image::RgbaImage::from_raw(self.width, self.height, self.pixels.clone())
            .ok_or_else(|| VkError::Invalid("image size mismatch".into()))?;
        img.save(path).map_err(|e| VkError::Image {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    pub fn load_png(path: &std::path::Path) -> Result<Self> {
        let img = image::open(path)
            .map_err(|e| VkError::Image {
                path: path.display().to_string(),
                message: e.to_string(),
            })?
            .to_rgba8();
        Ok(Self {
            width: img.width(),
            height: img.height(),
            pixels: img.into_raw(),
        })
    }
}

/// Color and depth images sized for one offscreen frame.
pub struct OffscreenTarget {
    pub color: Image,
    pub depth: Image,
    pub extent: vk::Extent2D,
}

impl OffscreenTarget {
    pub fn new(device: &Device, extent: vk::Extent2D) -> Result<Self> {
        if extent.width == 0 || extent.height == 0 || extent.width > 16384 || extent.height > 16384
        {
            return Err(VkError::Invalid(format!(
                "image size {}x{} is outside 1..16384",
                extent.width, extent.height
            )));
        }
        let color = Image::new(
            device,
            &ImageDesc {
                name: "offscreen color",
                extent,
                format: COLOR_FORMAT,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        let depth = Image::new(
            device,
            &ImageDesc {
                name: "offscreen depth",
                extent,
                format: DEPTH_FORMAT,
                usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                aspect: vk::ImageAspectFlags::DEPTH,
            },
        )?;
        Ok(Self {
            color,
            depth,
            extent,
        })
    }

    /// Records the transitions into attachment layouts and begins dynamic rendering with clears.
    pub fn cmd_begin(&self, device: &Device, cmd: vk::CommandBuffer, clear: [f32; 4]) {
        begin_rendering(
            device,
            cmd,
            &self.color,
            vk::ImageLayout::UNDEFINED,
            &self.depth,
            self.extent,
            clear,
        );
    }

    /// Ends rendering and records the copy of the color image into `readback`.
    pub fn cmd_end_and_copy(&self, device: &Device, cmd: vk::CommandBuffer, readback: &Buffer) {
        // SAFETY: rendering was begun by cmd_begin on this command buffer.
        unsafe { device.raw.cmd_end_rendering(cmd) };
        transition(
            &device.raw,
            cmd,
            self.color.raw,
            vk::ImageAspectFlags::COLOR,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        );
        // SAFETY: the image is in TRANSFER_SRC layout; readback has width*height*4 bytes.
        unsafe {
            crate::image::cmd_copy_color_to_buffer(
                &device.raw,
                cmd,
                self.color.raw,
                self.extent,
                readback.raw,
            )
        };
        let barrier = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::HOST_READ);
        // SAFETY: cmd is recording.
        unsafe {
            device.raw.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            )
        };
    }

    pub fn readback_buffer(&self, device: &Device) -> Result<Buffer> {
        Buffer::new(
            device,
            &BufferDesc {
                name: "offscreen readback",
                size: self.extent.width as u64 * self.extent.height as u64 * 4,
                usage: vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )
    }

    pub fn read(&self, readback: &Buffer) -> Result<Rgba8> {
        let bytes = readback
            .mapped()
            .ok_or_else(|| VkError::Invalid("readback buffer not mapped".into()))?;
        let n = (self.extent.width * self.extent.height * 4) as usize;
        Ok(Rgba8 {
            width: self.extent.width,
            height: self.extent.height,
            pixels: bytes[..n].to_vec(),
        })
    }
}

/// Transitions color (from `color_from`) and depth into attachment layouts, begins dynamic
/// rendering with clears, and sets a full-extent viewport (y flipped so +y is up) and scissor.
pub fn begin_rendering(
    device: &Device,
    cmd: vk::CommandBuffer,
    color: &Image,
    color_from: vk::ImageLayout,
    depth: &Image,
    extent: vk::Extent2D,
    clear: [f32; 4],
) {
    begin_rendering_view(
        device, cmd, color.raw, color.view, color_from, depth, extent, clear,
    )
}

#[allow(clippy::too_many_arguments)]
pub fn begin_rendering_view(
    device: &Device,
    cmd: vk::CommandBuffer,
    color: vk::Image,
    color_view: vk::ImageView,
    color_from: vk::ImageLayout,
    depth: &Image,
    extent: vk::Extent2D,
    clear: [f32; 4],
) {
    transition(
        &device.raw,
        cmd,
        color,
        vk::ImageAspectFlags::COLOR,
        color_from,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    );
    transition(
        &device.raw,
        cmd,
        depth.raw,
        vk::ImageAspectFlags::DEPTH,
        vk::ImageLayout::UNDEFINED,
        vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
    );
    let color_att = [vk::RenderingAttachmentInfo::default()
        .image_view(color_view)
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            color: vk::ClearColorValue { float32: clear },
        })];
    let depth_att = vk::RenderingAttachmentInfo::default()
        .image_view(depth.view)
        .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::DONT_CARE)
        .clear_value(vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: 1.0,
                stencil: 0,
            },
        });
    let info = vk::RenderingInfo::default()
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        })
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
    // SAFETY: cmd is recording; attachments are in the layouts named above.
    unsafe {
        device.raw.cmd_begin_rendering(cmd, &info);
        device.raw.cmd_set_viewport(cmd, 0, &[viewport]);
        device.raw.cmd_set_scissor(
            cmd,
            0,
            &[vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            }],
        );
    }
}
