//! Feature-adaptive Catmull-Clark on the tessellation stage, checked from the GPU's own output
//! (transform feedback): captured vertices against the CPU exact limit at their (base face,
//! sub-face, u, v), watertightness (weld by bits) under every factor policy, across level
//! transitions and end caps, with an animated base, and bad input. Validation is on and any
//! error fails (tests/common).
mod common;
use common::Gpu;
use rayon::prelude::*;
use tessera::tess::animation::{base_normals, base_positions, wave};
use tessera::tess::capture::{classify_open_edges, CapturedSoup, Capturer};
use tessera::tess::gpu::bindings::{ADAPTIVE_FLAG_LEVEL_SHIFT, ADAPTIVE_KIND_REGULAR};
use tessera::tess::techniques::adaptive;
use tessera::tess::techniques::planned_patches::{PlanBuild, PlannedPatches};
use tessera::tess::{Camera, Context, FactorPolicy, FrameParams, Spacing, Technique};
use tessera::topology::limit::eval::{LimitScheme, LocalMesh};
use tessera::topology::patches::adaptive::EndCap;
use tessera::topology::{self, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 640,
    height: 480,
};

fn shape(name: &str) -> ControlMesh {
    topology::load_obj(common::data(&format!(
        "tests/data/opensubdiv/shapes/{name}.obj"
    )))
    .expect("shape")
}

fn spot() -> ControlMesh {
    topology::load_obj(common::data("assets/spot_control_mesh.obj")).expect("spot")
}

/// Every Catmull-Clark shape of tests/data (hierarchical edits aside) and spot.
fn catmark_shapes() -> Vec<(String, ControlMesh)> {
    // `ADAPTIVE_SHAPES_DIR` points the accuracy test at another folder (OpenSubdiv's whole shape
    // set, say); shapes there that do not load are skipped.
    let (dir, other) = common::shapes_dir("ADAPTIVE_SHAPES_DIR");
    let names = common::shape_names(&dir, "catmark_");
    let mut out: Vec<(String, ControlMesh)> = names
        .into_iter()
        .filter_map(|n| {
            if !other {
                return Some((n.clone(), shape(&n)));
            }
            topology::load_obj(dir.join(format!("{n}.obj")))
                .ok()
                .map(|m| (n, m))
        })
        .collect();
    out.push(("spot".into(), spot()));
    out
}

fn diag(m: &ControlMesh) -> f64 {
    m.bbox_diagonal()
}

