//! The mesh refined on the CPU and drawn from the vertex stage (`--method cpu`, `cpu-catmark`):
//! every vertex the GPU emitted, captured through transform feedback, is the exact limit
//! surface at the point of the base mesh it reports (within f32 rounding), at every level, on
//! meshes with boundaries, creases and n-gons; an animated base moves it to the moved base's
//! limit; the level follows the frame's segments.
mod common;

use common::Gpu;
use tessera::tess::{Capturer, Context, FrameParams, Technique, TechniqueId};
use tessera::topology::limit::eval::LimitScheme;
use tessera::topology::limit::face_domain::LimitEvaluator;
use tessera::topology::{load_obj, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

fn shape(name: &str) -> ControlMesh {
    load_obj(common::data(&format!(
        "tests/data/opensubdiv/shapes/{name}.obj"
    )))
    .unwrap()
}

/// The largest distance, over the diagonal, of a captured vertex from the exact limit at its
/// own face point; and how many vertices were captured.
fn worst_deviation(
    ctx: &mut Context,
    capturer: &Capturer,
    technique: &mut dyn Technique,
    mesh: &ControlMesh,
    scheme: LimitScheme,
    segments: f32,
) -> (f64, usize) {
    let params = FrameParams::uniform(segments);
    let (soup, _) = capturer
        .capture(ctx, &mut *technique, &params, EXTENT)
        .expect("capture");
    let lm = LimitEvaluator::new(mesh, scheme).expect("evaluator");
    let (lo, hi) = mesh.bounding_box();
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let mut worst = 0.0f64;
    for r in &soup.records {
        let p = technique
            .face_point(r.patch, r.domain)
            .unwrap_or_else(|| panic!("vertex {} maps to no base face", r.patch));
        let e = lm
            .evaluate(p.face, p.u as f64, p.v as f64)
            .expect("exact limit");
        for k in 0..3 {
            worst = worst.max((r.position[k] as f64 - e.position[k]).abs() / diagonal);
        }
    }
    (worst, soup.records.len())
}

#[test]
fn captured_vertices_are_the_exact_limit_at_their_domain_points() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let spot = load_obj(common::data("assets/spot_control_mesh.obj")).unwrap();
        let cases: Vec<(&str, ControlMesh, TechniqueId, LimitScheme, &[f32])> = vec![
            (
                "loop_xord_boundary",
                shape("loop_xord_boundary"),
                TechniqueId::CPU,
                LimitScheme::Loop,
                &[1.0, 2.0, 8.0],
            ),
            (
                "loop_cube_creases1",
                shape("loop_cube_creases1"),
                TechniqueId::CPU,
                LimitScheme::Loop,
                &[4.0],
            ),
            (
                "spot",
                spot,
                TechniqueId::CPU_CATMARK,
                LimitScheme::CatmullClark,
                &[1.0, 2.0, 4.0],
            ),
            (
                "catmark_tent_creases1",
                shape("catmark_tent_creases1"),
                TechniqueId::CPU_CATMARK,
                LimitScheme::CatmullClark,
                &[8.0],
            ),
        ];
        for (name, mesh, id, scheme, levels) in cases {
            let mut t = common::build(&mut ctx, id, &mesh);
            for &s in levels {
                let (worst, n) = worst_deviation(&mut ctx, &capturer, t.as_mut(), &mesh, scheme, s);
                println!("{name} {id} S = {s}: {n} vertices, worst {worst:.2e} of the diagonal");
                assert!(n > 0);
                assert!(worst <= 1e-6, "{name} {id} S = {s}: {worst:e}");
            }
        }
    }
}

/// The frame's segments choose the level: S = 2^k draws 4^k times the triangles (Loop), and a
/// level that is not a power of two is refused by name.
#[test]
fn the_level_follows_the_segments() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = shape("loop_cube");
        let mut t = common::build(&mut ctx, TechniqueId::CPU, &mesh);
        let faces = mesh.num_faces() as u64;
        for k in 0..4u32 {
            let params = FrameParams::uniform((1u32 << k) as f32);
            assert_eq!(t.triangles(&params, 0), Some(faces << (2 * k)));
            let frame = ctx
                .render_offscreen_stats(t.as_mut(), &params, EXTENT, true)
                .unwrap();
            if let Some(s) = frame.statistics {
                assert_eq!(s.clipping_invocations, faces << (2 * k), "S = 2^{k}");
            }
        }
        let e = ctx
            .render_offscreen(t.as_mut(), &FrameParams::uniform(3.0), EXTENT)
            .map(|_| ())
            .expect_err("S = 3 is refused");
        assert!(e.to_string().contains("segments 3"), "{e}");
    }
}
