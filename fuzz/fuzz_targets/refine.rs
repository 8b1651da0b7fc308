//! Uniform refinement (Loop, Catmull-Clark, bilinear, Doo-Sabin) of structured meshes with creases,
//! corners and options. For accepted input: every level's positions are finite, the composed
//! stencils have finite weights summing to 1 (refinement is affine) and reproduce the
//! refined positions, and `uniform_stencils` agrees in size.
//! Bounds: `MeshSpec` (≤ 72 faces), coordinates within `MAX_COORD`, level 1..=3 and at most
//! 4,608 faces at the deepest level (the level is lowered until it fits).
#![no_main]

use libfuzzer_sys::fuzz_target;
use tessera_fuzz::{positions_in_range, MeshSpec};
use topology::refine::{refine_uniform, uniform_stencils};
use topology::Scheme;

const MAX_REFINED_FACES: usize = 4608;

fuzz_target!(
    init: tessera_fuzz::single_thread_rayon(),
    |data: &[u8]| {
        let Some((&knobs, rest)) = data.split_first() else {
            return;
        };
        let Some(spec) = MeshSpec::from_bytes(rest) else {
            return;
        };
        let mut mesh = spec.build();
        if !positions_in_range(&mesh) {
            return;
        }
        let scheme = match knobs & 3 {
            0 => Scheme::CatmullClark,
            1 => Scheme::Loop,
            2 => Scheme::Bilinear,
            _ => Scheme::DooSabin,
        };
        if scheme == Scheme::Loop && knobs & 0x80 == 0 {
            mesh = mesh.triangulated().0;
        }
        let mut level = 1 + (knobs >> 2) as usize % 3;
        // A quad split makes an n-gon n faces, then ×4 per level.
        let first = mesh.face_vertices.len().max(mesh.num_faces() * 4);
        while level > 1 && first * 4usize.pow(level as u32 - 1) > MAX_REFINED_FACES {
            level -= 1;
        }
        let Ok(r) = refine_uniform(&mesh, scheme, level) else {
            return;
        };
        for l in r.levels() {
            assert!(
                l.positions.iter().flatten().all(|c| c.is_finite()),
                "non-finite refined position"
            );
            assert!(l.edge_sharpness.iter().all(|s| !s.is_nan()));
        }
        let deepest = r.level(level);
        let table = r.stencils(level);
        assert_eq!(table.len(), deepest.num_vertices());
        let extent = mesh
            .positions
            .iter()
            .flatten()
            .fold(1.0f64, |m, c| m.max(c.abs()));
        for (i, p) in deepest.positions.iter().enumerate() {
            let (idx, w) = table.stencil(i);
            assert!(idx.iter().all(|&v| (v as usize) < mesh.positions.len()));
            assert!(w.iter().all(|x| x.is_finite()));
            let sum: f64 = w.iter().sum();
            assert!((sum - 1.0).abs() < 1e-9, "stencil {i} sums to {sum}");
            let mut q = [0.0; 3];
            for (&v, &x) in idx.iter().zip(w) {
                for k in 0..3 {
                    q[k] += x * mesh.positions[v as usize][k];
                }
            }
            for k in 0..3 {
                assert!(
                    (q[k] - p[k]).abs() <= 1e-9 * extent,
                    "stencil {i} gives {q:?}, refinement {p:?}"
                );
            }
        }
        if let Ok(direct) = uniform_stencils(&mesh, scheme, level) {
            assert_eq!(direct.len(), table.len());
        }
    }
);
