//! Doo-Sabin refined on the GPU (`--method doo-sabin`): every point the vertex stage emitted,
//! captured through transform feedback, is the CPU refiner's point of the same number at the
//! frame's level (within f32 rounding of the per-level stencil sums), on meshes with valence 3
//! and 5 vertices, triangles, pentagons and boundaries; the capture welds with 0 cracks; an
//! animated base refines to the CPU refinement of the moved base; the shaded normals approach
//! the exact limit normals at face centres as the level deepens; other segments are refused.
mod common;

use common::Gpu;
use tessera::tess::animation::Wave;
use tessera::tess::capture::classify_open_edges;
use tessera::tess::{Capturer, Context, FrameParams, Technique, TechniqueId, TessError};
use tessera::topology::limit::doo_sabin::face_limit;
use tessera::topology::refine::refine_uniform;
use tessera::topology::{load_obj, ControlMesh, Scheme};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

/// Valence 3 (cube), valence 5 and triangles (icosahedron), triangles around a quad
/// (pyramid), pentagons and triangles (spot), boundaries (edge-corner; an extraordinary
/// boundary vertex).
const SHAPES: [(&str, &str); 6] = [
    ("cube", "tests/data/opensubdiv/shapes/catmark_cube.obj"),
    (
        "icosahedron",
        "tests/data/opensubdiv/shapes/loop_icosahedron.obj",
    ),
    (
        "pyramid",
        "tests/data/opensubdiv/shapes/catmark_pyramid.obj",
    ),
    ("spot", "assets/spot_control_mesh.obj"),
    (
        "edgecorner",
        "tests/data/opensubdiv/shapes/catmark_edgecorner.obj",
    ),
    (
        "xord_boundary",
        "tests/data/opensubdiv/shapes/catmark_xord_boundary.obj",
    ),
];

fn mesh(path: &str) -> ControlMesh {
    load_obj(common::data(path)).unwrap()
}

/// What one capture at `segments` showed against the CPU refiner's level of `mesh`.
struct Compared {
    /// Largest distance of a captured point from the refiner's, over the bbox diagonal.
    worst: f64,
    /// Points of the level captured at least once, and the level's point count.
    covered: usize,
    points: usize,
    triangles: usize,
    /// (cracks, unmapped, on the base boundary) of the open edges.
    classes: (usize, usize, usize),
    /// Per point, its captured normal.
    normals: Vec<Option<[f32; 3]>>,
}

fn compare(
    ctx: &mut Context,
    capturer: &Capturer,
    t: &mut dyn Technique,
    mesh: &ControlMesh,
    reference: &ControlMesh,
    depth: u32,
) -> Compared {
    let params = FrameParams::uniform((1u32 << depth) as f32);
    let (soup, _) = capturer
        .capture(ctx, &mut *t, &params, EXTENT)
        .expect("capture");
    let r = refine_uniform(reference, Scheme::DooSabin, depth as usize).expect("CPU refiner");
    let level = r.level(depth as usize);
    let diagonal = mesh.bbox_diagonal();
    let mut worst = 0.0f64;
    let mut normals = vec![None; level.num_vertices()];
    for rec in &soup.records {
        let want = level
            .positions
            .get(rec.patch as usize)
            .unwrap_or_else(|| panic!("captured id {} is no point of the level", rec.patch));
        for (got, want) in rec.position.iter().zip(want) {
            worst = worst.max((*got as f64 - want).abs() / diagonal);
        }
        normals[rec.patch as usize] = Some(rec.normal);
    }
    let welded = soup.weld().expect("weld");
    let report = welded.open_edges();
    let map = |p: u32, d: [f32; 2]| t.face_point(p, d);
    let c = classify_open_edges(&soup, &welded, &report, &map, mesh);
    Compared {
        worst,
        covered: normals.iter().filter(|n| n.is_some()).count(),
        points: level.num_vertices(),
        triangles: soup.records.len() / 3,
        classes: (c.cracks, c.unmapped, c.on_base_boundary),
        normals,
    }
}

