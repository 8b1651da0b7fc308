//! Single-pass Catmull-Clark approximations on the tessellation stage (`--method gregory`,
//! `--method acc`), checked from the GPU's own output (transform feedback): captured vertices
//! against the exact CPU limit at their (base face, sub-face, u, v) (max and RMS over the bbox
//! diagonal, regular patches exact), watertightness (weld by bits) under every factor policy on
//! spot and catmark shapes, and bad input. Validation is on and any error fails (tests/common).
mod common;
use common::Gpu;
use tessera::tess::capture::{classify_open_edges, CapturedSoup, Capturer};
use tessera::tess::gpu::bindings::{ADAPTIVE_FLAG_CANONICAL, ADAPTIVE_KIND_REGULAR};
use tessera::tess::surface::{SurfaceMaps, SurfaceShow};
use tessera::tess::techniques::planned_patches;
use tessera::tess::techniques::planned_patches::PlannedPatches;
use tessera::tess::{Camera, Context, FactorPolicy, FrameParams, Spacing, Technique};
use tessera::topology::limit::eval::{LimitScheme, LocalMesh};
use tessera::topology::patches::adaptive::single_pass::SinglePassPatch;
use tessera::topology::{self, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 640,
    height: 480,
};

fn shape(name: &str) -> ControlMesh {
    if name == "spot" {
        return topology::load_obj(common::data("assets/spot_control_mesh.obj")).expect("spot");
    }
    topology::load_obj(common::data(&format!(
        "tests/data/opensubdiv/shapes/{name}.obj"
    )))
    .expect("shape")
}

fn diag(m: &ControlMesh) -> f64 {
    m.bbox_diagonal()
}

/// Angle in radians between two vectors.
fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d: f64 = (0..3).map(|k| a[k] * b[k]).sum();
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().atan2(d)
}

fn semi_sharp(m: &ControlMesh) -> bool {
    let finite = |s: f32| s > 0.0 && s < 10.0;
    m.creases.iter().any(|c| finite(c.sharpness)) || m.corners.iter().any(|c| finite(c.sharpness))
}

/// (regular max, max, RMS) of captured vertices against the exact limit, over the diagonal.
fn deviation(surf: &PlannedPatches, soup: &CapturedSoup, mesh: &ControlMesh) -> (f64, f64, f64) {
    sampled_deviation(surf, soup, mesh, usize::MAX)
}

/// [`deviation`] over at most `samples` welded vertices, evenly strided.
fn sampled_deviation(
    surf: &PlannedPatches,
    soup: &CapturedSoup,
    mesh: &ControlMesh,
    samples: usize,
) -> (f64, f64, f64) {
    let cpu = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark).expect("cpu mesh");
    let welded = soup.weld().expect("weld");
    let d = diag(mesh);
    let (mut regular, mut max, mut sq) = (0.0f64, 0.0f64, 0.0f64);
    let n = welded.positions.len();
    let stride = n.div_ceil(samples.max(1)).max(1);
    let mut counted = 0usize;
    for i in (0..n).step_by(stride) {
        counted += 1;
        let [u, v] = welded.domain[i].map(f64::from);
        let (f, sub, bu, bv) = surf.base_param(welded.patch[i], u, v).expect("patch");
        let e = if mesh.face(f as usize).len() == 4 {
            cpu.evaluate(f as usize, bu, bv)
        } else {
            cpu.evaluate_subface(f as usize, sub as usize, bu, bv)
        }
        .expect("exact limit");
        let p = welded.positions[i].map(f64::from);
        let err = (0..3)
            .map(|k| (p[k] - e.position[k]).powi(2))
            .sum::<f64>()
            .sqrt()
            / d;
        if welded.flags[i] & 15 == ADAPTIVE_KIND_REGULAR {
            regular = regular.max(err);
        }
        max = max.max(err);
        sq += err * err;
    }
    (regular, max, (sq / counted.max(1) as f64).sqrt())
}

/// Positions emitted by more than one patch, and how many of them carry more than one normal
/// (bits): single-pass surfaces shade a boundary vertex with its curve owner's normal.
fn normal_seams(soup: &CapturedSoup) -> (usize, usize) {
    let mut by_point = std::collections::HashMap::<[u32; 3], (u32, [u32; 3], bool, bool)>::new();
    for r in &soup.records {
        let n = r.normal.map(f32::to_bits);
        let e = by_point
            .entry(r.position.map(f32::to_bits))
            .or_insert((r.patch, n, false, false));
        if e.0 != r.patch {
            e.2 = true;
        }
        if e.1 != n {
            e.3 = true;
        }
    }
    let shared = by_point.values().filter(|e| e.2).count();
    let differing = by_point.values().filter(|e| e.2 && e.3).count();
    (shared, differing)
}

