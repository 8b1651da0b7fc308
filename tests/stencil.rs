//! The stencil evaluator (`tess::stencil`) on the GPU, validation on: what it writes is its CPU
//! mirror's f32 sum bit for bit, in place (levels that read the levels before them, as
//! feature-adaptive refinement applies them) and from one buffer into another (as BFT's
//! initial step), whole and under a storage range smaller than every buffer it indexes (the
//! vertices included, which no window could hold before the evaluator windowed them).
mod common;
use common::Gpu;
use tessera::tess::stencil::{
    vertex_bytes, vertices, GpuStencils, StencilBlock, StencilEvaluator, StencilVertex,
    StencilVertices,
};
use tessera::tess::TessError;
use tessera::vk_core::{vk, Buffer, BufferDesc, DeviceDesc, MemoryLocation};

fn capped(cap: Option<u32>) -> Gpu {
    Gpu::with(&DeviceDesc {
        storage_buffer_range_cap: cap,
        ..DeviceDesc::default()
    })
}

/// A synthetic refinement: `base` vertices far from the origin (where anchored sums matter),
/// then `levels` levels of twice the vertices each. Row `i` of a level blends 2 to 6
/// neighbours of vertex `i / 2` of the level before it (weights summing to 1), so chunks of
/// rows reach short runs of sources, as a mesh's levels do. Returns the base positions, the
/// table and its blocks (row `r` writes vertex `base + r`).
fn levels(base: u32, levels: u32) -> (Vec<[f32; 3]>, GpuStencils, Vec<StencilBlock>) {
    let positions: Vec<[f32; 3]> = (0..base)
        .map(|i| {
            let t = i as f32;
            [
                4096.0 + (0.37 * t).sin(),
                -2048.0 + 0.01 * t,
                1024.0 + (0.11 * t).cos(),
            ]
        })
        .collect();
    let mut table = GpuStencils::default();
    let mut blocks = Vec::new();
    let (mut prev, mut prev_len) = (0u32, base);
    for _ in 0..levels {
        let first = table.rows();
        let len = 2 * prev_len;
        for i in 0..len {
            let m = 2 + i % 5;
            let centre = (i / 2) as i64;
            let idx: Vec<u32> = (0..m as i64)
                .map(|k| prev + (centre + k - 2).clamp(0, prev_len as i64 - 1) as u32)
                .collect();
            let sum: f64 = (1..=m).map(f64::from).sum();
            let w: Vec<f64> = (1..=m).map(|k| f64::from(k) / sum).collect();
            table.push_row(&idx, &w).expect("row");
        }
        blocks.push(StencilBlock {
            rows: first..first + len,
            destination: base + first,
        });
        (prev, prev_len) = (base + first, len);
    }
    (positions, table, blocks)
}

/// A storage buffer the host writes and reads back.
fn host_buffer(gpu: &Gpu, name: &str, vertices: u32) -> Buffer {
    Buffer::new(
        gpu.device(),
        &BufferDesc {
            name,
            size: vertex_bytes(vertices),
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuToCpu,
        },
    )
    .expect("buffer")
}

