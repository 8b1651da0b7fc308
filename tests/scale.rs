//! Scale: storage buffers beyond the device's `maxStorageBufferRange`, and 1M-face
//! meshes through every technique. Validation is on and any error fails (tests/common).
//!
//! The range limit is lowered with `DeviceDesc::storage_buffer_range_cap`, so small meshes take
//! the windowed path (many chunks, non-zero bases) and must render and capture bit for bit as
//! the uncapped run does.
mod common;
#[path = "support/loop_grid.rs"]
mod loop_grid;
use common::Gpu;
use tessera::tess::capture::Capturer;
use tessera::tess::techniques::bft::{Bft, BftOptions};
use tessera::tess::techniques::planned_patches::PlanBuild;
use tessera::tess::techniques::{adaptive, planned_patches};
use tessera::tess::{Context, FrameParams, PipelineChoice, Technique};
use tessera::topology::ControlMesh;
use tessera::vk_core::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use tessera::vk_core::{
    vk, Buffer, BufferDesc, DescriptorError, DeviceDesc, MemoryLocation, VkError,
};

const SMALL: vk::Extent2D = vk::Extent2D {
    width: 320,
    height: 240,
};

fn capped(cap: Option<u32>) -> Gpu {
    Gpu::with(&DeviceDesc {
        storage_buffer_range_cap: cap,
        ..DeviceDesc::default()
    })
}

/// What a BFT run gives: image, capture, (pre-pass, draw) chunk counts, table bytes.
type BftRun = (
    Vec<u8>,
    Vec<tessera::tess::gpu::CaptureRecord>,
    (usize, usize),
    usize,
);

/// (image, capture) of a BFT surface of `mesh` under `params` on a device capped at `cap`, its
/// (pre-pass, draw) chunk counts and the bytes of its basis-function tables.
fn bft_run(cap: Option<u32>, mesh: &ControlMesh, params: &FrameParams) -> BftRun {
    bft_run_on(cap, mesh, params, PipelineChoice::Tessellation)
}

/// [`bft_run`] on the draw path `pipeline` chooses.
fn bft_run_on(
    cap: Option<u32>,
    mesh: &ControlMesh,
    params: &FrameParams,
    pipeline: PipelineChoice,
) -> BftRun {
    let gpu = capped(cap);
    let out = {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mut surf = Bft::new(
            &mut ctx,
            mesh,
            &BftOptions {
                table_level: 2,
                tangents: true,
                name: "grid".into(),
                pipeline,
                ..BftOptions::default()
            },
        )
        .expect("bft");
        let image = ctx
            .render_offscreen(&mut surf, params, SMALL)
            .expect("render");
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, params, SMALL)
            .expect("capture");
        (
            image.pixels,
            soup.records,
            surf.chunk_counts(),
            surf.table_bytes(),
        )
    };
    drop(gpu);
    out
}

/// A run under a capped storage range against the uncapped one (`what` names the case): the
/// uncapped run draws something, and both give the same image and capture bit for bit.
fn assert_same_run(
    what: &str,
    (image, capture): (&[u8], &[tessera::tess::gpu::CaptureRecord]),
    (image_c, capture_c): (&[u8], &[tessera::tess::gpu::CaptureRecord]),
) {
    assert!(image.iter().any(|&b| b != 0), "{what}: something is drawn");
    assert!(image == image_c, "{what}: images differ");
    assert_eq!(capture.len(), capture_c.len(), "{what}");
    assert!(capture == capture_c, "{what}: captures differ");
}

