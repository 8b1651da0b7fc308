//! Loop BFT on the tessellation stage, checked from the GPU's own output (transform feedback):
//! every captured vertex against the CPU exact limit, watertightness under every factor policy,
//! and animation. Validation is on and any error fails (tests/common).
mod common;
use common::Gpu;
use tessera::tess::animation::{base_normals, base_positions, wave};
use tessera::tess::capture::{classify_open_edges, CapturedSoup, Capturer};
use tessera::tess::techniques::bft::layout::GpuBft;
use tessera::tess::techniques::bft::{patch_uv, Bft, BftOptions};
use tessera::tess::{Context, FactorPolicy, FrameParams, Spacing, Technique};
use tessera::topology::limit::eval::{LimitScheme, LocalMesh};
use tessera::topology::patches::bft::prepare_loop_bft;
use tessera::topology::{self, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 640,
    height: 480,
};

/// A BFT surface of `mesh` at table level `level`, with tangent tables when `tangents`.
fn surface(ctx: &mut Context, mesh: &ControlMesh, name: &str, level: u32, tangents: bool) -> Bft {
    surface_built(ctx, mesh, name, level, tangents, None)
}

/// [`surface`] in the patch-block build `patch_block` (`None`: the device's).
fn surface_built(
    ctx: &mut Context,
    mesh: &ControlMesh,
    name: &str,
    level: u32,
    tangents: bool,
    patch_block: Option<bool>,
) -> Bft {
    Bft::new(
        ctx,
        mesh,
        &BftOptions {
            table_level: level,
            tangents,
            name: name.into(),
            patch_block,
            ..BftOptions::default()
        },
    )
    .expect(name)
}

/// Both builds of the BFT control and evaluation stages: with the patch block (lavapipe's
/// default) and without (a GPU's), so each is tested on any device.
const PATCH_BLOCK_BUILDS: [bool; 2] = [true, false];

/// Uniform factors of `s` segments per base edge.
fn uniform(s: u32) -> FrameParams {
    FrameParams::uniform(s as f32)
}

pub fn spot() -> ControlMesh {
    let m = topology::load_obj(common::data("assets/spot_control_mesh.obj")).expect("spot");
    m.triangulated().0
}

fn shape(name: &str) -> ControlMesh {
    topology::load_obj(common::data(&format!(
        "tests/data/opensubdiv/shapes/{name}.obj"
    )))
    .expect("shape")
}

fn diag(m: &ControlMesh) -> f64 {
    m.bbox_diagonal()
}

/// Worst distance (over the bounding-box diagonal) between captured vertices and the CPU exact
/// limit of `mesh` at the captured (base face, u, v), over at most `samples` welded vertices;
/// also asserts every captured vertex came from a table point when `all_exact`.
fn exactness(surf: &Bft, soup: &CapturedSoup, mesh: &ControlMesh, samples: usize) -> f64 {
    let cpu = LocalMesh::from_control_mesh(mesh, LimitScheme::Loop).expect("cpu mesh");
    let welded = soup.weld().expect("weld");
    let n = welded.positions.len();
    let stride = n.div_ceil(samples).max(1);
    let d = diag(mesh);
    let mut worst = 0.0f64;
    for i in (0..n).step_by(stride) {
        let (u, v) = patch_uv(welded.domain[i]);
        let (f, bu, bv) = surf
            .base_domain(welded.patch[i], u, v)
            .expect("captured patch");
        let e = cpu.evaluate(f, bu, bv).expect("exact limit");
        for k in 0..3 {
            worst = worst.max((welded.positions[i][k] as f64 - e.position[k]).abs() / d);
        }
    }
    worst
}

