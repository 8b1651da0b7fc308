//! `tessera limit --points`: many limit points at once, in the domain of `tessera export`'s
//! `# p` lines. An exported OBJ given as the points file comes back as its own vertices (the
//! GPU drew the limit surface); `F U V` lines give what `limit --face --uv` prints; bad lines,
//! faces and parameters are named by file and line.
mod common;
use common::tessera;
use std::path::{Path, PathBuf};
use std::process::Output;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-cli-limit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn data(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(p)
        .to_str()
        .unwrap()
        .to_owned()
}

fn ok(args: &[&str]) -> String {
    let o: Output = tessera(args, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect()
}

/// The `v` lines of an OBJ.
fn vertices(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let n = numbers(l);
            [n[0], n[1], n[2]]
        })
        .collect()
}

/// The cube exported by bft (the Loop limit of its fan triangulation) and by adaptive (the
/// Catmull-Clark limit, Gregory end caps at its eight valence-3 corners), fed back as points:
/// bft's vertices are the limit to float rounding, adaptive's on its regular patches.
#[test]
fn exported_points_evaluate_to_the_exported_vertices() {
    let cube = data("tests/data/meshes/cube.obj");
    for (method, scheme) in [("bft", "loop"), ("adaptive", "catmull-clark")] {
        let obj = tmp(&format!("cube_{method}.obj"));
        let positions = tmp(&format!("cube_{method}.xyz"));
        ok(&[
            "export",
            &cube,
            "--method",
            method,
            "--scheme",
            scheme,
            "--segments",
            "4",
            "-o",
            obj.to_str().unwrap(),
        ]);
        let said = ok(&[
            "limit",
            &cube,
            "--scheme",
            scheme,
            "--points",
            obj.to_str().unwrap(),
            "-o",
            positions.to_str().unwrap(),
        ]);
        let want = vertices(&obj);
        assert!(
            said.contains(&format!("{} limit points", want.len())),
            "{said}"
        );
        let got: Vec<Vec<f64>> = std::fs::read_to_string(&positions)
            .unwrap()
            .lines()
            .map(numbers)
            .collect();
        assert_eq!(got.len(), want.len());
        let mut errors: Vec<f64> = got
            .iter()
            .zip(&want)
            .map(|(g, w)| (0..3).map(|k| (g[k] - w[k]).abs()).fold(0.0, f64::max))
            .collect();
        errors.sort_by(f64::total_cmp);
        let (median, worst) = (errors[errors.len() / 2], errors[errors.len() - 1]);
        eprintln!("{method}: |GPU − limit| median {median:.2e}, worst {worst:.2e} (cube side 2)");
        if method == "bft" {
            assert!(worst < 2e-5, "{method}: {worst:.2e}");
        } else {
            assert!(
                median < 2e-6 && worst < 1e-2,
                "{method}: {median:.2e} {worst:.2e}"
            );
        }
    }
}

/// On quads the two conventions agree: `F U V` (F from 0) is `--face F+1 --uv U,V`; on Loop
/// triangles the `# p` (U, V) weigh corners 0 and 1, the patch domain's corners 1 and 2.
#[test]
fn points_are_what_limit_face_uv_prints() {
    let cube = data("tests/data/meshes/cube.obj");
    let ico = data("tests/data/opensubdiv/shapes/loop_icosahedron.obj");
    let file = tmp("points.txt");
    std::fs::write(&file, "# comment\n0 0.25 0.75\n\n3 0.5 0.125\n").unwrap();
    let single = |input: &str, scheme: &str, face: &str, uv: &str| -> Vec<f64> {
        let s = ok(&[
            "limit", input, "--scheme", scheme, "--face", face, "--uv", uv,
        ]);
        let line = s.lines().find_map(|l| l.strip_prefix("position ")).unwrap();
        numbers(line)
    };
    let many = ok(&[
        "limit",
        &cube,
        "--scheme",
        "catmull-clark",
        "--points",
        file.to_str().unwrap(),
        "--derivatives",
    ]);
    let rows: Vec<Vec<f64>> = many.lines().map(numbers).collect();
    assert_eq!(rows.len(), 2);
    assert!(rows.iter().all(|r| r.len() == 12), "{many}");
    for (row, (face, uv)) in rows.iter().zip([("1", "0.25,0.75"), ("4", "0.5,0.125")]) {
        let want = single(&cube, "catmull-clark", face, uv);
        for k in 0..3 {
            assert!(
                (row[k] - want[k]).abs() < 1e-11,
                "face {face}: {row:?} {want:?}"
            );
        }
        let n = &row[9..12];
        assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-12);
    }
    std::fs::write(&file, "2 0.2 0.3\n").unwrap();
    let many = ok(&[
        "limit",
        &ico,
        "--scheme",
        "loop",
        "--points",
        file.to_str().unwrap(),
    ]);
    let got = numbers(many.lines().next().unwrap());
    let want = single(&ico, "loop", "3", "0.3,0.5");
    for k in 0..3 {
        assert!((got[k] - want[k]).abs() < 1e-11, "{got:?} {want:?}");
    }
}