/// The windowed path (a 128 KiB range: several pre-pass and draw chunks; 12,800 patches) draws exactly what the
/// whole-buffer path draws, under uniform and screen-space factors and geometric normals.
#[test]
fn bft_under_a_tiny_storage_range_matches_the_whole_buffer_run() {
    let mesh = loop_grid::grid_mesh(40);
    let mut screen = FrameParams::uniform(8.0);
    screen.factors = tessera::tess::FactorPolicy::Screen { pixels: 6.0 };
    screen.geometric_normals = true;
    for params in [FrameParams::uniform(8.0), screen] {
        let (image, capture, chunks, _) = bft_run(None, &mesh, &params);
        assert_eq!(chunks, (1, 1));
        let (image_w, capture_w, chunks_w, _) = bft_run(Some(128 << 10), &mesh, &params);
        println!("chunks under a 128 KiB range: {chunks_w:?}");
        assert!(chunks_w.0 > 1 && chunks_w.1 > 2, "{chunks_w:?}");
        assert_same_run("bft windows", (&image, &capture), (&image_w, &capture_w));
    }
}

/// BFT's refinement patterns under a 128 KiB range: the faces are grouped by pattern key
/// within each draw chunk (whose windows hold only its faces), so under uniform and
/// screen-space factors, and geomorphing, the windowed run draws the same image and captures
/// the same records (in another draw order) as the whole-buffer run.
#[test]
fn bft_patterns_under_a_tiny_storage_range_match_the_whole_buffer_run() {
    let mesh = loop_grid::grid_mesh(40);
    let screen = FrameParams {
        factors: tessera::tess::FactorPolicy::Screen { pixels: 6.0 },
        ..FrameParams::uniform(8.0)
    };
    let morph = FrameParams {
        spacing: tessera::tess::Spacing::FractionalEven,
        ..screen
    };
    let sorted = |mut records: Vec<tessera::tess::gpu::CaptureRecord>| {
        records.sort_by_key(|r| {
            (
                r.patch,
                r.domain.map(f32::to_bits),
                r.position.map(f32::to_bits),
            )
        });
        records
    };
    for params in [FrameParams::uniform(8.0), screen, morph] {
        let pattern = PipelineChoice::Pattern;
        let (image, capture, chunks, _) = bft_run_on(None, &mesh, &params, pattern);
        assert_eq!(chunks, (1, 1));
        let (image_w, capture_w, chunks_w, _) =
            bft_run_on(Some(128 << 10), &mesh, &params, pattern);
        assert!(chunks_w.1 > 2, "{chunks_w:?}");
        let what = format!("bft patterns, {}", params.factors);
        assert_same_run(
            &what,
            (&image, &sorted(capture)),
            (&image_w, &sorted(capture_w)),
        );
    }
}

/// BFT's shaders read the basis-function tables by device address, so a storage range far
/// below them (an eighth of the tables of a creased cube, whose faces beside the creases need
/// private tables; the weights alone were refused above the range before) neither refuses the
/// surface nor changes it: it renders and captures bit for bit as on the uncapped device.
#[test]
fn bft_tables_beyond_the_storage_range_match_the_uncapped_run() {
    let mesh = tessera::topology::load_obj(common::data(
        "tests/data/opensubdiv/shapes/loop_cube_creases0.obj",
    ))
    .expect("shape");
    let params = FrameParams::uniform(8.0);
    let (image, capture, _, tables) = bft_run(None, &mesh, &params);
    // An eighth of the tables, in 256-byte steps (the offset alignment): the weights, most
    // of the tables, are several ranges.
    let cap = (tables / 8 / 256 * 256) as u32;
    assert!(
        cap >= 256 && tables >= 8 * cap as usize,
        "the tables ({tables} B) are eight ranges ({cap} B)"
    );
    let (image_c, capture_c, chunks_c, _) = bft_run(Some(cap), &mesh, &params);
    println!(
        "bft tables {tables} B under a {cap} B range: chunks {chunks_c:?}, {} records",
        capture.len()
    );
    assert_same_run("bft tables", (&image, &capture), (&image_c, &capture_c));
}

/// What an adaptive run gives: image, capture, (stencil dispatches, window sets), and the
/// bytes of (the largest buffer bound whole, the stencil terms).
type AdaptiveRun = (
    Vec<u8>,
    Vec<tessera::tess::gpu::CaptureRecord>,
    (usize, usize),
    (u64, u64),
);