fn cracks(surf: &Bft, soup: &CapturedSoup, mesh: &ControlMesh) -> (usize, usize, usize) {
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

/// Every captured vertex equals the exact limit within 1e-5 of the diagonal, for S = 2…64, on
/// OpenSubdiv's Loop shapes (valences 3 to 64, boundaries, coarse meshes with overlapping
/// rings, darts) and the triangulated spot; all come from table points (flag bit 0).
#[test]
#[ignore = "sweep tier (every level S = 2..64): tools/test.sh sweeps"]
fn captured_bft_vertices_are_the_exact_limit() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let cases: Vec<(&str, ControlMesh, &[u32])> = vec![
            ("loop_cube", shape("loop_cube"), &[2, 4, 8, 16, 32, 64]),
            ("loop_icosahedron", shape("loop_icosahedron"), &[2, 8, 64]),
            ("loop_pole64", shape("loop_pole64"), &[2, 16, 64]),
            ("loop_xord_boundary", shape("loop_xord_boundary"), &[4, 32]),
            ("loop_tetrahedron", shape("loop_tetrahedron"), &[2, 64]),
            // Darts: infinitely sharp edges ending inside (their exact limit position).
            (
                "loop_cubes_infsharp",
                shape("loop_cubes_infsharp"),
                &[8, 32],
            ),
            (
                "loop_saddle_edgeonly",
                shape("loop_saddle_edgeonly"),
                &[8, 64],
            ),
            ("spot", spot(), &[2, 16, 64]),
        ];
        for ((name, mesh, segments), block) in cases
            .iter()
            .flat_map(|c| PATCH_BLOCK_BUILDS.map(|b| (c, b)))
        {
            let name = &format!("{name} (patch block {block})");
            let mut surf = surface_built(&mut ctx, mesh, name, 5, false, Some(block));
            for &s in segments.iter() {
                let (soup, _) = capturer
                    .capture(&mut ctx, &mut surf, &uniform(s), EXTENT)
                    .expect("capture");
                assert!(!soup.records.is_empty());
                let inexact = soup.records.iter().filter(|r| r.flags & 1 == 0).count();
                assert_eq!(
                    inexact, 0,
                    "{name} S={s}: {inexact} vertices not from table points"
                );
                let worst = exactness(&surf, &soup, mesh, 3000);
                println!(
                    "{name} S={s}: {} triangles, worst |GPU − limit|/diag = {worst:.2e}",
                    soup.triangle_count()
                );
                assert!(worst <= 1e-5, "{name} S={s}: {worst:.3e}");
            }
        }
    }
}

/// Every Loop shape of tests/data, or of the folder `BFT_SHAPES_DIR` names (OpenSubdiv's whole
/// shape set, say), with nothing chosen for BFT: the captured vertices are the exact limit
/// within 1e-5 of the diagonal and weld without cracks at 8 and 32 segments, in the device's
/// build. A shape BFT does not take (non-manifold) must be refused with a named error, and the
/// refusals are listed.
#[test]
#[ignore = "sweep tier (every Loop shape): tools/test.sh sweeps"]
fn every_loop_shape_is_exact_and_watertight() {
    let (dir, other) = common::shapes_dir("BFT_SHAPES_DIR");
    let names = common::shape_names(&dir, "loop_");
    assert!(names.len() >= 10, "{} Loop shapes in {dir:?}", names.len());
    let gpu = Gpu::new();
    let mut failures = Vec::new();
    let mut refused = Vec::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        for name in &names {
            let path = dir.join(format!("{name}.obj"));
            let mesh = match topology::load_obj(&path) {
                Ok(m) => m,
                Err(e) => {
                    refused.push(format!("{name}: {e}"));
                    continue;
                }
            };
            let mut surf = match Bft::new(
                &mut ctx,
                &mesh,
                &BftOptions {
                    table_level: 5,
                    tangents: false,
                    name: name.clone(),
                    patch_block: None,
                    ..BftOptions::default()
                },
            ) {
                Ok(s) => s,
                Err(e) => {
                    refused.push(format!("{name}: {e}"));
                    continue;
                }
            };
            for s in [8, 32] {
                let (soup, _) = capturer
                    .capture(&mut ctx, &mut surf, &uniform(s), EXTENT)
                    .expect("capture");
                let worst = exactness(&surf, &soup, &mesh, 3000);
                let (open, boundary, nonmanifold) = cracks(&surf, &soup, &mesh);
                let inexact = soup.records.iter().filter(|r| r.flags & 1 == 0).count();
                // `exactness` takes a maximum, which a NaN would not enter.
                let finite = soup
                    .records
                    .iter()
                    .all(|r| r.position.iter().chain(&r.normal).all(|x| x.is_finite()));
                println!(
                    "{name} S={s}: {} patches, worst |GPU − limit|/diag {worst:.2e}, {open} cracks, \
                     {boundary} base-boundary edges",
                    surf.patch_count()
                );
                if worst > 1e-5 || open != 0 || nonmanifold != 0 || inexact != 0 || !finite {
                    failures.push(format!(
                        "{name} S={s}: {worst:.2e}, {open} cracks, {nonmanifold} non-manifold, \
                         {inexact} inexact, finite {finite}"
                    ));
                }
            }
        }
    }
    common::whole_set_verdict(&refused, other, &failures);
}

