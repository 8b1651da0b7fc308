//! Limit masks against deep refinement: positions converge to the mask value and the
//! refined neighbours approach the tangent plane spanned by the tangent masks.

use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::limit::masks::{catmark_limit_masks, loop_limit_masks, LimitRule, LimitVertex};
use topology::refine::refine_uniform;
use topology::{load_obj, ControlMesh, Scheme};

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
    check_mesh_vertex(name, &mesh, v, levels, plane);
}

fn check_mesh_vertex(name: &str, mesh: &ControlMesh, v: u32, levels: usize, plane: bool) {
    let quad = name.starts_with("catmark");
    let (scheme, refine_scheme) = if quad {
        (LimitScheme::CatmullClark, Scheme::CatmullClark)
    } else {
        (LimitScheme::Loop, Scheme::Loop)
    };
    let r = refine_uniform(mesh, refine_scheme, levels).expect("refine");
    // Limit from level 1 (all-quad rings for Catmull-Clark).
    let l1 = LocalMesh::from_refined_level(r.level(1), scheme, &mesh.options).expect("level 1");
    let limit = l1.vertex_limit_position(v).expect("mask applies");
    let Some(f) = l1.vertex_faces(v).next().map(|f| f as usize) else {
        return;
    };
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
    let mut angle = f64::INFINITY;
    for k in 1..=levels {
        let lv = r.level(k);
        let p = lv.positions[v as usize];
        let d = norm(sub(&p, &limit));
        assert!(
            d < prev * 0.9 || d < 1e-12,
            "{name} v{v}: level {k} not converging"
        );
        prev = d;
        if plane && k + 2 >= levels && k != levels - 1 {
            // Refined neighbours approach the plane: their angle to it shrinks with the level
            // (a wrong plane leaves a constant angle).
            let lm = LocalMesh::from_refined_level(lv, scheme, &mesh.options).expect("level");
            let worst = lm
                .vertex_ring(v)
                .iter()
                .map(|&w| {
                    let q = lm.vertex_limit_position(w).expect("neighbour limit");
                    let e = sub(&q, &limit);
                    (e[0] * n[0] + e[1] * n[1] + e[2] * n[2]).abs() / norm(e)
                })
                .fold(0.0, f64::max);
            if k == levels {
                assert!(
                    worst < 1e-6 || worst < 0.7 * angle,
                    "{name} v{v}: neighbours do not approach the tangent plane ({angle} -> {worst})"
                );
            }
            angle = worst;
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
    // Boundary vertices with the crease masks (exact cross tangents).
    check_vertex("loop_saddle_edgeonly", 0, 6, true);
    check_vertex("loop_triangle_edgeonly", 0, 5, false);
    check_vertex("catmark_edgeonly", 0, 5, true);
    check_vertex("catmark_edgecorner", 0, 4, false);
}

/// Every base vertex (smooth, dart, boundary/crease of any valence) of a few shapes.
#[test]
fn all_vertices_converge_with_tangent_planes() {
    for (name, verts, levels) in [
        ("catmark_edgeonly", 16u32, 5),
        ("catmark_dart_edgeonly", 8, 5),
        ("catmark_pyramid", 5, 6),
        ("catmark_tent", 16, 5),
        ("loop_saddle_edgeonly", 6, 6),
        ("loop_triangle_edgeonly", 12, 6),
        ("loop_cube", 14, 6),
    ] {
        for v in 0..verts {
            check_vertex(name, v, levels, true);
        }
    }
}

/// Boundary vertices with two and three interior edges (Catmull-Clark L-shapes and fans):
/// the cross-boundary tangent needs Biermann et al.'s eigenvector mask there.
#[test]
fn catmark_irregular_boundary_tangent_planes() {
    // 4x4 vertex grid, bumpy, with the quads of one corner region removed so the vertex 5 has
    // three faces (two interior edges) and vertex 10 has... see below.
    let m = 4u32;
    let mut pos = Vec::new();
    for y in 0..m {
        for x in 0..m {
            let (fx, fy) = (x as f64, y as f64);
            pos.push([fx, fy, 0.2 * fx * fx - 0.15 * fy * fx + 0.1 * fy * fy * fy]);
        }
    }
    let id = |x: u32, y: u32| y * m + x;
    let mut faces = Vec::new();
    for y in 0..m - 1 {
        for x in 0..m - 1 {
            // Drop the lower-left quad: vertex (1,1) becomes a boundary vertex with 3 faces.
            if (x, y) == (0, 0) {
                continue;
            }
            faces.push(vec![id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    let mesh = ControlMesh::from_polygons(pos.clone(), &faces);
    check_mesh_vertex("catmark L-shape", &mesh, id(1, 1), 6, true);
    // A boundary vertex with 4 faces (3 interior edges): drop one more quad.
    let faces2: Vec<Vec<u32>> = faces.iter().filter(|f| f[0] != id(2, 0)).cloned().collect();
    let pos2: Vec<[f64; 3]> = pos;
    let mesh2 = ControlMesh::from_polygons(pos2, &faces2);
    check_mesh_vertex("catmark two quads removed", &mesh2, id(1, 1), 6, true);
}