fn adaptive_run(cap: Option<u32>, mesh: &ControlMesh, params: &FrameParams) -> AdaptiveRun {
    let gpu = capped(cap);
    let out = {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mut surf = adaptive::new(
            &mut ctx,
            mesh,
            &PlanBuild {
                isolation: 2,
                name: "creases0".into(),
                ..Default::default()
            },
        )
        .expect("adaptive");
        let image = ctx
            .render_offscreen(&mut surf, params, SMALL)
            .expect("render");
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, params, SMALL)
            .expect("capture");
        let g = &surf.gpu;
        let whole = [
            g.vertex_bytes(),
            g.patches.len() as u64 * 48,
            g.control_points.len() as u64 * 4,
            g.curves.len() as u64 * 16,
            g.num_base_vertices as u64 * 12,
        ];
        let sizes = (
            whole.into_iter().max().unwrap_or(0),
            g.stencils.terms.len() as u64 * 8,
        );
        (image.pixels, soup.records, surf.chunk_counts(), sizes)
    };
    drop(gpu);
    out
}

/// Adaptive's stencil kernel under a storage range smaller than its stencil terms (chunks of
/// rows, each bound to its windows of the offsets and terms, non-zero bases) computes exactly
/// the vertices of the whole-buffer run: the images and captures are bit-identical.
#[test]
fn adaptive_under_a_small_storage_range_matches_the_whole_buffer_run() {
    let mesh = tessera::topology::load_obj(common::data(
        "tests/data/opensubdiv/shapes/catmark_cube_creases0.obj",
    ))
    .expect("shape");
    let params = FrameParams::uniform(4.0);
    let (image, capture, chunks, (whole, terms)) = adaptive_run(None, &mesh, &params);
    assert_eq!(chunks.1, 1, "uncapped: one window set");
    // A range just above the largest array (the vertices), rounded up to 256 bytes: the
    // stencil rows still need several windows of it.
    let cap = whole.div_ceil(256) * 256;
    println!("largest array {whole} B, stencil terms {terms} B, cap {cap} B");
    // The rows are 1.8 times the largest array (the vertices) since the regular corners and
    // the curve points have none; no shape in tests/data has over 2.2.
    assert!(
        2 * terms > 3 * cap,
        "the terms ({terms} B) need several windows of {cap} B"
    );
    let (image_w, capture_w, chunks_w, _) = adaptive_run(Some(cap as u32), &mesh, &params);
    println!("chunks under a {cap} B range: {chunks_w:?} (uncapped {chunks:?})");
    assert!(chunks_w.1 >= 2 && chunks_w.0 > chunks.0, "{chunks_w:?}");
    assert_same_run(
        "adaptive stencils",
        (&image, &capture),
        (&image_w, &capture_w),
    );
}

/// The planned-patch technique `which` of `mesh` ("adaptive" at isolation 2, "gregory" or
/// "acc"), rendered and captured under `params` on a device capped at `cap`: (image, capture,
/// vertex buffer bytes).
fn planned_run(
    cap: Option<u32>,
    which: &str,
    mesh: &ControlMesh,
    params: &FrameParams,
) -> (Vec<u8>, Vec<tessera::tess::gpu::CaptureRecord>, u64) {
    use tessera::topology::patches::adaptive::single_pass::SinglePassPatch;
    let gpu = capped(cap);
    let out = {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let maps = Default::default();
        let single = |ctx: &mut Context, patch| {
            planned_patches::single_pass(
                ctx,
                mesh,
                &planned_patches::SinglePassBuild {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles: true,
                    name: which,
                    maps: &maps,
                    path: tessera::tess::DrawPath::Tessellation,
                },
            )
        };
        let mut surf = match which {
            "gregory" => single(&mut ctx, SinglePassPatch::Gregory),
            "acc" => single(&mut ctx, SinglePassPatch::Acc1),
            _ => adaptive::new(
                &mut ctx,
                mesh,
                &PlanBuild {
                    isolation: 2,
                    name: which.into(),
                    ..Default::default()
                },
            ),
        }
        .unwrap_or_else(|e| panic!("{which} under a range of {cap:?} B: {e}"));
        let image = ctx
            .render_offscreen(&mut surf, params, SMALL)
            .expect("render");
        let (soup, _) = capturer
            .capture(&mut ctx, &mut surf, params, SMALL)
            .expect("capture");
        (image.pixels, soup.records, surf.gpu.vertex_bytes())
    };
    drop(gpu);
    out
}

