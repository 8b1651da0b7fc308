//! Inputs the fuzz targets (fuzz/, tools/fuzz.sh) found crashing, kept as ordinary tests so
//! `cargo test` guards the fixes without a nightly toolchain.

use topology::error::ObjSyntax;
use topology::mesh::obj::parse_obj;
use topology::TopologyError;

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// `t` counts near `usize::MAX` wrapped the "enough words" sum and the parser sliced past
/// the line (obj_parse target: "attempt to add with overflow" / slice index panic).
#[test]
fn tag_counts_that_overflow_are_a_count_mismatch() {
    for counts in [
        "18446744073709551615/1/0",
        "1/18446744073709551615/0",
        "0/0/18446744073709551615",
        "9223372036854775807/9223372036854775807/2",
    ] {
        let text = format!("{TRIANGLE}t crease {counts} 1 2 3\n");
        let err = parse_obj(&text, "t.obj").expect_err(counts);
        assert!(
            matches!(
                err,
                TopologyError::Parse {
                    line: 5,
                    kind: ObjSyntax::TagCountMismatch { .. },
                    ..
                }
            ),
            "{counts}: {err}"
        );
    }
}

/// Validation accepts vertices no face uses; their limit masks divided by valence 0 and
/// `vertex_limit_exact` returned NaN (limit target: "non-finite vertex limit 0: [NaN, NaN,
/// NaN]"). They have no limit point: the mask is `None` and the exact limit an error.
#[test]
fn isolated_vertex_has_no_limit_point() {
    use topology::limit::eval::{EvalError, LimitScheme, LocalMesh};
    use topology::ControlMesh;
    let positions = vec![
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
    ];
    // Vertex 0 is in no face.
    let mesh = ControlMesh::from_polygons(positions, &[[1u32, 2, 3]]);
    mesh.validate().expect("isolated vertices are allowed");
    for scheme in [LimitScheme::CatmullClark, LimitScheme::Loop] {
        let lm = LocalMesh::from_control_mesh(&mesh, scheme).unwrap();
        assert_eq!(lm.vertex_limit_position(0), None, "{scheme:?}");
        assert!(matches!(
            lm.vertex_limit_exact(0),
            Err(EvalError::IsolatedVertex { vertex: 0 })
        ));
        assert_eq!(lm.loop_tangent_stencils(0), None);
        for v in 1..4 {
            let p = lm.vertex_limit_exact(v).unwrap();
            assert!(
                p.iter().all(|x| x.is_finite()),
                "{scheme:?} vertex {v}: {p:?}"
            );
        }
    }
}
