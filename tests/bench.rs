//! The benchmark machinery on a tiny mesh, two timed frames: structure only (rows, triangle
//! counts, CSV round trip). Speed is measured by `tessera bench`, never asserted here.
mod common;
use common::Gpu;
use tessera::tess::bench::{self, parse_csv, BenchConfig, BenchMesh, BenchRow, TriangleSource};
use tessera::tess::tessellator::{uniform_triangle_count, Domain, Spacing};
use tessera::vk_core::vk;

fn tiny_config(segments: Vec<u32>) -> BenchConfig {
    BenchConfig {
        segments,
        frames: 2,
        warmup: 1,
        extent: vk::Extent2D {
            width: 96,
            height: 64,
        },
        ..BenchConfig::default()
    }
}

#[test]
fn bench_rows_counts_and_csv_round_trip() {
    let gpu = Gpu::new();
    // Six quads: fan-triangulated to 12 triangles on load, as the default meshes are.
    let cube = tessera::topology::load_obj(common::data("tests/data/meshes/cube.obj")).unwrap();
    let mesh = BenchMesh::new("cube", &cube).unwrap();
    assert_eq!(mesh.triangles(), 12);
    assert_eq!(mesh.notes.len(), 1, "the triangulation is reported");

    let mut config = tiny_config(vec![1, 3, 4]);
    config.methods = ["flat", "phong", "pn", "cpu"].map(String::from).to_vec();
    // Loop level 2 of the cube has 98 vertices: over this limit, so cpu rows skip S = 4.
    config.cpu_max_vertices = 50;
    let mut seen = 0;
    let report = bench::run_bench(gpu.device(), &[mesh], &config, &mut |_| seen += 1).unwrap();
    assert_eq!(seen, report.rows.len());

    let tess_methods = ["flat", "phong", "pn"];
    let cpu_methods = ["cpu", "cpu-animated"];
    let mut expected_rows = Vec::new();
    for s in [1u32, 3, 4] {
        for m in tess_methods {
            expected_rows.push((s, m));
        }
        if s == 1 {
            for m in cpu_methods {
                expected_rows.push((s, m));
            }
        }
    }
    let got: Vec<(u32, &str)> = report
        .rows
        .iter()
        .map(|r| (r.segments, r.method.as_str()))
        .collect();
    assert_eq!(got, expected_rows);
    // S = 3 is not a power of two; S = 4 is over the vertex limit.
    let skipped: Vec<(u32, &str)> = report
        .skipped
        .iter()
        .map(|s| (s.segments, s.method.as_str()))
        .collect();
    assert_eq!(
        skipped,
        vec![
            (3, "cpu"),
            (3, "cpu-animated"),
            (4, "cpu"),
            (4, "cpu-animated")
        ]
    );
    assert!(
        report.skipped[2].reason.contains("98 vertices"),
        "{:?}",
        report.skipped[2]
    );

    let stats = gpu.device().info.caps.pipeline_statistics_query;
    for r in &report.rows {
        let expected = if r.method.starts_with("cpu") {
            // Loop level k multiplies the triangles by 4^k; S = 2^k.
            12 * (r.segments as u64).pow(2)
        } else {
            12 * uniform_triangle_count(Domain::Triangle, Spacing::Equal, r.segments as f32)
        };
        assert_eq!(r.triangles_expected, expected, "{r:?}");
        assert_eq!(r.triangles, expected, "GPU count, {r:?}");
        assert_eq!(
            r.triangles_source,
            if stats {
                TriangleSource::PipelineStatistics
            } else {
                TriangleSource::Cpu
            }
        );
        assert_eq!(r.input_triangles, 12);
        assert_eq!((r.frames, r.warmup), (2, 1), "{r:?}");
        for t in [
            r.gpu_median_ms,
            r.gpu_p90_ms,
            r.total_median_ms,
            r.total_p90_ms,
            r.wall_median_ms,
        ] {
            assert!(t.is_finite() && t > 0.0, "{r:?}");
        }
        assert!(r.gpu_p90_ms >= r.gpu_median_ms, "{r:?}");
        match r.method.as_str() {
            "cpu-animated" => {
                let c = r.cpu_median_ms.expect("CPU time of the animated baseline");
                assert!(c.is_finite() && c > 0.0, "{r:?}");
                assert!(r.cpu_p90_ms.is_some());
            }
            _ => assert_eq!(r.cpu_median_ms, None, "{r:?}"),
        }
        let ratio = r.ratio_to_flat.expect("flat ran at every S");
        assert!(ratio.is_finite() && ratio > 0.0);
        if r.method == "flat" {
            assert_eq!(ratio, 1.0);
        }
        assert!(!r.note.contains("pipeline statistics counted"), "{r:?}");
    }

    eprintln!("{}", report.to_text());
    let csv = report.to_csv();
    let back: Vec<BenchRow> = parse_csv(&csv).unwrap();
    assert_eq!(back, report.rows);
    let md = report.to_markdown();
    assert!(md.contains(&report.device.name) && md.contains("Build profile"));
    assert!(md.contains("fan-triangulated"));
    assert_eq!(
        md.lines().filter(|l| l.starts_with("| cube |")).count(),
        report.rows.len()
    );
    if report.device.lavapipe {
        assert!(md.contains("CPU rasterizer"));
    }
}

