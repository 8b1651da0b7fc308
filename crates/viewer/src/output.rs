//! The files the commands write: each through [`tess::output::write_file`] (a temporary file
//! beside the target, flushed, synced and renamed; an error names the file and the operating
//! system's reason), so "wrote FILE" is printed only for a file written whole. Output names are
//! checked before any work (a PNG must be called `.png`), and a picture in which nothing was
//! drawn is refused instead of written.
use anyhow::{bail, Context as _, Result};
use image::ImageEncoder as _;
use std::path::Path;
use vk_core::target::Rgba8;

/// Refuses an image output not named `.png` (`option` is how the command line gave it), before
/// any work: PNG is the one format written.
pub fn check_png_name(path: &Path, option: &str) -> Result<()> {
    let png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        bail!(
            "{option} {}: give a file name ending in .png (PNG is the image format written)",
            path.display()
        );
    }
    Ok(())
}

/// `image` encoded as PNG.
pub fn png_bytes(image: &Rgba8) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            &image.pixels,
            image.width,
            image.height,
            image::ExtendedColorType::Rgba8,
        )
        .with_context(|| format!("encoding a {}x{} PNG", image.width, image.height))?;
    Ok(bytes)
}

/// Writes `image` to `path` as PNG, whole or not at all.
pub fn write_png(path: &Path, image: &Rgba8) -> Result<()> {
    Ok(tess::output::write_bytes(path, &png_bytes(image)?)?)
}

/// Writes `text` to `path`, whole or not at all.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    Ok(tess::output::write_bytes(path, text.as_bytes())?)
}

/// Whether nothing was drawn: every pixel is the clear colour (`clear`, linear RGBA), as an
/// 8-bit UNORM target stores it or as an sRGB one encodes it (within one step).
pub fn is_blank(image: &Rgba8, clear: [f32; 4]) -> bool {
    let Some(first) = image.pixels.get(..4) else {
        return true;
    };
    if !image.pixels.chunks_exact(4).all(|p| p == first) {
        return false;
    }
    let srgb = |c: f32| {
        if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let near = |encode: &dyn Fn(f32) -> f32| {
        (0..3).all(|k| {
            let want = (encode(clear[k]).clamp(0.0, 1.0) * 255.0).round();
            (f32::from(first[k]) - want).abs() <= 1.0
        })
    };
    near(&|c| c) || near(&srgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_names_are_checked_by_extension() {
        for ok in ["x.png", "dir/x.PNG", "a.b.png"] {
            check_png_name(Path::new(ok), "-o").unwrap();
        }
        for bad in ["x.xyz", "x", "x.png.txt", "png"] {
            let e = check_png_name(Path::new(bad), "-o")
                .unwrap_err()
                .to_string();
            assert_eq!(
                e,
                format!(
                    "-o {bad}: give a file name ending in .png (PNG is the image format written)"
                )
            );
        }
    }

    #[test]
    fn blank_is_the_clear_colour_everywhere() {
        let clear = [0.12, 0.13, 0.16, 1.0];
        let picture = |pixel: [u8; 4]| Rgba8 {
            width: 2,
            height: 2,
            pixels: pixel.repeat(4),
        };
        assert!(is_blank(&picture([31, 33, 41, 255]), clear), "UNORM");
        assert!(is_blank(&picture([97, 101, 111, 255]), clear), "sRGB");
        assert!(
            !is_blank(&picture([200, 33, 41, 255]), clear),
            "a uniform surface"
        );
        let mut one = picture([31, 33, 41, 255]);
        one.pixels[5] = 200;
        assert!(!is_blank(&one, clear), "one pixel drawn");
    }
}
