//! Golden images: each method on three meshes at a fixed level, with the wireframe overlay so
//! the tessellation itself is visible. Regenerate with TESSERA_UPDATE_GOLDEN=1.
mod common;
use common::Gpu;
use tessera::tess::{Context, FrameParams, TechniqueId};
use tessera::vk_core::target::Rgba8;
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 160,
    height: 120,
};
const LEVEL: f32 = 3.0;
const MESHES: [&str; 3] = [
    "assets/spot_control_mesh.obj",
    "tests/data/meshes/cube.obj",
    "tests/data/opensubdiv/shapes/loop_icosahedron.obj",
];
const METHODS: [TechniqueId; 3] = [TechniqueId::Flat, TechniqueId::Phong, TechniqueId::Pn];

/// A pixel differs when any channel moves by more than 24/255; an image matches when at most
/// 0.5% of its pixels differ. Rasterisation noise (an edge pixel flipping) stays far below; a
/// one-level change of the tessellation moves every wireframe line and fails.
fn differing_fraction(a: &Rgba8, b: &Rgba8) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let n = a
        .pixels
        .chunks(4)
        .zip(b.pixels.chunks(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 24))
        .count();
    n as f64 / (a.width * a.height) as f64
}
const TOLERANCE: f64 = 0.005;

fn render_all(level: f32) -> Vec<(String, Rgba8)> {
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut out = Vec::new();
    for path in MESHES {
        let mesh = tessera::topology::load_obj(common::data(path)).unwrap();
        for m in METHODS {
            let t = common::build(&mut ctx, m, &mesh);
            let p = FrameParams {
                wireframe: true,
                ..FrameParams::uniform(level)
            };
            let stem = std::path::Path::new(path)
                .file_stem()
                .unwrap()
                .to_string_lossy()
                .into_owned();
            out.push((
                format!("{stem}_{m:?}").to_lowercase(),
                ctx.render_offscreen(t.as_ref(), &p, EXTENT).unwrap(),
            ));
        }
    }
    out
}

#[test]
fn golden_images_match_and_detect_a_level_change() {
    let first = render_all(LEVEL);
    let dir = common::data("tests/data/golden");
    if std::env::var_os("TESSERA_UPDATE_GOLDEN").is_some() {
        for (name, img) in &first {
            img.save_png(&dir.join(format!("{name}.png"))).unwrap();
        }
    }
    let second = render_all(LEVEL);
    let changed = render_all(LEVEL + 1.0);
    for (((name, a), (_, b)), (_, c)) in first.iter().zip(&second).zip(&changed) {
        let golden = Rgba8::load_png(&dir.join(format!("{name}.png")))
            .unwrap_or_else(|e| panic!("{name}: {e} (TESSERA_UPDATE_GOLDEN=1 writes it)"));
        let d1 = differing_fraction(a, &golden);
        let d2 = differing_fraction(b, &golden);
        let d3 = differing_fraction(c, &golden);
        eprintln!(
            "{name}: run 1 {d1:.5}, run 2 {d2:.5}, level {} {d3:.5}",
            LEVEL + 1.0
        );
        assert!(
            d1 <= TOLERANCE && d2 <= TOLERANCE,
            "{name}: differs from golden ({d1:.5}, {d2:.5})"
        );
        assert!(
            d3 > TOLERANCE,
            "{name}: a one-level change passed the tolerance ({d3:.5}) — the check is too loose"
        );
    }
}

/// Larger than the other goldens: at 160 × 120 the spot's wireframe at S = 4 already covers
/// nearly every pixel, so no change of S could show.
const BFT_EXTENT: vk::Extent2D = vk::Extent2D {
    width: 320,
    height: 240,
};
const BFT_MESHES: [&str; 3] = [
    "assets/spot_control_mesh.obj",
    "tests/data/opensubdiv/shapes/loop_icosahedron.obj",
    "tests/data/opensubdiv/shapes/loop_xord_boundary.obj",
];

/// BFT images per mesh: shaded (subdivision shading at S segments, posed by the animation wave
/// at `time`) and wireframe with patch colours.
fn render_bft(segments: u32, time: f32) -> Vec<(String, Rgba8)> {
    use tessera::tess::techniques::bft::{base_normals, base_positions, wave};
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut out = Vec::new();
    for path in BFT_MESHES {
        let mesh = tessera::topology::load_obj(common::data(path))
            .unwrap()
            .triangulated()
            .0;
        let stem = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut surf = common::build_with(&mut ctx, TechniqueId::Bft, &mesh, 5, false);
        let rest = base_positions(&mesh);
        let (lo, hi) = surf.bbox();
        surf.update_base(0, &wave(&rest, &base_normals(&mesh), lo, hi, time))
            .unwrap();
        for (kind, wireframe) in [("shaded", false), ("wire", true)] {
            // From above: loop_xord_boundary is an open sheet seen edge-on by the default view.
            let params = FrameParams {
                wireframe,
                camera: tessera::tess::Camera {
                    pitch: 55.0,
                    ..Default::default()
                },
                patch_colours: wireframe,
                ..FrameParams::uniform(segments as f32)
            };
            let img = ctx
                .render_offscreen(surf.as_ref(), &params, BFT_EXTENT)
                .unwrap();
            out.push((format!("{stem}_bft_{kind}"), img));
        }
    }
    out
}