fn cracks(surf: &PlannedPatches, soup: &CapturedSoup, mesh: &ControlMesh) -> (usize, usize) {
    let welded = soup.weld().expect("weld");
    let report = welded.open_edges();
    let map = |p: u32, d: [f32; 2]| surf.face_point(p, d);
    let c = classify_open_edges(soup, &welded, &report, &map, mesh);
    (c.cracks + c.unmapped, report.non_manifold.len())
}

const PATCHES: [SinglePassPatch; 2] = [SinglePassPatch::Gregory, SinglePassPatch::Acc1];

/// Regular patches are the exact limit (≤ 1e-5 of the diagonal) on shapes without semi-sharp
/// tags (those are rounded); the whole surface stays within a few percent. Prints the table of
/// docs/approximations.md.
#[test]
fn captured_vertices_against_the_exact_limit() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        for name in [
            "spot",
            "catmark_cube",
            "catmark_pawn",
            "catmark_bishop",
            "catmark_car",
            "catmark_cube_creases0",
            "catmark_tent_creases1",
            "catmark_edgecorner",
            "catmark_flap",
            "catmark_pyramid",
        ] {
            let mesh = shape(name);
            for patch in PATCHES {
                let mut surf = planned_patches::single_pass(
                    &mut ctx,
                    &mesh,
                    &planned_patches::SinglePassBuild {
                        patch,
                        sharpness_scale: 1.0,
                        gregory_triangles: true,
                        name,
                        maps: &Default::default(),
                        path: tessera::tess::DrawPath::Tessellation,
                    },
                )
                .expect("build");
                let (soup, _) = capturer
                    .capture(&mut ctx, &mut surf, &FrameParams::uniform(4.0), EXTENT)
                    .expect("capture");
                let (regular, max, rms) = deviation(&surf, &soup, &mesh);
                println!(
                    "| {name} | {patch:?} | {} | {regular:.2e} | {max:.2e} | {rms:.2e} |",
                    surf.patch_counts()[1]
                );
                if !semi_sharp(&mesh) {
                    assert!(regular <= 1e-5, "{name} {patch:?}: regular {regular:e}");
                }
                assert!(max < 0.05, "{name} {patch:?}: {max:e}");
            }
        }
    }
}

/// Whether two faces have the same corners (back to back, as in catmark_val2_back2back).
fn back_to_back(m: &ControlMesh) -> bool {
    let mut seen = std::collections::HashSet::new();
    m.faces().any(|f| {
        let mut key = f.to_vec();
        key.sort_unstable();
        !seen.insert(key)
    })
}

/// Every Catmull-Clark shape of tests/data, or of the folder `SINGLE_PASS_SHAPES_DIR` names
/// (OpenSubdiv's whole shape set, say), with nothing chosen for the single-pass methods: both
/// patch types weld without cracks (holes' borders are boundaries), regular patches are the
/// exact limit where no crease is semi-sharp, and every vertex stays within a quarter of the
/// diagonal of the limit at its parameter. Shapes that do not load (non-manifold) or that a
/// method refuses are listed, named; in tests/data none is.
#[test]
#[ignore = "sweep tier (every Catmull-Clark shape): tools/test.sh sweeps"]
fn every_catmark_shape_welds_and_stays_near_the_limit() {
    let (dir, other) = common::shapes_dir("SINGLE_PASS_SHAPES_DIR");
    let names = common::shape_names(&dir, "catmark_");
    assert!(
        names.len() >= 10,
        "{} catmark shapes in {dir:?}",
        names.len()
    );
    let gpu = Gpu::new();
    let (mut failures, mut refused) = (Vec::new(), Vec::new());
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        for name in &names {
            let mesh = match topology::load_obj(dir.join(format!("{name}.obj"))) {
                Ok(m) => m,
                Err(e) => {
                    refused.push(format!("{name}: {e}"));
                    continue;
                }
            };
            for patch in PATCHES {
                let mut surf = match planned_patches::single_pass(
                    &mut ctx,
                    &mesh,
                    &planned_patches::SinglePassBuild {
                        patch,
                        sharpness_scale: 1.0,
                        gregory_triangles: true,
                        name,
                        maps: &Default::default(),
                        path: tessera::tess::DrawPath::Tessellation,
                    },
                ) {
                    Ok(s) => s,
                    Err(e) => {
                        refused.push(format!("{name} {patch:?}: {e}"));
                        continue;
                    }
                };
                let soup =
                    match capturer.capture(&mut ctx, &mut surf, &FrameParams::uniform(4.0), EXTENT)
                    {
                        Ok((soup, _)) => soup,
                        Err(e) => {
                            refused.push(format!("{name} {patch:?}: capture: {e}"));
                            continue;
                        }
                    };
                let (regular, max, rms) = sampled_deviation(&surf, &soup, &mesh, 3000);
                let (open, nonmanifold) = cracks(&surf, &soup, &mesh);
                println!(
                    "{name} {patch:?}: {} patches, regular {regular:.2e}, max {max:.2e}, \
                     RMS {rms:.2e}, {open} cracks",
                    surf.patch_counts().iter().sum::<u32>()
                );
                let regular_bad = !semi_sharp(&mesh) && regular > 1e-5;
                // Back-to-back faces have one limit surface: its two sides weld onto each other.
                let nonmanifold_bad = nonmanifold != 0 && !back_to_back(&mesh);
                // The deviation is at the same parameter, which the single-pass patches do not
                // share with the limit near extraordinary vertices and rounded creases (up to
                // 0.15 on OpenSubdiv's coarse cubes with semi-sharp corners): a sanity bound.
                let finite = soup
                    .records
                    .iter()
                    .all(|r| r.position.iter().chain(&r.normal).all(|x| x.is_finite()));
                let far = !finite || max >= 0.25;
                if regular_bad || far || open != 0 || nonmanifold_bad {
                    failures.push(format!(
                        "{name} {patch:?}: regular {regular:.2e}, max {max:.2e}, {open} cracks, \
                         {nonmanifold} non-manifold, finite {finite}"
                    ));
                }
            }
        }
    }
    common::whole_set_verdict(&refused, other, &failures);
}

