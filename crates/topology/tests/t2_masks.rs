//! Limit masks against deep refinement: positions converge to the mask value and the
//! refined neighbours approach the tangent plane spanned by the tangent masks.

use topology::eval::{LimitScheme, LocalMesh};
use topology::limit::{catmark_limit_masks, loop_limit_masks, LimitRule, LimitVertex};
use topology::refine::refine_uniform;
use topology::{load_obj, Scheme};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);

#[test]
fn regular_masks_have_the_known_weights() {
    let l = loop_limit_masks(&LimitVertex {
        valence: 6,
        boundary: false,
        rule: LimitRule::Smooth,
    });
    assert!((l.position.vertex - 0.5).abs() < 1e-15);
    assert!(l
        .position
        .edges
        .iter()
        .all(|&w| (w - 1.0 / 12.0).abs() < 1e-15));
    let c = catmark_limit_masks(&LimitVertex {
        valence: 4,
        boundary: false,
        rule: LimitRule::Smooth,
    });
    assert!((c.position.vertex - 4.0 / 9.0).abs() < 1e-15);
    assert!(c
        .position
        .edges
        .iter()
        .all(|&w| (w - 1.0 / 9.0).abs() < 1e-15));
    assert!(c
        .position
        .faces
        .iter()
        .all(|&w| (w - 1.0 / 36.0).abs() < 1e-15));
    for n in 3..=12 {
        for lv in [
            LimitVertex {
                valence: n,
                boundary: false,
                rule: LimitRule::Smooth,
            },
            LimitVertex {
                valence: n,
                boundary: true,
                rule: LimitRule::Crease { ends: [0, n - 1] },
            },
        ] {
            for m in [loop_limit_masks(&lv), catmark_limit_masks(&lv)] {
                let sum = m.position.vertex
                    + m.position.edges.iter().sum::<f64>()
                    + m.position.faces.iter().sum::<f64>();
                assert!((sum - 1.0).abs() < 1e-14, "position mask sums to 1");
                for t in [&m.tangent1, &m.tangent2] {
                    let s = t.vertex + t.edges.iter().sum::<f64>() + t.faces.iter().sum::<f64>();
                    assert!(s.abs() < 1e-12, "tangent masks annihilate constants");
                }
            }
        }
    }
}

fn sub(a: &[f64], b: &[f64]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Vertex `v` of `name` (which keeps its index through refinement) converges to its mask
/// limit, and its refined neighbours approach the mask tangent plane.
fn check_vertex(name: &str, v: u32, levels: usize, plane: bool) {
    let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape");
    let quad = name.starts_with("catmark");
    let (scheme, t1) = if quad {
        (LimitScheme::CatmullClark, Scheme::CatmullClark)
    } else {
        (LimitScheme::Loop, Scheme::Loop)
    };
    let r = refine_uniform(&mesh, t1, levels).expect("refine");
    // Limit from level 1 (all-quad rings for Catmull-Clark).
    let l1 = LocalMesh::from_refined_level(r.level(1), scheme, &mesh.options).expect("level 1");
    let limit = l1.vertex_limit_position(v).expect("mask applies");
    let f = l1.vertex_faces(v).next().expect("a face") as usize;
    let c = l1.face(f).iter().position(|&x| x == v).expect("corner");
    let (u0, v0) = match (quad, c) {
        (_, 0) => (0.0, 0.0),
        (_, 1) => (1.0, 0.0),
        (false, _) => (0.0, 1.0),
        (true, 2) => (1.0, 1.0),
        _ => (0.0, 1.0),
    };
    let s = l1.evaluate(f, u0, v0).expect("corner evaluation");
    let n = {
        let (a, b) = (&s.du, &s.dv);
        let n = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let l = norm(n);
        [n[0] / l, n[1] / l, n[2] / l]
    };
    let mut prev = f64::INFINITY;
    for k in 1..=levels {
        let lv = r.level(k);
        let p = lv.positions[v as usize];
        let d = norm(sub(&p, &limit));
        assert!(
            d < prev * 0.9 || d < 1e-12,
            "{name} v{v}: level {k} not converging"
        );
        prev = d;
        if plane && k == levels {
            let lm = LocalMesh::from_refined_level(lv, scheme, &mesh.options).expect("level");
            for &w in lm.vertex_ring(v) {
                let q = lm.vertex_limit_position(w).expect("neighbour limit");
                let e = sub(&q, &limit);
                let cos = (e[0] * n[0] + e[1] * n[1] + e[2] * n[2]).abs() / norm(e);
                assert!(
                    cos < 0.05,
                    "{name} v{v}: neighbour off the tangent plane ({cos})"
                );
            }
        }
    }
}

#[test]
fn extraordinary_limits_and_tangent_planes() {
    check_vertex("loop_icosahedron", 0, 6, true);
    check_vertex("catmark_cube", 0, 6, true);
    check_vertex("catmark_pyramid", 4, 6, true);
    check_vertex("loop_cube", 0, 6, true);
}

#[test]
fn boundary_and_corner_limits() {
    // Boundary vertices with the crease mask (Loop: exact cross tangent as well).
    check_vertex("loop_saddle_edgeonly", 0, 6, true);
    check_vertex("loop_triangle_edgeonly", 0, 5, false);
    check_vertex("catmark_edgeonly", 0, 5, false);
    check_vertex("catmark_edgecorner", 0, 4, false);
}