/// The canonical kernel and the draw read the vertex buffer and the patch arrays by device
/// address, so a storage range far below the vertex buffer (a 12,946-triangle CAD mesh at
/// isolation 4 has 139 MB of vertices against lavapipe's 128 MiB) changes nothing: adaptive,
/// gregory and acc (regular, Gregory, Gregory-triangle and ACC-1 patches, creases) render and
/// capture bit for bit as on the uncapped device. Only the stencil evaluator still binds
/// descriptors, in windows of the range.
#[test]
fn planned_patches_beyond_the_storage_range_match_the_uncapped_run() {
    let cube = tessera::topology::load_obj(common::data(
        "tests/data/opensubdiv/shapes/catmark_cube_creases0.obj",
    ))
    .expect("shape");
    let pyramid = tessera::topology::load_obj(common::data(
        "tests/data/opensubdiv/shapes/catmark_pyramid_creases0.obj",
    ))
    .expect("shape");
    let params = FrameParams::uniform(4.0);
    for (which, mesh) in [
        ("adaptive", &cube),
        ("gregory", &pyramid),
        ("acc", &pyramid),
    ] {
        let (image, capture, vertex_bytes) = planned_run(None, which, mesh, &params);
        // A quarter of the vertex buffer, in 256-byte steps (the offset alignment).
        let cap = (vertex_bytes / 4 / 256 * 256) as u32;
        assert!(
            cap >= 256 && vertex_bytes >= 4 * cap as u64,
            "{which}: the vertex buffer ({vertex_bytes} B) is four ranges ({cap} B)"
        );
        let (image_c, capture_c, _) = planned_run(Some(cap), which, mesh, &params);
        println!(
            "{which}: {vertex_bytes} B of vertices under a {cap} B range, {} records",
            capture.len()
        );
        assert_same_run(which, (&image, &capture), (&image_c, &capture_c));
    }
}

/// Doo-Sabin of `mesh` at `segments` (level log2 S) rendered and captured on a device capped
/// at `cap`: (image, capture, bytes of the deepest level's points and of its corner table).
fn doo_sabin_run(
    cap: Option<u32>,
    mesh: &ControlMesh,
    segments: f32,
) -> (Vec<u8>, Vec<tessera::tess::gpu::CaptureRecord>, (u64, u64)) {
    let gpu = capped(cap);
    let out = {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let mut surf = common::build_with(
            &mut ctx,
            tessera::tess::TechniqueId::DOO_SABIN,
            mesh,
            1,
            false,
        );
        let params = FrameParams::uniform(segments);
        let image = ctx
            .render_offscreen(surf.as_mut(), &params, SMALL)
            .unwrap_or_else(|e| panic!("doo-sabin under a range of {cap:?} B: {e}"));
        let (soup, _) = capturer
            .capture(&mut ctx, surf.as_mut(), &params, SMALL)
            .expect("capture");
        let points = surf.patch_arrays()[0].patches as u64;
        (image.pixels, soup.records, (16 * points, 32 * points))
    };
    drop(gpu);
    out
}

