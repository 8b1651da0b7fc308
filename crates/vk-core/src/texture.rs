//! Sampled 2D textures with their own sampler: colour textures and height maps for shaders.
//!
//! Design decisions:
//! - A texture is uploaded (through a staging buffer) and its mip chain generated when it is
//!   made, and between recordings every level is in `SHADER_READ_ONLY_OPTIMAL`: whatever records
//!   a transfer on it ([`crate::Encoder::upload_texture`]) returns it there, so descriptor writes
//!   and draws never track layouts.
//! - Mip levels are blitted with a linear filter, which needs the format's
//!   `SAMPLED_IMAGE_FILTER_LINEAR` and `BLIT_SRC|BLIT_DST` features. Without them the texture
//!   gets a single level (no mip chain to blit); without linear filtering the sampler is NEAREST
//!   too (sampling a format linearly that cannot be filtered so is invalid). `R32Float` height
//!   maps hit this on devices without linear float filtering.
//! - Image, view, memory and sampler live in a shared `TextureShared`, so a
//!   [`crate::DescriptorSet`] written with the texture keeps it alive (as for buffers); the last
//!   owner hands them to the retire queue.
use crate::buffer::{Buffer, BufferDesc};
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext, VkError};
use crate::image::{Image, ImageDesc};
use crate::retire::Retired;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// Texel formats a texture can hold; every one is 4 bytes a texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureFormat {
    /// Colour, sRGB-encoded (sampling returns linear values).
    Rgba8Srgb,
    /// Colour or data in [0, 1].
    Rgba8Unorm,
    /// One 32-bit float a texel (height maps).
    R32Float,
}

impl TextureFormat {
    pub fn vk(self) -> vk::Format {
        match self {
            TextureFormat::Rgba8Srgb => vk::Format::R8G8B8A8_SRGB,
            TextureFormat::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
            TextureFormat::R32Float => vk::Format::R32_SFLOAT,
        }
    }

    pub fn bytes_per_texel(self) -> u32 {
        match self {
            TextureFormat::Rgba8Srgb | TextureFormat::Rgba8Unorm | TextureFormat::R32Float => 4,
        }
    }
}

#[derive(Clone, Debug)]
pub struct TextureDesc<'a> {
    pub name: &'a str,
    pub width: u32,
    pub height: u32,
    pub format: TextureFormat,
    /// Generate a full mip chain (when the format allows it, see the module notes).
    pub mipmaps: bool,
    /// Address mode REPEAT, else CLAMP_TO_EDGE.
    pub repeat: bool,
}

/// Image (with view and memory) and sampler, shared by the [`Texture`] and the descriptor sets
/// written with it.
pub(crate) struct TextureShared {
    pub(crate) image: Image,
    pub(crate) sampler: vk::Sampler,
    device: Arc<DeviceShared>,
}

impl Drop for TextureShared {
    fn drop(&mut self) {
        // The image retires itself when the field drops, right after.
        self.device.retire(Retired::Sampler(self.sampler));
    }
}

/// A sampled 2D texture with its sampler; every level in `SHADER_READ_ONLY_OPTIMAL`.
pub struct Texture {
    pub(crate) shared: Arc<TextureShared>,
    name: String,
    extent: vk::Extent2D,
    format: TextureFormat,
    levels: u32,
    filter: vk::Filter,
    usage: vk::ImageUsageFlags,
}

