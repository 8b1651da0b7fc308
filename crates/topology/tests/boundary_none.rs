//! Boundary interpolation `none` (`t interpolateboundary 1/0/0 0`, USD's
//! `interpolateBoundary = "none"`): the faces around a boundary vertex whose boundary edges
//! are not all tagged infinitely sharp become holes, as in OpenSubdiv. Checked on OpenSubdiv's
//! own test shapes for the option, face by face, against what the rule gives worked by hand.

use topology::load_obj;
use topology::rules::options::BoundaryInterpolation;

fn shape(name: &str) -> topology::ControlMesh {
    let path = format!(
        "{}/../../tests/data/opensubdiv/shapes/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    load_obj(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn sorted(mut v: Vec<u32>) -> Vec<u32> {
    v.sort_unstable();
    v
}

/// catmark_edgenone: four 3×3 grids of quads, faces row by row. Grid 1 has no sharp
/// boundary edge: only its centre keeps a surface. Grid 2 sharpens its top edge: its
/// top-middle face (whose boundary vertices have only sharp boundary edges) stays too. Grid 3
/// sharpens its top and right edges: the top-middle, top-right, centre and middle-right
/// faces stay. Grid 4 sharpens every edge but the bottom one: only its bottom row goes.
#[test]
fn catmark_boundary_faces_become_holes_unless_their_boundary_is_sharp() {
    let mesh = shape("catmark_edgenone.obj");
    assert_eq!(mesh.options.boundary, BoundaryInterpolation::None);
    assert!(mesh.holes.len() == 23, "{:?}", mesh.holes);
    let grids: [&[u32]; 4] = [
        &[0, 1, 2, 3, 5, 6, 7, 8],
        &[0, 2, 3, 5, 6, 7, 8],
        &[0, 3, 6, 7, 8],
        &[6, 7, 8],
    ];
    let expected: Vec<u32> = (0u32..)
        .zip(grids)
        .flat_map(|(g, faces)| faces.iter().map(move |f| 9 * g + f))
        .collect();
    assert_eq!(sorted(mesh.holes.clone()), expected);
}

/// loop_triangle_edgenone's first shape (16 triangles, no sharp boundary edge): the one
/// triangle whose three vertices are interior (vertices 7, 8 and 11 of the file) keeps its
/// surface.
#[test]
fn loop_boundary_faces_become_holes() {
    let mesh = shape("loop_triangle_edgenone.obj");
    let kept: Vec<u32> = (0..16).filter(|f| !mesh.holes.contains(f)).collect();
    assert_eq!(kept, vec![8]);
    assert_eq!(mesh.face(8), &[6, 7, 10]);
}

/// The rule only applies under `none`: the same faces with the default option keep every
/// face, and applying it again (a loader then the C ABI) adds nothing. Tagged holes keep
/// their place at the front of the list, so their OBJ lines still name them.
#[test]
fn only_none_makes_holes_and_applying_twice_is_the_same() {
    let text = std::fs::read_to_string(format!(
        "{}/../../tests/data/opensubdiv/shapes/catmark_edgenone.obj",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let edges_only = text.replace(
        "t interpolateboundary 1/0/0 0",
        "t interpolateboundary 1/0/0 2",
    );
    let mesh = topology::mesh::obj::parse_obj(&edges_only, "edges_only.obj").unwrap();
    assert!(mesh.holes.is_empty());

    let tagged = format!("{text}\nt hole 1/0/0 31\n");
    let mut mesh = topology::mesh::obj::parse_obj(&tagged, "tagged.obj").unwrap();
    assert_eq!(mesh.holes[0], 31);
    assert_eq!(mesh.holes.len(), 24);
    let before = mesh.holes.clone();
    mesh.apply_boundary_none();
    assert_eq!(mesh.holes, before);
}

/// A bilinear mesh's faces need no neighbourhood, so `none` leaves them (OpenSubdiv exempts
/// schemes without a neighbourhood).
#[test]
fn bilinear_meshes_keep_their_faces() {
    let mut mesh = shape("catmark_edgenone.obj");
    mesh.holes.clear();
    mesh.scheme = Some(topology::rules::Scheme::Bilinear);
    mesh.apply_boundary_none();
    assert!(mesh.holes.is_empty());
    mesh.scheme = None;
    mesh.apply_boundary_none();
    assert_eq!(mesh.holes.len(), 23);
}
