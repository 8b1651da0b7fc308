//! The `tessera` binary as a user runs it: clear errors for bad input, and the window under
//! Xvfb showing what the offscreen renderer shows.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tessera(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tessera"));
    c.args(args);
    if matches!(
        args.first(),
        Some(&"render" | &"view" | &"info" | &"export")
    ) {
        c.arg("--validation");
    }
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("tessera runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn write(name: &str, text: &str) -> PathBuf {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn fails_with(args: &[&str], env: &[(&str, &str)], needles: &[&str]) {
    let o = tessera(args, env);
    let e = stderr(&o);
    assert!(!o.status.success(), "{args:?} should fail");
    assert_eq!(
        o.status.code(),
        Some(1),
        "{args:?}: an error exit, not a crash: {e}"
    );
    assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
    for n in needles {
        assert!(e.contains(n), "{args:?}: error should mention {n:?}: {e}");
    }
}

#[test]
fn default_render_writes_a_shaded_png() {
    let out = tmp("default.png");
    let o = tessera(
        &["render", "--size", "200x150", "-o", out.to_str().unwrap()],
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (200, 150));
    // The mesh covers a good part of the frame and is lit (not just background).
    let bg = img.get_pixel(0, 0).0;
    let covered = img.pixels().filter(|p| p.0 != bg).count();
    assert!(
        covered > 200 * 150 / 10,
        "only {covered} pixels show the mesh"
    );
}

#[test]
fn missing_file_names_the_file() {
    fails_with(
        &["render", "/nonexistent/cow.obj", "-o", "/tmp/x.png"],
        &[],
        &["/nonexistent/cow.obj"],
    );
}

#[test]
fn malformed_obj_names_file_and_line() {
    let p = write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n");
    fails_with(&["render", p.to_str().unwrap()], &[], &["bad.obj", ":3"]);
}

#[test]
fn out_of_range_face_names_the_face() {
    let p = write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
    fails_with(
        &["render", p.to_str().unwrap()],
        &[],
        &["range.obj", "face 1"],
    );
}

#[test]
fn empty_mesh_is_an_error() {
    let p = write("empty.obj", "# nothing here\nv 0 0 0\n");
    fails_with(
        &["render", p.to_str().unwrap()],
        &[],
        &["empty.obj", "empty"],
    );
}

#[test]
fn no_vulkan_loader_is_an_error() {
    fails_with(
        &["render", "-o", "/tmp/x.png"],
        &[("TESSERA_VULKAN_LIBRARY", "/nonexistent/libvulkan.so.1")],
        &["Vulkan loader"],
    );
}

#[test]
fn no_vulkan_device_is_an_error() {
    let icd = write("no_driver.json", "{}");
    let icd = icd.to_str().unwrap();
    fails_with(
        &["render", "-o", "/tmp/x.png"],
        &[("VK_ICD_FILENAMES", icd), ("VK_DRIVER_FILES", icd)],
        &["device"],
    );
}

#[test]
fn bad_level_is_an_error() {
    fails_with(
        &["render", "--level", "65", "-o", "/tmp/x.png"],
        &[],
        &["level"],
    );
}

#[test]
fn info_lists_devices_and_choice() {
    let o = tessera(&["info"], &[]);
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        s.contains("maxTessellationGenerationLevel") && s.contains("chosen:"),
        "{s}"
    );
}

