//! Bad input, as a hostile user would try it: input whose f32 intermediates overflow is refused
//! with its line and vertex, degenerate input gives finite output through every technique,
//! view options are checked when parsed, a UTF-8 BOM is skipped, and every message says its
//! cause once, in the OBJ's own numbers, before any device is opened. Also runs each CPU and
//! GPU command path (render, export, bench, info, subdivide, limit) with validation on.
mod common;
use common::tessera;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-cli-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn write(name: &str, text: &str) -> String {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_owned()
}

fn data(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(p)
        .to_str()
        .unwrap()
        .to_owned()
}

/// Fails with exit status `code` (1: our error, 2: clap's usage error), no panic, and a
/// message containing every needle; returns the message.
fn fails(args: &[&str], env: &[(&str, &str)], code: i32, needles: &[&str]) -> String {
    let o = tessera(args, env);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{args:?}: {e}");
    assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
    for n in needles {
        assert!(e.contains(n), "{args:?}: error should mention {n:?}: {e}");
    }
    e
}

fn succeeds(args: &[&str]) -> Output {
    let o = tessera(args, &[]);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    o
}

/// Every number on the `v`, `vn` and `# p` lines of an OBJ (panics on a word that is not one).
fn obj_numbers(path: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .filter_map(|l| {
            l.strip_prefix("v ")
                .or_else(|| l.strip_prefix("vn "))
                .or_else(|| l.strip_prefix("# p "))
        })
        .flat_map(|rest| rest.split_whitespace())
        .map(|w| w.parse::<f64>().unwrap_or_else(|_| panic!("{path}: '{w}'")))
        .collect()
}

/// The `vn` lines of an OBJ.
fn obj_normals(path: &str) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .filter_map(|l| l.strip_prefix("vn "))
        .map(|rest| {
            let w: Vec<f64> = rest
                .split_whitespace()
                .map(|w| w.parse().unwrap())
                .collect();
            [w[0], w[1], w[2]]
        })
        .collect()
}

/// A tool that makes sure a run used no loader: options refused with this set were checked
/// before any Vulkan call.
const NO_LOADER: (&str, &str) = ("TESSERA_VULKAN_LIBRARY", "/nonexistent/libvulkan.so.1");

const REPRO: &str = "v 3e38 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";

#[test]
fn coordinates_beyond_the_f32_safe_range_are_refused_with_line_and_vertex() {
    let p = write("repro.obj", REPRO);
    let out = tmp("never.obj");
    let out = out.to_str().unwrap();
    for args in [
        vec!["export", &p, "--method", "bft", "-o", out],
        vec!["render", &p, "-o", out],
        vec![
            "subdivide",
            &p,
            "--scheme",
            "loop",
            "--level",
            "1",
            "-o",
            out,
        ],
        vec![
            "limit", &p, "--scheme", "loop", "--face", "1", "--uv", "0.2,0.2",
        ],
    ] {
        fails(
            &args,
            &[],
            1,
            &["repro.obj:1: vertex 1 at (3e38, 0, 0)", "±1e12"],
        );
    }
    // 1e39 overflows f32 (it used to pass as a finite f64).
    let p = write(
        "f32_overflow.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n",
    );
    fails(
        &[
            "subdivide",
            &p,
            "--scheme",
            "loop",
            "--level",
            "1",
            "-o",
            out,
        ],
        &[],
        1,
        &["f32_overflow.obj:3: vertex 3 at (0, 1e39, 0)"],
    );
    assert!(!Path::new(out).exists(), "no output on error");
}