/// Runs `evaluator` on target 0 and waits, its writes visible to the host.
fn evaluate(gpu: &Gpu, evaluator: &StencilEvaluator) {
    gpu.device()
        .submit_once(|enc| -> tessera::tess::Result<()> {
            evaluator.record(enc, 0)?;
            enc.memory_barrier(
                (
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_WRITE,
                ),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
            Ok(())
        })
        .expect("submit")
        .expect("record");
}

/// The in-place levels on a device capped at `cap`: the vertices read back, and the
/// evaluator's (dispatches, chunks).
fn in_place(
    cap: Option<u32>,
    base: &[[f32; 3]],
    table: &GpuStencils,
    blocks: &[StencilBlock],
) -> (Vec<StencilVertex>, (usize, usize)) {
    let gpu = capped(cap);
    let out = {
        let n = base.len() as u32 + table.rows();
        let mut buffer = host_buffer(&gpu, "stencil test vertices", n);
        buffer
            .write(0, &as_bytes(&vertices(base)))
            .expect("base positions");
        let evaluator = StencilEvaluator::new(
            gpu.device(),
            "stencil test",
            table,
            blocks,
            StencilVertices {
                sources: n,
                destinations: n,
                in_place: true,
            },
            &[(&buffer, &buffer)],
        )
        .expect("evaluator");
        evaluate(&gpu, &evaluator);
        (
            buffer.read::<StencilVertex>().expect("read"),
            evaluator.counts(),
        )
    };
    drop(gpu);
    out
}

/// The CPU mirror of the in-place levels: every block in order over one vertex array.
fn mirror(base: &[[f32; 3]], table: &GpuStencils, blocks: &[StencilBlock]) -> Vec<StencilVertex> {
    let mut v = vertices(base);
    v.resize(base.len() + table.rows() as usize, [0.0; 4]);
    for b in blocks {
        for r in b.rows.clone() {
            let [x, y, z] = table.row_point(r, |i| {
                let p = v[i as usize];
                [p[0], p[1], p[2]]
            });
            v[(b.destination + r - b.rows.start) as usize] = [x, y, z, 1.0];
        }
    }
    v
}

/// Vertices as the bytes a buffer holds (little-endian f32s).
fn as_bytes(v: &[StencilVertex]) -> Vec<u8> {
    v.iter().flatten().flat_map(|c| c.to_le_bytes()).collect()
}

fn bits(v: &[StencilVertex]) -> Vec<[u32; 4]> {
    v.iter().map(|p| p.map(f32::to_bits)).collect()
}

#[test]
fn in_place_levels_are_the_mirror_bit_for_bit_whole_and_windowed() {
    let (base, table, blocks) = levels(300, 4);
    let expected = mirror(&base, &table, &blocks);
    let (whole, counts) = in_place(None, &base, &table, &blocks);
    assert_eq!(
        counts,
        (blocks.len(), 1),
        "uncapped: one dispatch per level"
    );
    assert_eq!(bits(&whole), bits(&expected), "uncapped");
    // 8 KiB: 512 vertices a window, where the buffer holds 9,300 (149 KB).
    let cap = 8 << 10;
    assert!(vertex_bytes(expected.len() as u32) > 16 * cap as u64);
    let (windowed, counts) = in_place(Some(cap), &base, &table, &blocks);
    println!("under {cap} B: (dispatches, chunks) {counts:?}");
    assert!(counts.1 > 16, "{counts:?}");
    assert_eq!(bits(&windowed), bits(&expected), "windowed");
}

/// BFT's shape: one block from a buffer of base positions into another, windowed.
#[test]
fn between_buffers_is_the_mirror_bit_for_bit_windowed() {
    let (base, all, _) = levels(2000, 1);
    let rows = all.rows();
    // Level 1 reads only the base: the same rows over the base buffer, written from 0.
    let blocks = [StencilBlock {
        rows: 0..rows,
        destination: 0,
    }];
    let gpu = capped(Some(4 << 10));
    {
        let mut source = host_buffer(&gpu, "stencil test base", base.len() as u32);
        source
            .write(0, &as_bytes(&vertices(&base)))
            .expect("base positions");
        let destination = host_buffer(&gpu, "stencil test level 1", rows);
        let evaluator = StencilEvaluator::new(
            gpu.device(),
            "stencil test",
            &all,
            &blocks,
            StencilVertices {
                sources: base.len() as u32,
                destinations: rows,
                in_place: false,
            },
            &[(&source, &destination)],
        )
        .expect("evaluator");
        assert!(evaluator.counts().1 > 8, "{:?}", evaluator.counts());
        evaluate(&gpu, &evaluator);
        let got = destination.read::<StencilVertex>().expect("read");
        let expected: Vec<StencilVertex> = (0..rows)
            .map(|r| {
                let [x, y, z] = all.row_point(r, |i| base[i as usize]);
                [x, y, z, 1.0]
            })
            .collect();
        assert_eq!(bits(&got), bits(&expected));
    }
    drop(gpu);
}

/// A row whose own reach does not fit the range is a typed error naming it, never a partial
/// binding; so is a target buffer smaller than its vertices.
#[test]
fn what_cannot_be_bound_is_refused_by_name() {
    let (base, table, blocks) = levels(64, 1);
    let n = base.len() as u32 + table.rows();
    let gpu = capped(Some(64));
    {
        let refused = |target: (&Buffer, &Buffer)| {
            let in_place = std::ptr::eq(target.0, target.1);
            StencilEvaluator::new(
                gpu.device(),
                "stencil test",
                &table,
                &blocks,
                StencilVertices {
                    sources: n,
                    destinations: n,
                    in_place,
                },
                &[target],
            )
            .err()
            .expect("refused")
        };
        let buffer = host_buffer(&gpu, "stencil test vertices", n);
        // A 64-byte range holds no row's sources.
        let e = refused((&buffer, &buffer));
        assert!(
            matches!(
                e,
                TessError::StorageWindow {
                    what: "stencil row",
                    ..
                }
            ),
            "{e}"
        );
        // A destination short of its vertices.
        let small = host_buffer(&gpu, "stencil test short", n - 1);
        let e = refused((&buffer, &small));
        assert!(e.to_string().contains("stencil test short holds"), "{e}");
    }
    drop(gpu);
}