#[test]
fn captured_points_are_the_cpu_refiners_points_and_weld_without_cracks() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in SHAPES {
            let mesh = mesh(path);
            let mut t = common::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh);
            let open = name == "edgecorner" || name == "xord_boundary";
            for depth in 1..=4u32 {
                let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, depth);
                println!(
                    "{name} D = {depth}: {} points, {} triangles, worst {:.2e} of the diagonal, \
                     (cracks, unmapped, boundary) {:?}",
                    c.points, c.triangles, c.worst, c.classes
                );
                assert!(c.worst <= 1e-5, "{name} D = {depth}: {:e}", c.worst);
                assert_eq!(c.covered, c.points, "{name} D = {depth}: every point drawn");
                let params = FrameParams::uniform((1u32 << depth) as f32);
                assert_eq!(Some(c.triangles as u64), t.triangles(&params, 0));
                assert_eq!((c.classes.0, c.classes.1), (0, 0), "{name} D = {depth}");
                assert_eq!(c.classes.2 > 0, open, "{name} D = {depth}: boundary edges");
            }
        }
    }
}

/// `cpu-doo-sabin`, the Doo-Sabin seed's CPU baseline: the same refined points as the refiner
/// (and so as `doo-sabin` on the GPU), every one drawn, the same triangle count, 0 cracks with
/// its vertices mapped to where their limits lie (boundary points to their corner's vertex).
#[test]
fn the_cpu_baseline_draws_the_refiners_level() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in SHAPES {
            let mesh = mesh(path);
            let mut cpu = common::build(&mut ctx, TechniqueId::CPU_DOO_SABIN, &mesh);
            let gpu_t = common::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh);
            let open = name == "edgecorner" || name == "xord_boundary";
            for depth in 1..=3u32 {
                let c = compare(&mut ctx, &capturer, cpu.as_mut(), &mesh, &mesh, depth);
                let what = format!("cpu-doo-sabin on {name}, D = {depth}");
                assert!(c.worst <= 1e-6, "{what}: {:e}", c.worst);
                assert_eq!(c.covered, c.points, "{what}: every point drawn");
                let params = FrameParams::uniform((1u32 << depth) as f32);
                assert_eq!(
                    Some(c.triangles as u64),
                    cpu.triangles(&params, 0),
                    "{what}"
                );
                assert_eq!(
                    gpu_t.triangles(&params, 0),
                    cpu.triangles(&params, 0),
                    "{what}"
                );
                assert_eq!((c.classes.0, c.classes.1), (0, 0), "{what}");
                assert_eq!(c.classes.2 > 0, open, "{what}: boundary edges");
            }
        }
        // Holes, creases and sharp vertices: Doo-Sabin's refinement has none, and both
        // techniques refuse them alike, naming the face, edge or vertex.
        for (shape, refused) in [
            ("catmark_hole_test1", "face 1 is a hole"),
            ("catmark_edgenone", "face 0 is a hole"),
            ("catmark_cube_creases0", "has crease sharpness"),
            ("catmark_cube_corner0", "vertex 0 has corner sharpness"),
        ] {
            let tagged = mesh(&format!("tests/data/opensubdiv/shapes/{shape}.obj"));
            let mut refusal = |id| {
                tessera::tess::techniques::build(&mut ctx, id, &tagged, &Default::default())
                    .err()
                    .expect("tags refused")
                    .to_string()
            };
            let (gpu_e, cpu_e) = (
                refusal(TechniqueId::DOO_SABIN),
                refusal(TechniqueId::CPU_DOO_SABIN),
            );
            assert!(gpu_e.contains(refused), "{shape}: {gpu_e}");
            assert_eq!(gpu_e, cpu_e);
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// Each drawn point's face point is where its limit lies: evaluating the exact Doo-Sabin limit
/// there gives a point the drawn one approaches as the level deepens (about halving per level,
/// the dual scheme's rate next to extraordinary faces), on closed meshes.
#[test]
fn drawn_points_approach_the_exact_limit_at_their_face_points() {
    use tessera::topology::limit::face_domain::LimitEvaluator;
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in &SHAPES[..4] {
            let mesh = mesh(path);
            let limit = LimitEvaluator::doo_sabin(&mesh).unwrap();
            let mut t = common::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh);
            let mut errors = Vec::new();
            for depth in 1..=4u32 {
                let params = FrameParams::uniform((1u32 << depth) as f32);
                let (soup, _) = capturer
                    .capture(&mut ctx, t.as_mut(), &params, EXTENT)
                    .unwrap();
                let mut worst = 0.0f64;
                for r in &soup.records {
                    let p = t.face_point(r.patch, r.domain).expect("a drawn point");
                    let e = limit.evaluate(p.face, p.u as f64, p.v as f64).unwrap();
                    let d = (0..3)
                        .map(|k| (r.position[k] as f64 - e.position[k]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    worst = worst.max(d / mesh.bbox_diagonal());
                }
                errors.push(worst);
            }
            let shown: Vec<String> = errors.iter().map(|e| format!("{e:.2e}")).collect();
            println!("{name}: drawn point to its limit, levels 1..4: {shown:?}");
            assert!(
                errors.windows(2).all(|w| w[1] < 0.75 * w[0]),
                "{name}: {errors:?}"
            );
            assert!(errors[3] < 5e-3, "{name}: {errors:?}");
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

#[test]
fn an_animated_frame_is_the_refinement_of_the_moved_base() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in [SHAPES[3], SHAPES[5]] {
            let mesh = mesh(path);
            let mut t = common::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh);
            let rest = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, 3);
            let moved = Wave::new(&mesh).at(0.37);
            t.update_base(0, &moved).expect("animated base");
            let mut deformed = mesh.clone();
            deformed.positions = moved.iter().map(|p| p.map(f64::from)).collect();
            let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &deformed, 3);
            let still = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, 3);
            println!(
                "{name} animated D = 3: worst {:.2e} of the diagonal against the moved base, \
                 {:.2e} against the rest",
                c.worst, still.worst
            );
            assert!(
                rest.worst <= 1e-5 && c.worst <= 1e-5,
                "{name}: {:e}",
                c.worst
            );
            assert!(still.worst > 1e-3, "{name}: the surface moved");
            assert_eq!((c.classes.0, c.classes.1), (0, 0), "{name}");
        }
    }
}

