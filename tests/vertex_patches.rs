//! Doo-Sabin as the seed's vertex patches (`--method vertex-patches`): every point the vertex
//! stage emitted, captured through transform feedback as a slot of the deepest patch arrays,
//! is the CPU refiner's point of the vertex that slot holds, at every depth, on meshes with
//! valence 3 and 5 vertices, triangles, pentagons and an extraordinary boundary vertex; every
//! refined point is drawn; the capture welds with 0 cracks; an animated base refines to the
//! CPU refinement of the moved base; the shaded normals approach the exact limit normals at
//! face centres; every OpenSubdiv shape without tags does the same to depth 5; other segments,
//! tags, faces over the kernel's arrays and depths over the vertex limit are refused by name.
mod common;

use common::Gpu;
use tessera::tess::animation::Wave;
use tessera::tess::capture::classify_open_edges;
use tessera::tess::techniques::shared::MAX_DOO_SABIN_DEPTH;
use tessera::tess::techniques::vertex_patches::layout::layout;
use tessera::tess::{Capturer, Context, FrameParams, Pass, Technique, TechniqueId, TessError};
use tessera::topology::limit::doo_sabin::face_limit;
use tessera::topology::limit::limit_mesh::doo_sabin_domain_points;
use tessera::topology::mesh::INVALID;
use tessera::topology::refine::{refine_uniform, Level};
use tessera::topology::{load_obj, ControlMesh, Scheme};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

/// (name, path): valence 3 (cube), valence 5 and triangles (icosahedron), triangles around a
/// quad (pyramid), pentagons and triangles (spot), an extraordinary boundary vertex. Each is
/// checked at every depth the technique draws, 1 to 6.
const SHAPES: [(&str, &str); 5] = [
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
        "xord_boundary",
        "tests/data/opensubdiv/shapes/catmark_xord_boundary.obj",
    ),
];

fn mesh(path: &str) -> ControlMesh {
    load_obj(common::data(path)).unwrap()
}

/// What one capture at depth `depth` showed against the CPU refiner's level of `reference`.
struct Compared {
    /// Largest distance of a captured point from its vertex's refined point, over the bbox
    /// diagonal.
    worst: f64,
    /// Level points captured at least once, and the level's point count.
    covered: usize,
    points: usize,
    triangles: usize,
    /// (cracks, unmapped, on the base boundary) of the open edges.
    classes: (usize, usize, usize),
    /// Captured slots whose face point is not their vertex's domain point.
    misplaced: usize,
    /// Per level point, its captured normal.
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
    let base = Level::from_mesh(mesh, Scheme::DooSabin).expect("base");
    let slots = layout(&base, depth).expect("layout").slot_vertices;
    let domain = doo_sabin_domain_points(mesh, depth as usize).expect("domain points");
    let diagonal = mesh.bbox_diagonal();
    let (mut worst, mut misplaced) = (0.0f64, 0);
    let mut normals = vec![None; level.num_vertices()];
    for rec in &soup.records {
        let v = *slots
            .get(rec.patch as usize)
            .unwrap_or_else(|| panic!("captured slot {} is no slot", rec.patch));
        assert_ne!(
            v, INVALID,
            "slot {} holds no point but was drawn",
            rec.patch
        );
        let want = level.positions[v as usize];
        for (got, want) in rec.position.iter().zip(want) {
            worst = worst.max((*got as f64 - want).abs() / diagonal);
        }
        let face_point = t.face_point(rec.patch, rec.domain);
        let exact = domain[v as usize];
        let same = match (face_point, exact) {
            (Some(p), Some(d)) => {
                p.face == d.face && p.u == d.uv[0] as f32 && p.v == d.uv[1] as f32
            }
            (None, None) => true,
            _ => false,
        };
        misplaced += !same as usize;
        normals[v as usize] = Some(rec.normal);
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
        misplaced,
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
            let mut t = common::build(&mut ctx, TechniqueId::VERTEX_PATCHES, &mesh);
            let open = name == "xord_boundary";
            for depth in 1..=MAX_DOO_SABIN_DEPTH {
                let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, depth);
                println!(
                    "{name} D = {depth}: {} points, {} triangles, worst {:.2e} of the diagonal, \
                     (cracks, unmapped, boundary) {:?}",
                    c.points, c.triangles, c.worst, c.classes
                );
                assert!(c.worst <= 1e-6, "{name} D = {depth}: {:e}", c.worst);
                assert_eq!(c.covered, c.points, "{name} D = {depth}: every point drawn");
                assert_eq!(c.misplaced, 0, "{name} D = {depth}: face points");
                let params = FrameParams::uniform((1u32 << depth) as f32);
                assert_eq!(Some(c.triangles as u64), t.triangles(&params, 0));
                assert_eq!((c.classes.0, c.classes.1), (0, 0), "{name} D = {depth}");
                assert_eq!(c.classes.2 > 0, open, "{name} D = {depth}: boundary edges");
            }
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// Every OpenSubdiv shape in tests/data (closed, open, n-gons, a valence-8 pole) to depth 5
/// against the CPU refiner; a shape is refused only by name, for tags Doo-Sabin has no rule for
/// (creases, corners, holes) or a face over the kernel's 32 corners (the valence-64 pole).
#[test]
fn every_shape_without_tags_matches_the_cpu_refiner() {
    let (dir, other) = common::shapes_dir("DOO_SABIN_SHAPES_DIR");
    let gpu = Gpu::new();
    let (mut refused, mut failures, mut checked) = (Vec::new(), Vec::new(), 0);
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for name in common::shape_names(&dir, "") {
            let mesh = load_obj(dir.join(format!("{name}.obj"))).unwrap();
            let id = TechniqueId::VERTEX_PATCHES;
            let built = tessera::tess::techniques::build(&mut ctx, id, &mesh, &Default::default());
            let mut t = match built {
                Ok(b) => b.technique,
                Err(e) => {
                    let e = e.to_string();
                    let too_large = e.contains("the refinement kernel takes");
                    if !(common::refused_for_doo_sabin_tags(&mesh, &e) || too_large) || other {
                        refused.push(format!("{name}: {e}"));
                    }
                    continue;
                }
            };
            checked += 1;
            for depth in 1..=5 {
                let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, depth);
                println!("{name} D = {depth}: worst {:.2e}, {:?}", c.worst, c.classes);
                let bad = c.worst > 1e-6
                    || c.covered != c.points
                    || c.misplaced != 0
                    || (c.classes.0, c.classes.1) != (0, 0);
                if bad {
                    failures.push(format!(
                        "{name} D = {depth}: worst {:e}, {} of {} points drawn, {} misplaced, \
                         (cracks, unmapped) ({}, {})",
                        c.worst, c.covered, c.points, c.misplaced, c.classes.0, c.classes.1
                    ));
                }
            }
        }
    }
    println!("{checked} shapes checked");
    assert!(checked >= 20, "{checked} shapes checked");
    common::whole_set_verdict(&refused, other, &failures);
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