/// A face tagged as a hole is not drawn, and the rest of the surface is unchanged: the exact
/// limit of the whole mesh (the hole still shapes its neighbours), no vertex in the hole, its
/// border open as a boundary and no crack.
#[test]
fn hole_faces_are_not_drawn() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mut mesh = shape("loop_icosahedron");
        mesh.holes = vec![0, 7];
        let s = 8;
        for block in PATCH_BLOCK_BUILDS {
            let mut surf =
                surface_built(&mut ctx, &mesh, "holed icosahedron", 5, false, Some(block));
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &uniform(s), EXTENT)
                .expect("capture");
            // 18 of the 20 faces: 4 level-1 patches each at level s / 2 = 4, which the triangle
            // tessellator splits into 3 · 4² / 2 = 24 triangles.
            assert_eq!(soup.triangle_count(), 18 * 4 * 24);
            for r in &soup.records {
                let (u, v) = patch_uv(r.domain);
                let (f, _, _) = surf.base_domain(r.patch, u, v).expect("patch");
                assert!(f != 0 && f != 7, "a vertex of hole face {f}");
            }
            let worst = exactness(&surf, &soup, &mesh, 3000);
            let (open, boundary, nonmanifold) = cracks(&surf, &soup, &mesh);
            assert!(worst <= 1e-5, "{worst:e}");
            assert_eq!((open, nonmanifold), (0, 0));
            // Two holes, three edges each, s segments an edge.
            assert_eq!(boundary, 2 * 3 * s as usize, "patch block {block}");
        }
    }
}

/// No open edge beyond the base mesh's own boundary, for uniform, both adaptive policies and
/// fractional factors, on every test mesh (positions welded only when bit-identical).
#[test]
#[ignore = "sweep tier (every factor policy): tools/test.sh sweeps"]
fn bft_is_watertight_under_every_factor_policy() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let meshes = [
            ("loop_cube", shape("loop_cube")),
            ("loop_pole64", shape("loop_pole64")),
            ("loop_xord_boundary", shape("loop_xord_boundary")),
            ("loop_saddle_edgeonly", shape("loop_saddle_edgeonly")),
            ("spot", spot()),
        ];
        let camera = tessera::tess::Camera {
            zoom: 2.5,
            yaw: 30.0,
            ..Default::default()
        };
        for ((name, mesh), block) in meshes
            .iter()
            .flat_map(|m| PATCH_BLOCK_BUILDS.map(|b| (m, b)))
        {
            let name = &format!("{name} (patch block {block})");
            let mut surf = surface_built(&mut ctx, mesh, name, 5, false, Some(block));
            let policies = [
                (
                    "uniform 16",
                    FactorPolicy::Uniform { segments: 16.0 },
                    false,
                ),
                ("screen 6px", FactorPolicy::Screen { pixels: 6.0 }, false),
                (
                    "distance",
                    FactorPolicy::Distance {
                        reference: 0.6 * diag(mesh) as f32,
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
                        reference: 0.45 * diag(mesh) as f32,
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
                let (cracks, boundary, nonmanifold) = cracks(&surf, &soup, mesh);
                let interpolated = soup.records.iter().filter(|r| r.flags & 1 == 0).count();
                println!(
                    "{name} {label}: {} triangles, {cracks} cracks, {boundary} boundary edges, \
                     {interpolated} interpolated corners",
                    soup.triangle_count()
                );
                assert_eq!(
                    cracks, 0,
                    "{name} {label}: open edges beyond the base boundary"
                );
                assert_eq!(nonmanifold, 0, "{name} {label}");
                if !fractional {
                    assert_eq!(
                        interpolated, 0,
                        "{name} {label}: power-of-two factors are exact"
                    );
                }
            }
        }
    }
}