/// Mean and largest angle (degrees) between the exact limit normal at the centre of each face
/// without boundary points and the normalized mean of its corners' captured normals.
fn normal_error(mesh: &ControlMesh, depth: u32, normals: &[Option<[f32; 3]>]) -> (f64, f64) {
    let r = refine_uniform(mesh, Scheme::DooSabin, depth as usize).expect("refine");
    let level = r.level(depth as usize);
    let t = &level.topology;
    let boundary: Vec<bool> = (0..t.num_vertices())
        .map(|v| {
            t.vertex_edges(v)
                .iter()
                .any(|&e| t.is_boundary_edge(e as usize))
        })
        .collect();
    let (mut sum, mut worst, mut n) = (0.0f64, 0.0f64, 0usize);
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        if fv.iter().any(|&v| boundary[v as usize]) {
            continue;
        }
        let corners: Vec<[f64; 3]> = fv.iter().map(|&v| level.positions[v as usize]).collect();
        let Some((_, exact)) = face_limit(&corners) else {
            continue;
        };
        let mut mean = [0.0f64; 3];
        for &v in fv {
            let g = normals[v as usize].expect("every point captured");
            for k in 0..3 {
                mean[k] += g[k] as f64;
            }
        }
        let len = mean.iter().map(|c| c * c).sum::<f64>().sqrt();
        let cos = (0..3).map(|k| mean[k] / len * exact[k]).sum::<f64>();
        let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
        sum += angle;
        worst = worst.max(angle);
        n += 1;
    }
    (sum / n as f64, worst)
}

#[test]
fn shaded_normals_approach_the_exact_limit_normals_at_face_centres() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in [SHAPES[0], SHAPES[3], SHAPES[4]] {
            let mesh = mesh(path);
            let mut t = common::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh);
            let mut errors = Vec::new();
            for depth in 1..=4u32 {
                let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, depth);
                let (mean, worst) = normal_error(&mesh, depth, &c.normals);
                println!(
                    "{name} D = {depth}: normal error mean {mean:.3} deg, worst {worst:.3} deg"
                );
                errors.push((mean, worst));
            }
            // From level 2 on (level 1 of a symmetric cube has exact normals by symmetry), the
            // mean error shrinks with every level (about 3x), the worst only over two levels:
            // it lies at the centres of a few of spot's base faces (above 50 degrees through
            // level 4, slowly shrinking) and next to edge-corner's boundary.
            for w in errors[1..].windows(2) {
                assert!(
                    w[1].0 < w[0].0,
                    "{name}: the mean error shrinks: {errors:?}"
                );
            }
            assert!(
                errors[3].1 < errors[1].1,
                "{name}: the worst error shrinks: {errors:?}"
            );
            let (mean, _) = errors[3];
            assert!(mean < 0.5, "{name} D = 4: mean {mean} degrees");
        }
    }
}