#[test]
fn bad_points_are_named_by_file_and_line() {
    let cube = data("tests/data/meshes/cube.obj");
    let file = tmp("bad_points.txt");
    let path = file.to_str().unwrap();
    for (text, needles) in [
        ("0 0.5 0.5\n0 0.5\n", vec![":2:", "expected `F U V`"]),
        (
            "0 0.5 0.5\nx 0.5 0.5\n",
            vec![":2:", "\"x\" is not a number from 0"],
        ),
        (
            "0 0.5 0.5\n\n6 0.5 0.5\n",
            vec![":3:", "face 6 out of range", "0 to 5"],
        ),
        ("0 nan 0.5\n", vec![":1:", "NaN", "domain"]),
        ("0 1.5 0.5\n", vec![":1:", "(1.5, 0.5)", "domain"]),
        ("# nothing\n", vec!["no `F U V`"]),
    ] {
        std::fs::write(&file, text).unwrap();
        let o = tessera(
            &[
                "limit",
                &cube,
                "--scheme",
                "catmull-clark",
                "--points",
                path,
            ],
            &[],
        );
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{text:?}: {e}");
        for n in needles {
            assert!(e.contains(n), "{text:?}: {e} should mention {n:?}");
        }
    }
    // --face with --points is a usage error.
    let o = tessera(
        &[
            "limit", &cube, "--scheme", "loop", "--points", path, "--face", "1",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    let o = tessera(&["limit", &cube, "--scheme", "loop"], &[]);
    assert_eq!(o.status.code(), Some(2));
}

/// The limit of `--face --corner --uv` (Doo-Sabin), as printed.
fn doo_sabin_at(input: &str, face: usize, corner: usize, uv: &str) -> String {
    ok(&[
        "limit",
        input,
        "--scheme",
        "doo-sabin",
        "--face",
        &face.to_string(),
        "--corner",
        &corner.to_string(),
        "--uv",
        uv,
    ])
}

fn position_of(printed: &str) -> Vec<f64> {
    numbers(
        printed
            .lines()
            .find_map(|l| l.strip_prefix("position "))
            .unwrap(),
    )
}

/// Doo-Sabin's points are (face, corner, u, v): `F C U V` lines (from 0) are what `--face
/// --corner --uv` (from 1) prints; a triangle's centre is its centroid, where no derivatives
/// are given (asked for, it is a named refusal); bad corners and parameters are named.
#[test]
fn doo_sabin_points_are_face_corner_uv() {
    let pyramid = data("tests/data/opensubdiv/shapes/catmark_pyramid.obj");
    let file = tmp("ds_points.txt");
    std::fs::write(&file, "0 1 0.3 0.7\n4 3 0.5 0.125\n").unwrap();
    let many = ok(&[
        "limit",
        &pyramid,
        "--scheme",
        "doo-sabin",
        "--points",
        file.to_str().unwrap(),
        "--derivatives",
    ]);
    let rows: Vec<Vec<f64>> = many.lines().map(numbers).collect();
    assert_eq!(rows.len(), 2, "{many}");
    for (row, (face, corner, uv)) in rows.iter().zip([(1, 2, "0.3,0.7"), (5, 4, "0.5,0.125")]) {
        assert_eq!(row.len(), 12);
        let want = position_of(&doo_sabin_at(&pyramid, face, corner, uv));
        for k in 0..3 {
            assert!((row[k] - want[k]).abs() < 1e-11, "{row:?} {want:?}");
        }
    }
    // Face 1 is a triangle: its centre is the centroid of its corners.
    let corners = vertices(Path::new(&pyramid));
    let text = std::fs::read_to_string(&pyramid).unwrap();
    let face: Vec<usize> = text
        .lines()
        .find_map(|l| l.strip_prefix("f "))
        .unwrap()
        .split_whitespace()
        .map(|w| w.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
        .collect();
    assert_eq!(face.len(), 3);
    let printed = doo_sabin_at(&pyramid, 1, 3, "1,1");
    let got = position_of(&printed);
    for k in 0..3 {
        let c: f64 = face.iter().map(|&x| corners[x][k]).sum::<f64>() / 3.0;
        assert!((got[k] - c).abs() < 1e-11, "{printed}");
    }
    assert!(printed.contains("du none"), "{printed}");
    for (text, needles) in [
        ("0 0 1 1\n", vec![":1:", "no parametric derivatives"]),
        (
            "0 0 0.5 0.5\n0 3 0.5 0.5\n",
            vec![":2:", "corner 3 out of range", "0 to 2"],
        ),
        ("0 0 1.5 0.5\n", vec![":1:", "(1.5, 0.5)", "corner's quad"]),
        ("0 0.5 0.5\n", vec![":1:", "expected `F C U V`"]),
    ] {
        std::fs::write(&file, text).unwrap();
        let o = tessera(
            &[
                "limit",
                &pyramid,
                "--scheme",
                "doo-sabin",
                "--points",
                file.to_str().unwrap(),
                "--derivatives",
            ],
            &[],
        );
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{text:?}: {e}");
        assert!(!e.contains("panicked"), "{e}");
        for n in needles {
            assert!(e.contains(n), "{text:?}: {e} should mention {n:?}");
        }
    }
    let o = tessera(
        &[
            "limit",
            &pyramid,
            "--scheme",
            "doo-sabin",
            "--face",
            "1",
            "--uv",
            "0.5,0.5",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs --corner"));
    // The dual refiner's refusal of a non-manifold vertex, in the OBJ's terms.
    let nonman = data("tests/data/opensubdiv/nonmanifold/catmark_nonman_verts.obj");
    let o = tessera(
        &[
            "limit",
            &nonman,
            "--scheme",
            "doo-sabin",
            "--face",
            "1",
            "--corner",
            "1",
            "--uv",
            "0.5,0.5",
        ],
        &[],
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("non-manifold vertex") && !e.contains("panicked"),
        "{e}"
    );
}

/// `subdivide --scheme doo-sabin --limit`: a level-1 vertex (the child of a face's corner,
/// numbered face by face) goes to the limit at the centre of its corner's quad, and a Chaikin
/// point of the boundary onto the boundary's quadratic B-spline, where the corner quads of its
/// edge's face put it: `(f, i, ½, 0)` on the edge leaving corner `i`, `(f, i, 0, ½)` on the
/// edge entering it.
#[test]
fn doo_sabin_subdivide_limit_is_the_corner_quads_centre() {
    let shape = data("tests/data/opensubdiv/shapes/catmark_xord_boundary.obj");
    let out = tmp("ds_xord_l1.obj");
    ok(&[
        "subdivide",
        &shape,
        "--scheme",
        "doo-sabin",
        "--level",
        "1",
        "--limit",
        "-o",
        out.to_str().unwrap(),
    ]);
    let limits = vertices(&out);
    let text = std::fs::read_to_string(&shape).unwrap();
    let sizes: Vec<usize> = text
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| l.split_whitespace().count())
        .collect();
    let mut w = 0;
    for (f, &n) in sizes.iter().enumerate() {
        for i in 0..n {
            if (f + i) % 3 == 0 {
                let want = position_of(&doo_sabin_at(&shape, f + 1, i + 1, "0.5,0.5"));
                for k in 0..3 {
                    assert!((limits[w][k] - want[k]).abs() < 1e-11, "vertex {w}");
                }
            }
            w += 1;
        }
    }
    // Every Chaikin point's limit is one of the sides' midpoints on the boundary.
    let file = tmp("ds_sides.txt");
    let mut lines = String::new();
    for (f, &n) in sizes.iter().enumerate() {
        for i in 0..n {
            lines.push_str(&format!("{f} {i} 0.5 0\n{f} {i} 0 0.5\n"));
        }
    }
    std::fs::write(&file, lines).unwrap();
    let sides: Vec<Vec<f64>> = ok(&[
        "limit",
        &shape,
        "--scheme",
        "doo-sabin",
        "--points",
        file.to_str().unwrap(),
    ])
    .lines()
    .map(numbers)
    .collect();
    let chaikin = &limits[w..];
    assert!(!chaikin.is_empty());
    for (k, p) in chaikin.iter().enumerate() {
        let near = sides
            .iter()
            .any(|q| (0..3).all(|c| (p[c] - q[c]).abs() < 1e-11));
        assert!(near, "Chaikin point {k}: {p:?} is on no side's midpoint");
    }
}