#[test]
fn bench_rejects_bad_configurations() {
    let gpu = Gpu::new();
    let cube = tessera::topology::load_obj(common::data("tests/data/meshes/cube.obj")).unwrap();
    let mesh = BenchMesh::new("cube", &cube).unwrap();
    let run = |c: BenchConfig| {
        bench::run_bench(gpu.device(), std::slice::from_ref(&mesh), &c, &mut |_| {})
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let mut c = tiny_config(vec![4]);
    c.methods = vec!["nope".into()];
    assert!(run(c).contains("unknown bench method 'nope'"));
    let mut c = tiny_config(vec![4]);
    c.frames = 0;
    assert!(run(c).contains("timed frame"));
    assert!(run(tiny_config(vec![])).contains("segments"));
    assert!(bench::run_bench(gpu.device(), &[], &tiny_config(vec![4]), &mut |_| {}).is_err());
}

/// BFT rows: one patch per level-1 face at S/2 emits exactly Flat's triangles at S; S outside
/// the tables' range is skipped with the reason; the animated row reports its upload's CPU time;
/// the report names the table memory.
#[test]
fn bench_bft_rows_match_flat_triangles() {
    let gpu = Gpu::new();
    let cube = tessera::topology::load_obj(common::data("tests/data/meshes/cube.obj")).unwrap();
    let mesh = BenchMesh::new("cube", &cube).unwrap();
    let mut config = tiny_config(vec![1, 4, 16]);
    config.methods = vec!["flat".into(), "bft".into()];
    let report = bench::run_bench(gpu.device(), &[mesh], &config, &mut |_| {}).unwrap();
    let got: Vec<(u32, &str)> = report
        .rows
        .iter()
        .map(|r| (r.segments, r.method.as_str()))
        .collect();
    assert_eq!(
        got,
        vec![
            (1, "flat"),
            (4, "flat"),
            (4, "bft"),
            (4, "bft-animated"),
            (16, "flat"),
            (16, "bft"),
            (16, "bft-animated"),
        ]
    );
    let skipped: Vec<(u32, &str)> = report
        .skipped
        .iter()
        .map(|s| (s.segments, s.method.as_str()))
        .collect();
    assert_eq!(skipped, vec![(1, "bft"), (1, "bft-animated")]);
    assert!(report.skipped[0].reason.contains("power of two in 2..=64"));
    for r in report.rows.iter().filter(|r| r.method.starts_with("bft")) {
        let flat = report
            .rows
            .iter()
            .find(|f| f.method == "flat" && f.segments == r.segments)
            .unwrap();
        assert_eq!(r.triangles, flat.triangles, "{r:?}");
        assert_eq!(
            r.triangles,
            12 * uniform_triangle_count(Domain::Triangle, Spacing::Equal, r.segments as f32)
        );
        assert_eq!(
            r.cpu_median_ms.is_some(),
            r.method == "bft-animated",
            "{r:?}"
        );
        assert!(r.ratio_to_flat.is_some_and(|x| x.is_finite() && x > 0.0));
    }
    assert!(
        report
            .extra_notes
            .iter()
            .any(|n| n.starts_with("cube: BFT tables") && n.contains("at level 5")),
        "{:?}",
        report.extra_notes
    );
}

/// Screen-space factors: BFT's rows on both paths draw under them (the pattern row counts its
/// host-chosen levels' triangles, more than one key's worth; the tessellation row's are chosen
/// on the device and its note says they were not counted), Flat keeps its uniform S, and the
/// report names the policy.
#[test]
fn bench_takes_screen_space_factors() {
    let gpu = Gpu::new();
    let cube = tessera::topology::load_obj(common::data("tests/data/meshes/cube.obj")).unwrap();
    let mesh = BenchMesh::new("cube", &cube).unwrap();
    let mut config = tiny_config(vec![4]);
    config.methods = ["flat", "bft", "bft@pattern"].map(String::from).to_vec();
    config.factors = bench::BenchFactors::Screen { pixels: 4.0 };
    let report = bench::run_bench(gpu.device(), &[mesh], &config, &mut |_| {}).unwrap();
    let row = |m: &str| report.rows.iter().find(|r| r.method == m).unwrap();
    let flat = row("flat");
    assert_eq!(
        flat.triangles,
        12 * uniform_triangle_count(Domain::Triangle, Spacing::Equal, 4.0)
    );
    let pattern = row("bft@pattern");
    assert!(pattern.triangles > 0, "{pattern:?}");
    assert!(!pattern.note.contains("not counted"), "{pattern:?}");
    for m in ["bft", "bft-animated"] {
        let tess = row(m);
        assert_eq!(tess.triangles, 0, "{tess:?}");
        assert!(tess.note.contains("not counted"), "{tess:?}");
    }
    let text = report.to_text();
    assert!(text.contains("screen-space factors (4 px"), "{text}");
}

/// `--equal-triangles` on a small mixed mesh (catmull-clark pyramid: four triangles and a
/// quad): Flat keeps S; every other technique draws the whole level per patch edge whose
/// triangle count is nearest Flat's. Checked from outside the chooser: the GPU's count
/// (transform feedback's primitives, since lavapipe's pipeline-statistics query is withheld
/// from one-control-point patches) equals the row's CPU count at its level; no neighbouring level (L - 1, L + 1) of the
/// same technique, counted again here, is nearer; and the counts land within 1/L of Flat's (the
/// gap a nearest whole level can leave when the count grows as L², see docs/benchmarks.md).
/// Memory per base face: the device bytes are positive, do not depend on S or on animation,
/// Flat's equal its vertex and index buffers, and the single-pass techniques' cover their
/// tables, vertex buffer and base positions.
#[test]
fn bench_equal_triangles_and_memory_per_face() {
    let gpu = Gpu::new();
    let pyramid = tessera::topology::load_obj(common::data(
        "tests/data/opensubdiv/shapes/catmark_pyramid.obj",
    ))
    .unwrap();
    let mesh = BenchMesh::new("pyramid", &pyramid).unwrap();
    let mut config = tiny_config(vec![4, 16]);
    config.methods = ["flat", "adaptive", "gregory", "acc"]
        .map(String::from)
        .to_vec();
    config.isolation = 2;
    config.equal_triangles = true;
    let report = bench::run_bench(
        gpu.device(),
        std::slice::from_ref(&mesh),
        &config,
        &mut |_| {},
    )
    .unwrap();
    assert!(report.skipped.is_empty(), "{:?}", report.skipped);
    // The techniques again, captured at each row's level: the GPU's own triangle count.
    let mut cap_ctx = tessera::tess::Context::offscreen(gpu.device()).unwrap();
    let capturer = tessera::tess::Capturer::new(&cap_ctx).unwrap();
    let mut surfaces: Vec<(&str, Box<dyn tessera::tess::Technique>)> =
        ["adaptive", "gregory", "acc"]
            .into_iter()
            .map(|name| {
                let built = tessera::tess::build(
                    &mut cap_ctx,
                    name.parse().unwrap(),
                    &pyramid,
                    &tessera::tess::BuildOptions {
                        isolation: config.isolation,
                        ..Default::default()
                    },
                )
                .unwrap();
                (name, built.technique)
            })
            .collect();
    let mut gpu_count = |name: &str, level: u32| {
        let surf = &mut surfaces.iter_mut().find(|(n, _)| *n == name).unwrap().1;
        let params = tessera::tess::FrameParams::uniform(level as f32);
        let (_, stats) = capturer
            .capture(&mut cap_ctx, surf.as_mut(), &params, config.extent)
            .unwrap();
        stats.primitives_needed
    };

    // The same methods again, to count neighbouring levels independently of the run.
    let ctx = bench::RowContext {
        device: gpu.device(),
        mesh: &mesh,
        config: &config,
        color_format: tessera::vk_core::target::COLOR_FORMAT,
        depth_format: tessera::vk_core::target::DEPTH_FORMAT,
    };
    let methods = bench::build_rows(&config.methods, &ctx).unwrap();
    let count = |label: &str, level: u32| {
        methods
            .iter()
            .find(|m| m.label() == label)
            .unwrap()
            .triangles_at(level)
    };

    for s in [4u32, 16] {
        let flat = report
            .rows
            .iter()
            .find(|r| r.method == "flat" && r.segments == s)
            .unwrap();
        assert_eq!(flat.level, s);
        assert_eq!(flat.triangle_ratio_to_flat, Some(1.0));
        assert_eq!(
            flat.triangles,
            6 * uniform_triangle_count(Domain::Triangle, Spacing::Equal, s as f32)
        );
        for name in ["adaptive", "gregory", "acc"] {
            for label in [name.to_string(), format!("{name}-animated")] {
                let r = report
                    .rows
                    .iter()
                    .find(|r| r.method == label && r.segments == s)
                    .unwrap_or_else(|| panic!("{label} at S = {s}"));
                let l = r.level;
                assert_eq!(r.triangles_expected, count(name, l).unwrap(), "{r:?}");
                assert_eq!(r.triangles, r.triangles_expected, "{r:?}");
                assert_eq!(gpu_count(name, l), r.triangles, "GPU count, {r:?}");
                let miss = |t: u64| t.abs_diff(flat.triangles);
                for n in [l.saturating_sub(1), l + 1] {
                    if let Some(t) = count(name, n).filter(|_| n >= 1) {
                        assert!(
                            miss(r.triangles) <= miss(t),
                            "{label} level {n}: {t}, {r:?}"
                        );
                    }
                }
                let ratio = r.triangle_ratio_to_flat.unwrap();
                assert_eq!(ratio, r.triangles as f64 / flat.triangles as f64);
                assert!(
                    (ratio - 1.0).abs() <= 1.0 / l as f64,
                    "{label} S = {s}: level {l}, {} triangles against Flat's {}",
                    r.triangles,
                    flat.triangles
                );
                eprintln!(
                    "{label} S = {s}: level {l}, {} triangles, {ratio:.3} × Flat",
                    r.triangles
                );
            }
        }
    }

    // Memory per base face (the pyramid's 5 faces as loaded, not its 6 fan triangles).
    for r in &report.rows {
        assert_eq!(r.base_faces, 5, "{r:?}");
        let bytes = r.device_bytes.expect("every technique states its memory");
        assert!(bytes > 0, "{r:?}");
        assert_eq!(r.bytes_per_base_face(), Some(bytes as f64 / 5.0));
        let base = r.method.trim_end_matches("-animated");
        for o in report.rows.iter().filter(|o| o.method.starts_with(base)) {
            assert_eq!(o.device_bytes, r.device_bytes, "{r:?} and {o:?}");
        }
    }
    let bytes = |m: &str| {
        report
            .rows
            .iter()
            .find(|r| r.method == m)
            .unwrap()
            .device_bytes
            .unwrap()
    };
    // Flat: 24-byte vertices (position, normal) and 3 indices of 4 bytes per fan triangle.
    assert_eq!(
        bytes("flat"),
        24 * mesh.render.vertices.len() as u64 + 12 * mesh.triangles()
    );
    let mut tctx = tessera::tess::Context::new(
        gpu.device(),
        tessera::vk_core::target::COLOR_FORMAT,
        tessera::vk_core::target::DEPTH_FORMAT,
        1,
    )
    .unwrap();
    use tessera::tess::techniques::planned_patches;
    use tessera::tess::Technique;
    use tessera::topology::patches::adaptive::single_pass::SinglePassPatch;
    for (name, patch) in [
        ("gregory", SinglePassPatch::Gregory),
        ("acc", SinglePassPatch::Acc1),
    ] {
        let surf = planned_patches::single_pass(
            &mut tctx,
            &pyramid,
            &planned_patches::SinglePassBuild {
                patch,
                sharpness_scale: 1.0,
                gregory_triangles: true,
                name,
                maps: &Default::default(),
                path: tessera::tess::DrawPath::Tessellation,
            },
        )
        .unwrap();
        let memory = surf.device_memory();
        for buffer in [
            "adaptive stencil terms",
            "adaptive patches",
            "adaptive patch surfaces",
            "adaptive curve owners",
            "adaptive corner owners",
            "adaptive vertices",
        ] {
            assert!(
                memory.iter().any(|a| a.name == buffer && a.bytes > 0),
                "{name}: {buffer} in {memory:?}"
            );
        }
        let total: u64 = memory.iter().map(|a| a.bytes).sum();
        assert_eq!(total, bytes(name), "{name}");
        let floor = surf.gpu.table_bytes() as u64
            + surf.gpu.vertex_bytes()
            + 12 * pyramid.positions.len() as u64;
        assert!(total >= floor, "{name}: {total} < {floor}");
        assert!(total > bytes("flat"), "{name}");
    }
}

#[test]
fn equal_triangles_needs_flat() {
    let gpu = Gpu::new();
    let cube = tessera::topology::load_obj(common::data("tests/data/meshes/cube.obj")).unwrap();
    let mesh = BenchMesh::new("cube", &cube).unwrap();
    let mut c = tiny_config(vec![4]);
    c.methods = vec!["gregory".into()];
    c.equal_triangles = true;
    let e = bench::run_bench(gpu.device(), &[mesh], &c, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("--equal-triangles") && e.contains("flat"), "{e}");
}
