//! Feature-adaptive Catmull-Clark plan (`plan_adaptive`) of structured meshes with creases,
//! corners, holes, both end caps and any sharpness scale, and the single-pass plans of
//! `--method gregory|acc` (`plan_single_pass`: Gregory or ACC-1 patches, Gregory triangle
//! patches or split triangles), and the Doo-Sabin limit plan (`plan_doo_sabin`, on the mesh
//! without its tags, which Doo-Sabin refuses), which share the plan's data. For accepted
//! input: every stencil
//! reads only earlier vertices, every patch and curve names existing vertices, the global
//! vertex buffer is finite, and every patch evaluates to a finite point and derivatives.
//! Bounds: `MeshSpec` (≤ 72 faces), coordinates within `MAX_COORD`, isolation 1..=3; with
//! `follow_semi_sharp`, inputs whose scaled semi-sharp sharpness exceeds 4 are skipped (the
//! plan would follow them to level 10, thousands of faces per crease edge).
#![no_main]

use arbitrary::Unstructured;
use libfuzzer_sys::fuzz_target;
use tessera_fuzz::{all_finite, param, positions_in_range, MeshSpec};
use topology::patches::adaptive::single_pass::{
    plan_single_pass, SinglePassOptions, SinglePassPatch,
};
use topology::patches::adaptive::PatchKind;
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, EndCap};
use topology::patches::doo_sabin_limit::plan_doo_sabin;

fuzz_target!(
    init: tessera_fuzz::single_thread_rayon(),
    |data: &[u8]| {
        if data.len() < 8 {
            return;
        }
        let (head, rest) = data.split_at(8);
        let Some(spec) = MeshSpec::from_bytes(rest) else {
            return;
        };
        let mut u = Unstructured::new(head);
        let knobs: u8 = u.arbitrary().unwrap_or(0);
        let scale = match u.arbitrary::<u8>().unwrap_or(0) % 6 {
            0 => 0.0,
            1 => 0.5,
            2 => 2.0,
            3 => f32::from_bits(u.arbitrary().unwrap_or(0)),
            _ => 1.0,
        };
        let mesh = spec.build();
        if !positions_in_range(&mesh) {
            return;
        }
        let opts = AdaptiveOptions {
            isolation: 1 + (knobs & 3) as u32 % 3,
            end_cap: if knobs & 4 == 0 {
                EndCap::Gregory
            } else {
                EndCap::Bilinear
            },
            sharpness_scale: scale,
            follow_semi_sharp: knobs & 8 != 0,
        };
        // Scaled as the plan scales it: an infinite tag (≥ 10) counts as 10.
        let deep = |s: f32| {
            let t = if scale == 1.0 { s } else { s.min(10.0) * scale };
            t > 4.0 && t < 10.0
        };
        if opts.follow_semi_sharp
            && (mesh.creases.iter().any(|c| deep(c.sharpness))
                || mesh.corners.iter().any(|c| deep(c.sharpness)))
        {
            return;
        }
        let plan = if knobs & 128 != 0 {
            let mut untagged = mesh.clone();
            untagged.creases.clear();
            untagged.corners.clear();
            untagged.holes.clear();
            plan_doo_sabin(&untagged, opts.isolation)
        } else if knobs & 16 != 0 {
            // Single pass: semi-sharp tags are rounded, nothing is followed.
            plan_single_pass(
                &mesh,
                &SinglePassOptions {
                    patch: if knobs & 32 == 0 {
                        SinglePassPatch::Gregory
                    } else {
                        SinglePassPatch::Acc1
                    },
                    sharpness_scale: scale,
                    gregory_triangles: knobs & 64 == 0,
                },
            )
        } else {
            plan_adaptive(&mesh, &opts)
        };
        let Ok(plan) = plan else {
            return;
        };
        assert_eq!(plan.num_base_vertices as usize, mesh.positions.len());
        for block in plan.steps.iter().chain(std::iter::once(&plan.local_points)) {
            for r in 0..block.table.len() {
                let (idx, w) = block.table.stencil(r);
                assert!(idx.iter().all(|&v| v < block.first_vertex));
                assert!(all_finite(w));
            }
        }
        let nv = plan.num_vertices;
        // Control points precede the curve points, which the device computes from them, and
        // the corners it computes from their owners' points follow those points.
        for p in &plan.patches {
            assert!(p.control_points.iter().all(|&v| v < plan.first_curve_point));
        }
        assert_eq!(
            plan.first_corner as usize + plan.corner_owners.len(),
            plan.first_curve_point as usize
        );
        let regular_from = (plan.first_regular_corner - plan.first_corner) as usize;
        for &[pi, c] in &plan.corner_owners[regular_from..] {
            let pa = &plan.patches[pi as usize];
            assert!(pa.kind == PatchKind::Regular && c < 4);
            assert!(pa.control_points.iter().all(|&v| v < plan.first_regular_corner));
        }
        for (c, curve) in plan.curves.iter().enumerate() {
            assert_eq!(curve[1], plan.first_curve_point + 2 * c as u32);
            assert_eq!(curve[2], curve[1] + 1);
        }
        assert_eq!(plan.first_curve_point + 2 * plan.curves.len() as u32, nv);
        for c in &plan.curves {
            assert!(c.iter().all(|&v| v < nv));
        }
        let verts = plan.apply(&mesh.positions);
        assert_eq!(verts.len(), nv as usize);
        assert!(
            verts.iter().flatten().all(|x| x.is_finite()),
            "non-finite plan vertex"
        );
        let extra = (param(&mut u), param(&mut u));
        for k in 0..plan.patches.len() {
            for (a, b) in [(0.0, 0.0), (1.0, 1.0), (0.5, 0.5), extra] {
                let s = plan.evaluate(&verts, k, a, b);
                assert!(
                    all_finite(&s.position) && all_finite(&s.du) && all_finite(&s.dv),
                    "non-finite patch {k} at ({a}, {b}): {s:?}"
                );
            }
        }
    }
);
