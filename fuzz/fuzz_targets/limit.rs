//! Exact limit evaluation (`LocalMesh::evaluate`, `evaluate_subface`, `vertex_limit_exact`,
//! `limit_point`) of structured Loop and Catmull-Clark meshes at parameters from the bytes
//! (corners, midpoints, dyadic and arbitrary fractions). For accepted input every position,
//! derivative and normal is finite.
//! Bounds: `MeshSpec` (≤ 72 faces), coordinates within `MAX_COORD`, at most 4 evaluations and
//! 2 vertex limits per input (each recursion is at most 56 local refinements).
#![no_main]

use arbitrary::Unstructured;
use libfuzzer_sys::fuzz_target;
use tessera_fuzz::{all_finite, param, positions_in_range, MeshSpec};
use topology::limit::eval::{limit_point, normal_of, LimitSample, LimitScheme, LocalMesh};

fn finite(s: &LimitSample) -> bool {
    all_finite(&s.position) && all_finite(&s.du) && all_finite(&s.dv)
}

fuzz_target!(
    init: tessera_fuzz::single_thread_rayon(),
    |data: &[u8]| {
        if data.len() < 16 {
            return;
        }
        // The first 16 bytes steer the queries; the rest is the mesh.
        let (query, rest) = data.split_at(16);
        let Some(spec) = MeshSpec::from_bytes(rest) else {
            return;
        };
        let mut u = Unstructured::new(query);
        let knobs: u8 = u.arbitrary().unwrap_or(0);
        let mut mesh = spec.build();
        if !positions_in_range(&mesh) {
            return;
        }
        let scheme = if knobs & 1 == 0 {
            LimitScheme::CatmullClark
        } else {
            if knobs & 2 == 0 {
                mesh = mesh.triangulated().0;
            }
            LimitScheme::Loop
        };
        let Ok(lm) = LocalMesh::from_control_mesh(&mesh, scheme) else {
            return;
        };
        let nf = lm.num_faces();
        for _ in 0..4 {
            let face = u.arbitrary::<u8>().unwrap_or(0) as usize % (nf + 1);
            let sub = u.arbitrary::<u8>().unwrap_or(0) as usize % 5;
            let (a, mut b) = (param(&mut u), param(&mut u));
            if scheme == LimitScheme::Loop && a + b > 1.0 {
                b = 1.0 - a;
            }
            let result = if scheme == LimitScheme::CatmullClark && face < nf && lm.face(face).len() != 4
            {
                lm.evaluate_subface(face, sub, a, b)
            } else {
                lm.evaluate(face, a, b)
            };
            if let Ok(s) = result {
                assert!(finite(&s), "non-finite limit at face {face} ({a}, {b}): {s:?}");
                let n = normal_of(
                    &[s.du[0], s.du[1], s.du[2]],
                    &[s.dv[0], s.dv[1], s.dv[2]],
                );
                assert!(all_finite(&n));
            }
        }
        for _ in 0..2 {
            let v = u.arbitrary::<u8>().unwrap_or(0) as u32 % lm.num_vertices().max(1) as u32;
            if let Ok(p) = lm.vertex_limit_exact(v) {
                assert!(all_finite(&p), "non-finite vertex limit {v}: {p:?}");
            }
        }
        if let Ok(p) = limit_point(&mesh, scheme, 0, 0.25, 0.25) {
            assert!(all_finite(&p.position) && all_finite(&p.normal));
        }
    }
);
