//! OBJ parsing, OpenSubdiv tags and every validation error on small inline meshes.

use topology::error::TagKind;
use topology::mesh::manifold::{ManifoldSplit, NonManifoldReport};
use topology::mesh::obj::{parse_obj, parse_obj_with_lines};
use topology::mesh::Topology;
use topology::rules::options::{BoundaryInterpolation, CreaseMethod, TriangleSubdivision};
use topology::TopologyError;

const QUAD_PAIR: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n";

fn err(text: &str) -> TopologyError {
    parse_obj(text, "inline.obj").expect_err("mesh should be rejected")
}

/// A mesh that loads (non-manifold input is drawn as OpenSubdiv draws it) but that the
/// manifold-only adjacency ([`Topology::from_mesh`]) refuses, located in the file; and what
/// the manifold split found.
fn manifold_err(text: &str) -> (TopologyError, NonManifoldReport) {
    let (mesh, lines) = parse_obj_with_lines(text, "inline.obj").expect("non-manifold loads");
    let report = ManifoldSplit::of(&mesh).expect("splits").report;
    let e = Topology::from_mesh(&mesh).expect_err("not manifold");
    (lines.locate(e, &mesh, "inline.obj"), report)
}

#[test]
fn parses_polygons_uvs_normals_and_tags() {
    let text = "# test\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 2 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 1\nvn 0 0 1\n\
f 1/1/1 2/2/1 3/3/1 4/4/1\nf 4/4/1 3/3/1 5/5/1\n\
t crease 2/1/0 0 1 2.5\nt crease 4/2/0 1 2 2 3 1.0 3.0\nt corner 1/1/0 4 10\n\
t interpolateboundary 1/0/0 1\nt creasemethod 0/0/1 chaikin\nt smoothtriangles 0/0/1 smooth\n\
t hole 1/0/0 1\nt vertexedit 1/0/0 3\n";
    let m = parse_obj(text, "tags.obj").unwrap();
    assert_eq!(m.positions.len(), 5);
    assert_eq!(m.num_faces(), 2);
    assert_eq!(m.face(0), &[0, 1, 2, 3]);
    assert_eq!(m.face(1), &[3, 2, 4]);
    assert_eq!(m.uvs.as_ref().unwrap()[6], [0.5, 1.0]);
    assert_eq!(m.normals.as_ref().unwrap().len(), 7);
    assert_eq!(m.creases.len(), 3);
    assert_eq!(m.creases[0].vertices, [0, 1]);
    assert_eq!(m.creases[0].sharpness, 2.5);
    assert_eq!(m.creases[2].vertices, [2, 3]);
    assert_eq!(m.creases[2].sharpness, 3.0);
    assert_eq!(m.corners[0].vertex, 4);
    assert_eq!(m.corners[0].sharpness, 10.0);
    assert_eq!(m.options.boundary, BoundaryInterpolation::EdgesAndCorners);
    assert_eq!(m.options.crease_method, CreaseMethod::Chaikin);
    assert_eq!(m.options.triangle_subdivision, TriangleSubdivision::Smooth);
    assert_eq!(m.holes, vec![1]);
}

#[test]
fn negative_indices_and_missing_attributes() {
    let m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", "neg.obj").unwrap();
    assert_eq!(m.face(0), &[0, 1, 2]);
    assert!(m.uvs.is_none() && m.normals.is_none());
}

#[test]
fn isolated_vertices_are_allowed() {
    let m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 2 3\n", "iso.obj").unwrap();
    m.validate().unwrap();
}

#[test]
fn missing_file_names_the_file() {
    let e = topology::load_obj("/nonexistent/dir/missing_mesh.obj").unwrap_err();
    assert!(matches!(e, TopologyError::Io { .. }));
    assert!(e.to_string().contains("missing_mesh.obj"), "{e}");
}

