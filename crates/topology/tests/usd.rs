//! USD input: each `.usda` under `tests/data/usd/` reads as the same control mesh as its
//! hand-written OBJ twin (positions after transforms, faces, tags, uvs, options); the same
//! layer written as `.usdc` and packed as `.usdz` by openusd's writers reads the same; bad
//! files give named errors (file, prim, attribute), never a panic.

use openusd::usdc::CrateWriter;
use openusd::usdz::ArchiveWriter;
use std::path::{Path, PathBuf};
use topology::error::UsdProblem;
use topology::mesh::usd::{is_usd_path, load_usd, read_usd};
use topology::rules::options::{
    BoundaryInterpolation, FVarLinearInterpolation, TriangleSubdivision,
};
use topology::{ControlMesh, Scheme, TopologyError};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/usd")
        .join(name)
}

/// Asserts `usd` is `obj` but for the scheme (OBJ has none) and positions within 1e-12.
fn assert_twins(usd: &ControlMesh, obj: &ControlMesh) {
    assert_eq!(usd.positions.len(), obj.positions.len());
    for (v, (a, b)) in usd.positions.iter().zip(&obj.positions).enumerate() {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= 1e-12, "vertex {v}: {a:?} vs {b:?}");
        }
    }
    let mut usd = usd.clone();
    usd.positions = obj.positions.clone();
    usd.scheme = None;
    assert_eq!(
        same_value_classes(&usd),
        same_value_classes(obj),
        "the texture layouts share values at the same corners"
    );
    usd.uv_indices = obj.uv_indices.clone();
    assert_eq!(&usd, obj);
}

/// Per corner, the first corner with its value number (its `uv_indices`, else its value's
/// bits): the layout's topology whatever the numbers are (a primvar's indices, an OBJ's `vt`
/// numbers).
fn same_value_classes(mesh: &ControlMesh) -> Option<Vec<usize>> {
    let uvs = mesh.uvs.as_ref()?;
    let keys: Vec<u64> = match &mesh.uv_indices {
        Some(ix) => ix.iter().map(|&i| u64::from(i)).collect(),
        None => {
            let mut ids = std::collections::HashMap::new();
            uvs.iter()
                .map(|uv| {
                    let n = ids.len() as u64;
                    *ids.entry(uv.map(f64::to_bits)).or_insert(n)
                })
                .collect()
        }
    };
    let mut first = std::collections::HashMap::new();
    Some(
        keys.iter()
            .enumerate()
            .map(|(c, &k)| *first.entry(k).or_insert(c))
            .collect(),
    )
}

fn twins(stem: &str) -> (ControlMesh, ControlMesh) {
    let usd = load_usd(data(&format!("{stem}.usda"))).unwrap();
    let obj = topology::load_obj(data(&format!("{stem}.obj"))).unwrap();
    assert_twins(&usd, &obj);
    (usd, obj)
}

#[test]
fn cube_with_creases_corners_hole_and_indexed_st_is_its_obj_twin() {
    let (usd, _) = twins("cube_tags");
    assert_eq!(usd.scheme, Some(Scheme::CatmullClark));
    assert_eq!(usd.creases.len(), 3, "lengths [3, 2]: 2 + 1 edges");
    assert!(topology::rules::is_infinite(usd.creases[2].sharpness));
    assert_eq!(usd.holes, vec![5]);
    assert_eq!(usd.options.boundary, BoundaryInterpolation::EdgesAndCorners);
    assert_eq!(usd.uvs.as_ref().map(Vec::len), Some(24));
}

#[test]
fn two_transformed_meshes_merge_and_hidden_ones_are_skipped() {
    let (usd, _) = twins("two_meshes");
    let read = read_usd(data("two_meshes.usda")).unwrap();
    let prims: Vec<(&str, u32, u32)> = read
        .prims
        .iter()
        .map(|p| (p.path.as_str(), p.first_vertex, p.first_face))
        .collect();
    assert_eq!(
        prims,
        vec![("/World/Grid", 0, 0), ("/World/Group/Scaled/Tetra", 6, 2)]
    );
    assert_eq!(
        usd.num_faces(),
        6,
        "the guide and the invisible mesh are not read"
    );
    assert_eq!(
        usd.corners[0].vertex, 9,
        "the second mesh's tags are offset"
    );
}