/// 0 cracks beyond the base boundary (positions welded only when bit-identical) under uniform,
/// screen, distance and fractional factors, on spot (triangles, quads, pentagons: split faces
/// and transition edges) and catmark shapes with boundaries and creases.
#[test]
#[ignore = "sweep tier (every shape and factor policy): tools/test.sh sweeps"]
fn watertight_under_every_factor_policy() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let camera = Camera {
            zoom: 2.5,
            yaw: 30.0,
            ..Default::default()
        };
        for name in [
            "spot",
            "catmark_cube",
            "catmark_pyramid",
            "catmark_tent_creases1",
            "catmark_edgecorner",
            "catmark_flap",
        ] {
            let mesh = shape(name);
            for patch in PATCHES {
                let mut surf = planned_patches::single_pass(
                    &mut ctx,
                    &mesh,
                    &planned_patches::SinglePassBuild {
                        patch,
                        sharpness_scale: 1.0,
                        gregory_triangles: true,
                        name,
                        maps: &Default::default(),
                        path: tessera::tess::DrawPath::Tessellation,
                    },
                )
                .expect("build");
                let mut maps_surface = None;
                let d = diag(&mesh) as f32;
                let policies = [
                    ("uniform 3", FactorPolicy::Uniform { segments: 3.0 }, false),
                    ("screen 6px", FactorPolicy::Screen { pixels: 6.0 }, false),
                    (
                        "distance",
                        FactorPolicy::Distance {
                            reference: 0.12 * d,
                        },
                        false,
                    ),
                    (
                        "screen fractional",
                        FactorPolicy::Screen { pixels: 6.0 },
                        true,
                    ),
                    (
                        "distance fractional",
                        FactorPolicy::Distance { reference: 0.1 * d },
                        true,
                    ),
                ];
                // Without and with displacement (procedural heights; spot also with its
                // height map and texture seams): boundary vertices move by their curve's owner.
                let displaced = [(0.0, false), (0.03 * d, false), (0.03 * d, true)];
                for ((label, factors, fractional), (displace, height_map)) in policies
                    .iter()
                    .flat_map(|p| displaced.iter().map(move |d| (*p, *d)))
                {
                    if height_map && name != "spot" {
                        continue;
                    }
                    let surf = if height_map {
                        maps_surface.get_or_insert_with(|| {
                            let maps = tessera::tess::surface::SurfaceMaps {
                                texture: None,
                                param_error: false,
                                height: Some(std::sync::Arc::new(
                                    tessera::tess::surface::load_height(common::data(
                                        "assets/spot_height.png",
                                    ))
                                    .expect("height map"),
                                )),
                            };
                            planned_patches::single_pass(
                                &mut ctx,
                                &mesh,
                                &planned_patches::SinglePassBuild {
                                    patch,
                                    sharpness_scale: 1.0,
                                    gregory_triangles: true,
                                    name,
                                    maps: &maps,
                                    path: tessera::tess::DrawPath::Tessellation,
                                },
                            )
                            .expect("build")
                        })
                    } else {
                        &mut surf
                    };
                    let params = FrameParams {
                        displace,
                        factors,
                        spacing: if fractional {
                            Spacing::FractionalEven
                        } else {
                            Spacing::Equal
                        },
                        camera,
                        ..FrameParams::default()
                    };
                    let (soup, _) = capturer
                        .capture(&mut ctx, &mut *surf, &params, EXTENT)
                        .expect("capture");
                    let (cracks, nonmanifold) = cracks(surf, &soup, &mesh);
                    let (shared, differing) = normal_seams(&soup);
                    println!(
                        "{name} {patch:?} {label} displace {displace} (height map {height_map}): {} triangles, {cracks} cracks, {differing} of {shared} shared vertices with two normals",
                        soup.triangle_count()
                    );
                    assert!(shared > 0 && differing == 0, "{name} {patch:?} {label} displace {displace}: {differing} of {shared} shared vertices with two normals");
                    assert_eq!(cracks, 0, "{name} {patch:?} {label} displace {displace}");
                    assert_eq!(
                        nonmanifold, 0,
                        "{name} {patch:?} {label} displace {displace}"
                    );
                }
            }
        }
    }
}