/// Segments that are not a level, and a level over the vertex limit, are refused by name.
#[test]
fn segments_that_are_not_a_level_are_refused_by_name() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = mesh(SHAPES[0].1);
        let mut t = common::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh);
        for s in [1.0, 3.0, 6.0, 128.0, 2.5] {
            let e = ctx
                .prepare(
                    t.as_mut(),
                    &FrameParams::uniform(s),
                    &[tessera::tess::Pass::Shaded],
                )
                .expect_err("refused");
            assert!(matches!(e, TessError::Param(_)), "S = {s}: {e}");
            assert!(e.to_string().contains("segments"), "{e}");
        }
        for d in 1..=6u32 {
            let params = FrameParams::uniform((1u32 << d) as f32);
            ctx.prepare(t.as_mut(), &params, &[tessera::tess::Pass::Shaded])
                .unwrap_or_else(|e| panic!("D = {d}: {e}"));
        }
        // A level beyond the build's vertex limit is refused by name before it is refined
        // (base 8 + levels 1-4 of the cube: 24 + 96 + 384 + 1,536 points).
        let small = tessera::tess::BuildOptions {
            max_refined_vertices: 1_000,
            ..Default::default()
        };
        let mut t =
            tessera::tess::techniques::build(&mut ctx, TechniqueId::DOO_SABIN, &mesh, &small)
                .expect("build")
                .technique;
        let pass = [tessera::tess::Pass::Shaded];
        ctx.prepare(t.as_mut(), &FrameParams::uniform(8.0), &pass)
            .expect("level 3: 512 vertices");
        match ctx.prepare(t.as_mut(), &FrameParams::uniform(16.0), &pass) {
            Err(TessError::RefinedTooLarge {
                level: 4,
                vertices: 2048,
                max: 1_000,
                ..
            }) => {}
            other => panic!("level 4 was not refused: {:?}", other.err()),
        }
    }
}

/// The deepest levels on every shape above: points equal, no crack; and every shape of the
/// OpenSubdiv set (`catmark_*`, `loop_*`) at D = 3. A shape with holes or sharpness tags is
/// refused by name, then drawn without them (Doo-Sabin has neither).
#[test]
#[ignore = "sweep tier (levels 5 and 6, every OpenSubdiv shape): tools/test.sh sweeps"]
fn deep_levels_and_every_shape_match_the_cpu_refiner() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let mut cases: Vec<(String, ControlMesh, Vec<u32>)> = SHAPES
            .iter()
            .map(|(name, path)| (name.to_string(), mesh(path), vec![5, 6]))
            .collect();
        let (dir, other) = common::shapes_dir("TESSERA_SHAPES");
        for prefix in ["catmark_", "loop_"] {
            for name in common::shape_names(&dir, prefix) {
                let m = load_obj(dir.join(format!("{name}.obj"))).unwrap();
                cases.push((name, m, vec![3]));
            }
        }
        let mut refused = Vec::new();
        for (name, mut mesh, depths) in cases {
            let build = |ctx: &mut Context, mesh: &ControlMesh| {
                tessera::tess::techniques::build(
                    ctx,
                    TechniqueId::DOO_SABIN,
                    mesh,
                    &Default::default(),
                )
            };
            let tagged = !mesh.holes.is_empty()
                || mesh.creases.iter().any(|c| c.sharpness > 0.0)
                || mesh.corners.iter().any(|c| c.sharpness > 0.0);
            if tagged {
                let e = build(&mut ctx, &mesh)
                    .err()
                    .expect("tags refused")
                    .to_string();
                assert!(
                    ["has no holes", "has no creases", "has no sharp vertices"]
                        .iter()
                        .any(|s| e.contains(s)),
                    "{name}: {e}"
                );
                println!("{name}: {e}; drawn without its tags");
                (mesh.holes, mesh.creases, mesh.corners) = Default::default();
                mesh.options.boundary = Default::default();
            }
            let mut t = match build(&mut ctx, &mesh) {
                Ok(b) => b.technique,
                Err(e) => {
                    refused.push(format!("{name}: {e}"));
                    continue;
                }
            };
            for depth in depths {
                let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, depth);
                println!(
                    "{name} D = {depth}: {} points, worst {:.2e}, {:?}",
                    c.points, c.worst, c.classes
                );
                assert!(c.worst <= 1e-5, "{name} D = {depth}: {:e}", c.worst);
                assert_eq!((c.classes.0, c.classes.1), (0, 0), "{name} D = {depth}");
            }
        }
        common::whole_set_verdict(&refused, other, &[]);
    }
}