#[test]
fn loop_triangles_with_vertex_uvs_and_per_edge_crease() {
    let (usd, _) = twins("loop_octahedron");
    assert_eq!(usd.scheme, Some(Scheme::Loop));
    assert_eq!(usd.options.boundary, BoundaryInterpolation::EdgesOnly);
    let s: Vec<f32> = usd.creases.iter().map(|c| c.sharpness).collect();
    assert_eq!(s, vec![1.0, 2.0, 3.0, 4.0]);
    let read = read_usd(data("loop_octahedron.usda")).unwrap();
    assert_eq!(read.prims[0].face_varying_linear_interpolation, "all");
    assert_eq!(usd.options.fvar_interpolation, FVarLinearInterpolation::All);
}

#[test]
fn left_handed_faces_are_reversed_with_their_uvs() {
    let (usd, _) = twins("left_handed");
    assert_eq!(usd.face(0), &[0, 1, 4, 3]);
    assert_eq!(
        usd.options.triangle_subdivision,
        TriangleSubdivision::Smooth
    );
    assert_eq!(usd.options.boundary, BoundaryInterpolation::EdgesOnly);
    let read = read_usd(data("left_handed.usda")).unwrap();
    assert_eq!(
        read.prims[0].face_varying_linear_interpolation,
        "cornersPlus1"
    );
    assert_eq!(
        usd.options.fvar_interpolation,
        FVarLinearInterpolation::CornersPlus1,
        "USD's default applies"
    );
}

/// `interpolateBoundary = "none"` is OpenSubdiv's: the faces around boundary vertices become
/// holes (a lone quad is all boundary).
#[test]
fn boundary_none_makes_boundary_faces_holes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("none.usda");
    std::fs::write(
        &path,
        quad_with("uniform token interpolateBoundary = \"none\""),
    )
    .unwrap();
    let mesh = load_usd(&path).unwrap();
    assert_eq!(mesh.options.boundary, BoundaryInterpolation::None);
    assert_eq!(mesh.holes, vec![0]);
}

/// `stem.usda` written as `.usdc` and packed into a `.usdz` in `dir`.
fn binary_copies(stem: &str, dir: &Path) -> (PathBuf, PathBuf) {
    let layer = openusd::usda::read_file(data(&format!("{stem}.usda"))).unwrap();
    let usdc = dir.join(format!("{stem}.usdc"));
    CrateWriter::write_to_file(&layer, usdc.to_str().unwrap()).unwrap();
    let usdz = dir.join(format!("{stem}.usdz"));
    let mut archive = ArchiveWriter::create(&usdz).unwrap();
    archive
        .add_layer(&format!("{stem}.usdc"), &std::fs::read(&usdc).unwrap())
        .unwrap();
    archive.finish().unwrap();
    (usdc, usdz)
}

#[test]
fn usdc_and_usdz_read_as_the_usda() {
    let dir = tempfile::tempdir().unwrap();
    for stem in ["cube_tags", "two_meshes", "loop_octahedron", "left_handed"] {
        let text = load_usd(data(&format!("{stem}.usda"))).unwrap();
        let (usdc, usdz) = binary_copies(stem, dir.path());
        assert!(is_usd_path(&usdc) && is_usd_path(&usdz));
        assert_eq!(load_usd(&usdc).unwrap(), text, "{stem}.usdc");
        assert_eq!(load_usd(&usdz).unwrap(), text, "{stem}.usdz");
    }
}

/// The error of reading `text` as `name` (a .usda in a temporary folder), and that folder's
/// path of the file.
fn usda_error(name: &str, text: &str) -> (TopologyError, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    let e = load_usd(&path).expect_err("refused");
    (e, path.display().to_string())
}

const QUAD: &str = "int[] faceVertexCounts = [4]\n    int[] faceVertexIndices = [0, 1, 2, 3]\n    \
                    point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]";

fn quad_with(extra: &str) -> String {
    format!("#usda 1.0\n\ndef Mesh \"Quad\"\n{{\n    {QUAD}\n    {extra}\n}}\n")
}