/// After T animated frames (base positions uploaded per frame, nothing else), the captured
/// vertices are the exact limit of the deformed base mesh.
#[test]
fn animated_base_mesh_gives_the_deformed_limit() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mesh = shape("loop_icosahedron");
        let mut surf = surface(&mut ctx, &mesh, "ico", 5, false);
        let base = base_positions(&mesh);
        let normals = base_normals(&mesh);
        let (lo, hi) = surf.bbox();
        let params = uniform(16);
        let mut deformed = base.clone();
        for frame in 0..5 {
            deformed = wave(&base, &normals, lo, hi, frame as f32 * 0.1);
            surf.update_base(0, &deformed).expect("upload");
            ctx.render_offscreen(&mut surf, &params, EXTENT)
                .expect("frame");
        }
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, &params, EXTENT)
            .expect("capture");
        let mut moved = mesh.clone();
        moved.positions = deformed
            .iter()
            .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
            .collect();
        let worst = exactness(&surf, &soup, &moved, 2000);
        let against_rest = exactness(&surf, &soup, &mesh, 2000);
        println!(
            "animated: {worst:.2e} to the deformed limit, {against_rest:.2e} to the rest pose"
        );
        assert!(worst <= 1e-5, "{worst}");
        assert!(
            against_rest > 1e-3,
            "the deformation must be visible in the capture"
        );
    }
}

#[test]
fn bft_renders_spot_with_patch_colours_and_wireframe() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let mesh = spot();
        let mut surf = surface(&mut ctx, &mesh, "spot", 5, false);
        let params = FrameParams {
            wireframe: true,
            patch_colours: true,
            ..uniform(4)
        };
        let frame = ctx
            .render_offscreen_stats(&mut surf, &params, EXTENT, false)
            .expect("render");
        let (img, counts) = (frame.image, frame.counts);
        assert_eq!(
            counts.patches,
            2 * surf.patch_count(),
            "the shaded pass and the wireframe overlay each draw every patch"
        );
        // The surface covers a good part of the frame, in both the regular (blue) and the
        // extraordinary (red) patch colours.
        let px = || img.pixels.chunks_exact(4);
        let lit = px().filter(|p| p[0] > 60 || p[1] > 60 || p[2] > 60).count();
        let red = px().filter(|p| p[0] as i32 > p[2] as i32 + 40).count();
        let blue = px().filter(|p| p[2] as i32 > p[0] as i32 + 20).count();
        assert!(lit > 10_000, "{lit} lit pixels");
        assert!(
            red > 500 && blue > 500,
            "patch colours: {red} red, {blue} blue"
        );
    }
}

#[test]
fn bad_segments_are_rejected_with_a_clear_error() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let mesh = shape("loop_cube");
        let mut surf = surface(&mut ctx, &mesh, "cube", 3, false);
        for s in [3, 0, 32] {
            let e = ctx
                .render_offscreen(&mut surf, &uniform(s), EXTENT)
                .map(|_| ())
                .expect_err("rejected");
            assert!(
                e.to_string().contains("segments ") && !e.to_string().contains("--"),
                "{e}"
            );
        }
    }
}

/// Asking for statistics never reaches the lavapipe crash: the workaround skips the query.
#[test]
fn statistics_request_is_safe_on_every_driver() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let mesh = shape("loop_cube");
        let mut surf = surface(&mut ctx, &mesh, "cube", 3, false);
        let frame = ctx
            .render_offscreen_stats(&mut surf, &uniform(16), EXTENT, true)
            .expect("render");
        let (stats, counts) = (frame.statistics, frame.counts);
        assert_eq!(counts.patches, surf.patch_count());
        let skipped = gpu
            .device()
            .workarounds
            .has(tessera::vk_core::workarounds::WorkaroundId::LavapipeStatisticsQueryPointPatches);
        assert_eq!(stats.is_none(), skipped);
    }
}

