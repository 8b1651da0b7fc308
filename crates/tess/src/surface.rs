//! Images a surface samples at its texture coordinates (the Catmull-Clark techniques): a colour
//! texture and a height map for displacement, read from PNG files.
use crate::error::{Result, TessError};
use std::path::Path;
use std::sync::Arc;
use vk_core::texture::TextureFormat;

/// Texels ready for upload.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceImage {
    /// The file, for messages.
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub format: TextureFormat,
    pub texels: Vec<u8>,
}

/// What a surface samples; `None` binds a neutral 1×1 texel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMaps {
    pub texture: Option<Arc<SurfaceImage>>,
    pub height: Option<Arc<SurfaceImage>>,
}

fn open(path: &Path) -> Result<image::DynamicImage> {
    image::open(path).map_err(|e| TessError::Image {
        file: path.display().to_string(),
        message: e.to_string(),
    })
}

/// A colour texture (sRGB, mipmapped on upload).
pub fn load_texture(path: impl AsRef<Path>) -> Result<SurfaceImage> {
    let path = path.as_ref();
    let img = open(path)?.to_rgba8();
    Ok(SurfaceImage {
        name: path.display().to_string(),
        width: img.width(),
        height: img.height(),
        format: TextureFormat::Rgba8Srgb,
        texels: img.into_raw(),
    })
}

/// A height map: the image's luminance in [0, 1], one float a texel.
pub fn load_height(path: impl AsRef<Path>) -> Result<SurfaceImage> {
    let path = path.as_ref();
    let img = open(path)?.to_luma16();
    let texels = img
        .pixels()
        .flat_map(|p| (p.0[0] as f32 / 65535.0).to_le_bytes())
        .collect();
    Ok(SurfaceImage {
        name: path.display().to_string(),
        width: img.width(),
        height: img.height(),
        format: TextureFormat::R32Float,
        texels,
    })
}