/// Doo-Sabin's vertex stage reads the deepest level's points and its corner table by device
/// address, so a storage range far below both (a quarter of the points) changes nothing: the
/// level is drawn and captured bit for bit as on the uncapped device (the stencil evaluator
/// windows the refined vertex buffer it writes).
#[test]
fn doo_sabin_beyond_the_storage_range_matches_the_uncapped_run() {
    let mut mesh = tessera::topology::load_obj(common::data(
        "tests/data/opensubdiv/shapes/catmark_pyramid_creases0.obj",
    ))
    .expect("shape");
    // Doo-Sabin refuses sharpness tags: the pyramid's creases are dropped.
    mesh.creases.clear();
    let (image, capture, (points, corners)) = doo_sabin_run(None, &mesh, 16.0);
    // A quarter of the points, in 256-byte steps (the offset alignment).
    let cap = (points / 4 / 256 * 256) as u32;
    assert!(
        cap >= 256 && points >= 4 * cap as u64 && corners > points,
        "the points ({points} B) are four ranges ({cap} B)"
    );
    let (image_c, capture_c, _) = doo_sabin_run(Some(cap), &mesh, 16.0);
    println!(
        "doo-sabin level 4: {points} B of points, {corners} B of corners under a {cap} B range, \
         {} records",
        capture.len()
    );
    assert_same_run("doo-sabin", (&image, &capture), (&image_c, &capture_c));
}

/// A descriptor write whose range exceeds the (capped) device limit is a typed error, and one
/// inside it at an offset is accepted: no silent overrun is possible.
#[test]
fn a_storage_write_beyond_the_range_is_refused() {
    let gpu = capped(Some(1024));
    {
        let device = gpu.device();
        assert_eq!(device.info.caps.max_storage_buffer_range, 1024);
        let layout = DescriptorSetLayout::new(
            device,
            "scale test layout",
            &[BindingDesc {
                binding: 0,
                ty: vk::DescriptorType::STORAGE_BUFFER,
                stages: vk::ShaderStageFlags::COMPUTE,
            }],
        )
        .expect("layout");
        let pool = DescriptorPool::new(device, "scale test pool", &layout, 1).expect("pool");
        let set = pool.allocate_set(&layout).expect("set");
        let buffer = Buffer::new(
            device,
            &BufferDesc {
                name: "scale test buffer",
                size: 4096,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
        )
        .expect("buffer");
        let range_error = |e: VkError| {
            matches!(
                e,
                VkError::Descriptor {
                    problem: DescriptorError::Range {
                        size: 4096,
                        max: 1024,
                        ..
                    },
                    ..
                }
            )
        };
        let e = set
            .write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, &buffer)
            .expect_err("whole buffer beyond the range");
        assert!(range_error(e));
        let align = device.info.caps.min_storage_buffer_offset_alignment;
        set.write_buffer_range(
            0,
            vk::DescriptorType::STORAGE_BUFFER,
            &buffer,
            4 * align,
            1024,
        )
        .expect("a window inside the range");
        let e = set
            .write_buffer_range(
                0,
                vk::DescriptorType::STORAGE_BUFFER,
                &buffer,
                4096 - 512,
                1024,
            )
            .expect_err("a window past the end");
        assert!(matches!(
            e,
            VkError::Descriptor {
                problem: DescriptorError::Window { .. },
                ..
            }
        ));
    }
    drop(gpu);
}

/// The 1M-face grid: `nx × ny` quads over the unit square with a gentle height field, split
/// into two triangles each when `triangles` (tools/grid.py writes the same meshes as OBJ).
fn grid(nx: u32, ny: u32, triangles: bool) -> ControlMesh {
    let mut pos = Vec::with_capacity(((nx + 1) * (ny + 1)) as usize);
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (i as f64 / nx as f64, j as f64 / ny as f64);
            pos.push([x, y, 0.05 * (6.0 * x).sin() * (5.0 * y).cos()]);
        }
    }
    let row = nx + 1;
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let v = j * row + i;
            let (a, b, c, d) = (v, v + 1, v + row + 1, v + row);
            if triangles {
                faces.push(vec![a, b, c]);
                faces.push(vec![a, c, d]);
            } else {
                faces.push(vec![a, b, c, d]);
            }
        }
    }
    ControlMesh::from_polygons(pos, &faces)
}

