//! Pipeline statistics against the CPU tessellator, and the lavapipe draw-split workaround.
mod common;
use common::Gpu;
use tessera::tess::tessellator::{uniform_vertex_count, Domain};
use tessera::tess::{Context, DrawSplit, FrameParams, Pass, Spacing, TechniqueId};
use tessera::topology::ControlMesh;
use tessera::vk_core::vk;

const SMALL: vk::Extent2D = vk::Extent2D {
    width: 96,
    height: 64,
};

/// A strip of `k` unit quads (or 2k triangles when `triangles`), with normals along +z.
fn strip(k: u32, triangles: bool) -> ControlMesh {
    let mut pos = Vec::new();
    for i in 0..=k {
        pos.push([i as f64, 0.0, 0.0]);
        pos.push([i as f64, 1.0, 0.0]);
    }
    ControlMesh::from_polygons(pos, &common::strip_faces(k, triangles))
}

#[test]
fn tes_invocations_equal_cpu_tessellator_counts() {
    let gpu = Gpu::new();
    let lavapipe = gpu.device().info.is_lavapipe();
    let mut r = Context::offscreen(gpu.device()).unwrap();
    for (triangles, domain) in [(true, Domain::Triangle), (false, Domain::Quad)] {
        let k = if triangles { 10 } else { 5 };
        let mut mesh = common::build(&mut r, TechniqueId::FLAT, &strip(5, triangles));
        for spacing in [
            Spacing::Equal,
            Spacing::FractionalEven,
            Spacing::FractionalOdd,
        ] {
            for level in [1.0f32, 2.0, 2.5, 3.0, 4.7, 7.0, 16.0, 33.3, 64.0] {
                let p = FrameParams {
                    spacing,
                    ..FrameParams::uniform(level)
                };
                let frame = r
                    .render_offscreen_stats(mesh.as_mut(), &p, SMALL, true)
                    .unwrap();
                let (stats, counts) = (frame.statistics.unwrap(), frame.counts);
                let expected = k as u64 * uniform_vertex_count(domain, spacing, level);
                assert_eq!(
                    stats.tess_control_patches, k as u64,
                    "{domain:?} {spacing:?} {level}"
                );
                assert_eq!(counts.patches, k, "{domain:?} {spacing:?} {level}");
                // Vulkan runs the TES at least once per distinct tessellated vertex; lavapipe
                // exactly once (NVIDIA's H100 runs 730 for lavapipe's 480 at level 7).
                let what = format!("TES invocations, {domain:?} {spacing:?} level {level}");
                if lavapipe {
                    assert_eq!(stats.tess_evaluation_invocations, expected, "{what}");
                } else {
                    assert!(stats.tess_evaluation_invocations >= expected, "{what}");
                }
            }
        }
    }
    assert!(gpu.errors().is_empty());
}

/// A gently curved w × h grid of quads (curved so the wireframe shows every patch's triangles).
fn grid(w: u32, h: u32) -> ControlMesh {
    let mut pos = Vec::new();
    for j in 0..=h {
        for i in 0..=w {
            let (x, y) = (i as f64, j as f64);
            pos.push([x, y, 0.1 * ((x * 0.7).sin() + (y * 0.9).cos())]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let v = j * (w + 1) + i;
            faces.push(vec![v, v + 1, v + w + 2, v + w + 1]);
        }
    }
    ControlMesh::from_polygons(pos, &faces)
}

/// lavapipe splits a draw into chunks of min(patches, 4096 / control points) patches and a chunk
/// emitting more than 65,536 vertices gets corrupt triangles. 24 quads at level 64 emit
/// 24 × 4225 = 101,400 vertices in one chunk. The split draw must equal a one-patch-per-draw reference
/// exactly; on lavapipe the unsplit draw must not (showing the test can fail without the split).
#[test]
fn draw_split_matches_per_patch_reference() {
    let gpu = Gpu::new();
    let mut r = Context::offscreen(gpu.device()).unwrap();
    let mut mesh = common::build(&mut r, TechniqueId::FLAT, &grid(6, 4));
    let extent = vk::Extent2D {
        width: 192,
        height: 192,
    };
    let base = FrameParams {
        wireframe: true,
        ..FrameParams::uniform(64.0)
    };
    let mut render = |r: &mut Context, split: DrawSplit| {
        let f = r
            .render_offscreen_stats(mesh.as_mut(), &FrameParams { split, ..base }, extent, false)
            .unwrap();
        (f.image, f.counts)
    };
    let (reference, ref_counts) = render(&mut r, DrawSplit::PerPatch);
    let (split, split_counts) = render(&mut r, DrawSplit::Auto);
    assert_eq!(ref_counts.patches, split_counts.patches);
    let differing =
        |a: &[u8], b: &[u8]| a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x != y).count();
    assert_eq!(
        differing(&split.pixels, &reference.pixels),
        0,
        "split draw differs from the per-patch reference"
    );
    if gpu.device().info.is_lavapipe() {
        assert!(
            split_counts.draws > 2,
            "lavapipe needs the split: {split_counts:?}"
        );
        let (unsplit, counts) = render(&mut r, DrawSplit::Off);
        assert_eq!(counts.draws, 2, "one draw per pass");
        let bad = differing(&unsplit.pixels, &reference.pixels);
        assert!(
            bad > 100,
            "expected lavapipe's chunk corruption without the split, only {bad} pixels differ"
        );
    }
}

/// Timestamps bracket real GPU work: the later one is not earlier, and the pool refuses to be
/// read as statistics.
#[test]
fn timestamp_queries_measure_a_draw() {
    use tessera::vk_core::query::QueryPool;
    use tessera::vk_core::target::OffscreenTarget;
    let gpu = Gpu::new();
    let device = gpu.device();
    let mut r = Context::offscreen(device).unwrap();
    let mut mesh = common::build(&mut r, TechniqueId::FLAT, &grid(6, 4));
    let target = OffscreenTarget::new(device, SMALL).unwrap();
    let readback = target.readback_buffer(device).unwrap();
    let pool = QueryPool::timestamps(device, "test timestamps", 2).unwrap();
    let params = FrameParams::uniform(32.0);
    r.prepare(mesh.as_mut(), &params, &[Pass::Shaded]).unwrap();
    let mesh = mesh.as_ref();
    r.write_frame(0, mesh.bbox(), &params, SMALL).unwrap();
    let r = &r;
    device
        .submit_once(|enc| {
            enc.reset_queries(&pool);
            enc.write_timestamp(&pool, vk::PipelineStageFlags::TOP_OF_PIPE, 0)
                .unwrap();
            enc.begin_offscreen(&target, params.clear_color);
            r.record_frame(enc, mesh, 0, &params).unwrap();
            enc.end_offscreen_and_copy(&target, &readback);
            enc.write_timestamp(&pool, vk::PipelineStageFlags::BOTTOM_OF_PIPE, 1)
                .unwrap();
        })
        .unwrap();
    let d = pool.durations_ns().unwrap();
    assert_eq!(d.len(), 1);
    assert!(d[0] >= 0.0 && d[0] < 60e9, "duration {} ns", d[0]);
    assert!(pool.statistics_results().is_err());
}