/// Starts Xvfb on a free display; None when Xvfb is not installed (the README's test command
/// installs it, and CI sets TESSERA_REQUIRE_XVFB=1 so a missing Xvfb fails there).
fn xvfb() -> Option<(std::process::Child, String)> {
    for n in 90..120 {
        if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
            || Path::new(&format!("/tmp/.X{n}-lock")).exists()
        {
            continue;
        }
        let display = format!(":{n}");
        let child = Command::new("Xvfb")
            .args([&display, "-screen", "0", "640x480x24", "-nolisten", "tcp"])
            .spawn()
            .ok()?;
        for _ in 0..100 {
            if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                return Some((child, display));
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        return Some((child, display));
    }
    None
}

#[test]
fn window_screenshot_matches_offscreen_render() {
    let Some((mut server, display)) = xvfb() else {
        assert!(
            std::env::var_os("TESSERA_REQUIRE_XVFB").is_none(),
            "Xvfb is required here but not installed"
        );
        eprintln!("skipping: Xvfb not installed");
        return;
    };
    let shot = tmp("window.png");
    let offscreen = tmp("offscreen.png");
    let common = [
        "--method",
        "pn",
        "--level",
        "5",
        "--wireframe",
        "--size",
        "320x240",
        "--yaw",
        "-30",
    ];
    let o = tessera(
        &[
            &["view"][..],
            &common,
            &["--frames", "30", "--screenshot", shot.to_str().unwrap()],
        ]
        .concat(),
        &[("DISPLAY", &display), ("WAYLAND_DISPLAY", "")],
    );
    let _ = server.kill();
    let _ = server.wait();
    assert!(o.status.success(), "view failed: {}", stderr(&o));
    let r = tessera(
        &[
            &["render"][..],
            &common,
            &["-o", offscreen.to_str().unwrap()],
        ]
        .concat(),
        &[],
    );
    assert!(r.status.success(), "{}", stderr(&r));
    let a = image::open(&shot).unwrap().to_rgba8();
    let b = image::open(&offscreen).unwrap().to_rgba8();
    assert_eq!(a.dimensions(), b.dimensions());
    let differing = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| {
            p.0.iter()
                .zip(q.0.iter())
                .take(3)
                .any(|(x, y)| x.abs_diff(*y) > 24)
        })
        .count();
    let fraction = differing as f64 / (a.width() * a.height()) as f64;
    assert!(
        fraction <= 0.005,
        "window and offscreen differ in {:.3}% of pixels",
        fraction * 100.0
    );
}

fn data(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(p)
        .to_string_lossy()
        .into_owned()
}

/// Base vertices keep their index under refinement, so `subdivide --limit` must put vertex v of
/// face 0 where `limit` evaluates face 0 at that corner: two independent code paths agree.
#[test]
fn subdivide_limit_agrees_with_limit_evaluation() {
    for (shape, scheme, corner_uv) in [
        (
            "tests/data/opensubdiv/shapes/loop_icosahedron.obj",
            "loop",
            [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)],
        ),
        (
            "tests/data/opensubdiv/shapes/catmark_cube.obj",
            "catmull-clark",
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)],
        ),
    ] {
        let out = tmp(&format!("{scheme}_limit.obj"));
        let o = tessera(
            &[
                "subdivide",
                &data(shape),
                "--scheme",
                scheme,
                "--level",
                "2",
                "--limit",
                "-o",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        let verts: Vec<[f64; 3]> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                [c[0], c[1], c[2]]
            })
            .collect();
        let base = std::fs::read_to_string(data(shape)).unwrap();
        let face0: Vec<usize> = base
            .lines()
            .find_map(|l| l.strip_prefix("f "))
            .unwrap()
            .split_whitespace()
            .map(|t| t.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
            .collect();
        for (k, (u, v)) in corner_uv.iter().enumerate() {
            let o = tessera(
                &[
                    "limit",
                    &data(shape),
                    "--scheme",
                    scheme,
                    "--face",
                    "0",
                    "--uv",
                    &format!("{u},{v}"),
                ],
                &[],
            );
            assert!(o.status.success(), "{}", stderr(&o));
            let s = String::from_utf8_lossy(&o.stdout);
            let pos: Vec<f64> = s
                .lines()
                .find_map(|l| l.strip_prefix("position "))
                .unwrap()
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            let got = verts[face0[k]];
            for c in 0..3 {
                assert!(
                    (got[c] - pos[c]).abs() < 1e-9,
                    "{shape} corner {k}: subdivide --limit {got:?} vs limit {pos:?}"
                );
            }
        }
    }
}

/// Runs `tessera export` and returns its stdout; panics with stderr when it fails.
fn export_ok(args: &[&str]) -> String {
    let o = tessera(args, &[]);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The number printed after `label` on its line of the export report.
fn reported(stdout: &str, label: &str) -> usize {
    let line = stdout
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no '{label}' line in:\n{stdout}"));
    line[label.len()..]
        .split_whitespace()
        .next()
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| panic!("no number after '{label}': {line}"))
}