fn surface(
    ctx: &mut Context,
    mesh: &ControlMesh,
    name: &str,
    isolation: u32,
    end_cap: EndCap,
) -> PlannedPatches {
    adaptive::new(
        ctx,
        mesh,
        &PlanBuild {
            isolation,
            end_cap,
            name: name.into(),
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Worst distances over the bbox diagonal between captured vertices and the exact limit, over
/// at most `samples` welded vertices of regular patches and every vertex of an end cap (a
/// stride over all vertices missed catmark_bishop's worst caps once a plan change shifted it):
/// (regular patches at their base point, end caps at their base point, end caps to the
/// nearest limit point when `geometric`, else 0).
///
/// The nearest point is searched in the base (sub-)face of every patch that captured the
/// vertex, and the least distance is kept: a search stays inside one (sub-)face, and a vertex
/// on a face's edge may be nearest to the surface across it.
fn deviations_with(
    surf: &PlannedPatches,
    soup: &CapturedSoup,
    mesh: &ControlMesh,
    samples: usize,
    geometric: bool,
) -> (f64, f64, f64) {
    let cpu = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark).expect("cpu mesh");
    let welded = soup.weld().expect("weld");
    let n = welded.positions.len();
    // Every (patch, domain) that captured each welded vertex.
    let mut captured_by: Vec<Vec<(u32, [f32; 2])>> = vec![Vec::new(); n];
    for (t, tri) in welded.triangles.iter().enumerate() {
        for (k, &w) in tri.iter().enumerate() {
            let r = &soup.records[3 * t + k];
            let by = &mut captured_by[w as usize];
            if !by.contains(&(r.patch, r.domain)) {
                by.push((r.patch, r.domain));
            }
        }
    }
    let stride = n.div_ceil(samples).max(1);
    let d = diag(mesh);
    // Base parameters first (the surface stays on this thread), then the exact limit and the
    // nearest-point searches in parallel.
    type At = (usize, usize, f64, f64, bool);
    let at = |patch: u32, [u, v]: [f32; 2]| -> At {
        let (f, sub, bu, bv) = surf
            .base_param(patch, f64::from(u), f64::from(v))
            .expect("patch");
        (
            f as usize,
            sub as usize,
            bu,
            bv,
            mesh.face(f as usize).len() == 4,
        )
    };
    let work: Vec<(bool, [f64; 3], At, Vec<At>)> = captured_by
        .iter()
        .enumerate()
        .filter_map(|(i, by)| {
            let cap = welded.flags[i] & 15 != ADAPTIVE_KIND_REGULAR;
            (cap || i % stride == 0).then(|| {
                let all = if cap && geometric {
                    by.iter().map(|&(patch, uv)| at(patch, uv)).collect()
                } else {
                    Vec::new()
                };
                (
                    cap,
                    welded.positions[i].map(f64::from),
                    at(welded.patch[i], welded.domain[i]),
                    all,
                )
            })
        })
        .collect();
    let measured: Vec<(bool, f64, f64)> = work
        .par_iter()
        .map(|(cap, p, (f, sub, bu, bv, quad), all)| {
            let e = if *quad {
                cpu.evaluate(*f, *bu, *bv)
            } else {
                cpu.evaluate_subface(*f, *sub, *bu, *bv)
            }
            .expect("exact limit");
            let err = (0..3)
                .map(|k| (p[k] - e.position[k]).abs())
                .fold(0.0, f64::max)
                / d;
            let g = if *cap && geometric && err * d > 1e-7 {
                all.iter()
                    .map(|&(f, sub, bu, bv, quad)| {
                        // An end cap's parameterization differs from the limit's near
                        // extraordinary vertices, so the nearest limit point is what says how
                        // close its surface is.
                        cpu.nearest_limit_distance(f, (!quad).then_some(sub), [bu, bv], p)
                            .expect("exact limit")
                    })
                    .fold(f64::MAX, f64::min)
                    / d
            } else {
                0.0
            };
            (*cap, err, g)
        })
        .collect();
    let (mut regular, mut caps, mut caps_geometric) = (0.0f64, 0.0f64, 0.0f64);
    for (cap, err, g) in measured {
        if cap {
            caps = caps.max(err);
            caps_geometric = caps_geometric.max(g);
        } else {
            regular = regular.max(err);
        }
    }
    (regular, caps, caps_geometric)
}

/// [`deviations_with`], the distance to the surface included.
fn deviations(
    surf: &PlannedPatches,
    soup: &CapturedSoup,
    mesh: &ControlMesh,
    samples: usize,
) -> (f64, f64, f64) {
    deviations_with(surf, soup, mesh, samples, true)
}

/// [`deviations_with`] at the base points only: (regular patches, end caps).
fn deviation(
    surf: &PlannedPatches,
    soup: &CapturedSoup,
    mesh: &ControlMesh,
    samples: usize,
) -> (f64, f64) {
    let (regular, caps, _) = deviations_with(surf, soup, mesh, samples, false);
    (regular, caps)
}

fn cracks(surf: &PlannedPatches, soup: &CapturedSoup, mesh: &ControlMesh) -> (usize, usize, usize) {
    let welded = soup.weld().expect("weld");
    let report = welded.open_edges();
    let map = |p: u32, d: [f32; 2]| surf.face_point(p, d);
    let c = classify_open_edges(soup, &welded, &report, &map, mesh);
    (
        c.cracks + c.unmapped,
        c.on_base_boundary,
        report.non_manifold.len(),
    )
}

/// Regular patches are the exact limit (≤ 1e-5 of the diagonal, f32 on the GPU); the whole
/// surface with Gregory end caps at isolation 4 is within 5e-5.
#[test]
#[ignore = "sweep tier (every Catmull-Clark shape): tools/test.sh sweeps"]
fn captured_vertices_are_the_exact_limit() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mut failures = Vec::new();
        let other_shapes = common::shapes_dir("ADAPTIVE_SHAPES_DIR").1;
        for (name, mesh) in catmark_shapes() {
            let mut surf = surface(&mut ctx, &mesh, &name, 4, EndCap::Gregory);
            let soup =
                match capturer.capture(&mut ctx, &mut surf, &FrameParams::uniform(3.0), EXTENT) {
                    Ok((soup, _)) => soup,
                    // Another folder's shapes may be too large to capture whole.
                    Err(e) if other_shapes => {
                        println!("{name}: skipped: {e}");
                        continue;
                    }
                    Err(e) => panic!("{name}: capture: {e}"),
                };
            let (regular, caps, geometric) = deviations(&surf, &soup, &mesh, 3000);
            let [r, g, b, _] = surf.patch_counts();
            println!("{name}: {r} regular, {g} Gregory, {b} bilinear: regular {regular:.2e}, end caps {caps:.2e} (parametric), {geometric:.2e} (to the surface)");
            // Every shape within 5e-5: vertices whose caps converge slowly (cones, darts,
            // valence 6 and up) are isolated deeper by the plan. Before that, capped after four
            // levels: catmark_cube_corner4 1.8e-3, catmark_cubes_infsharp 1.1e-3,
            // catmark_bishop 2.0e-4, spot 6.5e-5.
            let bound = 5e-5;
            if regular > 1e-5 || geometric > bound {
                failures.push(format!(
                    "{name}: regular {regular:.2e}, end caps {caps:.2e} / {geometric:.2e}"
                ));
            }
        }
        assert!(failures.is_empty(), "off the exact limit: {failures:#?}");
    }
}

