//! Scalar tags (`t scalartag`) through the OBJ reader: read as written; a malformed line, a bad
//! value and a vertex of two creases are errors naming the file and the tag's line.
use topology::mesh::obj::parse_obj;
use topology::mesh::scalar_tags::ScalarTag;

/// The OBJ extension: tags read as written; a malformed line, a bad value and a vertex of
/// two creases are errors naming the file and the tag's line.
#[test]
fn obj_tags_are_read_and_bad_ones_name_their_line() {
    let mut text = String::new();
    for j in 0..3 {
        for i in 0..4 {
            text += &format!("v {i} {j} 0\n");
        }
    }
    for i in [1, 2, 3, 5, 6, 7] {
        text += &format!("f {i} {} {} {}\n", i + 1, i + 5, i + 4);
    }
    let good = format!("{text}t scalartag 1/6/0 5 0 1 0 0.25 0.5 -0.5\n");
    let mesh = parse_obj(&good, "st.obj").unwrap();
    assert_eq!(
        mesh.scalar_tags,
        vec![ScalarTag {
            vertex: 5,
            deviation: [0.0, 1.0, 0.0],
            tension: 0.25,
            sharpness: 0.5,
            bias: -0.5,
        }]
    );
    // Line 19 is the first tag line (12 vertices, 6 faces).
    let cases = [
        ("t scalartag 1/5/0 5 0 1 0 0 1\n", "six numbers"),
        ("t scalartag 2/6/0 5 6 0 1 0 0 1 0\n", "one vertex"),
        ("t scalartag 1/6/0 5 0 1 0 0 2 0\n", "sharpness 2"),
        ("t scalartag 1/6/0 12 0 1 0 0 1 0\n", "names vertex 12"),
    ];
    for (line, expected) in cases {
        let e = parse_obj(&format!("{text}{line}"), "st.obj")
            .unwrap_err()
            .to_string();
        assert!(e.contains(expected) && e.contains("st.obj:19"), "{e}");
    }
    let row_and_column: String = [1, 4, 5, 6, 9]
        .iter()
        .map(|v| format!("t scalartag 1/6/0 {v} 0 1 0 0 1 0\n"))
        .collect();
    let e = parse_obj(&format!("{text}{row_and_column}"), "st.obj")
        .unwrap_err()
        .to_string();
    // Vertex 5's tag is the third tag line.
    assert!(e.contains("vertex 5") && e.contains("st.obj:21"), "{e}");
}
