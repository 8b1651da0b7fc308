//! The BFT GPU layout ([`GpuBft`], `glsl/bft/bft.glsl`): the TES's evaluation
//! ([`GpuBft::eval_tess`], the f32 mirror of `glsl/bft/bft.tese`) at the points the triangle
//! tessellator makes: exact at every vertex of power-of-two factors, bit-identical across shared
//! edges for any edge parameter; and packing that validates and points every patch at its ring.
//! (Moved from topology with the packing: topology hands over plain data, tess lays it out.)

use std::collections::HashMap;
use tess::techniques::bft::layout::{owner_face, pack_owner, GpuBft};
use topology::load_obj;
use topology::patches::bft::{prepare_loop_bft, tessellator_interior_points, LoopBft};

#[path = "../../../tests/support/loop_grid.rs"]
mod loop_grid;
use loop_grid::grid_mesh;

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);

/// 16.16 fixed point, as the tessellator hands coordinates to the TES.
fn fx(x: f64) -> f32 {
    ((x * 65536.0).round() / 65536.0) as f32
}

/// Tess coords (weights of v0, v1, v2) of a uniform level `s`: the outer ring and the interior
/// rings of the tessellator.
fn uniform_coords(s: u32) -> Vec<[f32; 3]> {
    let mut out = Vec::new();
    let sf = s as f64;
    for e in 0..3 {
        for k in 0..s {
            let mut b = [0.0f64; 3];
            b[e] = 1.0 - k as f64 / sf;
            b[(e + 1) % 3] = k as f64 / sf;
            out.push(b);
        }
    }
    for (a, c) in tessellator_interior_points(s) {
        let (u, v) = (a as f64 / (3.0 * sf), c as f64 / (3.0 * sf));
        out.push([1.0 - u - v, u, v]);
    }
    out.into_iter()
        .map(|b| {
            let (u, v) = (fx(b[1]), fx(b[2]));
            // The third weight as the TES sees it: 1 − u − v of the fixed-point pair.
            [1.0 - u - v, u, v]
        })
        .collect()
}

fn load(name: &str, level: u32) -> (LoopBft, GpuBft, f64) {
    let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape");
    let bft = prepare_loop_bft(&mesh, level, true).unwrap_or_else(|e| panic!("{name}: {e}"));
    let gpu = GpuBft::new(&bft).expect("packs");
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &mesh.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    (bft, gpu, diag)
}

fn level1_f32(bft: &LoopBft) -> Vec<[f32; 4]> {
    (0..bft.level1.num_vertices() as u32)
        .map(|v| {
            let p = bft.level1.point(v);
            [p[0] as f32, p[1] as f32, p[2] as f32, 0.0]
        })
        .collect()
}

fn check_exact(name: &str, level: u32, levels: &[u32]) {
    let (bft, gpu, diag) = load(name, level);
    let pos = level1_f32(&bft);
    let nrm = gpu.normals(&pos);
    let mut worst = 0.0f64;
    for f in 0..bft.records.len() {
        for &s in levels {
            for b in uniform_coords(s) {
                let t = gpu.eval_tess(&pos, &nrm, f, b, false);
                assert!(t.exact, "{name} face {f} s {s} {b:?} not a table point");
                let fb = bft.face_barycentric(f, b[1] as f64, b[2] as f64);
                let e = bft.level1.evaluate(f, fb[1], fb[2]).expect("eval");
                for k in 0..3 {
                    worst = worst.max((t.position[k] as f64 - e.position[k]).abs() / diag);
                }
            }
        }
    }
    println!("{name}: worst |GPU emulation − exact limit| / diagonal = {worst:.2e}");
    assert!(worst < 1e-5, "{name}: {worst}");
}

#[test]
fn every_uniform_tess_vertex_is_exact_cube_icosahedron() {
    check_exact("loop_cube", 5, &[1, 2, 4, 8, 16, 32]);
    check_exact("loop_icosahedron", 4, &[1, 2, 4, 8, 16]);
}

#[test]
fn every_uniform_tess_vertex_is_exact_boundaries() {
    check_exact("loop_xord_boundary", 3, &[1, 2, 4, 8]);
    check_exact("loop_triangle_edgeonly", 3, &[2, 8]);
    check_exact("loop_saddle_edgeonly", 3, &[4, 8]);
}

#[test]
fn every_uniform_tess_vertex_is_exact_high_valence() {
    check_exact("loop_pole64", 3, &[2, 8]);
}