/// The end caps' deviation from the exact limit shrinks as the isolation level rises.
#[test]
#[ignore = "sweep tier (every isolation level): tools/test.sh sweeps"]
fn end_cap_deviation_shrinks_with_isolation() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        for (name, mesh) in [
            ("spot".to_string(), spot()),
            ("catmark_cube".into(), shape("catmark_cube")),
        ] {
            for end_cap in [EndCap::Gregory, EndCap::Bilinear] {
                let mut devs = Vec::new();
                for isolation in 1..=6 {
                    let mut surf = surface(&mut ctx, &mesh, &name, isolation, end_cap);
                    let (soup, _) = capturer
                        .capture(&mut ctx, &mut surf, &FrameParams::uniform(2.0), EXTENT)
                        .expect("capture");
                    let (regular, caps) = deviation(&surf, &soup, &mesh, 4000);
                    assert!(
                        regular <= 1e-5,
                        "{name} isolation {isolation}: regular {regular:.2e}"
                    );
                    devs.push(caps);
                }
                println!(
                    "{name} {end_cap:?} end-cap deviation, isolation 1..6: {:?}",
                    devs.iter().map(|d| format!("{d:.2e}")).collect::<Vec<_>>()
                );
                assert!(
                    devs[5] < 0.25 * devs[0],
                    "{name} {end_cap:?}: {devs:?} does not shrink"
                );
                for w in devs.windows(2) {
                    assert!(w[1] <= w[0] * 1.05, "{name} {end_cap:?}: {devs:?} grows");
                }
            }
        }
    }
}

/// 0 cracks beyond the base boundary under uniform, screen, distance and fractional factors,
/// across transitions, with Gregory and bilinear end caps (positions welded only when
/// bit-identical).
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
            "catmark_cube",
            "catmark_pyramid",
            "catmark_tent_creases1",
            "catmark_edgecorner",
            "catmark_chaikin1",
            "catmark_flap",
            // Faces tagged as holes: their borders are boundaries, not cracks.
            "catmark_hole_test2",
            "spot",
        ] {
            let mesh = if name == "spot" { spot() } else { shape(name) };
            let caps: &[EndCap] = if matches!(name, "catmark_cube" | "spot") {
                &[EndCap::Gregory, EndCap::Bilinear]
            } else {
                &[EndCap::Gregory]
            };
            for &end_cap in caps {
                let mut surf = surface(&mut ctx, &mesh, name, 3, end_cap);
                let policies = [
                    ("uniform 3", FactorPolicy::Uniform { segments: 3.0 }, false),
                    ("screen 6px", FactorPolicy::Screen { pixels: 6.0 }, false),
                    (
                        "distance",
                        FactorPolicy::Distance {
                            reference: 0.12 * diag(&mesh) as f32,
                        },
                        false,
                    ),
                    (
                        "screen 6px fractional",
                        FactorPolicy::Screen { pixels: 6.0 },
                        true,
                    ),
                    (
                        "distance fractional",
                        FactorPolicy::Distance {
                            reference: 0.1 * diag(&mesh) as f32,
                        },
                        true,
                    ),
                ];
                for (label, factors, fractional) in policies {
                    let params = FrameParams {
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
                        .capture(&mut ctx, &mut surf, &params, EXTENT)
                        .expect("capture");
                    let (cracks, boundary, nonmanifold) = cracks(&surf, &soup, &mesh);
                    println!(
                        "{name} {end_cap:?} {label}: {} triangles, {cracks} cracks, {boundary} boundary edges",
                        soup.triangle_count()
                    );
                    assert_eq!(
                        cracks, 0,
                        "{name} {end_cap:?} {label}: open edges beyond the base boundary"
                    );
                    assert_eq!(nonmanifold, 0, "{name} {end_cap:?} {label}");
                }
            }
        }
    }
}