#[test]
fn export_writes_a_watertight_outward_obj_for_flat() {
    let out = tmp("cube_flat.obj");
    let cube = data("tests/data/meshes/cube.obj");
    let s = export_ok(&[
        "export",
        &cube,
        "--method",
        "flat",
        "--segments",
        "4",
        "--scheme",
        "loop",
        "-o",
        out.to_str().unwrap(),
    ]);
    // 6 quads × 2 × 4² triangles; 6 × 4² + 2 vertices once welded.
    assert_eq!(reported(&s, "captured:"), 192, "{s}");
    assert!(s.contains("192 triangles, 576 vertices"), "{s}");
    assert_eq!(reported(&s, "welded:"), 98, "{s}");
    assert_eq!(reported(&s, "open edges:"), 0, "{s}");
    assert!(s.contains("0 cracks"), "{s}");
    assert_eq!(reported(&s, "zero-area triangles:"), 0, "{s}");

    let text = std::fs::read_to_string(&out).unwrap();
    let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!((count("v "), count("vn "), count("# p ")), (98, 98, 98));
    assert_eq!(count("f "), 192);
    // Every vertex's base face and domain coordinate: a cube face, inside the unit square.
    for l in text.lines().filter(|l| l.starts_with("# p ")) {
        let w: Vec<f64> = l[4..]
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        assert!(w[0] >= 0.0 && w[0] < 6.0 && w[0].fract() == 0.0, "{l}");
        assert!(
            (0.0..=1.0).contains(&w[1]) && (0.0..=1.0).contains(&w[2]),
            "{l}"
        );
    }
    // The topology reader accepts it as a closed, consistently oriented manifold, wound
    // outward like the input (positive volume: 8 for the 2 × 2 × 2 cube).
    let mesh = topology::load_obj(&out).expect("exported OBJ parses and validates");
    assert_eq!((mesh.positions.len(), mesh.num_faces()), (98, 192));
    let volume: f64 = mesh
        .faces()
        .map(|f| {
            let [a, b, c] = [0, 1, 2].map(|i| mesh.positions[f[i] as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum();
    assert!((volume - 8.0).abs() < 1e-9, "volume {volume}");
}

#[test]
fn export_reports_pn_cracks_and_fails_on_them_when_asked() {
    let out = tmp("cube_pn.obj");
    let cube = data("tests/data/meshes/cube.obj");
    let args = [
        "export",
        &cube,
        "--method",
        "pn",
        "--segments",
        "5",
        "-o",
        out.to_str().unwrap(),
    ];
    // PN evaluates shared edges in a different float order from each side: bit-level cracks,
    // reported (exit 0) unless --fail-on-cracks.
    let s = export_ok(&args);
    let open = reported(&s, "open edges:");
    assert!(
        open > 0 && s.contains(&format!("0 on the base mesh's boundary, {open} cracks")),
        "{s}"
    );
    let mut strict = args.to_vec();
    strict.push("--fail-on-cracks");
    fails_with(&strict, &[], &["cracks", "--fail-on-cracks"]);
}

#[test]
fn export_tells_base_boundary_from_cracks() {
    // An open square of two quads: its 6 base edges, 3 segments each, are boundary.
    let p = write(
        "open_quads.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0.5\nv 2 1 0\nf 1 2 5 4\nf 2 3 6 5\n",
    );
    let out = tmp("open_quads_out.obj");
    let s = export_ok(&[
        "export",
        p.to_str().unwrap(),
        "--method",
        "flat",
        "--segments",
        "3",
        "--fail-on-cracks",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(reported(&s, "open edges:"), 18, "{s}");
    assert!(
        s.contains("18 on the base mesh's boundary, 0 cracks"),
        "{s}"
    );
}

#[test]
fn export_bad_inputs_are_named_errors() {
    let out = tmp("never.obj");
    let out = out.to_str().unwrap();
    fails_with(
        &[
            "export",
            "/nonexistent/cow.obj",
            "--method",
            "flat",
            "--segments",
            "4",
            "-o",
            out,
        ],
        &[],
        &["/nonexistent/cow.obj"],
    );
    let cube = data("tests/data/meshes/cube.obj");
    fails_with(
        &[
            "export",
            &cube,
            "--method",
            "flat",
            "--segments",
            "4",
            "--scheme",
            "catmull-clark",
            "-o",
            out,
        ],
        &[],
        &["--scheme catmull-clark", "loop"],
    );
    fails_with(
        &[
            "export",
            &cube,
            "--method",
            "flat",
            "--segments",
            "65",
            "-o",
            out,
        ],
        &[],
        &["--segments"],
    );
    let bad = write("bad_export.obj", "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n");
    fails_with(
        &[
            "export",
            bad.to_str().unwrap(),
            "--method",
            "pn",
            "--segments",
            "2",
            "-o",
            out,
        ],
        &[],
        &["bad_export.obj", ":3"],
    );
    assert!(!Path::new(out).exists(), "no output on error");
}
