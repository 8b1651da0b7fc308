//! Golden images: each method on three meshes at a fixed level, with the wireframe overlay so
//! the tessellation itself is visible; BFT, adaptive and Doo-Sabin (limit patches and vertex
//! patches) goldens; textured, reparameterized and displaced spot (gregory). Regenerate with
//! TESSERA_UPDATE_GOLDEN=1.
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
const METHODS: [TechniqueId; 3] = [TechniqueId::FLAT, TechniqueId::PHONG, TechniqueId::PN];

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
/// Goldens are lavapipe's images. Another device rasterizes and filters textures with its own
/// precision (NVIDIA's 8-bit filter weights move a displaced silhouette by a pixel here and
/// there: 0.9 % of spot's pixels), so there an image matches with up to 2 % of pixels off.
const OTHER_DEVICE_TOLERANCE: f64 = 0.02;
static ON_LAVAPIPE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

fn note_device(gpu: &Gpu) {
    let _ = ON_LAVAPIPE.set(gpu.device().info.is_lavapipe());
}

/// The most pixels an image may differ from its golden by on the device the goldens ran on.
fn match_tolerance() -> f64 {
    if *ON_LAVAPIPE.get().expect("a golden rendered first") {
        TOLERANCE
    } else {
        OTHER_DEVICE_TOLERANCE
    }
}