/// After uploading the `--animate` wave (base positions only), the captured surface is the
/// exact limit of the deformed base mesh, still watertight.
#[test]
fn animated_base_mesh_gives_the_deformed_limit() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mesh = spot();
        let mut surf = surface(&mut ctx, &mesh, "spot", 3, EndCap::Gregory);
        let rest = base_positions(&mesh);
        let (lo, hi) = surf.bbox();
        let posed = wave(&rest, &base_normals(&mesh), lo, hi, 0.37);
        surf.update_base(0, &posed).expect("upload");
        let mut deformed = mesh.clone();
        deformed.positions = posed.iter().map(|p| p.map(f64::from)).collect();
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, &FrameParams::uniform(4.0), EXTENT)
            .expect("capture");
        let (regular, caps, geometric) = deviations(&surf, &soup, &deformed, 3000);
        let (rest_regular, _) = deviation(&surf, &soup, &mesh, 3000);
        println!("animated spot: regular {regular:.2e}, end caps {caps:.2e} (parametric), {geometric:.2e} (to the surface); vs rest pose {rest_regular:.2e}");
        assert!(
            regular <= 1e-5 && geometric <= 2e-4,
            "{regular:.2e} {geometric:.2e}"
        );
        assert!(rest_regular > 1e-3, "the surface did not move");
        assert_eq!(cracks(&surf, &soup, &deformed).0, 0);
    }
}

/// Patch kinds and levels come back in the capture flags: isolation raises the deepest level.
#[test]
fn isolation_level_shows_in_the_captured_levels() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mesh = spot();
        for isolation in [1, 2, 5] {
            let mut surf = surface(&mut ctx, &mesh, "spot", isolation, EndCap::Gregory);
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &FrameParams::uniform(1.0), EXTENT)
                .expect("capture");
            let deepest = soup
                .records
                .iter()
                .map(|r| (r.flags >> ADAPTIVE_FLAG_LEVEL_SHIFT) & 15)
                .max()
                .unwrap();
            // Spot's deepest patches surround its valence-6 vertices, whose caps are isolated
            // until their region shrinks as a regular patch's does: ⌈iso · ln 2 / −ln λ_6⌉
            // levels, λ_6 the subdominant eigenvalue (0.58).
            let c = (std::f64::consts::PI / 3.0).cos();
            let lambda6 = (c + 5.0 + ((c + 9.0) * (c + 1.0)).sqrt()) / 16.0;
            let expected = (isolation as f64 * std::f64::consts::LN_2 / -lambda6.ln()).ceil();
            assert_eq!(deepest, expected as u32, "isolation {isolation}");
        }
    }
}

/// Bad options and meshes give named errors, never a panic.
#[test]
fn bad_input_gives_named_errors() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let mesh = shape("catmark_cube");
        for isolation in [0, 9] {
            let e = adaptive::new(
                &mut ctx,
                &mesh,
                &PlanBuild {
                    isolation,
                    name: "cube".into(),
                    ..Default::default()
                },
            )
            .err()
            .expect("refused");
            assert!(e.to_string().contains("isolation"), "{e}");
        }
        for scale in [f32::NAN, -1.0] {
            let e = adaptive::new(
                &mut ctx,
                &mesh,
                &PlanBuild {
                    sharpness_scale: scale,
                    name: "cube".into(),
                    ..Default::default()
                },
            )
            .err()
            .expect("refused");
            assert!(e.to_string().contains("sharpness"), "{e}");
        }
        let mut creased = shape("catmark_cube_creases1");
        creased.creases[0].sharpness = f32::NAN;
        let e = adaptive::new(&mut ctx, &creased, &PlanBuild::default())
            .err()
            .expect("NaN sharpness refused");
        assert!(e.to_string().contains("sharpness"), "{e}");
        // Three quads on one edge: non-manifold.
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
        assert!(adaptive::new(&mut ctx, &fan, &PlanBuild::default()).is_err());
        let ok = surface(&mut ctx, &mesh, "cube", 2, EndCap::Gregory);
        for bad in [
            FrameParams::uniform(0.0),
            FrameParams::uniform(2.5),
            FrameParams::uniform(40.0),
            FrameParams {
                spacing: Spacing::FractionalOdd,
                ..FrameParams::uniform(4.0)
            },
        ] {
            assert!(ok.check(&bad).is_err(), "{bad:?}");
        }
    }
}