/// BFT goldens: shaded and wireframe. The shaded image must notice the surface moving (an
/// animation frame later), the wireframe one a change of the segments.
#[test]
fn bft_golden_images_match_and_detect_changes() {
    const S: u32 = 4;
    const T: f32 = 0.0;
    let first = render_bft(S, T);
    let dir = common::data("tests/data/golden");
    if std::env::var_os("TESSERA_UPDATE_GOLDEN").is_some() {
        for (name, img) in &first {
            img.save_png(&dir.join(format!("{name}.png"))).unwrap();
        }
    }
    let second = render_bft(S, T);
    let finer = render_bft(2 * S, T);
    let later = render_bft(S, T + 0.5);
    for (((name, a), b), (c, d)) in first.iter().zip(&second).zip(finer.iter().zip(&later)) {
        let golden = Rgba8::load_png(&dir.join(format!("{name}.png")))
            .unwrap_or_else(|e| panic!("{name}: {e} (TESSERA_UPDATE_GOLDEN=1 writes it)"));
        let d1 = differing_fraction(a, &golden);
        let d2 = differing_fraction(&b.1, &golden);
        let changed = if name.ends_with("_wire") {
            differing_fraction(&c.1, &golden)
        } else {
            differing_fraction(&d.1, &golden)
        };
        eprintln!("{name}: run 1 {d1:.5}, run 2 {d2:.5}, changed {changed:.5}");
        assert!(
            d1 <= TOLERANCE && d2 <= TOLERANCE,
            "{name}: differs from golden ({d1:.5}, {d2:.5})"
        );
        assert!(
            changed > TOLERANCE,
            "{name}: a change passed the tolerance ({changed:.5}) — the check is too loose"
        );
    }
}

const ADAPTIVE_MESHES: [&str; 3] = [
    "assets/spot_control_mesh.obj",
    "tests/data/opensubdiv/shapes/catmark_cube_creases0.obj",
    "tests/data/opensubdiv/shapes/catmark_pyramid.obj",
];

const ADAPTIVE_EXTENT: vk::Extent2D = vk::Extent2D {
    width: 320,
    height: 240,
};

/// Feature-adaptive Catmull-Clark images per mesh at `isolation`: wireframe with patch colours
/// (kind and level), one segment per patch edge (the patches themselves).
fn render_adaptive(isolation: u32) -> Vec<(String, Rgba8)> {
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut out = Vec::new();
    for path in ADAPTIVE_MESHES {
        let mesh = tessera::topology::load_obj(common::data(path)).unwrap();
        let stem = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let surf = tessera::tess::build(
            &mut ctx,
            TechniqueId::Adaptive,
            &mesh,
            &tessera::tess::BuildOptions {
                isolation,
                ..Default::default()
            },
        )
        .unwrap()
        .technique;
        // The CLI's default view.
        let params = FrameParams {
            wireframe: true,
            patch_colours: true,
            camera: tessera::tess::Camera {
                yaw: 145.0,
                pitch: 20.0,
                ..Default::default()
            },
            ..FrameParams::uniform(1.0)
        };
        let img = ctx
            .render_offscreen(surf.as_ref(), &params, ADAPTIVE_EXTENT)
            .unwrap();
        out.push((format!("{stem}_adaptive"), img));
    }
    out
}

/// Adaptive goldens (isolation 2): they match run to run and fail when the isolation level
/// changes by one (patch colours by level and the finer wireframe move).
#[test]
fn adaptive_golden_images_match_and_detect_an_isolation_change() {
    let first = render_adaptive(2);
    let dir = common::data("tests/data/golden");
    if std::env::var_os("TESSERA_UPDATE_GOLDEN").is_some() {
        for (name, img) in &first {
            img.save_png(&dir.join(format!("{name}.png"))).unwrap();
        }
    }
    let second = render_adaptive(2);
    let other = render_adaptive(3);
    for ((name, a), (b, c)) in first.iter().zip(second.iter().zip(&other)) {
        let golden = Rgba8::load_png(&dir.join(format!("{name}.png")))
            .unwrap_or_else(|e| panic!("{name}: {e} (TESSERA_UPDATE_GOLDEN=1 writes it)"));
        let d1 = differing_fraction(a, &golden);
        let d2 = differing_fraction(&b.1, &golden);
        let changed = differing_fraction(&c.1, &golden);
        eprintln!("{name}: run 1 {d1:.5}, run 2 {d2:.5}, isolation 3 {changed:.5}");
        assert!(
            d1 <= TOLERANCE && d2 <= TOLERANCE,
            "{name}: differs from golden ({d1:.5}, {d2:.5})"
        );
        assert!(
            changed > TOLERANCE,
            "{name}: an isolation change passed the tolerance ({changed:.5})"
        );
    }
}
