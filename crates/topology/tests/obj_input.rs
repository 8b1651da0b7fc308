//! What a hostile user feeds the OBJ reader: every tag's malformed forms, attribute indices
//! out of range wherever they appear, corners with too many indices, bytes that are not UTF-8,
//! UTF-16, paths that are not regular files; and errors found after loading located on their
//! line. Each is refused (or read) with the file and line named.

use topology::error::ObjSyntax;
use topology::mesh::obj::{load_obj_with_lines, parse_obj, parse_obj_bytes};
use topology::{load_obj, TopologyError};

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
/// A closed tetrahedron (every edge shared by two faces), 4 vertices then 4 faces.
const TET: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

fn parse_error(text: &str) -> (usize, String) {
    match parse_obj(text, "in.obj") {
        Err(TopologyError::Parse { file, line, kind }) => {
            assert_eq!(file, "in.obj");
            (line, kind.to_string())
        }
        other => panic!("{text:?}: expected a parse error, got {other:?}"),
    }
}

/// Every malformed form of every tag the reader knows is refused on its line, with what is
/// wrong in words (not "bad value (none)").
#[test]
fn every_tags_malformed_forms_are_refused_on_their_line() {
    let cases: [(&str, &str); 24] = [
        ("t", "'t' needs a tag name and its counts"),
        ("t crease", "'t' needs a tag name and its counts"),
        (
            "t crease 2/1 0 1 1",
            "counts '2/1' are not three whole numbers",
        ),
        (
            "t crease x/1/0 0 1 1",
            "counts 'x/1/0' are not three whole numbers",
        ),
        ("t crease -2/1/0 0 1 1", "counts '-2/1/0' are not three"),
        ("t crease 2/1/0/0 0 1 1", "counts '2/1/0/0' are not three"),
        (
            "t crease 2/1/0 0 1",
            "counts '2/1/0' do not match the 2 values",
        ),
        (
            "t crease 2/1/0 0 1 2 3",
            "counts '2/1/0' do not match the 4 values",
        ),
        (
            "t crease 18446744073709551615/1/0 1",
            "do not match the 1 values",
        ),
        (
            "t crease 2/1/0 0 x 1",
            "tag 'crease': 'x' is not an integer",
        ),
        (
            "t crease 2/1/0 0 1.5 1",
            "tag 'crease': '1.5' is not an integer",
        ),
        (
            "t crease 2/1/0 0 1 soft",
            "tag 'crease': 'soft' is not a number",
        ),
        (
            "t crease 3/1/0 0 1 2 1",
            "needs vertex pairs (an even number of integers), found 3",
        ),
        ("t crease 2/0/0 0 1", "tag 'crease' needs a sharpness value"),
        ("t crease 4/3/0 0 1 1 2 1 2 3", "3 values for 2 elements"),
        ("t crease 2/1/0 0 -1 1", "tag 'crease': negative index -1"),
        ("t crease 2/1/0 0 1 nan", "sharpness NaN is not finite"),
        ("t corner 0/1/0 1", "tag 'corner' needs at least one vertex"),
        ("t corner 1/1/0 0 inf", "sharpness inf is not finite"),
        ("t hole 0/0/0", "tag 'hole' needs at least one face"),
        ("t hole 1/0/0 -1", "tag 'hole': negative index -1"),
        (
            "t interpolateboundary 0/0/1 edges",
            "tag 'interpolateboundary': 'edges'; expected one integer: 0 (none)",
        ),
        (
            "t creasemethod 0/0/0",
            "tag 'creasemethod': no value; expected one string: chaikin",
        ),
        (
            "t smoothtriangles 1/0/0 2",
            "tag 'smoothtriangles': 2; expected one string, smooth or catmark",
        ),
    ];
    let mut failures = Vec::new();
    for (tag, said) in cases {
        let text = format!("{TET}{tag}\n");
        let (line, message) = parse_error(&text);
        if line != 9 || !message.contains(said) {
            failures.push(format!(
                "{tag:?}: line {line}: {message:?}, expected {said:?}"
            ));
        }
    }
    // Option tags with more values than one, or of the wrong kind.
    for tag in [
        "t interpolateboundary 2/0/0 1 2",
        "t interpolateboundary 0/1/0 1",
        "t creasemethod 0/0/2 chaikin normal",
        "t creasemethod 1/0/1 1 chaikin",
        "t smoothtriangles 0/0/1 loop",
    ] {
        let (line, message) = parse_error(&format!("{TET}{tag}\n"));
        if line != 9 || !message.contains("expected") {
            failures.push(format!("{tag:?}: line {line}: {message:?}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The well-formed tags are read as before.
#[test]
fn well_formed_option_tags_are_read() {
    use topology::rules::options::{BoundaryInterpolation, CreaseMethod, TriangleSubdivision};
    let m = parse_obj(
        &format!(
            "{TET}t interpolateboundary 1/0/0 2\nt creasemethod 0/0/1 normal\n\
             t smoothtriangles 1/0/0 0\nt hole 1/0/0 3\n"
        ),
        "in.obj",
    )
    .unwrap();
    assert_eq!(m.options.boundary, BoundaryInterpolation::EdgesOnly);
    assert_eq!(m.options.crease_method, CreaseMethod::Uniform);
    assert_eq!(m.options.triangle_subdivision, TriangleSubdivision::Catmark);
    assert_eq!(m.holes, [3]);
}

/// Texture and normal indices are checked wherever they are given: a face naming a missing
/// normal is refused whether or not other faces have normals (before, only when every corner
/// of the file had one), and a corner with four indices is refused.
#[test]
fn attribute_indices_are_checked_wherever_they_are_given() {
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nvt 0 0\nvn 0 0 1\n";
    let cases: [(&str, usize, &str); 8] = [
        (
            "f 1//99 2//99 3//99\n",
            9,
            "normal 99 is named, but the file has 1 'vn' lines",
        ),
        ("f 1 2 3 4\nf 2//99 5//99 6//99\n", 10, "normal 99 is named"),
        ("f 2//99 5//99 6//99\nf 1 2 3 4\n", 9, "normal 99 is named"),
        (
            "f 1/5 2/1 3/1 4/1\n",
            9,
            "texture coordinate 5 is named, but the file has 1 'vt'",
        ),
        (
            "f 1 2 3 4\nf 2/5 5/1 6/1\n",
            10,
            "texture coordinate 5 is named",
        ),
        (
            "f 1/1/-3 2/1/1 3/1/1\n",
            9,
            "relative index '1/1/-3' points before the start",
        ),
        (
            "f 1/1/1/1 2/1/1 3/1/1\n",
            9,
            "'1/1/1/1' has more than three indices",
        ),
        (
            "f 1 2 3 4/1/1/\n",
            9,
            "'4/1/1/' has more than three indices",
        ),
    ];
    let mut failures = Vec::new();
    for (faces, want_line, said) in cases {
        let (line, message) = parse_error(&format!("{quad}{faces}"));
        if line != want_line || !message.contains(said) {
            failures.push(format!(
                "{faces:?}: line {line}: {message:?}, expected {said:?}"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    // Attributes that exist are kept only where every corner has them, as before.
    let m = parse_obj(
        &format!("{quad}f 1 2 3 4\nf 2//1 5//1 6//1 3//1\n"),
        "in.obj",
    )
    .unwrap();
    assert!(m.normals.is_none() && m.uvs.is_none());
}

/// A Latin-1 byte in a comment or a name changes nothing; in a number it is refused on its
/// line; UTF-16 with a byte-order mark is read; NUL bytes (UTF-16 without one) are refused on
/// the line of the first.
#[test]
fn text_encodings_are_read_or_refused_on_their_line() {
    let with_latin1 = |line: &[u8]| {
        let mut bytes = Vec::from(&b"v 0 0 0\nv 1 0 0\n"[..]);
        bytes.extend_from_slice(line);
        bytes.extend_from_slice(b"\nv 0 1 0\nf 1 2 3\n");
        bytes
    };
    for line in [
        &b"# Kuh \xe9t\xe9"[..],
        b"o vache_\xe9t\xe9",
        b"usemtl m\xe9tal",
    ] {
        let m = parse_obj_bytes(&with_latin1(line), "latin1.obj").unwrap();
        assert_eq!(m.num_faces(), 1);
    }
    match parse_obj_bytes(&with_latin1(b"v 0 0 1\xe9"), "latin1.obj") {
        Err(TopologyError::Parse { line: 3, kind, .. }) => {
            assert!(matches!(kind, ObjSyntax::NotANumber { .. }), "{kind}")
        }
        other => panic!("{other:?}"),
    }
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let le: Vec<u8> = text.encode_utf16().flat_map(u16::to_le_bytes).collect();
    let be: Vec<u8> = text.encode_utf16().flat_map(u16::to_be_bytes).collect();
    for (bytes, bom) in [(&le, [0xFF, 0xFE]), (&be, [0xFE, 0xFF])] {
        let mut with_bom = bom.to_vec();
        with_bom.extend_from_slice(bytes);
        let m = parse_obj_bytes(&with_bom, "utf16.obj").unwrap();
        assert_eq!((m.positions.len(), m.num_faces()), (3, 1));
        match parse_obj_bytes(bytes, "utf16.obj") {
            Err(e @ TopologyError::Parse { line: 1, .. }) => {
                assert!(
                    e.to_string().contains("UTF-16 without a byte-order mark"),
                    "{e}"
                )
            }
            other => panic!("{other:?}"),
        }
    }
    let mut nul = Vec::from(text.as_bytes());
    nul.extend_from_slice(b"v 0 0\x000\n");
    assert!(matches!(
        parse_obj_bytes(&nul, "nul.obj"),
        Err(TopologyError::Parse {
            line: 5,
            kind: ObjSyntax::NulByte,
            ..
        })
    ));
}

/// A crease tag between vertices no edge joins is dropped at load (a warning names its line),
/// so refinement never meets it.
#[test]
fn creases_off_the_edges_are_dropped_at_load() {
    let m = parse_obj(
        &format!("{TET}t crease 2/1/0 0 1 2\nt crease 2/1/0 0 0 3\nt crease 2/1/0 1 3 4\n"),
        "in.obj",
    )
    .unwrap();
    let kept: Vec<[u32; 2]> = m.creases.iter().map(|c| c.vertices).collect();
    assert_eq!(kept, [[0, 1], [1, 3]]);
    let _ = TRI;
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("topology-obj-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Paths that are not regular files are refused unopened, naming the file and what it is.
#[test]
fn what_is_not_a_regular_file_is_refused() {
    let dir = scratch("dir.obj");
    std::fs::create_dir_all(&dir).unwrap();
    let mut cases = vec![(dir, "is a directory, not a regular file")];
    #[cfg(unix)]
    {
        cases.push(("/dev/zero".into(), "is a character device"));
        let fifo = scratch("fifo.obj");
        let _ = std::fs::remove_file(&fifo);
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        assert!(made, "mkfifo");
        cases.push((fifo, "is a FIFO (named pipe), not a regular file"));
    }
    for (path, said) in cases {
        let e = load_obj(&path).unwrap_err();
        let m = e.to_string();
        assert!(
            matches!(e, TopologyError::Io { .. })
                && m.starts_with(&path.display().to_string())
                && m.contains(said),
            "{m}"
        );
    }
}

/// Errors found after loading (an adaptive plan's face too large) are located on the face's
/// line, in the file's 1-based numbers.
#[test]
fn later_errors_are_located_on_their_line() {
    use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions};
    let mut text = String::from(TET);
    let n = 300;
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        text += &format!("v {} {} 5\n", a.cos(), a.sin());
    }
    text += "f";
    for i in 0..n {
        text += &format!(" {}", i + 5);
    }
    text += "\n";
    let path = scratch("ngon.obj");
    std::fs::write(&path, &text).unwrap();
    let (mesh, lines) = load_obj_with_lines(&path).unwrap();
    let e = plan_adaptive(&mesh, &AdaptiveOptions::default()).expect_err("a 300-gon");
    let name = path.display().to_string();
    let m = lines.locate(e, &mesh, &name).to_string();
    assert_eq!(
        m,
        format!(
            "{name}:{}: adaptive plan: face 5 has 300 corners (at most 256)",
            4 + 4 + n + 1
        )
    );
}