/// A closed octahedron with its vertices at ±`s` on the axes (triangles, so every technique
/// takes it).
fn octahedron(s: f64) -> String {
    let mut t = String::new();
    for p in [
        [s, 0.0, 0.0],
        [-s, 0.0, 0.0],
        [0.0, s, 0.0],
        [0.0, -s, 0.0],
        [0.0, 0.0, s],
        [0.0, 0.0, -s],
    ] {
        t.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    t.push_str("f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
    t
}

/// The same octahedron's faces over other positions: all coincident, collinear, tiny.
fn octahedron_faces_over(positions: &[[f64; 3]; 6]) -> String {
    let mut t = String::new();
    for p in positions {
        t.push_str(&format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]));
    }
    t.push_str("f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
    t
}

/// At the accepted bound and on degenerate (but finite) meshes, every technique exports finite
/// positions, normals and domain points, validation-clean. At the bound, the surface
/// techniques' normals are unit vectors: `|du × dv|²` overflows f32 there, so the shaders scale
/// before normalising (before, BFT and adaptive wrote `vn 0 0 0`, and later Gregory and ACC-1
/// too, through the owners' normals of their shared points). Opposite corner normals make
/// PN's quadratic normal field vanish at the edge midpoint (before, `normalize` wrote NaN).
#[test]
fn bound_and_degenerate_meshes_export_finite_through_every_technique() {
    let meshes = [
        ("at_bound", octahedron(1e12)),
        ("coincident", octahedron_faces_over(&[[0.5, 0.5, 0.5]; 6])),
        (
            "collinear",
            octahedron_faces_over(&[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [3.0, 0.0, 0.0],
                [4.0, 0.0, 0.0],
                [5.0, 0.0, 0.0],
            ]),
        ),
        ("tiny", octahedron(1e-30)),
        (
            "opposite_normals",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//2 3//1\n".to_string(),
        ),
        (
            // Face `f 3 1 6` of zero area (vertex 6 halfway between 1 and 3).
            "zero_area",
            octahedron_faces_over(&[
                [1.0, 0.0, 0.0],
                [-1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, -1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.5, 0.5, 0.0],
            ]),
        ),
    ];
    let mut failures = Vec::new();
    for (name, text) in &meshes {
        let input = write(&format!("{name}.obj"), text);
        // The surface methods also displaced (procedural heights): the displaced normal is
        // |du x dv| n + ..., whose length overflowed f32 at the bound (NaN normals, refused by
        // export's finiteness check) until it was taken after scaling.
        for (method, displace) in [
            ("flat", false),
            ("phong", false),
            ("pn", false),
            ("bft", false),
            ("adaptive", false),
            ("adaptive", true),
            ("gregory", false),
            ("gregory", true),
            ("acc", false),
            ("acc", true),
        ] {
            let out = tmp(&format!("{name}_{method}_{displace}_out.obj"));
            let out = out.to_str().unwrap();
            let mut args = vec![
                "export",
                &input,
                "--method",
                method,
                "--segments",
                "4",
                "-o",
                out,
            ];
            if displace {
                args.extend(["--displace", "0.05"]);
            }
            let method = if displace {
                format!("{method} displaced")
            } else {
                method.to_string()
            };
            let o = tessera(&args, &[]);
            if !o.status.success() {
                failures.push(format!("{name} {method}: {}", stderr(&o)));
                continue;
            }
            let numbers = obj_numbers(out);
            if numbers.is_empty() || !numbers.iter().all(|x| x.is_finite()) {
                failures.push(format!(
                    "{name} {method}: {} numbers, non-finite: {:?}",
                    numbers.len(),
                    numbers
                        .iter()
                        .filter(|x| !x.is_finite())
                        .take(4)
                        .collect::<Vec<_>>()
                ));
            }
            if *name == "at_bound" && !["flat", "phong"].contains(&method.as_str()) {
                let not_unit = obj_normals(out)
                    .into_iter()
                    .filter(|n| {
                        ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() > 1e-3
                    })
                    .count();
                if not_unit > 0 {
                    failures.push(format!(
                        "{name} {method}: {not_unit} normals not of unit length"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The CPU commands at the bound: subdivided, limit and printed limit values are all finite.
#[test]
fn subdivide_and_limit_at_the_bound_are_finite() {
    let input = write("bound_cpu.obj", &octahedron(1e12));
    for (scheme, limit) in [("loop", true), ("catmull-clark", true), ("loop", false)] {
        let out = tmp(&format!("bound_{scheme}_{limit}.obj"));
        let out = out.to_str().unwrap();
        let mut args = vec![
            "subdivide",
            &input,
            "--scheme",
            scheme,
            "--level",
            "2",
            "-o",
            out,
        ];
        if limit {
            args.push("--limit");
        }
        succeeds(&args);
        let numbers = obj_numbers(out);
        assert!(!numbers.is_empty() && numbers.iter().all(|x| x.is_finite()));
    }
    let o = succeeds(&[
        "limit", &input, "--scheme", "loop", "--face", "4", "--uv", "0.25,0.5",
    ]);
    let s = stdout(&o);
    let values: Vec<f64> = s
        .lines()
        .filter(|l| {
            ["position", "du", "dv", "normal"]
                .iter()
                .any(|k| l.starts_with(k))
        })
        .flat_map(|l| l.split_whitespace().skip(1))
        .map(|w| w.parse().unwrap())
        .collect();
    assert_eq!(values.len(), 12, "{s}");
    assert!(values.iter().all(|x| x.is_finite()), "{s}");
    // The normal is a unit vector, not zero: the f64 path keeps its squares.
    let n = &values[9..12];
    assert!(
        ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-9,
        "{s}"
    );
}

#[test]
fn view_options_are_checked_when_parsed() {
    let out = tmp("never_view.png");
    let out = out.to_str().unwrap();
    for (option, value) in [
        ("--zoom", "0"),
        ("--zoom", "-1"),
        ("--zoom", "nan"),
        ("--zoom", "1e30"),
        ("--yaw", "nan"),
        ("--yaw", "inf"),
        ("--pitch", "100"),
        ("--alpha", "nan"),
        ("--alpha", "2"),
    ] {
        fails(&["render", option, value, "-o", out], &[], 2, &[option]);
    }
    // export shares the camera options and α.
    let cube = data("tests/data/meshes/cube.obj");
    fails(
        &[
            "export", &cube, "--method", "flat", "--zoom", "nan", "-o", out,
        ],
        &[],
        2,
        &["--zoom"],
    );
    fails(&["view", "--frames", "0"], &[], 2, &["--frames"]);
    fails(&["bench", "--frames", "0"], &[], 2, &["--frames"]);
    assert!(!Path::new(out).exists());
}

#[test]
fn a_utf8_byte_order_mark_is_skipped() {
    let p = write(
        "bom.obj",
        "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
    );
    let out = tmp("bom_out.obj");
    let o = succeeds(&[
        "subdivide",
        &p,
        "--scheme",
        "loop",
        "--level",
        "1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!stderr(&o).contains("unknown"), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("10 vertices, 16 faces"),
        "{}",
        stdout(&o)
    );
}

/// Each cause is said once; topology errors use the OBJ's numbers and line.
#[test]
fn messages_say_each_cause_once_in_obj_terms() {
    let out = tmp("never_msg.png");
    let out = out.to_str().unwrap();
    let e = fails(
        &["render", "/nonexistent/cow.obj", "-o", out],
        &[],
        1,
        &["/nonexistent/cow.obj"],
    );
    assert_eq!(e.matches("os error").count(), 1, "{e}");
    let p = write("empty.obj", "v 0 0 0\n");
    let e = fails(
        &["render", &p, "-o", out],
        &[],
        1,
        &["empty.obj: empty mesh: no faces"],
    );
    assert_eq!(e.matches("empty mesh").count(), 1, "{e}");
    let p = write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    fails(
        &["render", &p, "-o", out],
        &[],
        1,
        &["index.obj:4: face 1 names vertex 4, but the file has 3 vertices"],
    );
    let p = write(
        "tag.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/1/0 0 7 2\n",
    );
    fails(
        &["render", &p, "-o", out],
        &[],
        1,
        &[
            "tag.obj:5: invalid tag: crease names vertex 7",
            "3 vertices",
        ],
    );
    // A technique's error wrapping the mesh's (thiserror embeds and chains a `source` field):
    // said once.
    let mut ngon = String::new();
    for i in 0..300 {
        let a = i as f64 * std::f64::consts::TAU / 300.0;
        ngon.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    ngon.push('f');
    for i in 1..=300 {
        ngon.push_str(&format!(" {i}"));
    }
    ngon.push('\n');
    let p = write("ngon.obj", &ngon);
    let e = fails(
        &["render", &p, "--method", "adaptive", "-o", out],
        &[],
        1,
        // The face's line too, since errors found after loading are located.
        &["ngon.obj:301: adaptive plan: "],
    );
    assert_eq!(e.matches("300 corners").count(), 1, "{e}");
    // Refinement errors after loading speak the same language (Loop on a quad).
    let quad = write(
        "quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    fails(
        &[
            "subdivide",
            &quad,
            "--scheme",
            "loop",
            "--level",
            "1",
            "-o",
            out,
        ],
        &[],
        1,
        &["quad.obj:5: Loop subdivision needs triangles, but face 1 has 4 vertices"],
    );
}

/// Segment counts are checked before any device (no loader is even looked for), and named as
/// the command names them.
#[test]
fn segments_are_checked_before_the_device_and_named_as_given() {
    let cube = data("tests/data/meshes/cube.obj");
    let out = tmp("never_seg.obj");
    let out = out.to_str().unwrap();
    for method in ["flat", "bft", "adaptive"] {
        let e = fails(
            &[
                "export",
                &cube,
                "--method",
                method,
                "--segments",
                "0",
                "-o",
                out,
            ],
            &[NO_LOADER],
            1,
            &["--segments 0", "from 1 to 64"],
        );
        assert!(
            !e.contains("whole segments") && !e.contains("loader"),
            "{e}"
        );
        for bad in ["nan", "1e30", "-3"] {
            let segments = format!("--segments={bad}");
            fails(
                &["export", &cube, "--method", method, &segments, "-o", out],
                &[NO_LOADER],
                1,
                &["--segments"],
            );
        }
        // One vocabulary: render says `--segments` too, also when given the old
        // spelling `--level`, which stays a hidden alias.
        for option in ["--segments", "--level"] {
            let e = fails(
                &["render", "--method", method, option, "0", "-o", out],
                &[NO_LOADER],
                1,
                &["--segments 0", "from 1 to 64"],
            );
            assert!(!e.contains("--level"), "{e}");
        }
    }
    assert!(!Path::new(out).exists());
}

/// Technique rules that need no device or mesh (BFT's dyadic segments up to its table level,
/// adaptive's whole segments, spacings a technique refuses) are checked before the device too:
/// a bad option on a large mesh must not cost the table build first.
#[test]
fn technique_rules_are_checked_before_the_device() {
    let out = tmp("never_rule.png");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &[&str]); 5] = [
        (
            &["--method", "bft", "--segments", "3"],
            &["--segments 3", "power of two"],
        ),
        (
            &["--method", "bft", "--table-level", "2", "--segments", "16"],
            &["--segments 16", "2..=8"],
        ),
        (
            &["--method", "adaptive", "--segments", "2.5"],
            &["--segments", "whole segments"],
        ),
        (
            &["--method", "bft", "--spacing", "fractional-odd"],
            &["fractional-odd"],
        ),
        (
            &["--method", "adaptive", "--spacing", "fractional-odd"],
            &["fractional-odd"],
        ),
    ];
    for (options, expected) in cases {
        let mut args = vec!["render", "-o", out];
        args.extend_from_slice(options);
        let e = fails(&args, &[NO_LOADER], 1, expected);
        assert!(!e.contains("loader"), "{options:?}: {e}");
    }
    assert!(!Path::new(out).exists());
}

#[test]
fn device_selectors_are_named_as_given_and_info_fails_on_a_missing_one() {
    let out = tmp("never_dev.png");
    let e = fails(
        &["render", "--device", "99", "-o", out.to_str().unwrap()],
        &[],
        1,
        &["--device 99", "devices seen"],
    );
    assert!(!e.contains("Index("), "{e}");
    let e = fails(&["info", "--device", "99"], &[], 1, &["--device 99"]);
    assert!(!e.contains("Index("), "{e}");
    let e = fails(
        &[
            "render",
            "--device",
            "no-such-gpu",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
        1,
        &["--device no-such-gpu"],
    );
    assert!(!e.contains("Name("), "{e}");
}

#[test]
fn negative_crease_sharpness_is_reported_as_smooth() {
    let p = write(
        "negative.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\nt crease 2/1/0 0 1 -2\n",
    );
    let out = tmp("negative_out.obj");
    let o = succeeds(&[
        "subdivide",
        &p,
        "--scheme",
        "loop",
        "--level",
        "1",
        "-o",
        out.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(
        e.contains("negative.obj:9") && e.contains("-2 is treated as 0 (smooth)"),
        "{e}"
    );
}

#[test]
fn no_window_system_error_names_no_source_path() {
    let e = fails(
        &["view", "--frames", "1"],
        &[("DISPLAY", ""), ("WAYLAND_DISPLAY", "")],
        1,
        &["no window system", "DISPLAY"],
    );
    assert!(!e.contains(".cargo") && !e.contains(".rs:"), "{e}");
}

/// Every command path, GPU ones with the validation layer on (their runs fail on any
/// validation error): render, export, bench, info, subdivide, limit.
#[test]
fn every_command_path_runs_with_validation_on() {
    let cube = data("tests/data/meshes/cube.obj");
    let png = tmp("paths.png");
    let obj = tmp("paths.obj");
    let (png, obj) = (png.to_str().unwrap(), obj.to_str().unwrap());
    succeeds(&["render", &cube, "--size", "64x48", "-o", png]);
    succeeds(&[
        "export",
        &cube,
        "--method",
        "pn",
        "--segments",
        "3",
        "-o",
        obj,
    ]);
    let o = succeeds(&[
        "bench",
        "--mesh",
        &cube,
        "--methods",
        "flat,bft",
        "--segments",
        "4",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--size",
        "64x48",
    ]);
    assert!(stdout(&o).contains("flat"), "{}", stdout(&o));
    let o = succeeds(&["info"]);
    assert!(
        stdout(&o).contains("validation layer: on, with synchronization validation"),
        "{}",
        stdout(&o)
    );
    succeeds(&[
        "subdivide",
        &cube,
        "--scheme",
        "catmull-clark",
        "--level",
        "1",
        "-o",
        obj,
    ]);
    let o = succeeds(&[
        "limit",
        &cube,
        "--scheme",
        "catmull-clark",
        "--face",
        "1",
        "--uv",
        "0.5,0.5",
    ]);
    assert!(stdout(&o).contains("normal"), "{}", stdout(&o));
}

/// `limit --face` counts like the OBJ's `f` lines and every message: from 1; 0 and numbers past
/// the last face are named, and evaluation errors speak of the same face.
#[test]
fn limit_faces_are_numbered_from_one() {
    let cube = data("tests/data/meshes/cube.obj");
    for face in ["0", "7"] {
        fails(
            &[
                "limit",
                &cube,
                "--scheme",
                "catmull-clark",
                "--face",
                face,
                "--uv",
                "0.5,0.5",
            ],
            &[],
            1,
            &[&format!("--face {face}"), "faces 1 to 6"],
        );
    }
    let o = succeeds(&[
        "limit",
        &cube,
        "--scheme",
        "catmull-clark",
        "--face",
        "6",
        "--uv",
        "0.5,0.5",
    ]);
    assert!(stdout(&o).contains("face 6 uv"), "{}", stdout(&o));
    let quads = write(
        "two_quads.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 5 6 3\n",
    );
    fails(
        &[
            "limit", &quads, "--scheme", "loop", "--face", "2", "--uv", "0.2,0.2",
        ],
        &[],
        1,
        &["two_quads.obj", "face 1 has 4 vertices"],
    );
}

/// `tessera info | head -0`: stdout closed before anything is written. `println!` panicked
/// (exit 101, "failed printing to stdout"); the command now ends quietly.
#[test]
fn closed_stdout_is_not_a_panic() {
    for args in [&["info"][..], &["limit", "--help"][..]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tessera"))
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("tessera runs");
        // Closing the read end before the child has started writing makes every write fail
        // with EPIPE.
        drop(child.stdout.take());
        let o = child.wait_with_output().expect("tessera ends");
        let e = stderr(&o);
        assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
        assert!(
            o.status.code() == Some(0) || args[1..].contains(&"--help"),
            "{args:?}: {:?} {e}",
            o.status
        );
    }
}

/// One error line, said once: `error: ` then the message, no panic, no repeated prefix, the
/// file named exactly once.
fn one_line_naming(e: &str, file: &str) {
    assert_eq!(e.trim_end().lines().count(), 1, "one line: {e}");
    assert!(e.starts_with("error: "), "{e}");
    assert_eq!(e.matches("error:").count(), 1, "said once: {e}");
    assert_eq!(e.matches(file).count(), 1, "names {file} once: {e}");
}

/// Bad surface maps: a colour texture or height map that is missing or not an image is a
/// one-line error naming the file, given before any device is opened (no loader is even
/// looked for), by render, export and bench alike.
#[test]
fn missing_or_unreadable_texture_and_height_map_are_named() {
    let spot = data("assets/spot_control_mesh.obj");
    let out = tmp("never_textured.png");
    let out = out.to_str().unwrap();
    let obj = tmp("never_textured.obj");
    let obj = obj.to_str().unwrap();
    let missing = tmp("no_such_texture.png");
    let _ = std::fs::remove_file(&missing);
    let missing = missing.to_str().unwrap();
    let not_png = write("not_an_image.png", "this is text, not a PNG\n");
    let height = data("assets/spot_height.png");
    let texture = data("assets/spot_texture.png");
    for method in ["gregory", "acc"] {
        let e = fails(
            &[
                "render",
                &spot,
                "--method",
                method,
                "--texture",
                missing,
                "-o",
                out,
            ],
            &[NO_LOADER],
            1,
            &["os error"],
        );
        one_line_naming(&e, missing);
        let e = fails(
            &[
                "render",
                &spot,
                "--method",
                method,
                "--displace",
                "0.1",
                "--height",
                &not_png,
                "-o",
                out,
            ],
            &[NO_LOADER],
            1,
            &[],
        );
        one_line_naming(&e, &not_png);
    }
    // The other map's slot, and the other commands.
    let cases: [(Vec<&str>, &str); 4] = [
        (
            vec![
                "render",
                &spot,
                "--method",
                "gregory",
                "--texture",
                &not_png,
                "--displace",
                "0.1",
                "--height",
                &height,
                "-o",
                out,
            ],
            &not_png,
        ),
        (
            vec![
                "export",
                &spot,
                "--method",
                "gregory",
                "--texture",
                &texture,
                "--displace",
                "0.1",
                "--height",
                missing,
                "-o",
                obj,
            ],
            missing,
        ),
        (
            vec![
                "bench",
                "--mesh",
                &spot,
                "--methods",
                "flat,gregory",
                "--texture",
                missing,
            ],
            missing,
        ),
        (
            vec![
                "bench",
                "--mesh",
                &spot,
                "--methods",
                "flat,gregory",
                "--displace",
                "0.05",
                "--height",
                &not_png,
            ],
            &not_png,
        ),
    ];
    for (args, file) in cases {
        let e = fails(&args, &[NO_LOADER], 1, &[]);
        one_line_naming(&e, file);
    }
    assert!(!Path::new(out).exists() && !Path::new(obj).exists());
}

/// A colour texture or a height map alone on a mesh without `vt` is refused naming the mesh
/// and the map, before the device; procedural displacement needs no `vt` and runs.
#[test]
fn maps_on_a_mesh_without_vt_are_named_before_the_device() {
    let cube = data("tests/data/meshes/cube.obj");
    let out = tmp("never_bare.png");
    let out = out.to_str().unwrap();
    let texture = data("assets/spot_texture.png");
    let height = data("assets/spot_height.png");
    let maps: [(&[&str], &str); 2] = [
        (&["--texture", &texture], "a colour texture was given"),
        (
            &["--displace", "0.1", "--height", &height],
            "a height map was given",
        ),
    ];
    for (options, said) in maps {
        for method in ["gregory", "acc", "adaptive"] {
            let mut args = vec!["render", &cube, "--method", method, "-o", out];
            args.extend_from_slice(options);
            let e = fails(&args, &[NO_LOADER], 1, &[said, "`vt`"]);
            one_line_naming(&e, &cube);
        }
        let mut args = vec!["bench", "--mesh", &cube, "--methods", "flat,gregory"];
        args.extend_from_slice(options);
        let e = fails(&args, &[NO_LOADER], 1, &[said, "`vt`"]);
        one_line_naming(&e, &cube);
    }
    assert!(!Path::new(out).exists());
    succeeds(&[
        "render",
        &cube,
        "--method",
        "gregory",
        "--displace",
        "0.1",
        "--segments",
        "2",
        "--size",
        "64x48",
        "-o",
        out,
    ]);
}

/// `bench --scheme doo-sabin` draws `adaptive` as the Doo-Sabin limit patches, as render does.
#[test]
fn bench_takes_the_scheme_as_render_does() {
    let cube = data("tests/data/opensubdiv/shapes/catmark_cube.obj");
    let csv = tmp("doo_sabin_rows.csv");
    let csv = csv.to_str().unwrap();
    succeeds(&[
        "bench",
        "--scheme",
        "doo-sabin",
        "--methods",
        "flat,adaptive",
        "--mesh",
        &cube,
        "--segments",
        "2",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--size",
        "64x48",
        "--csv",
        csv,
    ]);
    let methods: Vec<String> = bench_csv_rows(csv).into_iter().map(|(m, _)| m).collect();
    assert!(
        methods.iter().any(|m| m == "doo-sabin-limit"),
        "{methods:?}"
    );
    assert!(
        !methods.iter().any(|m| m.starts_with("adaptive")),
        "{methods:?}"
    );
}

/// The CSV rows of a `bench --csv` run: (method, note).
fn bench_csv_rows(path: &str) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let method = header.iter().position(|c| *c == "method").unwrap();
    assert_eq!(header.last(), Some(&"note"), "{header:?}");
    lines
        .map(|l| {
            // The note is the last column and the only one that may be quoted.
            let fields: Vec<&str> = l.splitn(header.len(), ',').collect();
            let note = fields[header.len() - 1].trim_matches('"').to_owned();
            (fields[method].to_owned(), note)
        })
        .collect()
}

/// `tessera bench` takes render's surface options (the surface-map interface): the texture,
/// height map and displacement are built into the gregory rows (their device memory holds
/// both images) and their notes say so, Flat draws as always; `--no-reparam` is accepted and
/// noted; bad combinations are refused as render refuses them.
#[test]
fn bench_applies_the_surface_options_to_the_surface_rows() {
    let spot = data("assets/spot_control_mesh.obj");
    let texture = data("assets/spot_texture.png");
    let height = data("assets/spot_height.png");
    let cheap = [
        "--segments",
        "2",
        "--frames",
        "1",
        "--warmup",
        "1",
        "--size",
        "64x48",
    ];
    let csv = tmp("bench_surface.csv");
    let csv = csv.to_str().unwrap();
    let mut args = vec![
        "bench",
        "--mesh",
        &spot,
        "--methods",
        "flat,gregory",
        "--texture",
        &texture,
        "--displace",
        "0.05",
        "--height",
        &height,
        "--csv",
        csv,
    ];
    args.extend_from_slice(&cheap);
    let text = stdout(&succeeds(&args));
    // The binary's heap policy is part of what was measured (docs/benchmarks.md, "Devices, and how to read the figures").
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    assert!(
        text.contains("Host heap: glibc mmap threshold fixed at 128 KiB, heap top never trimmed"),
        "{text}"
    );
    assert!(
        text.contains(
            "Surface maps on the adaptive, gregory, acc rows (their notes say so; the other \
             methods draw as always): textured (spot_texture.png), displaced by 0.05 × \
             spot_height.png, reparameterized texture coordinates"
        ),
        "{text}"
    );
    // Both images were uploaded for gregory (its device memory lists them by file).
    let memory = text
        .lines()
        .find(|l| l.contains("gregory device memory"))
        .unwrap_or_else(|| panic!("no memory line: {text}"));
    assert!(
        memory.contains("spot_texture.png") && memory.contains("spot_height.png"),
        "{memory}"
    );
    let rows = bench_csv_rows(csv);
    let note = |m: &str| {
        rows.iter()
            .find(|(method, _)| method == m)
            .map(|(_, n)| n.clone())
            .unwrap_or_else(|| panic!("no {m} row: {rows:?}"))
    };
    for m in ["gregory", "gregory-animated"] {
        let n = note(m);
        assert!(
            n.contains("textured (spot_texture.png)")
                && n.contains("displaced by 0.05 × spot_height.png")
                && n.contains("reparameterized"),
            "{m}: {n}"
        );
    }
    assert!(!note("flat").contains("textured"), "{}", note("flat"));

    // --no-reparam alone (procedural displacement would need no vt either).
    let mut args = vec![
        "bench",
        "--mesh",
        &spot,
        "--methods",
        "flat,gregory",
        "--no-reparam",
        "--csv",
        csv,
    ];
    args.extend_from_slice(&cheap);
    succeeds(&args);
    let rows = bench_csv_rows(csv);
    assert!(
        rows.iter()
            .any(|(m, n)| m == "gregory" && n.contains("no reparameterization")),
        "{rows:?}"
    );

    // Bad combinations, before the device, in render's words.
    let e = fails(
        &["bench", "--methods", "flat,bft", "--texture", &texture],
        &[NO_LOADER],
        1,
        &[
            "--texture only applies to the adaptive, gregory, acc rows",
            "flat,bft",
        ],
    );
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    fails(
        &["bench", "--methods", "flat,gregory", "--height", &height],
        &[NO_LOADER],
        1,
        &["--height needs --displace S"],
    );
    fails(
        &["bench", "--methods", "gregory", "--displace", "inf"],
        &[NO_LOADER],
        1,
        &["--displace inf: give a finite scale"],
    );
}

/// An OBJ disk around one interior vertex of valence `n` (its `n` quads and a ring of `2n`
/// quads around them), gently curved, `vt` the planar projection.
fn high_valence_disk_obj(n: usize) -> String {
    let tau = std::f64::consts::TAU;
    let mut t = String::from("v 0 0 0\nvt 0.5 0.5\n");
    // The first ring alternates edge neighbours (radius 1) and diagonal vertices (1.3).
    for radii in [[1.0, 1.3], [2.2, 2.2]] {
        for k in 0..2 * n {
            let r = radii[k % 2];
            let a = tau * k as f64 / (2 * n) as f64;
            let (x, y) = (r * a.cos(), r * a.sin());
            let z = 0.15 * r * r + 0.05 * r * (3.0 * a).cos();
            t.push_str(&format!(
                "v {x} {y} {z}\nvt {} {}\n",
                0.5 + x / 4.8,
                0.5 + y / 4.8
            ));
        }
    }
    let ring = |k: usize| 2 + k % (2 * n);
    let outer = |k: usize| 2 + 2 * n + k % (2 * n);
    let f = |t: &mut String, vs: [usize; 4]| {
        t.push('f');
        for v in vs {
            t.push_str(&format!(" {v}/{v}"));
        }
        t.push('\n');
    };
    for i in 0..n {
        f(&mut t, [1, ring(2 * i), ring(2 * i + 1), ring(2 * i + 2)]);
    }
    for k in 0..2 * n {
        f(&mut t, [ring(k), outer(k), outer(k + 1), ring(k + 1)]);
    }
    t
}

/// A Gregory corner of valence 20, beyond the fitted table (3–16), renders textured and
/// displaced with the reparameterization on (the documented fallback: the valence-16 row),
/// validation-clean, and the reparameterization visibly moves the texture there.
#[test]
fn a_corner_above_the_reparameterization_table_renders() {
    let disk = write("valence20.obj", &high_valence_disk_obj(20));
    let texture = data("assets/spot_texture.png");
    let height = data("assets/spot_height.png");
    let mut images = Vec::new();
    for (name, reparam) in [("on", true), ("off", false)] {
        let png = tmp(&format!("valence20_{name}.png"));
        let png = png.to_str().unwrap();
        let mut args = vec![
            "render",
            &disk,
            "--method",
            "gregory",
            "--texture",
            &texture,
            "--displace",
            "0.02",
            "--height",
            &height,
            "--segments",
            "8",
            // Facing the disk.
            "--yaw",
            "0",
            "--pitch",
            "0",
            "--size",
            "160x120",
            "-o",
            png,
        ];
        if !reparam {
            args.push("--no-reparam");
        }
        let e = stderr(&succeeds(&args));
        assert!(!e.contains("panicked"), "{e}");
        images.push(image::open(png).unwrap().to_rgba8());
    }
    let differing = images[0]
        .pixels()
        .zip(images[1].pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 8))
        .count();
    println!("{differing} of {} pixels differ", images[0].pixels().len());
    assert!(
        differing > 400,
        "the reparameterization should move the texture: {differing} pixels differ"
    );
}

/// The draw path: `render` says which it drew; patterns draw without tessellation shaders;
/// what cannot be drawn on a path is refused naming the option, and malformed values of the
/// path and displacement options are refused with their forms.
#[test]
fn the_draw_path_options_draw_or_name_what_is_wrong() {
    let png = tmp("path.png");
    let png = png.to_str().unwrap();
    for (args, path) in [
        (
            vec!["--method", "flat", "--pipeline", "pattern"],
            "pattern path",
        ),
        (
            vec!["--method", "pn", "--no-tessellation-shader"],
            "pattern path",
        ),
        (
            vec!["--method", "bft", "--no-tessellation-shader"],
            "pattern path",
        ),
        (
            vec!["--method", "phong", "--pipeline", "tessellation"],
            "tessellation path",
        ),
        (
            vec!["--method", "adaptive", "--pipeline", "pattern"],
            "pattern path",
        ),
        (
            vec!["--method", "gregory", "--no-tessellation-shader"],
            "pattern path",
        ),
        (
            vec![
                "--method",
                "adaptive",
                "--pipeline",
                "pattern",
                "--factors",
                "distance",
            ],
            "pattern path",
        ),
        (
            vec![
                "--method",
                "pn",
                "--pipeline",
                "pattern",
                "--displace-sine",
                "0.02,25",
            ],
            "pattern path",
        ),
        (
            vec![
                "--method",
                "adaptive",
                "--pipeline",
                "pattern",
                "--factors",
                "screen",
                "--spacing",
                "fractional-even",
            ],
            "pattern path",
        ),
    ] {
        let mut all = vec!["render", "--size", "96x72", "-o", png];
        all.extend(args);
        let o = succeeds(&all);
        assert!(stdout(&o).contains(path), "{all:?}: {}", stdout(&o));
    }
    let render = |extra: &[&'static str]| {
        let mut all = vec!["render", "--size", "96x72", "-o", png];
        all.extend(extra);
        all
    };
    fails(
        &render(&["--method", "cpu-catmark", "--pipeline", "pattern"]),
        &[],
        1,
        &["cpu-catmark", "--pipeline pattern"],
    );
    fails(
        &render(&[
            "--method",
            "pn",
            "--no-tessellation-shader",
            "--spacing",
            "fractional-odd",
        ]),
        &[],
        1,
        &["equal spacing", "--spacing equal"],
    );
    fails(
        &render(&["--pipeline", "mesh"]),
        &[],
        2,
        &["tessellation, pattern, auto"],
    );
    for bad in ["1", "nan,1", "1,-1", "2000,1", "1,x"] {
        fails(
            &render(&["--method", "pn", "--displace-sine", bad]),
            &[],
            2,
            &["--displace-sine"],
        );
    }
    fails(
        &render(&["--method", "doo-sabin-limit", "--displace-sine", "0.1,2"]),
        &[],
        1,
        &["--displace-sine", "--method pn"],
    );
    fails(
        &["bench", "--methods", "flat@mesh", "--frames", "1"],
        &[],
        1,
        &["flat@mesh", "tessellation or pattern"],
    );
    fails(
        &["bench", "--scheme", "doo-sabin", "--methods", "flat,bft"],
        &[],
        1,
        &["--scheme doo-sabin", "--methods bft", "another scheme"],
    );
    fails(
        &["bench", "--scheme", "bicubic", "--methods", "flat"],
        &[],
        1,
        &["--scheme bicubic"],
    );
    fails(
        &[
            "bench",
            "--figure7",
            "--csv",
            tmp("f7.csv").to_str().unwrap(),
        ],
        &[],
        1,
        &["--figure7", "--markdown"],
    );
}

/// `--depth D` draws a uniform refinement's level D (2^D segments): the seed's vertex patches
/// at depth 2 draw; a depth out of 1..6 and `--depth` with `--segments` are refused by name.
#[test]
fn the_depth_option_draws_a_level_or_names_what_is_wrong() {
    let png = tmp("depth.png");
    let png = png.to_str().unwrap();
    let o = succeeds(&[
        "render",
        "--size",
        "96x72",
        "-o",
        png,
        "--scheme",
        "doo-sabin",
        "--method",
        "vertex-patches",
        "--depth",
        "2",
    ]);
    assert!(stdout(&o).contains("vertex-patches"), "{}", stdout(&o));
    for depth in ["0", "7", "2.5"] {
        fails(
            &[
                "render",
                "--method",
                "vertex-patches",
                "--depth",
                depth,
                "-o",
                png,
            ],
            &[],
            2,
            &["--depth", depth],
        );
    }
    fails(
        &[
            "render",
            "--method",
            "vertex-patches",
            "--depth",
            "2",
            "--segments",
            "4",
            "-o",
            png,
        ],
        &[],
        2,
        &["--depth", "--segments"],
    );
}