#[test]
fn malformed_text_names_file_and_line() {
    let e = err("v 0 0 0\nv 1 zero 0\n");
    match &e {
        TopologyError::Parse { file, line, .. } => {
            assert_eq!(file, "inline.obj");
            assert_eq!(*line, 2);
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(matches!(
        err("v 0 0\n"),
        TopologyError::Parse { line: 1, .. }
    ));
    assert!(matches!(
        err("v 0 0 0\nf 0 1 2\n"),
        TopologyError::Parse { line: 2, .. }
    ));
    assert!(matches!(
        err("v 0 0 0\nf 1/x 1 1\n"),
        TopologyError::Parse { .. }
    ));
    assert!(matches!(
        err("v 0 0 0\nt crease 2/1/0 0\n"),
        TopologyError::Parse { .. }
    ));
    assert!(matches!(
        err("v 0 0 0\nt crease x/1/0 0 1 1\n"),
        TopologyError::Parse { .. }
    ));
    let text = format!("{QUAD_PAIR}vt 0 0\nf 1/1 2/1 3/7\n");
    assert!(matches!(err(&text), TopologyError::Parse { line: 8, .. }));
}

#[test]
fn empty_mesh() {
    assert!(matches!(err("").root(), TopologyError::EmptyMesh { .. }));
    assert!(matches!(
        err("v 0 0 0\n").root(),
        TopologyError::EmptyMesh { what: "no faces" }
    ));
    let e = err("# nothing\n");
    assert!(e.to_string().contains("inline.obj"), "{e}");
}

#[test]
fn index_out_of_range() {
    let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 9\n");
    assert!(e.to_string().contains("inline.obj"), "{e}");
    match e.root() {
        TopologyError::IndexOutOfRange { face, index, count } => {
            assert_eq!((*face, *index, *count), (1, 8, 3));
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn face_with_too_few_or_repeated_vertices() {
    let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
    assert!(matches!(
        e.root(),
        TopologyError::DegenerateFace { face: 0, size: 2 }
    ));
    // A vertex named twice in a row is a degenerate edge (OpenSubdiv's quad poles): it loads,
    // the refiner takes it through the manifold split, the manifold adjacency names it.
    let (e, report) = manifold_err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 2 3\n");
    assert!(matches!(
        e.root(),
        TopologyError::RepeatedVertex { face: 1, vertex: 1 }
    ));
    assert!(e.to_string().contains("inline.obj:5"), "{e}");
    assert_eq!(report.sharpened, 3, "{report:?}");
}

#[test]
fn non_manifold_edge() {
    // Three triangles on edge 0-1.
    let (e, report) =
        manifold_err("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
    assert_eq!(report.shared_edges, 1);
    match e.root() {
        TopologyError::NonManifoldEdge { v0, v1, faces } => {
            assert_eq!((*v0, *v1, *faces), (0, 1, 3));
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn inconsistent_orientation() {
    // The second quad walks the shared edge 1->2 the same way as the first.
    let (e, report) = manifold_err(&format!("{QUAD_PAIR}f 1 2 3 4\nf 2 3 6 5\n"));
    assert_eq!(report.opposite_winding_edges, 1);
    match e.root() {
        TopologyError::InconsistentOrientation {
            face0,
            face1,
            v0,
            v1,
        } => {
            assert_eq!((*face0, *face1), (0, 1));
            assert_eq!((*v0, *v1), (1, 2));
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn non_manifold_vertex() {
    // Two triangles touching only at vertex 0 (a bow tie).
    let (e, report) =
        manifold_err("v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n");
    assert_eq!(report.vertices_with_fans, 1);
    match e.root() {
        TopologyError::NonManifoldVertex { vertex, fans } => {
            assert_eq!((*vertex, *fans), (0, 2));
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn non_finite_positions() {
    let e = err("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(matches!(
        e.root(),
        TopologyError::NonFinitePosition { vertex: 1, .. }
    ));
    let e = err("v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
    assert!(matches!(
        e.root(),
        TopologyError::NonFinitePosition { vertex: 2, .. }
    ));
}

#[test]
fn tags_naming_missing_vertices() {
    let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt corner 1/1/0 7 1.0\n");
    assert!(matches!(
        e.root(),
        TopologyError::TagOutOfRange {
            tag: TagKind::Corner,
            index: 7,
            count: 3
        }
    ));
    let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/1/0 0 5 1.0\n");
    assert!(matches!(
        e.root(),
        TopologyError::TagOutOfRange {
            tag: TagKind::Crease,
            index: 5,
            count: 3
        }
    ));
}

#[test]
fn write_obj_round_trips() {
    let m = parse_obj(&format!("{QUAD_PAIR}f 1 2 3 4\nf 2 5 6 3\n"), "rt.obj").unwrap();
    let mut buf = Vec::new();
    topology::mesh::obj::write_obj(&mut buf, &m.positions, &m.face_offsets, &m.face_vertices)
        .unwrap();
    let back = parse_obj(std::str::from_utf8(&buf).unwrap(), "back.obj").unwrap();
    assert_eq!(back.positions, m.positions);
    assert_eq!(back.face_vertices, m.face_vertices);
}

mod never_panics {
    use proptest::prelude::*;
    use topology::mesh::obj::parse_obj;
    use topology::refine::refine_uniform;
    use topology::{ControlMesh, Scheme};

    fn line() -> impl Strategy<Value = String> {
        prop_oneof![
            (-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0)
                .prop_map(|(x, y, z)| format!("v {x} {y} {z}")),
            prop::collection::vec(-8i64..9, 0..6).prop_map(|ix| {
                let s: Vec<String> = ix.iter().map(|i| i.to_string()).collect();
                format!("f {}", s.join(" "))
            }),
            (0i64..8, 0i64..8, -1.0f32..12.0)
                .prop_map(|(a, b, s)| format!("t crease 2/1/0 {a} {b} {s}")),
            (0i64..8, -1.0f32..12.0).prop_map(|(a, s)| format!("t corner 1/1/0 {a} {s}")),
            "[ -~]{0,20}",
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        /// Arbitrary OBJ-like text: parse either succeeds or returns an error, and whatever
        /// parses also refines without panicking.
        #[test]
        fn parse_and_refine_never_panic(lines in prop::collection::vec(line(), 0..24)) {
            let text = lines.join("\n");
            if let Ok(mesh) = parse_obj(&text, "fuzz.obj") {
                for scheme in [Scheme::CatmullClark, Scheme::Loop, Scheme::Bilinear, Scheme::DooSabin] {
                    let _ = refine_uniform(&mesh, scheme, 2);
                }
            }
        }

        /// Random polygon soups built in memory (bypassing the parser) are validated, not trusted.
        #[test]
        fn random_polygon_soups_never_panic(
            n in 0usize..8,
            faces in prop::collection::vec(prop::collection::vec(0u32..10, 0..6), 0..8),
        ) {
            let positions = (0..n).map(|i| [i as f64, (i * i) as f64, 1.0]).collect();
            let mesh = ControlMesh::from_polygons(positions, &faces);
            if mesh.validate().is_ok() {
                for scheme in [Scheme::CatmullClark, Scheme::Loop, Scheme::DooSabin] {
                    let _ = refine_uniform(&mesh, scheme, 2);
                }
            }
        }
    }
}

/// Errors raised after loading (here the adaptive plan) still speak the file's 1-based face
/// numbers once wrapped by `in_file`, like the parser's own.
#[test]
fn later_errors_use_the_files_face_numbers() {
    use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions};
    let n = 300;
    let mut text = String::from("v 5 5 0\nv 6 5 0\nv 5 6 0\nf 1 2 3\n");
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        text += &format!("v {} {} 0\n", a.cos(), a.sin());
    }
    text += "f";
    for i in 0..n {
        text += &format!(" {}", i + 4);
    }
    text += "\n";
    let mesh = parse_obj(&text, "inline.obj").expect("valid mesh");
    let e = plan_adaptive(&mesh, &AdaptiveOptions::default())
        .expect_err("a 300-gon is beyond the adaptive plan")
        .in_file("inline.obj", None);
    match e.root() {
        TopologyError::AdaptiveFaceTooLarge { face, size } => assert_eq!((*face, *size), (1, n)),
        other => panic!("unexpected {other:?}"),
    }
    let message = e.to_string();
    assert!(
        message.contains("inline.obj") && message.contains("face 2 has 300 corners"),
        "{message}"
    );
}
