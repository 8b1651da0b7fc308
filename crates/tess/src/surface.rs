//! Images a surface samples at its texture coordinates (the Catmull-Clark techniques): a colour
//! texture and a height map for displacement, read from PNG files.
use crate::error::{Result, TessError};
use std::path::Path;
use std::sync::Arc;
use topology::ControlMesh;
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
    /// Also compute the pointwise Eq. 1 error lattice (`topology::patches::texcoord::ParamErrorLattice`)
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

/// The largest image file read as a colour texture or height map: 512 MiB.
pub const MAX_IMAGE_BYTES: u64 = 512 << 20;

/// The largest side, in pixels, of a colour texture or height map: what Vulkan devices commonly
/// take (`maxImageDimension2D`, 16384 on lavapipe and most desktop GPUs; a device with less
/// refuses the upload by its own limit).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The image at `path`, decoded only after its header says a size within
/// [`MAX_IMAGE_SIDE`] (so a 20000×20000 map is refused before 2 GB are decoded); the file is
/// read as every input is ([`topology::mesh::input::read_regular_file`]: regular files within
/// [`MAX_IMAGE_BYTES`]).
fn open(path: &Path) -> Result<image::DynamicImage> {
    let err = |message: String| TessError::Image {
        file: path.display().to_string(),
        message,
    };
    let bytes = topology::mesh::input::read_regular_file(path, MAX_IMAGE_BYTES, "an image")
        .map_err(|e| err(format!("cannot read file: {e}")))?;
    // The size is bounded here, not by the decoder's default allocation limit (512 MiB,
    // less than a 16384² RGBA map takes).
    let reader = || {
        let mut r = image::ImageReader::new(std::io::Cursor::new(&bytes))
            .with_guessed_format()
            .map_err(|e| err(e.to_string()))?;
        r.no_limits();
        Ok::<_, TessError>(r)
    };
    let (width, height) = reader()?
        .into_dimensions()
        .map_err(|e| err(e.to_string()))?;
    if width == 0 || height == 0 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(err(format!(
            "{width}x{height} pixels, outside 1..{MAX_IMAGE_SIDE} per side"
        )));
    }
    reader()?.decode().map_err(|e| err(e.to_string()))
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

/// A colour texture or height map needs the mesh's `vt` at every face corner: without them
/// each face would show the whole image, which is never what was meant. Checked before the
/// surface is planned. Procedural displacement works without `vt` (the (sub)face parameter
/// stands in).
pub fn check_texcoords(mesh: &ControlMesh, maps: &SurfaceMaps, name: &str) -> Result<()> {
    let wanted = match (&maps.texture, &maps.height) {
        (Some(_), _) => "a colour texture",
        (None, Some(_)) => "a height map",
        (None, None) => return Ok(()),
    };
    if topology::patches::texcoord::has_texcoords(mesh) {
        return Ok(());
    }
    Err(TessError::Mesh {
        name: name.to_string(),
        source: format!(
            "{wanted} was given, but the mesh has no `vt` texture coordinate at every face corner (procedural displacement works without them)"
        )
        .into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch directory of this test process.
    fn scratch() -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("tess-surface-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Bad surface maps: a colour texture or height map that is missing, or a file that is
    /// not an image (text, with and without an image's extension), is `TessError::Image`
    /// naming the file, whose message says it once, with the reader's reason after it.
    #[test]
    fn missing_and_unreadable_images_are_named_errors() {
        let dir = scratch();
        let missing = dir.join("no_such_texture.png");
        let _ = std::fs::remove_file(&missing);
        let text_png = dir.join("not_an_image.png");
        std::fs::write(&text_png, "this is text, not a PNG\n").unwrap();
        let text_txt = dir.join("height_notes.txt");
        std::fs::write(&text_txt, "v 0 0 0\n").unwrap();
        type Loader = fn(&Path) -> Result<SurfaceImage>;
        let loaders: [(&str, Loader); 2] = [
            ("load_texture", |p| load_texture(p)),
            ("load_height", |p| load_height(p)),
        ];
        for (what, load) in loaders {
            for path in [&missing, &text_png, &text_txt] {
                let shown = path.display().to_string();
                let Err(e) = load(path) else {
                    panic!("{what} {shown}: loaded");
                };
                let line = e.to_string();
                let TessError::Image { file, message } = e else {
                    panic!("{what} {shown}: not an image error: {line}");
                };
                assert_eq!(file, shown, "{what}");
                assert!(!message.trim().is_empty(), "{what} {shown}: no reason");
                assert!(line.starts_with(&format!("{shown}: ")), "{what}: {line}");
                assert_eq!(line.matches(&shown).count(), 1, "{what}: {line}");
                assert!(!line.contains('\n'), "{what}: {line}");
            }
        }
        // The missing file's reason is the system's, not a decoder's.
        let e = load_texture(&missing).unwrap_err().to_string();
        assert!(e.contains("os error"), "{e}");
        // And the real maps load: RGBA8 texels, heights in [0, 1].
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
        let tex = load_texture(assets.join("spot_texture.png")).expect("spot texture");
        assert_eq!(tex.format, TextureFormat::Rgba8Srgb);
        assert_eq!(tex.texels.len(), (tex.width * tex.height * 4) as usize);
        let height = load_height(assets.join("spot_height.png")).expect("spot height map");
        assert_eq!(height.format, TextureFormat::R32Float);
        let h: Vec<f32> = height
            .texels
            .chunks(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(h.len(), (height.width * height.height) as usize);
        assert!(h.iter().all(|x| (0.0..=1.0).contains(x)));
        assert!(h.iter().any(|&x| x > 0.0) && h.iter().any(|&x| x < 1.0));
    }

    /// A map wider or taller than [`MAX_IMAGE_SIDE`] is refused by its header, naming the file
    /// and the size; what is not a regular file is refused unopened.
    #[test]
    fn oversized_and_irregular_images_are_refused_before_decoding() {
        let dir = scratch();
        let wide = dir.join("wide.png");
        image::GrayImage::new(MAX_IMAGE_SIDE + 1, 1)
            .save(&wide)
            .unwrap();
        let e = load_height(&wide).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}: 16385x1 pixels, outside 1..16384 per side",
                wide.display()
            )
        );
        #[cfg(unix)]
        {
            let e = load_texture("/dev/zero").unwrap_err().to_string();
            assert!(
                e.contains("/dev/zero: cannot read file: is a character device"),
                "{e}"
            );
        }
    }
}
