//! The second hostile probe of the command line, by class: inputs that are not regular files or
//! are too large, every writer against a full disk, every numeric option's negative, NaN and
//! out-of-range values, every tag's malformed forms, meshes f32 cannot draw or whose pictures
//! came out blank, errors found after loading, and the messages the probe found wanting. Each
//! case must end (no hang, no panic) with a named error or a correct result.
mod common;
use common::tessera;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-cli-reliability-{}", std::process::id()));
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

/// No loader at all: options refused with this set were checked before any Vulkan call.
const NO_LOADER: (&str, &str) = ("TESSERA_VULKAN_LIBRARY", "/nonexistent/libvulkan.so.1");

/// Runs `tessera` as [`tessera`] does, killed after `limit` (a hang is a failure, not a stuck
/// test): its output, or `None` when it had to be killed.
fn tessera_within(args: &[&str], env: &[(&str, &str)], limit: Duration) -> Option<Output> {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tessera"));
    c.args(args);
    if matches!(
        args.first(),
        Some(&"render" | &"view" | &"info" | &"export" | &"bench")
    ) {
        c.args(["--validation", "--sync-validation"]);
    }
    c.envs(env.iter().copied())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = c.spawn().expect("tessera runs");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            return Some(child.wait_with_output().expect("output"));
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A run that should fail: its message when it did (exit 1 or 2, no panic, every needle in
/// its message, nothing reported written), else what was wrong.
fn refused_with(args: &[&str], env: &[(&str, &str)], needles: &[&str]) -> Result<String, String> {
    let Some(o) = tessera_within(args, env, Duration::from_secs(120)) else {
        return Err(format!("{args:?}: still running after 120 s (killed)"));
    };
    let e = stderr(&o);
    let ok = matches!(o.status.code(), Some(1 | 2))
        && !e.contains("panicked")
        && needles.iter().all(|n| e.contains(n))
        && !stdout(&o).contains("wrote ");
    if ok {
        Ok(e)
    } else {
        Err(format!("{args:?}: {:?}: {e}", o.status.code()))
    }
}

/// What is wrong with a run that should fail ([`refused_with`]), or `None`.
fn refusal(args: &[&str], env: &[(&str, &str)], needles: &[&str]) -> Option<String> {
    refused_with(args, env, needles).err()
}

fn succeeds(args: &[&str]) -> Output {
    let o = tessera(args, &[]);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    o
}

/// A FIFO at `name` (Linux's mkfifo).
fn fifo(name: &str) -> String {
    let p = tmp(name);
    let _ = std::fs::remove_file(&p);
    let made = Command::new("mkfifo")
        .arg(&p)
        .status()
        .is_ok_and(|s| s.success());
    assert!(made, "mkfifo {}", p.display());
    p.to_str().unwrap().to_owned()
}

/// A sparse file of `bytes` bytes (no disk used): larger than a bound, read by nothing.
fn sparse(name: &str, bytes: u64) -> String {
    let p = tmp(name);
    std::fs::File::create(&p).unwrap().set_len(bytes).unwrap();
    p.to_str().unwrap().to_owned()
}

/// Every input Tessera reads (OBJ meshes of every command, dropped meshes aside; texture and
/// height maps; a benchmark CSV), given a character device, a FIFO, a directory or a file past
/// its size bound: each is refused at once, naming the file and what it is (before, /dev/zero
/// grew to 12 GB and a FIFO blocked forever).
#[test]
fn inputs_that_are_not_regular_files_or_too_large_are_refused() {
    let spot = data("assets/spot_control_mesh.obj");
    let out = tmp("never.png");
    let out = out.to_str().unwrap();
    let obj_out = tmp("never.obj");
    let obj_out = obj_out.to_str().unwrap();
    let dir = tmp("a_directory.obj");
    std::fs::create_dir_all(&dir).unwrap();
    let dir = dir.to_str().unwrap().to_owned();
    let fifo = fifo("f.obj");
    let big_obj = sparse("big.obj", (1 << 30) + 1);
    let big_png = sparse("big.png", (512 << 20) + 1);
    let big_csv = sparse("big.csv", (64 << 20) + 1);
    type Args<'a> = Box<dyn Fn(&'a str) -> Vec<&'a str> + 'a>;
    let commands: Vec<(&str, Args)> = vec![
        ("render", Box::new(|i| vec!["render", i, "-o", out])),
        ("view", Box::new(|i| vec!["view", i, "--frames", "1"])),
        (
            "subdivide",
            Box::new(|i| {
                vec![
                    "subdivide",
                    i,
                    "--scheme",
                    "loop",
                    "--level",
                    "1",
                    "-o",
                    obj_out,
                ]
            }),
        ),
        (
            "limit",
            Box::new(|i| vec!["limit", i, "--scheme", "loop", "--face", "1", "--uv", "0,0"]),
        ),
        ("export", Box::new(|i| vec!["export", i, "-o", obj_out])),
        (
            "bench",
            Box::new(|i| vec!["bench", "--mesh", i, "--methods", "flat"]),
        ),
        (
            "texture",
            Box::new(|i| {
                vec![
                    "render",
                    spot.as_str(),
                    "--method",
                    "gregory",
                    "--texture",
                    i,
                    "-o",
                    out,
                ]
            }),
        ),
        (
            "height",
            Box::new(|i| {
                vec![
                    "render",
                    spot.as_str(),
                    "--method",
                    "gregory",
                    "--displace",
                    "0.1",
                    "--height",
                    i,
                    "-o",
                    out,
                ]
            }),
        ),
        ("plot", Box::new(|i| vec!["plot", i, "-o", out])),
    ];
    let mut failures = Vec::new();
    for (what, args) in &commands {
        let mut inputs = vec![
            (
                "/dev/zero",
                "is a character device, not a regular file".to_string(),
            ),
            (
                fifo.as_str(),
                "is a FIFO (named pipe), not a regular file".into(),
            ),
            (dir.as_str(), "is a directory".into()),
        ];
        let (big, said) = match *what {
            "texture" | "height" => (&big_png, "more than the 512 MiB an image may have"),
            "plot" => (&big_csv, "more than the 64 MiB a benchmark CSV may have"),
            _ => (&big_obj, "more than the 1 GiB an OBJ file may have"),
        };
        inputs.push((big.as_str(), said.into()));
        for (input, said) in inputs {
            let args = args(input);
            let env = [NO_LOADER, ("DISPLAY", ""), ("WAYLAND_DISPLAY", "")];
            if let Some(f) = refusal(&args, &env, &[input, &said]) {
                failures.push(format!("{what}: {f}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `path` made a link to /dev/full: every write to it fails with ENOSPC.
fn full(name: &str) -> String {
    let p = tmp(name);
    let _ = std::fs::remove_file(&p);
    std::os::unix::fs::symlink("/dev/full", &p).unwrap();
    p.to_str().unwrap().to_owned()
}

/// Every writer (render's PNG, subdivide's and export's OBJ, bench's CSV, Markdown and plot,
/// plot's SVG and PNG) against a full disk: exit 1 naming the file and the OS reason, nothing
/// reported written (before, `render -o full.png` printed "wrote full.png" and exited 0). The
/// window's screenshot is window.rs's.
#[test]
fn every_writer_reports_a_failed_write() {
    let cube = data("tests/data/meshes/cube.obj");
    let csv = tmp("run.csv");
    let csv = csv.to_str().unwrap().to_owned();
    let bench = [
        "bench",
        "--mesh",
        &cube,
        "--methods",
        "flat",
        "--segments",
        "2",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--size",
        "64x48",
    ];
    succeeds(&[&bench[..], &["--csv", &csv]].concat());
    let png = full("full.png");
    let obj = full("full.obj");
    let txt = full("full.csv");
    let md = full("full.md");
    let svg = full("full.svg");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "render", &cube, "--method", "flat", "--size", "64x48", "-o", &png,
            ],
            &png,
        ),
        (
            vec![
                "render", &cube, "--method", "adaptive", "--size", "64x48", "-o", &png,
            ],
            &png,
        ),
        (
            vec![
                "render", &cube, "--method", "bft", "--size", "64x48", "-o", &png,
            ],
            &png,
        ),
        (
            vec![
                "subdivide",
                &cube,
                "--scheme",
                "catmull-clark",
                "--level",
                "1",
                "-o",
                &obj,
            ],
            &obj,
        ),
        (
            vec![
                "export",
                &cube,
                "--method",
                "flat",
                "--segments",
                "2",
                "-o",
                &obj,
            ],
            &obj,
        ),
        ([&bench[..], &["--csv", &txt]].concat(), &txt),
        ([&bench[..], &["--markdown", &md]].concat(), &md),
        ([&bench[..], &["--plot", &svg]].concat(), &svg),
        ([&bench[..], &["--plot", &png]].concat(), &png),
        (vec!["plot", &csv, "-o", &svg], &svg),
        (vec!["plot", &csv, "-o", &png], &png),
    ];
    let mut failures = Vec::new();
    for (args, file) in &cases {
        let needle = format!("cannot write {file}: ");
        if let Some(f) = refusal(args, &[], &[&needle, "os error 28"]) {
            failures.push(f);
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Output directories: missing ones are made; one that is a file is named with the reason.
#[test]
fn output_directories_are_made_or_named() {
    let cube = data("tests/data/meshes/cube.obj");
    let deep = tmp("made/for/it.obj");
    let _ = std::fs::remove_dir_all(tmp("made"));
    let deep = deep.to_str().unwrap();
    succeeds(&[
        "subdivide",
        &cube,
        "--scheme",
        "catmull-clark",
        "--level",
        "0",
        "-o",
        deep,
    ]);
    assert!(Path::new(deep).is_file());
    let file = write("plain_file", "x");
    let under = format!("{file}/x.png");
    let f = refusal(
        &["render", &cube, "--size", "64x48", "-o", &under],
        &[],
        &[&format!("cannot write {under}: cannot create {file}")],
    );
    assert!(f.is_none(), "{f:?}");
}

/// Every numeric option of every command, given a negative number, NaN, a number past its
/// range and one past its type: refused (exit 1 or 2) with the option and its range named,
/// before any device; never clap's "unexpected argument '-1'" (before, negatives were taken
/// for options).
#[test]
fn every_numeric_option_names_its_range() {
    let cube = data("tests/data/meshes/cube.obj");
    let out = tmp("never_numbers.png");
    let out = out.to_str().unwrap();
    let obj = tmp("never_numbers.obj");
    let obj = obj.to_str().unwrap();
    // (command line before the option, option, extra options it needs, its range's ends, a
    // value past the range).
    let render = vec!["render", cube.as_str(), "-o", out];
    let adaptive = vec!["render", cube.as_str(), "--method", "adaptive", "-o", out];
    let bft = vec!["render", cube.as_str(), "--method", "bft", "-o", out];
    let export = vec!["export", cube.as_str(), "--method", "flat", "-o", obj];
    let bench = vec!["bench", "--mesh", cube.as_str(), "--methods", "flat"];
    let subdivide = vec!["subdivide", cube.as_str(), "--scheme", "loop", "-o", obj];
    let limit = vec!["limit", cube.as_str(), "--scheme", "catmull-clark"];
    let view = vec!["view", cube.as_str()];
    type Case<'a> = (&'a [&'a str], &'a str, &'a [&'a str], [&'a str; 2], &'a str);
    let cases: Vec<Case> = vec![
        (&render, "--segments", &[], ["1", "64"], "257"),
        (&render, "--size", &[], ["1", "16384"], "16385x5"),
        (&render, "--yaw", &[], ["-360", "360"], "361"),
        (&render, "--pitch", &[], ["-90", "90"], "91"),
        (&render, "--zoom", &[], ["0.1", "20"], "21"),
        (
            &render,
            "--alpha",
            &["--method", "phong"],
            ["0", "1"],
            "1.5",
        ),
        (&adaptive, "--isolation", &[], ["1", "8"], "9"),
        (&adaptive, "--sharpness-scale", &[], ["0", "1000"], "1001"),
        (&adaptive, "--displace", &[], ["-1000", "1000"], "1001"),
        (&bft, "--table-level", &[], ["1", "6"], "7"),
        (
            &bft,
            "--pixels",
            &["--factors", "screen"],
            ["0.5", "16384"],
            "16385",
        ),
        (
            &bft,
            "--distance",
            &["--factors", "distance"],
            ["0", "1000000"],
            "1e7",
        ),
        (&bft, "--frame", &[], ["-1000000", "1000000"], "3.4e38"),
        (&export, "--segments", &[], ["1", "64"], "257"),
        (&export, "--size", &[], ["1", "16384"], "0x5"),
        (&bench, "--segments", &[], ["1", "64"], "65"),
        (&bench, "--frames", &[], ["1", "4294967295"], "4294967296"),
        (&bench, "--warmup", &[], ["0", "4294967295"], "4294967296"),
        (&bench, "--row-budget", &[], ["0", "1000000"], "1e7"),
        (
            &bench,
            "--min-frames",
            &[],
            ["1", "4294967295"],
            "4294967296",
        ),
        (
            &bench,
            "--cpu-max-vertices",
            &[],
            ["0", "18446744073709551615"],
            "18446744073709551616",
        ),
        (&bench, "--isolation", &[], ["1", "8"], "9"),
        (&bench, "--size", &[], ["1", "16384"], "5x0"),
        (
            &bench,
            "--displace",
            &["--methods", "gregory"],
            ["-1000", "1000"],
            "1001",
        ),
        (&subdivide, "--level", &[], ["0", "6"], "7"),
        (&limit, "--face", &["--uv", "0,0"], ["--face", "1"], "7"),
        (&view, "--frames", &[], ["1", "4294967295"], "4294967296"),
        (&view, "--size", &[], ["1", "16384"], "-1x5"),
    ];
    let mut failures = Vec::new();
    for (command, option, extra, [lo, hi], past) in &cases {
        for value in [
            "-1",
            "-1e-300",
            "nan",
            "-inf",
            past,
            "99999999999999999999999",
        ] {
            let value = if option.contains("size") && !value.contains('x') {
                format!("{value}x5")
            } else {
                value.to_string()
            };
            // Values in range for a signed option are not refusals.
            if (*option == "--yaw" || *option == "--displace" || *option == "--frame")
                && ["-1", "-1e-300"].contains(&value.as_str())
            {
                continue;
            }
            // -1e-300 is -0 in f32: within ranges that start at 0.
            if ["--sharpness-scale", "--alpha"].contains(option) && value == "-1e-300" {
                continue;
            }
            if *option == "--pitch" && ["-1", "-1e-300"].contains(&value.as_str()) {
                continue;
            }
            let mut args: Vec<&str> = command.to_vec();
            args.extend_from_slice(extra);
            args.extend([*option, value.as_str()]);
            let env = [NO_LOADER, ("DISPLAY", ""), ("WAYLAND_DISPLAY", "")];
            match refused_with(&args, &env, &[option, lo, hi]) {
                Err(f) => failures.push(f),
                Ok(e) if e.contains("unexpected argument") || e.contains("00000000000000000") => {
                    failures.push(format!("{args:?}: {e}"))
                }
                Ok(_) => {}
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures: {failures:#?}",
        failures.len()
    );
}

/// `--device ''` is refused (it meant `auto` silently); `limit --uv` is shown as written.
#[test]
fn device_and_uv_values_are_named_as_given() {
    let f = refusal(
        &["render", "--device", "", "-o", "/tmp/x.png"],
        &[NO_LOADER],
        &["--device"],
    );
    assert!(f.is_none(), "{f:?}");
    let f = refusal(
        &["render", "--device", "  ", "-o", "/tmp/x.png"],
        &[NO_LOADER],
        &["--device"],
    );
    assert!(f.is_none(), "{f:?}");
    let cube = data("tests/data/meshes/cube.obj");
    let o = tessera(
        &[
            "limit",
            &cube,
            "--scheme",
            "catmull-clark",
            "--face",
            "1",
            "--uv",
            "0,-1e-300",
        ],
        &[],
    );
    let e = stderr(&o);
    assert!(
        e.contains("--uv 0,-1e-300: outside the face's domain") && e.len() < 300,
        "{e}"
    );
}

/// `bench` with more minimum frames than frames (the default `--min-frames 5` with `--frames
/// 2`, or `--min-frames 3`) panicked in `clamp` under `--row-budget`: now each row takes its 2
/// frames.
#[test]
fn bench_budgets_never_panic() {
    let cube = data("tests/data/meshes/cube.obj");
    let base = [
        "bench",
        "--methods",
        "flat",
        "--segments",
        "4",
        "--mesh",
        &cube,
        "--size",
        "64x48",
        "--warmup",
        "1",
        "--frames",
        "2",
    ];
    for extra in [
        &["--row-budget", "1.5"][..],
        &["--row-budget", "1.5", "--min-frames", "3"],
    ] {
        let csv = tmp("budget.csv");
        let csv = csv.to_str().unwrap();
        let args = [&base[..], extra, &["--csv", csv]].concat();
        succeeds(&args);
        assert_eq!(frames_column(csv), [2], "{extra:?}");
    }
}

/// The `frames` column of a bench CSV.
fn frames_column(csv: &str) -> Vec<u64> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|c| *c == "frames").unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// `--row-budget` with `--warmup 0` fits the row after its first timed frame (it was ignored:
/// all 3,000 frames ran, and `--frames 4294967295` never ended).
#[test]
fn the_row_budget_holds_without_warm_up() {
    let cube = data("tests/data/meshes/cube.obj");
    for frames in ["3000", "4294967295"] {
        let csv = tmp("no_warmup.csv");
        let csv = csv.to_str().unwrap();
        let args = [
            "bench",
            "--methods",
            "flat",
            "--segments",
            "2",
            "--mesh",
            &cube,
            "--size",
            "64x48",
            "--warmup",
            "0",
            "--frames",
            frames,
            "--row-budget",
            "0.5",
            "--min-frames",
            "2",
            "--csv",
            csv,
        ];
        let o = tessera_within(&args, &[], Duration::from_secs(240))
            .unwrap_or_else(|| panic!("--frames {frames}: still running after 240 s"));
        assert!(o.status.success(), "{}", stderr(&o));
        let got = frames_column(csv);
        assert!(
            got.len() == 1 && got[0] < 3000,
            "--frames {frames}: {got:?}"
        );
    }
    // Frame numbers that would pass u32: named.
    let f = refusal(
        &[
            "bench",
            "--mesh",
            &cube,
            "--frames",
            "4294967295",
            "--warmup",
            "1",
        ],
        &[NO_LOADER],
        &["--frames 4294967295 --warmup 1"],
    );
    assert!(f.is_none(), "{f:?}");
}

/// The normal next to an extraordinary vertex: the cube's corner normal at 1e-20 (it was
/// (0.707, -0.707, 0)) and at 1e-12 (3° off), Loop on the triangulated cube at 1e-17 (it was
/// `normal 0 0 0`).
#[test]
fn limit_normals_next_to_an_extraordinary_vertex() {
    let cube = data("tests/data/meshes/cube.obj");
    let normal = |args: &[&str]| -> [f64; 3] {
        let o = succeeds(args);
        let s = stdout(&o);
        let line = s.lines().find(|l| l.starts_with("normal ")).unwrap();
        let w: Vec<f64> = line
            .split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        [w[0], w[1], w[2]]
    };
    let third = -(1.0f64 / 3.0).sqrt();
    for uv in ["1e-20,1e-20", "1e-12,1e-12", "1e-300,1e-300", "0,0"] {
        let n = normal(&[
            "limit",
            &cube,
            "--scheme",
            "catmull-clark",
            "--face",
            "1",
            "--uv",
            uv,
        ]);
        assert!(n.iter().all(|c| (c - third).abs() < 1e-6), "{uv}: {n:?}");
    }
    let mut tri = String::from(
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n",
    );
    for f in [
        "1 4 3 2", "5 6 7 8", "1 2 6 5", "2 3 7 6", "3 4 8 7", "4 1 5 8",
    ] {
        let v: Vec<&str> = f.split(' ').collect();
        tri += &format!(
            "f {} {} {}\nf {} {} {}\n",
            v[0], v[1], v[2], v[0], v[2], v[3]
        );
    }
    let tri = write("tri_cube.obj", &tri);
    let corner = normal(&[
        "limit", &tri, "--scheme", "loop", "--face", "1", "--uv", "0,0",
    ]);
    for uv in ["1e-17,1e-17", "1e-300,1e-300"] {
        let n = normal(&["limit", &tri, "--scheme", "loop", "--face", "1", "--uv", uv]);
        let dot: f64 = n.iter().zip(&corner).map(|(a, b)| a * b).sum();
        assert!(dot > 1.0 - 1e-9, "{uv}: {n:?} against {corner:?}");
    }
}

/// The cube's text with its positions mapped by `f`, and `extra` lines after.
fn cube_with(f: impl Fn([f64; 3]) -> [f64; 3], extra: &str) -> String {
    let text = std::fs::read_to_string(data("tests/data/meshes/cube.obj")).unwrap();
    let mut out = String::new();
    for l in text.lines() {
        match l.strip_prefix("v ") {
            Some(rest) => {
                let p: Vec<f64> = rest
                    .split_whitespace()
                    .map(|x| x.parse().unwrap())
                    .collect();
                let q = f([p[0], p[1], p[2]]);
                out += &format!("v {:e} {:e} {:e}\n", q[0], q[1], q[2]);
            }
            None => out += &format!("{l}\n"),
        }
    }
    out + extra
}

/// The share of pixels that are not the background (the top-left pixel's colour).
fn drawn_share(png: &str) -> f64 {
    let img = image::open(png).unwrap().to_rgba8();
    let bg = *img.get_pixel(0, 0);
    let drawn = img.pixels().filter(|p| **p != bg).count();
    drawn as f64 / (img.width() * img.height()) as f64
}

/// Meshes accepted before but drawn blank with exit 0: a cube scaled by 1e-9 (the camera's
/// radius had a floor of 1e-6) and a cube beside a far vertex no face uses (the view was fitted
/// to it) now fill the picture like the cube does, with every technique; a picture of a cube
/// of 1e-30 (the surfaces' normals underflow f32) and any use of one at x ≈ 1e12 (its corners
/// collapse in f32) are refused naming the file (and the face's line); a picture in which
/// nothing was drawn is an error, not a file.
#[test]
fn meshes_are_framed_or_refused_never_blank() {
    let tiny = write("tiny.obj", &cube_with(|p| p.map(|c| c * 1e-9), ""));
    let unused = write("unused.obj", &cube_with(|p| p, "v 1e9 1e9 1e9\n"));
    let cube = data("tests/data/meshes/cube.obj");
    let mut failures = Vec::new();
    for method in ["flat", "phong", "pn", "bft", "adaptive", "gregory", "acc"] {
        let mut shares = Vec::new();
        for mesh in [&cube, &tiny, &unused] {
            let png = tmp(&format!("framed_{method}.png"));
            let png = png.to_str().unwrap();
            let o = tessera(
                &[
                    "render",
                    mesh,
                    "--method",
                    method,
                    "--segments",
                    "4",
                    "--size",
                    "96x72",
                    "-o",
                    png,
                ],
                &[],
            );
            if !o.status.success() {
                failures.push(format!("{method} {mesh}: {}", stderr(&o)));
                continue;
            }
            shares.push(drawn_share(png));
        }
        if let [full, small, beside] = shares[..] {
            if !(full > 0.1 && (small - full).abs() < 0.02 && (beside - full).abs() < 0.02) {
                failures.push(format!("{method}: drawn shares {full} {small} {beside}"));
            }
        }
    }
    let tiny30 = write("tiny30.obj", &cube_with(|p| p.map(|c| c * 1e-30), ""));
    let far = write("far.obj", &cube_with(|p| [p[0] + 0.999e12, p[1], p[2]], ""));
    let out = tmp("never_blank.png");
    let out = out.to_str().unwrap();
    for (mesh, said) in [
        (&tiny30, format!("{tiny30}: the drawn faces span 3.46")),
        (&far, format!("{far}:10: face 1: vertices 4 ")),
    ] {
        // A capture needs no shading: export takes the tiny mesh (cli_errors.rs exports it).
        let commands: &[&str] = if mesh == &tiny30 {
            &["render", "view"]
        } else {
            &["render", "export", "view"]
        };
        for &command in commands {
            let args = [command, mesh.as_str(), "-o", out];
            let args = if command == "view" {
                vec![command, mesh, "--frames", "1"]
            } else {
                args.to_vec()
            };
            let env = [NO_LOADER, ("DISPLAY", ""), ("WAYLAND_DISPLAY", "")];
            if let Some(f) = refusal(&args, &env, &[&said]) {
                failures.push(f);
            }
        }
    }
    // Every face a hole: nothing drawn, nothing written.
    let text = std::fs::read_to_string(&cube).unwrap();
    let holes = write("holes.obj", &format!("{text}t hole 6/0/0 0 1 2 3 4 5\n"));
    for method in ["flat", "bft", "adaptive", "gregory"] {
        failures.extend(refusal(
            &[
                "render", &holes, "--method", method, "--size", "64x48", "-o", out,
            ],
            &[],
            &[&holes, "nothing was drawn", "nothing written"],
        ));
    }
    assert!(!Path::new(out).exists());
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A face too large for the adaptive plan is named in the file's terms (1-based, with its
/// line) by every technique that plans the mesh as given (it was "face 6", 0-based, no file).
#[test]
fn plan_errors_name_the_face_and_its_line() {
    let mut text = std::fs::read_to_string(data("tests/data/meshes/cube.obj")).unwrap();
    let n = 300;
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        text += &format!("v {} {} 5\n", a.cos(), a.sin());
    }
    text += "f";
    for i in 0..n {
        text += &format!(" {}", i + 9);
    }
    text += "\n";
    let lines = text.lines().count();
    let p = write("cube_and_ngon.obj", &text);
    let out = tmp("never_plan.png");
    let out = out.to_str().unwrap();
    let said = format!("{p}:{lines}: adaptive plan: face 7 has 300 corners (at most 256)");
    let mut failures = Vec::new();
    for method in ["adaptive", "gregory", "acc"] {
        failures.extend(refusal(
            &["render", &p, "--method", method, "-o", out],
            &[],
            &[&said],
        ));
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `--sharpness-scale 0` makes an infinitely sharp crease (10.5) smooth, as the help says: the
/// picture equals that of the mesh without the crease (it stayed sharp).
#[test]
fn sharpness_scale_zero_smooths_infinite_creases() {
    let cube = std::fs::read_to_string(data("tests/data/meshes/cube.obj")).unwrap();
    let creased = write("creased.obj", &format!("{cube}t crease 2/1/0 0 1 10.5\n"));
    let plain = write("plain.obj", &cube);
    let render = |mesh: &str, scale: &str, name: &str| {
        let png = tmp(name);
        let png = png.to_str().unwrap().to_owned();
        succeeds(&[
            "render",
            mesh,
            "--method",
            "adaptive",
            "--sharpness-scale",
            scale,
            "--size",
            "96x72",
            "-o",
            &png,
        ]);
        image::open(&png).unwrap().to_rgba8()
    };
    let smooth = render(&plain, "1", "plain.png");
    assert_eq!(
        render(&creased, "0", "scaled0.png"),
        smooth,
        "scale 0: no crease"
    );
    assert_ne!(
        render(&creased, "1", "scaled1.png"),
        smooth,
        "scale 1: the crease"
    );
    let help = stdout(&succeeds(&["render", "--help"]));
    assert!(help.contains("counts as 10"), "{help}");
}

/// The messages the probe found wanting, each now naming what it is about.
#[test]
fn messages_name_their_culprit() {
    let cube = data("tests/data/meshes/cube.obj");
    let out = tmp("never_msg.png");
    let out = out.to_str().unwrap();
    let tet = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    let mut failures = Vec::new();
    let mut refused = |args: &[&str], needles: &[&str]| {
        failures.extend(refusal(args, &[NO_LOADER], needles));
    };
    // plot names its own option and the CSV.
    let csv = write("empty_run.csv", "mesh,segments\n");
    refused(
        &["plot", &csv, "-o", "x.pdf"],
        &["-o x.pdf: give a file name ending in .svg"],
    );
    refused(&["plot", &csv, "-o", out], &[&csv]);
    // An image output not called .png.
    refused(
        &["render", &cube, "-o", "x.xyz"],
        &["-o x.xyz: give a file name ending in .png"],
    );
    // --segments past u32 echoed without 20 digits.
    refused(
        &["render", "--segments", "18446744073709551616", "-o", out],
        &["--segments 1.8446744e19"],
    );
    // Tags in their own words, with their line.
    let t = write(
        "tag.obj",
        &format!("{tet}t interpolateboundary 0/0/1 edges\n"),
    );
    refused(
        &["render", &t, "-o", out],
        &[&format!(
            "{t}:9: tag 'interpolateboundary': 'edges'; expected one integer"
        )],
    );
    // A normal index missing wherever it is given, and four indices to a corner.
    for (name, faces) in [
        ("n1.obj", "f 1//99 3//99 2//99\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"),
        ("n2.obj", "f 1 3 2\nf 1//99 2//99 4//99\nf 2 3 4\nf 3 1 4\n"),
    ] {
        let p = write(
            name,
            &format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\n{faces}"),
        );
        refused(
            &["render", &p, "-o", out],
            &[&p, "normal 99 is named, but the file has 1 'vn' lines"],
        );
    }
    let p = write("four.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n");
    refused(
        &["render", &p, "-o", out],
        &[&format!(
            "{p}:4: face corner '1/1/1/1' has more than three indices"
        )],
    );
    // UTF-16 without a byte-order mark: refused on its first line, once.
    let utf16: Vec<u8> = tet.encode_utf16().flat_map(u16::to_le_bytes).collect();
    let p = tmp("utf16.obj");
    std::fs::write(&p, utf16).unwrap();
    let p = p.to_str().unwrap();
    refused(
        &["render", p, "-o", out],
        &[&format!("{p}:1: NUL byte"), "UTF-16"],
    );
    // An oversized height map: refused by its header, naming the option and the file.
    let huge = tmp("huge_height.png");
    std::fs::write(&huge, png_header_only(20000, 20000)).unwrap();
    let huge = huge.to_str().unwrap();
    let spot = data("assets/spot_control_mesh.obj");
    let start = Instant::now();
    refused(
        &[
            "render",
            &spot,
            "--method",
            "gregory",
            "--displace",
            "0.1",
            "--height",
            huge,
            "-o",
            out,
        ],
        &[&format!(
            "--height {huge}: 20000x20000 pixels, outside 1..16384 per side"
        )],
    );
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "decoded before refusing"
    );
    assert!(failures.is_empty(), "{failures:#?}");

    // Read, not refused: a Latin-1 byte in a comment, a crease off the edges (warned with its
    // line), a CSV with a byte-order mark.
    let mut latin1 = b"# Kuh \xe9t\xe9\n".to_vec();
    latin1.extend_from_slice(tet.as_bytes());
    latin1.extend_from_slice(b"t crease 2/1/0 0 0 2\n");
    let p = tmp("latin1.obj");
    std::fs::write(&p, latin1).unwrap();
    let p = p.to_str().unwrap();
    let o = succeeds(&[
        "subdivide",
        p,
        "--scheme",
        "loop",
        "--level",
        "1",
        "-o",
        &tmp("l.obj").to_string_lossy(),
    ]);
    let e = stderr(&o);
    assert!(
        e.contains(&format!("{p}:10: crease tag on vertices 0 and 0")),
        "{e}"
    );
    let run = tmp("bom_run.csv");
    let bench = [
        "bench",
        "--mesh",
        &cube,
        "--methods",
        "flat",
        "--segments",
        "2",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--size",
        "64x48",
        "--csv",
        run.to_str().unwrap(),
    ];
    succeeds(&bench);
    let mut text = b"\xef\xbb\xbf".to_vec();
    text.extend(std::fs::read(&run).unwrap());
    std::fs::write(&run, text).unwrap();
    let svg = tmp("bom_plot.svg");
    let o = succeeds(&["plot", run.to_str().unwrap(), "-o", svg.to_str().unwrap()]);
    assert!(stdout(&o).contains("rows of"), "{}", stdout(&o));
}

/// A PNG whose header says `width`×`height` and whose data is missing: readers that decode
/// before checking the size fail late; the header alone must be enough to refuse it.
fn png_header_only(width: u32, height: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |kind: &[u8], data: &[u8]| {
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        png.extend((data.len() as u32).to_be_bytes());
        png.extend(&body);
        png.extend(crc32(&body).to_be_bytes());
    };
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    chunk(b"IHDR", &ihdr);
    // The start of a zlib stream, no pixels: decoding would fail, after gigabytes.
    chunk(b"IDAT", &[0x78, 0x9c]);
    chunk(b"IEND", &[]);
    png
}