/// Points of a shared edge at any parameter (fractional factors) come out bit-identical from
/// both faces, and interior non-table points are flagged as interpolated.
#[test]
fn fractional_edge_points_are_bit_identical() {
    let (bft, gpu, _) = load("loop_cube", 3);
    let pos = level1_f32(&bft);
    let nrm = gpu.normals(&pos);
    let mut seen: HashMap<(u32, u32, u32), [u32; 6]> = HashMap::new();
    let mut compared = 0;
    let params: Vec<f32> = (1..40)
        .flat_map(|k| {
            let t = fx(k as f64 * 0.0247 + 0.003);
            [t, 1.0 - t]
        })
        .collect();
    for (f, r) in bft.records.iter().enumerate() {
        for e in 0..3 {
            for &t in &params {
                let mut b = [0.0f32; 3];
                let (from, to) = (e, (e + 1) % 3);
                b[to] = t;
                b[from] = 1.0 - t;
                let s = gpu.eval_tess(&pos, &nrm, f, b, false);
                let (va, vb) = (r.corners[from], r.corners[to]);
                // The point's identity: the edge and the parameter from its smaller vertex.
                let key = if va < vb {
                    (va, vb, t.to_bits())
                } else {
                    (vb, va, (1.0 - t).to_bits())
                };
                let bits = [
                    s.position[0].to_bits(),
                    s.position[1].to_bits(),
                    s.position[2].to_bits(),
                    s.normal[0].to_bits(),
                    s.normal[1].to_bits(),
                    s.normal[2].to_bits(),
                ];
                if let Some(prev) = seen.insert(key, bits) {
                    assert_eq!(prev, bits, "edge point {key:?} differs");
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 100, "{compared}");
    let inner = gpu.eval_tess(
        &pos,
        &nrm,
        0,
        [1.0 - fx(0.31) - fx(0.29), fx(0.31), fx(0.29)],
        false,
    );
    assert!(
        !inner.exact,
        "an off-grid interior point is interpolated: {inner:?}"
    );
}

/// The level-1 positions the compute pass makes (same stencils) match the CPU refinement, and
/// limit normals point outward on a closed mesh.
#[test]
fn compute_pass_mirror_matches_refinement() {
    let mesh = load_obj(format!("{DATA}loop_icosahedron.obj")).expect("shape");
    let bft = prepare_loop_bft(&mesh, 2, false).expect("covered");
    let gpu = GpuBft::new(&bft).expect("packs");
    let base: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect();
    let l1 = gpu.subdivide(&base);
    for (v, p) in l1.iter().enumerate() {
        let q = bft.level1.point(v as u32);
        for k in 0..3 {
            assert!((p[k] as f64 - q[k]).abs() < 1e-6);
        }
    }
    let n = gpu.normals(&l1);
    for (p, n) in l1.iter().zip(&n) {
        // The icosahedron is centred at the origin: outward means along the position.
        let d = p[0] * n[0] + p[1] * n[1] + p[2] * n[2];
        assert!(d > 0.0, "inward normal");
    }
}

/// Out-of-range indices never reach the GPU: a corrupted ring index fails validation.
#[test]
fn validation_rejects_out_of_range_indices() {
    let (_, mut gpu, _) = load("loop_tetrahedron", 2);
    gpu.validate().expect("valid");
    let ring_start = gpu.patches[0].ring_offset as usize;
    gpu.patch_rings[ring_start] = gpu.level1_vertices;
    assert!(gpu.validate().is_err());
    let (_, mut gpu, _) = load("loop_tetrahedron", 2);
    let last = gpu.stencils.terms.len() - 1;
    gpu.stencils.terms[last].index = gpu.base_vertices + 7;
    assert!(gpu.validate().is_err());
    let (_, mut gpu, _) = load("loop_tetrahedron", 2);
    gpu.patches[0].edge_owner[0] = pack_owner(9999, 0);
    assert!(gpu.validate().is_err());
}

/// Every crease-free Loop shape of the test data prepares for the GPU: faces no shared table
/// covers (overlapping rings, corner triangles, "edges and corners" corners) get private
/// tables, and every level-1 vertex gets a normal stencil.
#[test]
fn every_crease_free_loop_shape_is_covered() {
    for name in [
        "loop_cube",
        "loop_icosahedron",
        "loop_pole64",
        "loop_pole8",
        "loop_xord_interior",
        "loop_xord_boundary",
        "loop_tetrahedron",
        "loop_cube_asymmetric",
        "loop_toroidal_tet",
        "loop_saddle_edgeonly",
        "loop_triangle_edgeonly",
        "loop_saddle_edgecorner",
        "loop_triangle_edgecorner",
    ] {
        let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape");
        let bft = prepare_loop_bft(&mesh, 2, false).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(bft.records.len(), 4 * mesh.num_faces(), "{name}");
        GpuBft::new(&bft).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// One header per patch with its six owners, every ring back to back, and a header that
/// points at its own ring (what topology's `pack_patches` test asserted of the packing).
#[test]
fn prepare_and_pack_for_the_gpu() {
    let mesh = grid_mesh(4);
    let bft = prepare_loop_bft(&mesh, 2, true).expect("grid is covered");
    assert_eq!(bft.records.len(), bft.level1.num_faces());
    let packed = GpuBft::new(&bft).expect("packed");
    assert_eq!(packed.patches.len(), bft.records.len());
    for (h, r) in packed.patches.iter().zip(bft.records.iter()) {
        assert_eq!(
            h.edge_owner,
            r.edge_owner.map(|o| pack_owner(o.face(), o.local()))
        );
        assert_eq!(
            h.corner_owner,
            r.corner_owner.map(|o| pack_owner(o.face(), o.local()))
        );
        assert!(h
            .corner_owner
            .iter()
            .all(|&o| (owner_face(o) as usize) < bft.records.len()));
    }
    let total: usize = bft.records.iter().map(|r| r.ring_size as usize).sum();
    assert_eq!(packed.patch_rings.len(), total);
    // Header of face 1 points at its ring.
    let r = bft.records.ring(1);
    let off = packed.patches[1].ring_offset as usize;
    assert_eq!(packed.patches[1].ring_size as usize, r.len());
    assert_eq!(&packed.patch_rings[off..off + r.len()], r);
}