/// Asserts `e` is a [`TopologyError::Usd`] about `attribute` of `/Quad` in `file`, whose
/// message names all three, and returns its problem.
fn usd_problem<'a>(e: &'a TopologyError, file: &str, attribute: &str) -> &'a UsdProblem {
    let message = e.to_string();
    assert!(
        message.starts_with(&format!("{file}: /Quad.{attribute}: ")),
        "{message}"
    );
    match e {
        TopologyError::Usd { problem, .. } => problem.as_ref(),
        other => panic!("not a USD error: {other:?}"),
    }
}

#[test]
fn counts_that_do_not_add_up_are_refused_by_name() {
    let text = quad_with("").replace("faceVertexCounts = [4]", "faceVertexCounts = [3]");
    let (e, file) = usda_error("counts.usda", &text);
    let p = usd_problem(&e, &file, "faceVertexIndices");
    assert!(matches!(p, UsdProblem::Length { len: 4, .. }), "{p:?}");
    let text = quad_with("").replace("faceVertexCounts = [4]", "faceVertexCounts = [-4]");
    let (e, file) = usda_error("negative.usda", &text);
    let p = usd_problem(&e, &file, "faceVertexCounts");
    assert!(
        matches!(
            p,
            UsdProblem::NegativeCount {
                position: 0,
                value: -4
            }
        ),
        "{p:?}"
    );
}

#[test]
fn unknown_scheme_is_refused_by_name() {
    let (e, file) = usda_error(
        "scheme.usda",
        &quad_with("uniform token subdivisionScheme = \"butterfly\""),
    );
    let p = usd_problem(&e, &file, "subdivisionScheme");
    assert!(
        matches!(p, UsdProblem::UnknownToken { value, .. } if value == "butterfly"),
        "{p:?}"
    );
    assert!(e.to_string().contains("'butterfly'"), "{e}");
}

#[test]
fn indices_out_of_range_are_refused_by_name() {
    let text = quad_with("").replace("[0, 1, 2, 3]", "[0, 1, 2, 7]");
    let (e, file) = usda_error("index.usda", &text);
    let p = usd_problem(&e, &file, "faceVertexIndices");
    assert!(
        matches!(
            p,
            UsdProblem::IndexOutOfRange {
                position: 3,
                index: 7,
                count: 4,
                ..
            }
        ),
        "{p:?}"
    );
    for (extra, attribute) in [
        ("int[] holeIndices = [1]", "holeIndices"),
        ("int[] cornerIndices = [4]\n    float[] cornerSharpnesses = [1]", "cornerIndices"),
        (
            "int[] creaseIndices = [0, 9]\n    int[] creaseLengths = [2]\n    float[] creaseSharpnesses = [1]",
            "creaseIndices",
        ),
    ] {
        let (e, file) = usda_error("tag.usda", &quad_with(extra));
        let p = usd_problem(&e, &file, attribute);
        assert!(matches!(p, UsdProblem::IndexOutOfRange { .. }), "{attribute}: {p:?}");
    }
}

#[test]
fn crease_lengths_that_disagree_are_refused_by_name() {
    for (extra, attribute) in [
        (
            "int[] creaseIndices = [0, 1, 2]\n    int[] creaseLengths = [2]\n    float[] creaseSharpnesses = [1]",
            "creaseIndices",
        ),
        (
            "int[] creaseIndices = [0, 1, 2]\n    int[] creaseLengths = [3]\n    float[] creaseSharpnesses = [1, 2, 3]",
            "creaseSharpnesses",
        ),
        (
            "int[] creaseIndices = [0]\n    int[] creaseLengths = [1]\n    float[] creaseSharpnesses = [1]",
            "creaseLengths",
        ),
        ("int[] cornerIndices = [0, 1]\n    float[] cornerSharpnesses = [1]", "cornerSharpnesses"),
        (
            "texCoord2f[] primvars:st = [(0, 0)] (\n        interpolation = \"faceVarying\"\n    )",
            "primvars:st",
        ),
    ] {
        let (e, file) = usda_error("crease.usda", &quad_with(extra));
        usd_problem(&e, &file, attribute);
    }
}

#[test]
fn a_stage_without_a_mesh_to_draw_is_refused() {
    let text = "#usda 1.0\n\ndef Xform \"World\"\n{\n}\n\ndef Mesh \"Guide\"\n{\n    uniform token purpose = \"guide\"\n}\n";
    let (e, file) = usda_error("empty.usda", text);
    assert!(
        matches!(&e, TopologyError::Usd { problem, .. } if matches!(**problem, UsdProblem::NoMesh { skipped: 1 })),
        "{e:?}"
    );
    assert!(
        e.to_string().starts_with(&format!("{file}: no Mesh prim")),
        "{e}"
    );
}