#[test]
fn an_animated_frame_is_the_refinement_of_the_moved_base() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in [SHAPES[3], SHAPES[4]] {
            let mesh = mesh(path);
            let mut t = common::build(&mut ctx, TechniqueId::VERTEX_PATCHES, &mesh);
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
                rest.worst <= 1e-6 && c.worst <= 1e-6,
                "{name}: {:e}",
                c.worst
            );
            assert!(still.worst > 1e-3, "{name}: the surface moved");
            assert_eq!((c.classes.0, c.classes.1), (0, 0), "{name}");
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
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

/// The normals are `doo-sabin`'s (per point from its face corners, read across patches): the
/// mean angle to the exact limit normal at face centres shrinks with every level from 2 on.
#[test]
fn shaded_normals_approach_the_exact_limit_normals_at_face_centres() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for (name, path) in [SHAPES[0], SHAPES[3]] {
            let mesh = mesh(path);
            let mut t = common::build(&mut ctx, TechniqueId::VERTEX_PATCHES, &mesh);
            let mut errors = Vec::new();
            for depth in 1..=4u32 {
                let c = compare(&mut ctx, &capturer, t.as_mut(), &mesh, &mesh, depth);
                let (mean, worst) = normal_error(&mesh, depth, &c.normals);
                println!(
                    "{name} D = {depth}: normal error mean {mean:.3} deg, worst {worst:.3} deg"
                );
                errors.push((mean, worst));
            }
            for w in errors[1..].windows(2) {
                assert!(
                    w[1].0 < w[0].0,
                    "{name}: the mean error shrinks: {errors:?}"
                );
            }
            let (mean, _) = errors[3];
            assert!(mean < 0.5, "{name} D = 4: mean {mean} degrees");
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// Segments that are not a depth, tags Doo-Sabin has no rule for, and a depth over the
/// build's vertex limit are refused by name.
#[test]
fn bad_input_is_refused_by_name() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let cube = mesh(SHAPES[0].1);
        let mut t = common::build(&mut ctx, TechniqueId::VERTEX_PATCHES, &cube);
        for s in [1.0, 3.0, 6.0, 128.0, 2.5] {
            let e = ctx
                .prepare(t.as_mut(), &FrameParams::uniform(s), &[Pass::Shaded])
                .expect_err("refused");
            assert!(matches!(e, TessError::Param(_)), "S = {s}: {e}");
            assert!(e.to_string().contains("segments"), "{e}");
        }
        for (shape, refused) in [
            ("catmark_hole_test1", "face 1 is a hole"),
            ("catmark_cube_creases0", "has crease sharpness"),
            ("catmark_cube_corner0", "vertex 0 has corner sharpness"),
            (
                "loop_pole64",
                "patch of vertex 4 has a face of 64 corners, more than the 32",
            ),
        ] {
            let tagged = mesh(&format!("tests/data/opensubdiv/shapes/{shape}.obj"));
            let e = tessera::tess::techniques::build(
                &mut ctx,
                TechniqueId::VERTEX_PATCHES,
                &tagged,
                &Default::default(),
            )
            .err()
            .expect("tags refused")
            .to_string();
            assert!(e.contains(refused), "{shape}: {e}");
        }
        let small = tessera::tess::BuildOptions {
            max_refined_vertices: 1_000,
            ..Default::default()
        };
        let mut t =
            tessera::tess::techniques::build(&mut ctx, TechniqueId::VERTEX_PATCHES, &cube, &small)
                .expect("build")
                .technique;
        ctx.prepare(t.as_mut(), &FrameParams::uniform(8.0), &[Pass::Shaded])
            .expect("depth 3: 512 vertices");
        match ctx.prepare(t.as_mut(), &FrameParams::uniform(16.0), &[Pass::Shaded]) {
            Err(TessError::RefinedTooLarge {
                level: 4,
                vertices: 2048,
                max: 1_000,
                ..
            }) => {}
            other => panic!("depth 4 was not refused: {:?}", other.err()),
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}
