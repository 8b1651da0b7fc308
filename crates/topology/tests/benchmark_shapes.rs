//! OpenSubdiv's benchmark shapes (`catmark_car`, `catmark_bishop`, `catmark_pawn`, the meshes its
//! `far_perf` times) load and refine: the counts of the files, a manifold at every level (Euler
//! characteristic kept), quads from level 1 on, and their sharpness-6 creases decaying by one
//! per level along twice as many edges.

use topology::refine::{refine_uniform, Level};
use topology::rules::is_semi_sharp;
use topology::{load_obj, Scheme};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);

fn euler(l: &Level) -> i64 {
    l.num_vertices() as i64 - l.topology.num_edges() as i64 + l.num_faces() as i64
}

fn semi_sharp_edges(l: &Level) -> Vec<f32> {
    (0..l.topology.num_edges())
        .filter(|&e| !l.topology.is_boundary_edge(e))
        .map(|e| l.edge_sharpness[e])
        .filter(|&s| is_semi_sharp(s))
        .collect()
}

#[test]
fn benchmark_shapes_load_and_refine() {
    // name, vertices, faces (triangles among them), crease tags, Euler characteristic
    for (name, vertices, faces, triangles, creases, chi) in [
        ("catmark_car", 1642, 1575, 0, 314, 37),
        ("catmark_bishop", 917, 968, 132, 224, 3),
        ("catmark_pawn", 601, 588, 0, 120, 1),
    ] {
        let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape loads");
        assert_eq!(mesh.positions.len(), vertices, "{name} vertices");
        assert_eq!(mesh.face_offsets.len() - 1, faces, "{name} faces");
        let sizes: Vec<usize> = mesh
            .face_offsets
            .windows(2)
            .map(|w| (w[1] - w[0]) as usize)
            .collect();
        assert_eq!(sizes.iter().filter(|&&n| n == 3).count(), triangles);
        assert_eq!(sizes.iter().filter(|&&n| n == 4).count(), faces - triangles);
        assert_eq!(mesh.creases.len(), creases, "{name} crease tags");
        assert!(mesh.creases.iter().all(|c| c.sharpness == 6.0));

        let r = refine_uniform(&mesh, Scheme::CatmullClark, 3).expect("refines");
        let base = r.level(0);
        assert_eq!(euler(base), chi, "{name} level 0");
        let sharp0 = semi_sharp_edges(base);
        assert_eq!(
            sharp0.len(),
            creases,
            "{name}: every crease on an interior edge"
        );
        let mut expect_faces = sizes.iter().sum::<usize>();
        for k in 1..=3 {
            let l = r.level(k);
            assert_eq!(l.num_faces(), expect_faces, "{name} level {k} faces");
            assert!(l.face_offsets().windows(2).all(|w| w[1] - w[0] == 4));
            assert_eq!(euler(l), chi, "{name} level {k}: Euler characteristic");
            let sharp = semi_sharp_edges(l);
            assert_eq!(sharp.len(), creases << k, "{name} level {k} crease edges");
            assert!(
                sharp.iter().all(|&s| s == 6.0 - k as f32),
                "{name} level {k}: sharpness decays by one per level"
            );
            assert!(l.positions.iter().flatten().all(|x| x.is_finite()));
            expect_faces *= 4;
        }
    }
}