/// Bad sharpness scales, non-manifold meshes and refused frame options are named errors.
#[test]
fn bad_input_gives_named_errors() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let mesh = shape("catmark_cube");
        for scale in [f32::NAN, -1.0] {
            let e = planned_patches::single_pass(
                &mut ctx,
                &mesh,
                &planned_patches::SinglePassBuild {
                    patch: SinglePassPatch::Gregory,
                    sharpness_scale: scale,
                    gregory_triangles: true,
                    name: "cube",
                    maps: &Default::default(),
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
            .err()
            .expect("refused");
            assert!(e.to_string().contains("sharpness"), "{e}");
        }
        let fan = ControlMesh::from_polygons(
            vec![
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [0.0, -1.0, 0.0],
                [1.0, -1.0, 0.0],
            ],
            &[vec![0u32, 1, 3, 2], vec![1, 0, 4, 5], vec![0, 1, 7, 6]],
        );
        assert!(planned_patches::single_pass(
            &mut ctx,
            &fan,
            &planned_patches::SinglePassBuild {
                patch: SinglePassPatch::Acc1,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name: "fan",
                maps: &Default::default(),
                path: tessera::tess::DrawPath::Tessellation
            }
        )
        .is_err());
        let ok = planned_patches::single_pass(
            &mut ctx,
            &mesh,
            &planned_patches::SinglePassBuild {
                patch: SinglePassPatch::Gregory,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name: "cube",
                maps: &Default::default(),
                path: tessera::tess::DrawPath::Tessellation,
            },
        )
        .expect("cube");
        for bad in [
            FrameParams::uniform(0.0),
            FrameParams::uniform(2.5),
            FrameParams {
                spacing: Spacing::FractionalOdd,
                ..FrameParams::uniform(4.0)
            },
        ] {
            assert!(ok.check(&bad).is_err(), "{bad:?}");
        }
        // A texture on a mesh without `vt` is refused, naming the mesh.
        let mut bare = mesh.clone();
        bare.uvs = None;
        let textured = SurfaceMaps {
            texture: Some(std::sync::Arc::new(
                tessera::tess::surface::load_texture(common::data("assets/spot_texture.png"))
                    .expect("texture"),
            )),
            ..Default::default()
        };
        for patch in PATCHES {
            let e = planned_patches::single_pass(
                &mut ctx,
                &bare,
                &planned_patches::SinglePassBuild {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles: true,
                    name: "bare.obj",
                    maps: &textured,
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
            .err()
            .expect("texture without vt");
            assert!(
                e.to_string().contains("bare.obj") && e.to_string().contains("vt"),
                "{e}"
            );
        }
        // A height map alone too (the displacement would read it at `vt`); procedural
        // displacement, which needs no map, is not refused.
        let height_only = SurfaceMaps {
            height: Some(std::sync::Arc::new(
                tessera::tess::surface::load_height(common::data("assets/spot_height.png"))
                    .expect("height map"),
            )),
            ..Default::default()
        };
        for patch in PATCHES {
            let e = planned_patches::single_pass(
                &mut ctx,
                &bare,
                &planned_patches::SinglePassBuild {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles: true,
                    name: "bare.obj",
                    maps: &height_only,
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
            .err()
            .expect("height map without vt");
            let e = e.to_string();
            assert!(
                e.contains("bare.obj") && e.contains("a height map was given") && e.contains("vt"),
                "{e}"
            );
        }
        assert!(planned_patches::single_pass(
            &mut ctx,
            &bare,
            &planned_patches::SinglePassBuild {
                patch: SinglePassPatch::Gregory,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name: "bare.obj",
                maps: &Default::default(),
                path: tessera::tess::DrawPath::Tessellation
            }
        )
        .is_ok());
        assert!(planned_patches::single_pass(
            &mut ctx,
            &mesh,
            &planned_patches::SinglePassBuild {
                patch: SinglePassPatch::Gregory,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name: "cube",
                maps: &textured,
                path: tessera::tess::DrawPath::Tessellation
            }
        )
        .is_ok());
        // The Eq. 1 view needs the lattice, which is built only on request.
        let e = ok
            .check(&FrameParams {
                show: SurfaceShow::ParamError,
                ..FrameParams::uniform(4.0)
            })
            .expect_err("param-error without its lattice");
        assert!(e.to_string().contains("param-error"), "{e}");
    }
}

/// Hue in degrees of the surface pixels of `img` (background black, specular whites skipped).
fn surface_hues(img: &tessera::vk_core::target::Rgba8) -> Vec<f64> {
    img.pixels
        .chunks(4)
        .filter_map(|p| {
            let [r, g, b] = [p[0], p[1], p[2]].map(|c| c as f64 / 255.0);
            let (max, min) = (r.max(g).max(b), r.min(g).min(b));
            if max < 0.05 || max - min < 0.15 * max {
                return None;
            }
            let d = max - min;
            let h = if max == r {
                60.0 * ((g - b) / d).rem_euclid(6.0)
            } else if max == g {
                60.0 * ((b - r) / d + 2.0)
            } else {
                60.0 * ((r - g) / d + 4.0)
            };
            Some(h)
        })
        .collect()
}

/// `--show param-error` (seed 003's Fig. 8) as the GPU draws it: the colour ramp runs from blue
/// (exact) to red (1e-2 of the diagonal) by hue, so the drawn hues must follow the CPU lattice:
/// an all-regular mesh is blue everywhere; on spot the reparameterization turns pixels bluer
/// (the CPU lattice's RMS falls to 0.6x), and warm pixels exist where Gregory patches deviate.
#[test]
fn param_error_view_follows_the_cpu_lattice() {
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).expect("context");
    let maps = SurfaceMaps {
        param_error: true,
        ..Default::default()
    };
    let extent = vk::Extent2D {
        width: 320,
        height: 240,
    };
    let render = |ctx: &mut Context, surf: &mut PlannedPatches, reparam: bool| {
        let params = FrameParams {
            show: SurfaceShow::ParamError,
            reparam,
            clear_color: [0.0, 0.0, 0.0, 1.0],
            ..FrameParams::uniform(8.0)
        };
        surf.check(&params).expect("param-error view");
        ctx.render_offscreen(surf, &params, extent).expect("frame")
    };
    let mean = |h: &[f64]| h.iter().sum::<f64>() / h.len().max(1) as f64;
    // Exact everywhere: every patch is a B-spline patch of a mesh without semi-sharp tags.
    let edgecorner = shape("catmark_edgecorner");
    let mut surf = planned_patches::single_pass(
        &mut ctx,
        &edgecorner,
        &planned_patches::SinglePassBuild {
            patch: SinglePassPatch::Gregory,
            sharpness_scale: 1.0,
            gregory_triangles: true,
            name: "edgecorner",
            maps: &maps,
            path: tessera::tess::DrawPath::Tessellation,
        },
    )
    .expect("build");
    let hues = surface_hues(&render(&mut ctx, &mut surf, true));
    let blue = hues.iter().filter(|&&h| h > 200.0).count();
    println!(
        "catmark_edgecorner: {} surface pixels, {blue} blue",
        hues.len()
    );
    assert!(
        hues.len() > 1000 && blue == hues.len(),
        "exact surface not blue: {blue} of {}",
        hues.len()
    );

    let spot = shape("spot");
    for patch in [SinglePassPatch::Gregory, SinglePassPatch::Acc1] {
        let mut surf = planned_patches::single_pass(
            &mut ctx,
            &spot,
            &planned_patches::SinglePassBuild {
                patch,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name: "spot",
                maps: &maps,
                path: tessera::tess::DrawPath::Tessellation,
            },
        )
        .expect("build");
        let note = surf.param_error_note().expect("a lattice summary");
        println!("{note}");
        let patches: u32 = surf.patch_counts().iter().sum();
        assert!(
            note.starts_with("spot: Eq. 1") && note.contains(&format!("of {patches} patches")),
            "{note}"
        );
        let on = surface_hues(&render(&mut ctx, &mut surf, true));
        let off = surface_hues(&render(&mut ctx, &mut surf, false));
        let warm = |h: &[f64]| h.iter().filter(|&&x| x < 100.0).count();
        println!(
            "spot {patch:?}: mean hue reparameterized {:.1} (warm {}), identity {:.1} (warm {}), {} pixels",
            mean(&on),
            warm(&on),
            mean(&off),
            warm(&off),
            on.len()
        );
        assert!(on.len() > 5000, "spot covers too few pixels");
        assert!(
            warm(&off) > 0,
            "no visible error anywhere on spot's Gregory patches"
        );
        match patch {
            // Reparameterized corners are Gregory corners only (ACC-1's stay the identity).
            SinglePassPatch::Gregory => assert!(
                mean(&on) > mean(&off) + 2.0 && warm(&on) < warm(&off),
                "reparameterization does not lower the drawn error"
            ),
            SinglePassPatch::Acc1 => assert!(
                (mean(&on) - mean(&off)).abs() < 1e-9,
                "ACC-1 patches have no reparameterized corner, yet the view changed"
            ),
        }
    }
}

/// ACC-1's shading normals as the GPU draws them: every captured vertex of an ACC-1 patch
/// carries the tangent patches' normal of the CPU reference (`AdaptivePlan::shading_normal`),
/// and where two ACC-1 patches meet (a vertex captured by both) their normals agree, while the
/// geometry patches' own normals there differ by up to tenths of a radian (CPU, same points).
#[test]
fn acc_tangent_patch_normals_on_the_gpu() {
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).expect("context");
    let capturer = Capturer::new(&ctx).expect("capturer");
    for name in ["spot", "catmark_pawn", "catmark_cube"] {
        let mesh = shape(name);
        let mut surf = planned_patches::single_pass(
            &mut ctx,
            &mesh,
            &planned_patches::SinglePassBuild {
                patch: SinglePassPatch::Acc1,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name,
                maps: &Default::default(),
                path: tessera::tess::DrawPath::Tessellation,
            },
        )
        .expect("build");
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, &FrameParams::uniform(6.0), EXTENT)
            .expect("capture");
        let verts = surf.plan.apply(&mesh.positions);
        let plan_patch = |id: u32| surf.gpu.order[id as usize] as usize;
        let is_acc = |id: u32| surf.plan.patches[plan_patch(id)].tangent_valences != [0; 4];
        let (mut cpu_max, mut seam_max, mut geometric_max, mut seams, mut acc_records) =
            (0.0f64, 0.0f64, 0.0f64, 0usize, 0usize);
        let mut transition_max = 0.0f64;
        let mut by_point = std::collections::HashMap::<[u32; 3], Vec<usize>>::new();
        for (k, r) in soup.records.iter().enumerate() {
            if !is_acc(r.patch) {
                continue;
            }
            acc_records += 1;
            // Boundary vertices carry their curve owner's normal (below); the patch's own
            // tangent-patch normal everywhere else.
            if r.flags & ADAPTIVE_FLAG_CANONICAL == 0 {
                let [u, v] = r.domain.map(f64::from);
                let cpu = surf.plan.shading_normal(&verts, plan_patch(r.patch), u, v);
                cpu_max = cpu_max.max(angle(r.normal.map(f64::from), cpu));
            }
            by_point
                .entry(r.position.map(f32::to_bits))
                .or_default()
                .push(k);
        }
        for ks in by_point.values() {
            let first = &soup.records[ks[0]];
            for &k in &ks[1..] {
                let r = &soup.records[k];
                if r.patch == first.patch {
                    continue;
                }
                // Level transitions (a level-0 patch beside split children) are outside the
                // tangent-patch construction, which pairs two patches along a whole edge; there
                // the owner's normal is both sides' (canonical normals).
                let level = |id: u32| surf.plan.patches[plan_patch(id)].level;
                if level(r.patch) != level(first.patch) {
                    transition_max = transition_max
                        .max(angle(r.normal.map(f64::from), first.normal.map(f64::from)));
                    continue;
                }
                seams += 1;
                seam_max =
                    seam_max.max(angle(r.normal.map(f64::from), first.normal.map(f64::from)));
                let g = |rec: &tessera::tess::CaptureRecord| {
                    let [u, v] = rec.domain.map(f64::from);
                    let s = surf.plan.evaluate(&verts, plan_patch(rec.patch), u, v);
                    topology::limit::eval::normal_of(&s.du, &s.dv)
                };
                geometric_max = geometric_max.max(angle(g(r), g(first)));
            }
        }
        println!(
            "{name}: {acc_records} ACC-1 vertices, GPU vs CPU normal {cpu_max:.1e} rad; {seams} seam pairs: tangent patches {seam_max:.1e} rad, geometry normals {geometric_max:.1e} rad; across level transitions {transition_max:.1e} rad"
        );
        assert!(acc_records > 0 && seams > 0, "{name}: nothing measured");
        assert!(
            cpu_max < 1e-3,
            "{name}: GPU normals off the CPU's by {cpu_max:e} rad"
        );
        assert!(
            seam_max == 0.0 && transition_max == 0.0,
            "{name}: normals jump across ACC-1 edges by {seam_max:e} rad, across transitions by {transition_max:e} rad"
        );
        assert!(geometric_max > 1e-2, "{name}: the check cannot tell");
    }
}

/// Displaced surfaces are shaded with the displaced surface's normal: the captured normals
/// follow the normals of the captured (welded) triangles far better than the undisplaced
/// surface's normals at the same (patch, u, v) do, on Gregory, ACC-1 and adaptive surfaces.
#[test]
fn displaced_surfaces_shade_with_displaced_normals() {
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).expect("context");
    let capturer = Capturer::new(&ctx).expect("capturer");
    let mesh = shape("spot");
    let height = SurfaceMaps {
        height: Some(std::sync::Arc::new(
            tessera::tess::surface::load_height(common::data("assets/spot_height.png"))
                .expect("height map"),
        )),
        ..Default::default()
    };
    let scale = 0.02 * diag(&mesh) as f32;
    // The height map's slopes are finer than 16 segments per patch resolve: the mesh's own
    // normals only approach the shading normals at finer tessellation.
    for (label, maps, segments, bound) in [
        ("procedural", SurfaceMaps::default(), 16.0, 0.5),
        ("height map", height, 32.0, 0.5),
    ] {
        for patch in PATCHES {
            let mut surf = planned_patches::single_pass(
                &mut ctx,
                &mesh,
                &planned_patches::SinglePassBuild {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles: true,
                    name: "spot",
                    maps: &maps,
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
            .expect("build");
            let mut capture = |ctx: &mut Context, displace: f32| {
                capturer
                    .capture(
                        ctx,
                        &mut surf,
                        &FrameParams {
                            displace,
                            ..FrameParams::uniform(segments)
                        },
                        EXTENT,
                    )
                    .expect("capture")
                    .0
            };
            let displaced = capture(&mut ctx, scale);
            let flat = capture(&mut ctx, 0.0);
            assert_eq!(displaced.records.len(), flat.records.len());
            // Area-weighted normals of the displaced mesh, welded by bits.
            let welded = displaced.weld().expect("weld");
            let mut mesh_normals = vec![[0.0f64; 3]; welded.positions.len()];
            for t in &welded.triangles {
                let p = t.map(|i| welded.positions[i as usize].map(f64::from));
                let (e1, e2) = (
                    [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]],
                    [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]],
                );
                let c = [
                    e1[1] * e2[2] - e1[2] * e2[1],
                    e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0],
                ];
                for &i in t {
                    for k in 0..3 {
                        mesh_normals[i as usize][k] += c[k];
                    }
                }
            }
            let index: std::collections::HashMap<[u32; 3], usize> = welded
                .positions
                .iter()
                .enumerate()
                .map(|(i, p)| (p.map(f32::to_bits), i))
                .collect();
            let (mut shaded, mut base, mut n) = (0.0f64, 0.0f64, 0usize);
            for (r, f) in displaced.records.iter().zip(&flat.records) {
                // Skip patch boundaries, where the welded normal mixes patches' triangles.
                if r.domain.iter().any(|&x| x == 0.0 || x == 1.0) {
                    continue;
                }
                let m = mesh_normals[index[&r.position.map(f32::to_bits)]];
                // Line angle: the capture's winding runs against the normals.
                let line = |a: f64| a.min(std::f64::consts::PI - a);
                shaded += line(angle(r.normal.map(f64::from), m));
                base += line(angle(f.normal.map(f64::from), m));
                n += 1;
            }
            let (shaded, base) = (shaded / n as f64, base / n as f64);
            println!(
                "spot {patch:?} {label}, {segments} segments: mean angle to the displaced mesh's normals {shaded:.4} rad (undisplaced normals {base:.4} rad), {n} vertices"
            );
            assert!(
                shaded < bound * base,
                "{patch:?} {label}: displaced shading normals {shaded} vs undisplaced {base}"
            );
        }
    }
}