#[test]
fn a_mesh_that_fails_validation_names_its_prim() {
    // A coordinate beyond the drawable range, at the prim's point 2.
    let text = quad_with("").replace("(1, 1, 0)", "(1, 1e13, 0)");
    let (e, file) = usda_error("far.usda", &text);
    assert!(
        matches!(&e, TopologyError::InUsdPrim { prim, .. } if prim == "/Quad"),
        "{e:?}"
    );
    assert!(
        matches!(
            e.root(),
            TopologyError::CoordinateOutOfRange { vertex: 2, .. }
        ),
        "{e:?}"
    );
    assert!(
        e.to_string().starts_with(&format!("{file}: /Quad: ")),
        "{e}"
    );
}

#[test]
fn truncated_usdc_and_empty_usdz_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (usdc, _) = binary_copies("cube_tags", dir.path());
    let bytes = std::fs::read(&usdc).unwrap();
    for cut in [bytes.len() / 2, bytes.len() - 1, 100, 16, 0] {
        let path = dir.path().join(format!("cut{cut}.usdc"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let e = load_usd(&path).expect_err("a cut crate file is refused");
        assert!(matches!(e, TopologyError::Usd { .. }), "{e:?}");
        assert!(
            e.to_string().starts_with(&path.display().to_string()),
            "{e}"
        );
    }
    let empty = dir.path().join("empty.usdz");
    ArchiveWriter::create(&empty).unwrap().finish().unwrap();
    let e = load_usd(&empty).expect_err("an empty package is refused");
    assert!(matches!(e, TopologyError::Usd { .. }), "{e:?}");
    assert!(
        e.to_string().starts_with(&empty.display().to_string()),
        "{e}"
    );
}

#[test]
fn missing_file_and_garbage_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.usda");
    let e = load_usd(&missing).expect_err("missing");
    assert!(matches!(e, TopologyError::Io { .. }), "{e:?}");
    let e = load_usd(dir.path()).expect_err("a directory");
    assert!(
        e.to_string().contains("is a directory, not a regular file"),
        "{e}"
    );
    for (name, bytes) in [
        (
            "garbage.usda",
            &b"#usda 1.0\ndef Mesh \"A\" { int[] faceVertexCounts = [ }"[..],
        ),
        (
            "garbage.usdc",
            &b"PXR-USDC\0\0\0\0\0\0\0\0\xff\xff\xff\xff\xff\xff\xff\xff"[..],
        ),
        ("garbage.usdz", &b"PK\x03\x04garbage"[..]),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = load_usd(&path).expect_err(name);
        assert!(matches!(e, TopologyError::Usd { .. }), "{name}: {e:?}");
    }
}

/// Pixar's own test files (`tests/data/usd/real/`, see its README): time samples only, a
/// left-handed cube with indexed face-varying st, the `none` scheme; a file with legacy type
/// names openusd does not parse is refused by name.
#[test]
fn pixar_test_files_load() {
    let cube = load_usd(data("real/indexedTextureCoordinates.def.usda")).unwrap();
    assert_eq!((cube.positions.len(), cube.num_faces()), (8, 6));
    assert_eq!(
        cube.scheme,
        Some(Scheme::Bilinear),
        "subdivisionScheme none"
    );
    assert_eq!(cube.positions[0], [-1.0, -1.0, 1.0]);
    // Left-handed [2, 3, 1, 0] is drawn [2, 0, 1, 3]; its st follows its corners.
    assert_eq!(cube.face(0), &[2, 0, 1, 3]);
    let st = cube.uvs.as_ref().unwrap();
    assert_eq!(st.len(), 24);
    assert_eq!(st[1], [0.9999133f32 as f64, 0.5000001f32 as f64]);
    let ring = load_usd(data("real/ring.usda")).unwrap();
    assert_eq!((ring.positions.len(), ring.num_faces()), (32, 16));
    assert_eq!(
        ring.scheme,
        Some(Scheme::Bilinear),
        "subdivisionScheme none"
    );
    let legacy = data("real/subdivMesh.usda");
    let e = load_usd(&legacy).expect_err("legacy type names");
    assert!(matches!(e, TopologyError::Usd { .. }), "{e:?}");
    let message = e.to_string();
    assert!(
        message.starts_with(&legacy.display().to_string()) && message.contains("Vec3f"),
        "{message}"
    );
}