fn render_all(level: f32) -> Vec<(String, Rgba8)> {
    let gpu = Gpu::new();
    note_device(&gpu);
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut out = Vec::new();
    for path in MESHES {
        let mesh = tessera::topology::load_obj(common::data(path)).unwrap();
        for m in METHODS {
            let mut t = common::build(&mut ctx, m, &mesh);
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
                format!("{stem}_{m}"),
                ctx.render_offscreen(t.as_mut(), &p, EXTENT).unwrap(),
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
            d1 <= match_tolerance() && d2 <= match_tolerance(),
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
    use tessera::tess::animation::{base_normals, base_positions, wave};
    let gpu = Gpu::new();
    note_device(&gpu);
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
        let mut surf = common::build_with(&mut ctx, TechniqueId::BFT, &mesh, 5, false);
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
                .render_offscreen(surf.as_mut(), &params, BFT_EXTENT)
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
            d1 <= match_tolerance() && d2 <= match_tolerance(),
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
    note_device(&gpu);
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut out = Vec::new();
    for path in ADAPTIVE_MESHES {
        let mesh = tessera::topology::load_obj(common::data(path)).unwrap();
        let stem = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut surf = tessera::tess::build(
            &mut ctx,
            TechniqueId::ADAPTIVE,
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
            .render_offscreen(surf.as_mut(), &params, ADAPTIVE_EXTENT)
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
            d1 <= match_tolerance() && d2 <= match_tolerance(),
            "{name}: differs from golden ({d1:.5}, {d2:.5})"
        );
        assert!(
            changed > TOLERANCE,
            "{name}: an isolation change passed the tolerance ({changed:.5})"
        );
    }
}

/// Doo-Sabin images of spot and the pyramid: the limit patches (`doo-sabin-limit`, patch
/// colours by kind and level, one segment per patch edge) at `isolation`, and the seed's vertex
/// patches (`vertex-patches`) at depth `depth`, both with the wireframe.
fn render_doo_sabin(isolation: u32, depth: u32) -> Vec<(String, Rgba8)> {
    let gpu = Gpu::new();
    note_device(&gpu);
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut out = Vec::new();
    for path in [ADAPTIVE_MESHES[0], ADAPTIVE_MESHES[2]] {
        let mesh = tessera::topology::load_obj(common::data(path)).unwrap();
        let stem = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        for (id, segments, patch_colours) in [
            (TechniqueId::DOO_SABIN_LIMIT, 1.0, true),
            (TechniqueId::VERTEX_PATCHES, (1u32 << depth) as f32, false),
        ] {
            let options = tessera::tess::BuildOptions {
                isolation,
                ..Default::default()
            };
            let mut surf = tessera::tess::build(&mut ctx, id, &mesh, &options)
                .unwrap()
                .technique;
            let params = FrameParams {
                wireframe: true,
                patch_colours,
                camera: tessera::tess::Camera {
                    yaw: 145.0,
                    pitch: 20.0,
                    ..Default::default()
                },
                ..FrameParams::uniform(segments)
            };
            let img = ctx
                .render_offscreen(surf.as_mut(), &params, ADAPTIVE_EXTENT)
                .unwrap();
            out.push((format!("{stem}_{id}"), img));
        }
    }
    out
}

/// Doo-Sabin goldens (limit patches at isolation 2, vertex patches at depth 2): they match run
/// to run, and fail when the isolation level or the depth changes by one.
#[test]
fn doo_sabin_golden_images_match_and_detect_an_isolation_or_depth_change() {
    let first = render_doo_sabin(2, 2);
    let dir = common::data("tests/data/golden");
    if std::env::var_os("TESSERA_UPDATE_GOLDEN").is_some() {
        for (name, img) in &first {
            img.save_png(&dir.join(format!("{name}.png"))).unwrap();
        }
    }
    let second = render_doo_sabin(2, 2);
    let other = render_doo_sabin(3, 3);
    for ((name, a), (b, c)) in first.iter().zip(second.iter().zip(&other)) {
        let golden = Rgba8::load_png(&dir.join(format!("{name}.png")))
            .unwrap_or_else(|e| panic!("{name}: {e} (TESSERA_UPDATE_GOLDEN=1 writes it)"));
        let d1 = differing_fraction(a, &golden);
        let d2 = differing_fraction(&b.1, &golden);
        let changed = differing_fraction(&c.1, &golden);
        eprintln!("{name}: run 1 {d1:.5}, run 2 {d2:.5}, one level deeper {changed:.5}");
        assert!(
            d1 <= match_tolerance() && d2 <= match_tolerance(),
            "{name}: differs from golden ({d1:.5}, {d2:.5})"
        );
        assert!(
            changed > TOLERANCE,
            "{name}: a level change passed the tolerance ({changed:.5})"
        );
    }
}

/// Spot through `--method gregory` with a colour texture: its own (assets/spot_texture.png) and
/// a fine checker (the seed paper's Fig. 1: a checker shows every texel the reparameterization
/// moves), each with the reparameterization on and off, and displaced by its height map. Zoomed
/// on the neck and face, where the extraordinary vertices (and the reparameterized Gregory
/// patches) are.
const SURFACE_EXTENT: vk::Extent2D = vk::Extent2D {
    width: 320,
    height: 240,
};
const SURFACE_CAMERA: tessera::tess::Camera = tessera::tess::Camera {
    yaw: 30.0,
    pitch: 15.0,
    zoom: 2.5,
    fov_y_degrees: 40.0,
};
const SURFACE_SEGMENTS: f32 = 8.0;
/// Displacement scale of the displaced golden, as a fraction of the bbox diagonal (height 1).
const SURFACE_DISPLACE: f32 = 0.03;

/// A 512 × 512 checker of 4-texel cells (128 across the texture atlas), light and dark grey.
fn checker() -> tessera::tess::surface::SurfaceImage {
    const N: u32 = 512;
    const CELL: u32 = 4;
    let mut texels = Vec::with_capacity((N * N * 4) as usize);
    for y in 0..N {
        for x in 0..N {
            let v = if (x / CELL + y / CELL).is_multiple_of(2) {
                230
            } else {
                40
            };
            texels.extend_from_slice(&[v, v, v, 255]);
        }
    }
    tessera::tess::surface::SurfaceImage {
        name: "checker".into(),
        width: N,
        height: N,
        format: tessera::vk_core::texture::TextureFormat::Rgba8Srgb,
        texels,
    }
}

/// The surface goldens, in the order: textured, textured without reparameterization,
/// displaced (textured, height map), checker, checker without reparameterization.
fn render_surface() -> Vec<(String, Rgba8)> {
    use std::sync::Arc;
    use tessera::tess::surface::{load_height, load_texture, SurfaceMaps};
    let gpu = Gpu::new();
    note_device(&gpu);
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mesh = tessera::topology::load_obj(common::data("assets/spot_control_mesh.obj")).unwrap();
    let texture = Arc::new(load_texture(common::data("assets/spot_texture.png")).unwrap());
    let height = Arc::new(load_height(common::data("assets/spot_height.png")).unwrap());
    let mut build = |maps: SurfaceMaps| {
        let options = tessera::tess::BuildOptions {
            name: "spot".into(),
            maps,
            ..Default::default()
        };
        tessera::tess::build(&mut ctx, TechniqueId::GREGORY, &mesh, &options)
            .unwrap()
            .technique
    };
    let textured = build(SurfaceMaps {
        texture: Some(texture),
        height: Some(height),
        param_error: false,
    });
    let checkered = build(SurfaceMaps {
        texture: Some(Arc::new(checker())),
        height: None,
        param_error: false,
    });
    let (lo, hi) = textured.bbox();
    let diag = (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f32>().sqrt();
    let mut out = Vec::new();
    let mut surfaces = [textured, checkered];
    for (name, surf, reparam, displace) in [
        ("spot_gregory_textured", 0, true, 0.0),
        ("spot_gregory_textured_no_reparam", 0, false, 0.0),
        ("spot_gregory_displaced", 0, true, SURFACE_DISPLACE * diag),
        ("spot_gregory_checker", 1, true, 0.0),
        ("spot_gregory_checker_no_reparam", 1, false, 0.0),
    ] {
        let params = FrameParams {
            reparam,
            displace,
            camera: SURFACE_CAMERA,
            ..FrameParams::uniform(SURFACE_SEGMENTS)
        };
        let img = ctx
            .render_offscreen(surfaces[surf].as_mut(), &params, SURFACE_EXTENT)
            .unwrap();
        out.push((name.to_owned(), img));
    }
    out
}

/// The fraction of pixels where any channel moves by more than `threshold`.
fn fraction_above(a: &Rgba8, b: &Rgba8, threshold: u8) -> f64 {
    let n = a
        .pixels
        .chunks(4)
        .zip(b.pixels.chunks(4))
        .filter(|(p, q)| {
            p.iter()
                .zip(q.iter())
                .any(|(x, y)| x.abs_diff(*y) > threshold)
        })
        .count();
    n as f64 / (a.width * a.height) as f64
}

/// The fraction of pixels covered by the surface in one image and background in the other
/// (the silhouette moved): background is the clear colour, the top-left pixel of both.
fn silhouette_change(a: &Rgba8, b: &Rgba8) -> f64 {
    let bg = &a.pixels[..4];
    assert_eq!(
        bg,
        &b.pixels[..4],
        "the top-left pixel is background in both"
    );
    let n = a
        .pixels
        .chunks(4)
        .zip(b.pixels.chunks(4))
        .filter(|(p, q)| (*p == bg) != (*q == bg))
        .count();
    n as f64 / (a.width * a.height) as f64
}

/// Surface goldens: each matches its golden run to run; the reparameterization switched off
/// is seen (the checker's golden fails it under the golden tolerance; spot's own texture moves
/// fewer pixels, so its pair is compared directly with a finer threshold); displacement moves
/// the silhouette.
#[test]
fn surface_golden_images_match_and_show_reparameterization_and_displacement() {
    let first = render_surface();
    let dir = common::data("tests/data/golden");
    if std::env::var_os("TESSERA_UPDATE_GOLDEN").is_some() {
        for (name, img) in &first {
            img.save_png(&dir.join(format!("{name}.png"))).unwrap();
        }
    }
    let second = render_surface();
    let mut golden = Vec::new();
    for ((name, a), (_, b)) in first.iter().zip(&second) {
        let g = Rgba8::load_png(&dir.join(format!("{name}.png")))
            .unwrap_or_else(|e| panic!("{name}: {e} (TESSERA_UPDATE_GOLDEN=1 writes it)"));
        let d1 = differing_fraction(a, &g);
        let d2 = differing_fraction(b, &g);
        let noise = fraction_above(a, b, 4);
        eprintln!("{name}: run 1 {d1:.5}, run 2 {d2:.5}; run 1 vs run 2 (> 4/255) {noise:.5}");
        assert!(
            d1 <= match_tolerance() && d2 <= match_tolerance(),
            "{name}: differs from golden ({d1:.5}, {d2:.5})"
        );
        golden.push(g);
    }
    let [textured, textured_off, displaced, checker, checker_off] = &first[..] else {
        panic!("five surface images");
    };
    // Reparameterization off against the reparameterized golden.
    let checker_golden = differing_fraction(&checker_off.1, &golden[3]);
    let textured_golden = differing_fraction(&textured_off.1, &golden[0]);
    // The pairs within one run (run to run the images are identical on lavapipe).
    let textured_fine = fraction_above(&textured.1, &textured_off.1, 8);
    let checker_fine = fraction_above(&checker.1, &checker_off.1, 8);
    eprintln!(
        "reparameterization off vs on: checker {checker_golden:.5} against its golden \
         (> 24/255; tolerance {TOLERANCE}), {checker_fine:.5} (> 8/255); spot texture \
         {textured_golden:.5} against its golden (> 24/255), {textured_fine:.5} (> 8/255)"
    );
    // Measured 0.0094 (> 24/255) and 0.036 (> 8/255) on lavapipe; identical renders give 0.
    assert!(
        checker_golden > TOLERANCE && checker_fine > 0.01,
        "the checker without reparameterization passes the reparameterized golden \
         ({checker_golden:.5}, {checker_fine:.5}): the reparameterization no longer shows"
    );
    // Measured 0.0022 on lavapipe; identical renders give 0.
    assert!(
        textured_fine > 0.0005,
        "spot's texture moves too few pixels without reparameterization ({textured_fine:.5})"
    );
    let moved = silhouette_change(&textured.1, &displaced.1);
    let changed = differing_fraction(&textured.1, &displaced.1);
    eprintln!("displaced vs undisplaced: silhouette {moved:.5}, pixels (> 24/255) {changed:.5}");
    // Measured 0.089 and 0.26: a height of up to 3% of the diagonal.
    assert!(
        moved > 0.02,
        "displacement hardly moves the silhouette ({moved:.5})"
    );
    assert!(
        changed > 0.05,
        "displacement hardly changes the image ({changed:.5})"
    );
    assert!(
        differing_fraction(&displaced.1, &golden[0]) > TOLERANCE,
        "the displaced image passes the undisplaced golden"
    );
}

/// The scalar-tagged ridge (the seed's Fig. 6 kind of crease): PN on both draw paths matches
/// its golden, and the same dome without its tags does not (the crease is what the image
/// shows).
#[test]
fn scalar_tagged_ridge_golden_shows_the_crease_on_both_paths() {
    use tessera::tess::{BuildOptions, PipelineChoice};
    let gpu = Gpu::new();
    note_device(&gpu);
    let dir = common::data("tests/data/golden");
    let golden_path = dir.join("st_ridge_pn.png");
    let tagged =
        tessera::topology::load_obj(common::data("tests/data/meshes/st_ridge.obj")).unwrap();
    let untagged = tessera::topology::ControlMesh {
        scalar_tags: Vec::new(),
        ..tagged.clone()
    };
    let params = FrameParams {
        camera: tessera::tess::Camera {
            pitch: 25.0,
            yaw: 20.0,
            ..Default::default()
        },
        ..FrameParams::uniform(12.0)
    };
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    let mut render = |mesh: &tessera::topology::ControlMesh, pipeline| {
        let options = BuildOptions {
            name: "st_ridge".into(),
            pipeline,
            ..BuildOptions::default()
        };
        let mut t = tessera::tess::build(&mut ctx, TechniqueId::PN, mesh, &options)
            .unwrap()
            .technique;
        ctx.render_offscreen(t.as_mut(), &params, BFT_EXTENT)
            .unwrap()
    };
    let tess = render(&tagged, PipelineChoice::Tessellation);
    let pattern = render(&tagged, PipelineChoice::Pattern);
    let smooth = render(&untagged, PipelineChoice::Tessellation);
    if std::env::var_os("TESSERA_UPDATE_GOLDEN").is_some() {
        tess.save_png(&golden_path).unwrap();
    }
    let golden = Rgba8::load_png(&golden_path)
        .unwrap_or_else(|e| panic!("st_ridge_pn: {e} (TESSERA_UPDATE_GOLDEN=1 writes it)"));
    let (d1, d2, d3) = (
        differing_fraction(&tess, &golden),
        differing_fraction(&pattern, &golden),
        differing_fraction(&smooth, &golden),
    );
    eprintln!("st_ridge_pn: tessellation {d1:.5}, pattern {d2:.5}, untagged {d3:.5}");
    assert!(
        d1 <= match_tolerance() && d2 <= match_tolerance(),
        "{d1} {d2}"
    );
    assert!(
        d3 > 4.0 * TOLERANCE,
        "without tags only {d3:.5} of pixels change"
    );
    drop(ctx);
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}