/// An open, bumpy grid of `n`×`n` quads each cut into two triangles, next to a strip of quads
/// along one side: triangles next to triangles, to quads and to the boundary, valences 2 to 8.
fn triangles_and_quads(n: u32) -> ControlMesh {
    let mut p = Vec::new();
    for y in 0..=n + 1 {
        for x in 0..=n {
            let z = ((x * 7 + y * 3) % 5) as f64 * 0.15;
            p.push([x as f64, y as f64, z]);
        }
    }
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let mut faces = Vec::new();
    for y in 0..n {
        for x in 0..n {
            if (x + y) % 2 == 0 {
                faces.push(vec![id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                faces.push(vec![id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
            } else {
                faces.push(vec![id(x, y), id(x + 1, y), id(x, y + 1)]);
                faces.push(vec![id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)]);
            }
        }
    }
    for x in 0..n {
        faces.push(vec![id(x, n), id(x + 1, n), id(x + 1, n + 1), id(x, n + 1)]);
    }
    ControlMesh::from_polygons(p, &faces)
}

/// Gregory triangle patches (one per triangle) on the GPU: one patch per triangle; captured
/// vertices within a few percent of the exact limit at their base parameter; 0 cracks (weld by
/// bits) under uniform, screen, distance and fractional factors, displaced or not, where
/// triangles meet triangles, quads (transition edges) and the boundary; and with
/// `--split-triangles` three quad patches per triangle instead.
#[test]
fn gregory_triangle_patches_on_the_gpu() {
    let gpu = Gpu::new();
    let mut ctx = Context::offscreen(gpu.device()).expect("context");
    let capturer = Capturer::new(&ctx).expect("capturer");
    for (name, mesh) in [
        ("triangles and quads", triangles_and_quads(4)),
        ("catmark_pyramid", shape("catmark_pyramid")),
    ] {
        let triangles = (0..mesh.num_faces())
            .filter(|&f| mesh.face(f).len() == 3)
            .count() as u32;
        let d = diag(&mesh) as f32;
        for patch in PATCHES {
            let mut surf = planned_patches::single_pass(
                &mut ctx,
                &mesh,
                &planned_patches::SinglePassBuild {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles: true,
                    name,
                    maps: &Default::default(),
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
            .expect("build");
            assert_eq!(surf.patch_counts()[3], triangles, "{name} {patch:?}");
            let split = planned_patches::single_pass(
                &mut ctx,
                &mesh,
                &planned_patches::SinglePassBuild {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles: false,
                    name,
                    maps: &Default::default(),
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
            .expect("build");
            assert_eq!(split.patch_counts()[3], 0, "{name} {patch:?} split");
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &FrameParams::uniform(4.0), EXTENT)
                .expect("capture");
            let (_, max, rms) = deviation(&surf, &soup, &mesh);
            println!(
                "{name} {patch:?}: {triangles} triangle patches, max {max:.2e}, RMS {rms:.2e}"
            );
            assert!(max < 0.05, "{name} {patch:?}: {max:e}");
            for (label, factors, spacing) in [
                (
                    "uniform 5",
                    FactorPolicy::Uniform { segments: 5.0 },
                    Spacing::Equal,
                ),
                (
                    "screen 6px",
                    FactorPolicy::Screen { pixels: 6.0 },
                    Spacing::Equal,
                ),
                (
                    "distance",
                    FactorPolicy::Distance {
                        reference: 0.12 * d,
                    },
                    Spacing::Equal,
                ),
                (
                    "screen fractional",
                    FactorPolicy::Screen { pixels: 6.0 },
                    Spacing::FractionalEven,
                ),
            ] {
                for displace in [0.0, 0.03 * d] {
                    let params = FrameParams {
                        displace,
                        factors,
                        spacing,
                        camera: Camera {
                            zoom: 2.0,
                            yaw: 20.0,
                            ..Default::default()
                        },
                        ..FrameParams::default()
                    };
                    let (soup, _) = capturer
                        .capture(&mut ctx, &mut surf, &params, EXTENT)
                        .expect("capture");
                    let (cracks, nonmanifold) = cracks(&surf, &soup, &mesh);
                    let (shared, differing) = normal_seams(&soup);
                    println!(
                        "{name} {patch:?} {label} displace {displace}: {} triangles, {cracks} cracks, {differing} of {shared} shared vertices with two normals",
                        soup.triangle_count()
                    );
                    assert!(
                        shared > 0 && differing == 0,
                        "{name} {patch:?} {label}: two normals"
                    );
                    assert_eq!(cracks, 0, "{name} {patch:?} {label} displace {displace}");
                    assert_eq!(nonmanifold, 0, "{name} {patch:?} {label}");
                }
            }
        }
    }
}
