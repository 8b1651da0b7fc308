//! Doo-Sabin's boundary rule: every refined level's boundary polygon is Chaikin's refinement of
//! the level before it (starting from the control mesh's boundary polygon), so the boundary
//! curve is the quadratic B-spline of the control boundary.

use std::collections::HashSet;
use std::path::PathBuf;
use topology::refine::{refine_uniform, Level};
use topology::{load_obj, ControlMesh, Scheme};

fn shape(name: &str) -> ControlMesh {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../tests/data/opensubdiv/shapes/{name}.obj"));
    load_obj(p).unwrap()
}

/// The boundary edges of a level, each as its two end positions.
fn boundary_edges(level: &Level) -> Vec<[[f64; 3]; 2]> {
    let t = &level.topology;
    (0..t.num_edges())
        .filter(|&e| t.is_boundary_edge(e))
        .map(|e| t.edge_vertices(e).map(|v| level.positions[v as usize]))
        .collect()
}

/// A position rounded to 1e-9 (the stencils and Chaikin's weights sum in different orders).
fn key(p: [f64; 3]) -> [i64; 3] {
    p.map(|c| (c * 1e9).round() as i64)
}

#[test]
fn each_boundary_polygon_is_chaikins_refinement_of_the_last() {
    for name in [
        "catmark_hole_test2",
        "catmark_tent",
        "loop_xord_boundary",
        "catmark_xord_boundary",
    ] {
        let r = refine_uniform(&shape(name), Scheme::DooSabin, 4).unwrap();
        for d in 0..4 {
            let parent = boundary_edges(r.level(d));
            let child = boundary_edges(r.level(d + 1));
            assert!(!parent.is_empty(), "{name}");
            // Chaikin: two points per edge, (3a + b)/4 and (a + 3b)/4; the child polygon has
            // one edge per parent edge (between its two points) and one per parent vertex.
            let mut want: HashSet<[i64; 3]> = HashSet::new();
            for [a, b] in &parent {
                for (p, q) in [(a, b), (b, a)] {
                    want.insert(key([0, 1, 2].map(|k| 0.75 * p[k] + 0.25 * q[k])));
                }
            }
            let got: HashSet<[i64; 3]> = child.iter().flatten().map(|&p| key(p)).collect();
            assert_eq!(got, want, "{name} level {}", d + 1);
            assert_eq!(child.len(), 2 * parent.len(), "{name} level {}", d + 1);
        }
    }
}