/// Angles (degrees) between captured normals and the exact limit normal du × dv over at most
/// `samples` welded vertices plus every level-1 vertex (patch corner): (worst at the corners,
/// worst, mean). Orientation-free: the winding convention is not at stake here.
fn normal_angles(
    surf: &Bft,
    soup: &CapturedSoup,
    mesh: &ControlMesh,
    samples: usize,
) -> (f64, f64, f64) {
    let cpu = LocalMesh::from_control_mesh(mesh, LimitScheme::Loop).expect("cpu mesh");
    let welded = soup.weld().expect("weld");
    let n = welded.positions.len();
    let stride = n.div_ceil(samples).max(1);
    let (mut corners, mut worst, mut sum, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    let corner = |d: [f32; 2]| (d[0] == 0.0 || d[0] == 1.0) && (d[1] == 0.0 || d[1] == 1.0);
    for i in (0..n).filter(|&i| i % stride == 0 || corner(welded.domain[i])) {
        let (u, v) = patch_uv(welded.domain[i]);
        let (f, bu, bv) = surf
            .base_domain(welded.patch[i], u, v)
            .expect("captured patch");
        let e = cpu.evaluate(f, bu, bv).expect("exact limit");
        let (a, b) = (&e.du, &e.dv);
        let exact = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let g = welded.normals[i].map(f64::from);
        let dot: f64 = (0..3).map(|k| exact[k] * g[k]).sum();
        let len = |x: [f64; 3]| x.iter().map(|c| c * c).sum::<f64>().sqrt();
        let cos = (dot.abs() / (len(exact) * len(g))).min(1.0);
        let a = cos.acos().to_degrees();
        if corner(welded.domain[i]) {
            corners = corners.max(a);
        }
        worst = worst.max(a);
        sum += a;
        count += 1;
    }
    (corners, worst, sum / count.max(1) as f64)
}

/// Geometric normals from the tangent tables are the exact limit normals; subdivision shading
/// approximates them (the paper's point: close, and cheaper to store). A surface built without
/// tangent tables refuses geometric normals instead of reading past its tables.
#[test]
fn geometric_normals_are_the_exact_limit_normals() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mesh = spot();
        let mut surf = surface(&mut ctx, &mesh, "spot", 5, true);
        let mut angles = Vec::new();
        for geometric_normals in [true, false] {
            let params = FrameParams {
                geometric_normals,
                ..uniform(8)
            };
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &params, EXTENT)
                .expect("capture");
            angles.push(normal_angles(&surf, &soup, &mesh, 3000));
        }
        let ((_, geo_worst, geo_mean), (sub_corners, sub_worst, sub_mean)) = (angles[0], angles[1]);
        println!(
            "spot S=8: angle to the exact normal: geometric worst {geo_worst:.4}° mean \
             {geo_mean:.5}°; subdivision shading at level-1 vertices {sub_corners:.2}°, worst \
             {sub_worst:.2}°, mean {sub_mean:.3}°"
        );
        assert!(geo_worst < 0.01, "geometric normals: {geo_worst:.4}°");
        // Subdivision shading treats the level-1 limit normals as control values: its normal
        // field is their limit (then normalised), an approximation of the true normal even at
        // level-1 vertices. It must be the shader's arithmetic, the f32 mirror's, exactly.
        assert!(
            sub_mean > geo_mean && sub_mean < 10.0,
            "subdivision shading: mean {sub_mean:.3}°"
        );
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, &uniform(8), EXTENT)
            .expect("capture");
        let base = base_positions(&mesh);
        // The CPU mirror, packed from its own preparation (the surface keeps its arrays only on
        // the GPU).
        let loop_mesh = surf.base_mesh().expect("loop mesh");
        let cpu = prepare_loop_bft(loop_mesh, 5, true).expect("prepare");
        let mirror = GpuBft::new(&cpu).expect("pack");
        let level1 = mirror.subdivide(&base);
        let normals = mirror.normals(&level1);
        let mut mirror_worst = 0.0f64;
        for r in &soup.records {
            let [x, y] = r.domain;
            let m = mirror.eval_tess(
                &level1,
                &normals,
                r.patch as usize,
                [x, y, 1.0 - x - y],
                false,
            );
            let len = |v: [f32; 3]| v.iter().map(|&c| (c as f64).powi(2)).sum::<f64>().sqrt();
            let dot: f64 = (0..3)
                .map(|k| m.normal[k] as f64 * r.normal[k] as f64)
                .sum();
            let cos = (dot / (len(m.normal) * len(r.normal))).clamp(-1.0, 1.0);
            mirror_worst = mirror_worst.max(cos.acos().to_degrees());
        }
        println!("subdivision shading vs its f32 mirror: worst {mirror_worst:.5}°");
        assert!(
            mirror_worst < 0.01,
            "subdivision shading vs mirror: {mirror_worst:.4}°"
        );

        let mut plain = surface(&mut ctx, &mesh, "spot", 5, false);
        let params = FrameParams {
            geometric_normals: true,
            ..uniform(16)
        };
        let e = ctx
            .render_offscreen(&mut plain, &params, EXTENT)
            .map(|_| ())
            .expect_err("geometric normals without tangent tables");
        assert!(e.to_string().contains("tangent tables"), "{e}");
    }
}