/// The GPU (stencil kernel, TES) draws what the CPU plan evaluates (f64), on every patch kind:
/// the oracle chain is GPU → plan → exact limit.
#[test]
fn gpu_matches_the_cpu_plan() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        for (name, end_cap) in [
            ("catmark_chaikin0", EndCap::Gregory),
            ("catmark_pyramid", EndCap::Bilinear),
        ] {
            let mesh = shape(name);
            let mut surf = surface(&mut ctx, &mesh, name, 3, end_cap);
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &FrameParams::uniform(3.0), EXTENT)
                .expect("capture");
            let welded = soup.weld().unwrap();
            let verts = surf.plan.apply(&mesh.positions);
            let mut worst = 0.0f64;
            for i in 0..welded.positions.len() {
                let [u, v] = welded.domain[i].map(f64::from);
                let pi = surf.gpu.order[welded.patch[i] as usize] as usize;
                let s = surf.plan.evaluate(&verts, pi, u, v);
                let e = (0..3)
                    .map(|k| (welded.positions[i][k] as f64 - s.position[k]).abs())
                    .fold(0.0, f64::max);
                worst = worst.max(e / diag(&mesh));
            }
            println!("{name} {end_cap:?}: GPU vs CPU plan {worst:.2e}");
            assert!(worst <= 1e-5, "{name}: GPU off the CPU plan by {worst:.2e}");
        }
    }
}

/// Under uniform factors the CPU knows the triangle count exactly (coarse transition edges
/// doubled): it equals what the GPU emitted, equal and fractional spacing.
#[test]
fn uniform_triangle_count_matches_the_capture() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mesh = spot();
        let mut surf = surface(&mut ctx, &mesh, "spot", 3, EndCap::Gregory);
        for (s, spacing) in [
            (1.0, Spacing::Equal),
            (3.0, Spacing::Equal),
            (3.0, Spacing::FractionalEven),
        ] {
            let params = FrameParams {
                spacing,
                ..FrameParams::uniform(s)
            };
            let expected: u64 = (0..surf.patch_arrays().len())
                .map(|a| surf.triangles(&params, a).expect("uniform count"))
                .sum();
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &params, EXTENT)
                .expect("capture");
            assert_eq!(
                soup.triangle_count() as u64,
                expected,
                "S = {s} {spacing:?}"
            );
        }
    }
}

/// `--sharpness-scale`: 0 draws the smooth surface (the exact limit of the mesh without its
/// creases), 1 the creased one; the plan is rebuilt, the mesh not reloaded.
#[test]
fn sharpness_scale_reshapes_the_surface() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mesh = shape("catmark_cube_creases0");
        let mut smooth = mesh.clone();
        smooth.creases.clear();
        smooth.corners.clear();
        let mut results = Vec::new();
        for scale in [0.0f32, 1.0] {
            let mut surf = adaptive::new(
                &mut ctx,
                &mesh,
                &PlanBuild {
                    isolation: 3,
                    sharpness_scale: scale,
                    name: "creases0".into(),
                    ..Default::default()
                },
            )
            .expect("surface");
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &FrameParams::uniform(2.0), EXTENT)
                .expect("capture");
            let (vs_smooth, _) = deviation(&surf, &soup, &smooth, 2000);
            let (vs_creased, _) = deviation(&surf, &soup, &mesh, 2000);
            println!(
                "scale {scale}: regular vs smooth {vs_smooth:.2e}, vs creased {vs_creased:.2e}"
            );
            results.push((vs_smooth, vs_creased));
        }
        assert!(
            results[0].0 <= 1e-5 && results[0].1 > 1e-3,
            "scale 0: {:?}",
            results[0]
        );
        assert!(
            results[1].1 <= 1e-5 && results[1].0 > 1e-3,
            "scale 1: {:?}",
            results[1]
        );
    }
}