/// Writes `text` as `name` in a temporary folder and reads it.
fn read_text(name: &str, text: &str) -> ControlMesh {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    load_usd(&path).unwrap()
}

#[test]
fn time_sampled_points_read_their_earliest_sample() {
    let text = quad_with("").replace(
        "point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]",
        "point3f[] points.timeSamples = {\n        2: [(0, 0, 2), (1, 0, 2), (1, 1, 2), (0, 1, 2)],\n        \
         1: [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],\n    }",
    );
    let mesh = read_text("sampled.usda", &text);
    assert!(
        mesh.positions.iter().all(|p| p[2] == 1.0),
        "{:?}",
        mesh.positions
    );
}

#[test]
fn a_mirroring_transform_reverses_faces_and_left_handed_cancels_it() {
    let mirror =
        "float3 xformOp:scale = (-1, 1, 1)\n    uniform token[] xformOpOrder = [\"xformOp:scale\"]";
    let mesh = read_text("mirror.usda", &quad_with(mirror));
    assert_eq!(mesh.face(0), &[0, 3, 2, 1]);
    assert_eq!(mesh.positions[1], [-1.0, 0.0, 0.0]);
    let both = format!("{mirror}\n    uniform token orientation = \"leftHanded\"");
    let mesh = read_text("mirror_left.usda", &quad_with(&both));
    assert_eq!(mesh.face(0), &[0, 1, 2, 3]);
}

#[test]
fn an_xform_op_order_entry_that_is_no_attribute_name_is_refused() {
    // openusd loops forever composing a property path it cannot parse; the reader refuses it.
    let order =
        "float3 xformOp:scale = (2, 2, 2)\n    uniform token[] xformOpOrder = [\"xfor}Op:scale\"]";
    let (e, file) = usda_error("op.usda", &quad_with(order));
    let p = usd_problem(&e, &file, "xformOpOrder");
    assert!(
        matches!(p, UsdProblem::Transform(m) if m.contains("'xfor}Op:scale'")),
        "{p:?}"
    );
}

#[test]
fn a_prim_name_that_is_no_identifier_is_refused() {
    // openusd recurses without end on such a prim's path (a stack overflow); found by fuzzing.
    let text = "#usda 1.0\ndef Xform \"}orld\"\n{\n    def Mesh \"Quad\"\n    {\n    }\n}\n";
    let (e, file) = usda_error("name.usda", text);
    let message = e.to_string();
    assert!(message.starts_with(&format!("{file}: /: ")), "{message}");
    assert!(message.contains("'}orld'"), "{message}");
    // Unicode identifiers are names.
    let unicode = quad_with("").replace("\"Quad\"", "\"Würfel\"");
    assert_eq!(read_text("unicode.usda", &unicode).num_faces(), 1);
}

/// `write_usda` writes what `load_usd` reads: spot's control mesh (triangles, quads,
/// pentagons) comes back with the same faces, its positions rounded to `f32` as USD stores
/// them, and the scheme named.
#[test]
fn written_usda_reads_back() {
    let spot = topology::load_obj(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spot_control_mesh.obj"),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("spot.usda");
    let mut text = Vec::new();
    topology::mesh::usda::write_usda(
        &mut text,
        &spot.positions,
        &spot.face_offsets,
        &spot.face_vertices,
        "catmullClark",
    )
    .unwrap();
    std::fs::write(&path, text).unwrap();
    let back = load_usd(&path).unwrap();
    assert_eq!(back.face_offsets, spot.face_offsets);
    assert_eq!(back.face_vertices, spot.face_vertices);
    let rounded: Vec<[f64; 3]> = spot
        .positions
        .iter()
        .map(|p| p.map(|x| x as f32 as f64))
        .collect();
    assert_eq!(back.positions, rounded);
    assert_eq!(back.scheme, Some(Scheme::CatmullClark));
    assert!(
        back.positions != spot.positions,
        "some coordinate needs rounding"
    );
}
