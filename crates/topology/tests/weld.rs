//! Welding coincident vertices on request (`topology::mesh::weld`): exact positions or a
//! tolerance, collapsed edges and faces, tags following their vertices, the report.
use topology::mesh::manifold::ManifoldSplit;
use topology::mesh::obj::parse_obj_with_lines;
use topology::mesh::weld::weld_vertices;
use topology::mesh::Topology;
use topology::ControlMesh;

/// Two quads side by side whose shared edge is written twice (vertices 4 and 5 repeat 1 and
/// 2): an open seam until welded.
const SEAM: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 0\nv 1 1 0\nv 2 0 0\nv 2 1 0\n\
f 1 2 3 4\nf 5 7 8 6\nt crease 2/1/0 4 5 2.0\n";

#[test]
fn an_exact_weld_closes_a_seam_and_moves_tags() {
    let (mesh, _) = parse_obj_with_lines(SEAM, "seam.obj").unwrap();
    let topology = Topology::from_mesh(&mesh).unwrap();
    let open = |t: &Topology| {
        (0..t.num_edges())
            .filter(|&e| t.is_boundary_edge(e))
            .count()
    };
    assert_eq!(open(&topology), 8, "as given: two separate quads");
    let (welded, kept, report) = weld_vertices(&mesh, 0.0);
    assert_eq!((report.groups, report.merged), (2, 2));
    assert_eq!(report.collapsed_edges, 0);
    assert_eq!(kept, vec![0, 1]);
    assert_eq!(welded.face(1), &[1, 6, 7, 2]);
    assert_eq!(
        welded.creases[0].vertices,
        [1, 2],
        "the tag follows its vertices"
    );
    assert_eq!(
        welded.positions.len(),
        8,
        "vertex numbers keep their meaning"
    );
    let t = Topology::from_mesh(&welded).unwrap();
    assert_eq!(open(&t), 6, "the seam is an interior edge");
    assert!(report
        .summary()
        .contains("welded 4 vertices at identical positions into 2"));
}

#[test]
fn a_tolerance_merges_near_vertices_and_collapses_edges() {
    // A quad with a sliver edge 3-4 (1e-4 long) and a triangle that collapses entirely.
    let mesh = ControlMesh::from_polygons(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1e-4, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0],
            [5.0, 5.0, 5.00001],
            [5.00001, 5.0, 5.0],
        ],
        &[vec![0u32, 1, 2, 3, 4], vec![5, 6, 7]],
    );
    let (exact, _, report) = weld_vertices(&mesh, 0.0);
    assert_eq!(report.merged, 0);
    assert_eq!(exact, mesh);
    let (welded, kept, report) = weld_vertices(&mesh, 1e-3);
    assert_eq!(kept, vec![0]);
    assert_eq!(report.dropped_faces, vec![1]);
    assert_eq!(welded.face(0), &[0, 1, 2, 3]);
    assert_eq!((report.groups, report.merged), (2, 3));
    assert_eq!(report.collapsed_edges, 1 + 2);
}

/// Two cubes touching at a corner written twice: as given, two closed cubes; welded, one
/// pinched vertex that the manifold split cuts again (what was merged is reported, and the
/// refiner draws it as OpenSubdiv would).
#[test]
fn welding_can_make_a_mesh_non_manifold() {
    let cube = |o: f64| -> Vec<[f64; 3]> {
        (0..8)
            .map(|i| {
                [
                    o + f64::from(i & 1),
                    o + f64::from((i >> 1) & 1),
                    o + f64::from((i >> 2) & 1),
                ]
            })
            .collect()
    };
    let quads = [
        [0u32, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut positions = cube(0.0);
    positions.extend(cube(1.0));
    let mut faces: Vec<[u32; 4]> = quads.to_vec();
    faces.extend(quads.iter().map(|q| q.map(|v| v + 8)));
    let mesh = ControlMesh::from_polygons(positions, &faces);
    assert!(ManifoldSplit::of(&mesh).unwrap().is_identity());
    let (welded, _, report) = weld_vertices(&mesh, 0.0);
    assert_eq!((report.groups, report.merged), (1, 1));
    let split = ManifoldSplit::of(&welded).unwrap();
    assert_eq!(split.report.vertices_with_fans, 1);
}
