//! Loop basis-function-table preparation (`prepare_loop_bft`: one uniform refinement, patch
//! records, shared and private tables) of structured meshes, fan-triangulated as the BFT
//! technique does. For accepted input: level-1 points, stencils, tangent stencils and table
//! weights are finite, and the CPU shader emulation gives a finite position and normal at
//! every dyadic table point of every face.
//! Bounds: `MeshSpec` (≤ 72 faces), coordinates within `MAX_COORD`, table level 1 (2 for
//! meshes of at most 24 triangles, 3 for at most 8).
#![no_main]

use libfuzzer_sys::fuzz_target;
use tessera_fuzz::{all_finite, positions_in_range, MeshSpec};
use topology::patches::bft::{prepare_loop_bft, shader_eval_full};

fuzz_target!(
    init: tessera_fuzz::single_thread_rayon(),
    |data: &[u8]| {
        let Some((&knobs, rest)) = data.split_first() else {
            return;
        };
        let Some(spec) = MeshSpec::from_bytes(rest) else {
            return;
        };
        let mesh = spec.build();
        if !positions_in_range(&mesh) {
            return;
        }
        let mesh = mesh.triangulated().0;
        // Table cost grows as 4^level per distinct ring: level 1 mostly, deeper on small meshes.
        let level = match knobs & 3 {
            2 if mesh.num_faces() <= 24 => 2,
            3 if mesh.num_faces() <= 8 => 3,
            _ => 1,
        };
        let tangents = knobs & 4 == 0;
        let Ok(bft) = prepare_loop_bft(&mesh, level, tangents) else {
            return;
        };
        assert!(all_finite(&bft.level1.points), "non-finite level-1 point");
        for i in 0..bft.stencils.len() {
            assert!(all_finite(bft.stencils.stencil(i).1));
        }
        let ts = &bft.tangent_stencils;
        assert_eq!(ts.indices.len(), ts.t1.len());
        assert_eq!(ts.indices.len(), ts.t2.len());
        assert!(ts.offsets.windows(2).all(|w| w[0] <= w[1]));
        assert!(ts
            .offsets
            .last()
            .is_none_or(|&end| end as usize == ts.indices.len()));
        assert!(all_finite(&ts.t1) && all_finite(&ts.t2));
        assert!(
            bft.tables.weights.iter().all(|w| w.is_finite()),
            "non-finite table weight"
        );
        let points: Vec<[f32; 3]> = bft
            .level1
            .points
            .chunks_exact(3)
            .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
            .collect();
        let n = bft.tables.segments();
        for face in 0..bft.records.len() {
            for j in 0..=n {
                for i in 0..=n - j {
                    let Some((p, nrm)) =
                        shader_eval_full(&bft.tables, &bft.records, &points, face, i, j)
                    else {
                        panic!("no table row for face {face} point ({i}, {j})");
                    };
                    assert!(
                        p.iter().chain(&nrm).all(|x| x.is_finite()),
                        "non-finite shader output at face {face} ({i}, {j}): {p:?} {nrm:?}"
                    );
                }
            }
        }
    }
);