impl Texture {
    /// Makes the texture from `texels` (rows top to bottom, tightly packed), uploads them and
    /// generates the mip chain. Typed errors: a side of 0 or beyond the device's
    /// `maxImageDimension2D` ([`VkError::Extent`]), `texels` not `width·height·4` bytes
    /// ([`VkError::PictureSize`]), a format the device cannot sample ([`VkError::Unsupported`]).
    pub fn new(device: &Device, desc: &TextureDesc<'_>, texels: &[u8]) -> Result<Texture> {
        let max = device.info.caps.max_image_dimension_2d;
        let (width, height) = (desc.width, desc.height);
        if width == 0 || height == 0 || width > max || height > max {
            return Err(VkError::Extent {
                what: "texture",
                width,
                height,
                max,
            });
        }
        let bytes = width as u64 * height as u64 * desc.format.bytes_per_texel() as u64;
        if texels.len() as u64 != bytes {
            // PictureSize says "width·height·4", which every TextureFormat is.
            return Err(VkError::PictureSize {
                width,
                height,
                bytes: texels.len(),
            });
        }
        let format = desc.format.vk();
        // SAFETY: the physical device belongs to the device's instance, which is alive.
        let properties = unsafe {
            device
                .instance
                .raw
                .get_physical_device_format_properties(device.physical, format)
        };
        let features = properties.optimal_tiling_features;
        if !features.contains(vk::FormatFeatureFlags::SAMPLED_IMAGE) {
            return Err(VkError::Unsupported {
                device: device.info.name.clone(),
                what: "sampling this texture format",
            });
        }
        let linear = features.contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR);
        let blit =
            features.contains(vk::FormatFeatureFlags::BLIT_SRC | vk::FormatFeatureFlags::BLIT_DST);
        let levels = if desc.mipmaps && linear && blit {
            32 - width.max(height).leading_zeros()
        } else {
            1
        };
        let mut usage = vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST;
        if desc.mipmaps {
            usage |= vk::ImageUsageFlags::TRANSFER_SRC;
        }
        let extent = vk::Extent2D { width, height };
        let image = Image::with_levels(
            device,
            &ImageDesc {
                name: desc.name,
                extent,
                format,
                usage,
                aspect: vk::ImageAspectFlags::COLOR,
            },
            levels,
        )?;
        let filter = if linear {
            vk::Filter::LINEAR
        } else {
            vk::Filter::NEAREST
        };
        let mipmap_mode = if levels > 1 {
            vk::SamplerMipmapMode::LINEAR
        } else {
            vk::SamplerMipmapMode::NEAREST
        };
        let address = if desc.repeat {
            vk::SamplerAddressMode::REPEAT
        } else {
            vk::SamplerAddressMode::CLAMP_TO_EDGE
        };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
            .mipmap_mode(mipmap_mode)
            .address_mode_u(address)
            .address_mode_v(address)
            .address_mode_w(address)
            .min_lod(0.0)
            .max_lod(levels as f32);
        // SAFETY: device live; info valid (no anisotropy or compare, filters the format
        // supports). On failure `image` drops and retires itself.
        let sampler = unsafe { device.raw.create_sampler(&info, None) }.ctx("vkCreateSampler")?;
        device.created(1);
        device.set_name(sampler, &format!("{} sampler", desc.name));
        let texture = Texture {
            shared: Arc::new(TextureShared {
                image,
                sampler,
                device: device.shared.clone(),
            }),
            name: desc.name.to_owned(),
            extent,
            format: desc.format,
            levels,
            filter,
            usage,
        };
        let mut staging = Buffer::new(
            device,
            &BufferDesc {
                name: &format!("{} (staging)", desc.name),
                size: bytes,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        staging.write(0, texels)?;
        device.submit_once(|enc| enc.upload_texture(&staging, &texture))??;
        Ok(texture)
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Mip levels: 1 without mipmaps or where the format cannot be blitted linearly.
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// The extent of level 0.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }

    /// The extent of `level` (each side halved per level, at least 1).
    pub fn level_extent(&self, level: u32) -> vk::Extent2D {
        vk::Extent2D {
            width: self.extent.width.checked_shr(level).unwrap_or(0).max(1),
            height: self.extent.height.checked_shr(level).unwrap_or(0).max(1),
        }
    }

    pub fn format(&self) -> TextureFormat {
        self.format
    }

    /// The sampler's filter: LINEAR, or NEAREST where the format cannot be filtered linearly.
    pub fn filter(&self) -> vk::Filter {
        self.filter
    }

    pub fn usage(&self) -> vk::ImageUsageFlags {
        self.usage
    }

    /// Bytes of level 0, tightly packed: what an upload's staging buffer holds.
    pub fn byte_len(&self) -> u64 {
        self.extent.width as u64 * self.extent.height as u64 * self.format.bytes_per_texel() as u64
    }

    pub(crate) fn raw_image(&self) -> vk::Image {
        self.shared.image.raw
    }
}