/// The topology error a build failed with, if it failed on the mesh.
fn topology_error(e: &tessera::tess::TessError) -> Option<&tessera::topology::TopologyError> {
    let tessera::tess::TessError::Mesh { source, .. } = e else {
        panic!("not a mesh error: {e}")
    };
    source.downcast_ref::<tessera::topology::TopologyError>()
}

/// Flat, Phong, PN and BFT draw the 1,001,112-triangle grid validation-clean at a
/// small viewport (BFT's tangent terms, patch headers and rings exceed lavapipe's 128 MiB
/// storage range: the windowed path), and adaptive the 1M-quad grid (its stencil terms, 264 MB,
/// are windowed by rows); adaptive on the triangle grid is refused by the plan's size bound
/// with a typed error naming the mesh size and the isolation; Gregory and ACC-1 draw the
/// 1M-quad grid and refuse the triangle grid by their end caps' bound. One test, so the meshes are built once and the runs never overlap
/// in memory. Prints each build and frame time (the CI cost).
#[test]
#[ignore = "sweep tier (1M faces): tools/test.sh sweeps"]
fn one_million_faces_through_every_technique() {
    use tessera::tess::TechniqueId;
    let t = std::time::Instant::now();
    let tri = grid(708, 707, true);
    let quad = grid(1000, 1000, false);
    assert_eq!(tri.num_faces(), 1_001_112);
    assert_eq!(quad.num_faces(), 1_000_000);
    println!("grids: {:.1} s", t.elapsed().as_secs_f64());
    let tiny = vk::Extent2D {
        width: 64,
        height: 48,
    };
    // Capped at lavapipe's 128 MiB storage range, so the windowed path is taken on any device
    // (NVIDIA's range is 4 GiB: one chunk would hold the grid).
    let gpu = capped(Some(128 << 20));
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        for (id, mesh, segments) in [
            (TechniqueId::FLAT, &tri, 1.0),
            (TechniqueId::PHONG, &tri, 1.0),
            (TechniqueId::PN, &tri, 1.0),
            (TechniqueId::BFT, &tri, 2.0),
        ] {
            let t = std::time::Instant::now();
            // BFT built directly, to see its chunking (table level 1 either way).
            let (mut technique, chunks): (Box<dyn Technique>, _) = if id == TechniqueId::BFT {
                let b = Bft::new(
                    &mut ctx,
                    mesh,
                    &BftOptions {
                        table_level: 1,
                        tangents: false,
                        name: "1M grid".into(),
                        ..BftOptions::default()
                    },
                )
                .expect("bft");
                let chunks = b.chunk_counts();
                (Box::new(b), Some(chunks))
            } else {
                (common::build_with(&mut ctx, id, mesh, 1, false), None)
            };
            let built = t.elapsed().as_secs_f64();
            let t = std::time::Instant::now();
            let image = ctx
                .render_offscreen(technique.as_mut(), &FrameParams::uniform(segments), tiny)
                .unwrap_or_else(|e| panic!("{id}: {e}"));
            let frame = t.elapsed().as_secs_f64();
            println!(
                "{id}: {} faces, build {built:.1} s, frame {frame:.1} s",
                mesh.num_faces()
            );
            // The camera frames the mesh with a margin: the corner pixel is the clear colour.
            let clear = &image.pixels[..4];
            let lit = image.pixels.chunks_exact(4).filter(|p| p != &clear).count();
            assert!(lit > 64 * 48 / 8, "{id}: the grid covers {lit} pixels");
            if let Some(chunks) = chunks {
                println!("bft chunks (pre-pass, draw): {chunks:?}");
                assert!(
                    chunks.1 > 1,
                    "the patch buffers exceed 128 MiB: several draw chunks"
                );
            }
        }
        // Adaptive on the 1M-quad grid: the vertex and patch buffers are bound whole. Its
        // stencil terms (276 KB: the refinement around its four corners) fit the range since
        // its regular corners and curve points have no rows (they were 264 MB, two window
        // sets); windows are checked under a small range above and in the pre-pass's test.
        let t = std::time::Instant::now();
        let mut surf = adaptive::new(
            &mut ctx,
            &quad,
            &PlanBuild {
                name: "1M quad grid".into(),
                ..Default::default()
            },
        )
        .expect("adaptive");
        let built = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let image = ctx
            .render_offscreen(&mut surf, &FrameParams::uniform(1.0), tiny)
            .expect("adaptive render");
        let frame = t.elapsed().as_secs_f64();
        let chunks = surf.chunk_counts();
        println!(
            "adaptive: {} faces, isolation {}, build {built:.1} s, frame {frame:.1} s, \
             stencil terms {} B, (dispatches, window sets) {chunks:?}",
            quad.num_faces(),
            surf.plan.isolation,
            surf.gpu.stencils.terms.len() * 8,
        );
        let clear = &image.pixels[..4];
        let lit = image.pixels.chunks_exact(4).filter(|p| p != &clear).count();
        assert!(lit > 64 * 48 / 8, "adaptive: the grid covers {lit} pixels");
        let terms = surf.gpu.stencils.terms.len() as u64 * 8;
        assert_eq!(
            chunks.1 > 1,
            terms > 128 << 20,
            "several window sets exactly when the stencil terms exceed 128 MiB"
        );
        drop(surf);
        // Adaptive on the 1M-triangle grid (every vertex extraordinary under Catmull-Clark):
        // refused by the plan's size bound before refining, never an allocation abort.
        let t = std::time::Instant::now();
        let e = adaptive::new(
            &mut ctx,
            &tri,
            &PlanBuild {
                name: "1M triangle grid".into(),
                ..Default::default()
            },
        )
        .map(|_| ())
        .expect_err("the 1M-triangle grid at isolation 4 is beyond the bound");
        println!(
            "adaptive on triangles: refused in {:.1} s: {e}",
            t.elapsed().as_secs_f64()
        );
        assert!(
            matches!(
                topology_error(&e),
                Some(tessera::topology::TopologyError::AdaptiveTooLarge {
                    faces: 1_001_112,
                    isolation: 4,
                    ..
                })
            ),
            "{e}"
        );
        // The single-pass approximations: one patch per quad of the 1M-quad grid; on the
        // triangle grid (3M Gregory patches after the split, ~5.7e8 point-stencil terms, which
        // took 24 GB before the OOM killer) refused by the Gregory bound before building any.
        for id in [TechniqueId::GREGORY, TechniqueId::ACC] {
            let t = std::time::Instant::now();
            let mut surf = common::build_with(&mut ctx, id, &quad, 1, false);
            let built = t.elapsed().as_secs_f64();
            let image = ctx
                .render_offscreen(surf.as_mut(), &FrameParams::uniform(1.0), tiny)
                .unwrap_or_else(|e| panic!("{id}: {e}"));
            println!("{id}: {} faces, build {built:.1} s", quad.num_faces());
            let clear = &image.pixels[..4];
            let lit = image.pixels.chunks_exact(4).filter(|p| p != &clear).count();
            assert!(lit > 64 * 48 / 8, "{id}: the grid covers {lit} pixels");
            drop(surf);
            let t = std::time::Instant::now();
            let e = tessera::tess::build(
                &mut ctx,
                id,
                &tri,
                &tessera::tess::BuildOptions {
                    name: "1M triangle grid".into(),
                    ..Default::default()
                },
            )
            .map(|_| ())
            .expect_err("3M Gregory patches are beyond the bound");
            println!(
                "{id} on triangles: refused in {:.1} s: {e}",
                t.elapsed().as_secs_f64()
            );
            assert!(
                matches!(
                    topology_error(&e),
                    Some(tessera::topology::TopologyError::GregoryTooLarge {
                        faces: 1_001_112,
                        patches: 3_003_336,
                        ..
                    })
                ),
                "{e}"
            );
        }
    }
    drop(gpu);
}
