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
    /// Also compute the pointwise Eq. 1 error lattice (`topology::texcoord::ParamErrorLattice`)
    /// that [`SurfaceShow::ParamError`] draws: exact limit evaluations on the CPU at build
    /// time (seconds on meshes of thousands of patches), so only on request.
    pub param_error: bool,
}

/// What the surface is coloured by (techniques with the `surface` feature).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SurfaceShow {
    /// Lighting of the albedo (texture, patch colours or base colour).
    #[default]
    Shading,
    /// How far the reparameterization moves the texture parameter, `|s(u, v) − (u, v)|` in
    /// patch units: blue 0, red 0.05 and beyond.
    ParamShift,
    /// The pointwise texture error of Eq. 1 (seed 003, its Fig. 8) with the current
    /// reparameterization setting, relative to the bounding-box diagonal, on a log scale:
    /// blue ≤ 1e-5, green 3e-4, yellow 2e-3, red ≥ 1e-2. Needs [`SurfaceMaps::param_error`].
    ParamError,
}

impl SurfaceShow {
    /// The `--show` names.
    pub const NAMES: &'static str = "param-shift, param-error";

    /// Parses a `--show` value.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "param-shift" => Some(Self::ParamShift),
            "param-error" => Some(Self::ParamError),
            _ => None,
        }
    }
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
