//! Offscreen render target: RGBA8 color + 32-bit float depth, read back to an RGBA8 image.
use crate::buffer::{Buffer, BufferDesc};
use crate::device::Device;

use crate::error::{Result, VkError};
use crate::image::{Image, ImageDesc};
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
        let img = image::RgbaImage::from_raw(self.width, self.height, self.pixels.clone()).ok_or(
            VkError::PictureSize {
                width: self.width,
                height: self.height,
                bytes: self.pixels.len(),
            },
        )?;
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
            return Err(VkError::Extent {
                what: "offscreen target",
                width: extent.width,
                height: extent.height,
                max: 16384,
            });
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
        let bytes = readback.mapped().ok_or_else(|| VkError::NotHostVisible {
            buffer: readback.name().to_owned(),
        })?;
        let n = self.extent.width as usize * self.extent.height as usize * 4;
        if bytes.len() < n {
            return Err(VkError::OutOfBounds {
                object: readback.name().to_owned(),
                what: "readback",
                offset: 0,
                len: n as u64,
                size: bytes.len() as u64,
            });
        }
        Ok(Rgba8 {
            width: self.extent.width,
            height: self.extent.height,
            pixels: bytes[..n].to_vec(),
        })
    }
}
