//! USD files on the command line (`tests/data/usd/`): render, export, bench and subdivide take
//! a `.usda` as they take an OBJ; the file's `subdivisionScheme` picks the default technique
//! (Catmull-Clark: adaptive, Loop: bft, none: flat); the bench row is named by the file's
//! stem; a bad file is refused before any device is opened, naming the file, the prim and the
//! attribute. GPU commands run with validation on.
mod common;
use common::tessera;
use std::path::{Path, PathBuf};
use std::process::Output;

fn data(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/usd")
        .join(p)
        .to_str()
        .unwrap()
        .to_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-cli-usd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn succeeds(args: &[&str]) -> Output {
    let o = tessera(args, &[]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{args:?}: {e}");
    assert!(!e.contains("validation error"), "{args:?}: {e}");
    o
}

#[test]
fn the_usd_scheme_picks_the_default_technique() {
    let png = tmp("r.png");
    let png = png.to_str().unwrap();
    for (file, technique) in [
        ("cube_tags.usda", "adaptive"),
        ("two_meshes.usda", "adaptive"),
        ("loop_octahedron.usda", "bft"),
        ("real/ring.usda", "flat"),
    ] {
        let o = succeeds(&["render", &data(file), "--size", "64x48", "-o", png]);
        let said =
            String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
        assert!(said.contains(&format!(", {technique},")), "{file}: {said}");
    }
}

#[test]
fn export_bench_and_subdivide_take_usd() {
    let out = tmp("out.obj");
    let out = out.to_str().unwrap();
    let cube = data("cube_tags.usda");
    succeeds(&[
        "export",
        &data("two_meshes.usda"),
        "--segments",
        "2",
        "-o",
        out,
    ]);
    assert!(std::fs::read_to_string(out).unwrap().contains("\nf "));
    let o = succeeds(&[
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
    ]);
    let rows = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(rows.contains("cube_tags"), "{rows}");
    succeeds(&[
        "subdivide",
        &cube,
        "--scheme",
        "catmull-clark",
        "--level",
        "1",
        "-o",
        out,
    ]);
    let refined = std::fs::read_to_string(out).unwrap();
    let faces = refined.lines().filter(|l| l.starts_with("f ")).count();
    assert_eq!(faces, 24, "six quads split into four each");

    // The same level as USD text: read back by render as the OBJ is; Doo-Sabin has no USD
    // scheme and is refused before any work.
    let usda = tmp("out.usda");
    let usda = usda.to_str().unwrap();
    let args = |scheme| {
        [
            "subdivide",
            &cube,
            "--scheme",
            scheme,
            "--level",
            "1",
            "-o",
            usda,
        ]
    };
    let o = succeeds(&args("catmull-clark"));
    assert!(String::from_utf8_lossy(&o.stdout).contains("24 faces"));
    let png = tmp("usda.png");
    let o = succeeds(&[
        "render",
        usda,
        "--size",
        "32x24",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(String::from_utf8_lossy(&o.stdout).contains(", adaptive,"));
    let o = tessera(&args("doo-sabin"), &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("USD has no doo-sabin subdivision scheme"));
}

/// The file's face-varying mode (USD's default `cornersPlus1` for cube_tags.usda) shapes the
/// exported `vt`; `--uv-interpolation all` gives the bilinear ones instead, `--uv-interpolation`
/// with an unknown mode is refused by name, and `render` and `bench` take the option too.
#[test]
fn uv_interpolation_comes_from_the_file_or_the_command_line() {
    let out = tmp("uv.obj");
    let out = out.to_str().unwrap();
    let cube = data("cube_tags.usda");
    let vt = |extra: &[&str]| {
        let mut args = vec!["export", cube.as_str(), "--segments", "2", "-o", out];
        args.extend_from_slice(extra);
        succeeds(&args);
        let text = std::fs::read_to_string(out).unwrap();
        assert!(text.contains("\nf 1/"), "faces name their vt");
        text.lines()
            .filter(|l| l.starts_with("vt "))
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    let file_mode = vt(&[]);
    assert!(!file_mode.is_empty(), "cube_tags has texture coordinates");
    assert_eq!(file_mode, vt(&["--uv-interpolation", "cornersPlus1"]));
    assert_ne!(
        file_mode,
        vt(&["--uv-interpolation", "all"]),
        "smooth vs bilinear"
    );
    let o = tessera(
        &["export", &cube, "--uv-interpolation", "smooth", "-o", out],
        &[],
    );
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("unknown face-varying interpolation 'smooth'"),
        "{e}"
    );
    let png = tmp("uv.png");
    succeeds(&[
        "render",
        &cube,
        "--uv-interpolation",
        "none",
        "--size",
        "64x48",
        "-o",
        png.to_str().unwrap(),
    ]);
    succeeds(&[
        "bench",
        "--mesh",
        &cube,
        "--methods",
        "adaptive",
        "--segments",
        "2",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--size",
        "64x48",
        "--uv-interpolation",
        "boundaries",
    ]);
}

#[test]
fn a_bad_usd_file_is_refused_by_file_prim_and_attribute() {
    let bad = tmp("bad.usda");
    std::fs::write(
        &bad,
        "#usda 1.0\ndef Mesh \"M\" {\n int[] faceVertexCounts = [3]\n int[] faceVertexIndices = \
         [0, 1, 5]\n point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]\n}\n",
    )
    .unwrap();
    let bad = bad.to_str().unwrap();
    let png = tmp("bad.png");
    let o = tessera(&["render", bad, "-o", png.to_str().unwrap()], &[]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    assert!(
        e.contains(&format!(
            "{bad}: /M.faceVertexIndices: entry 2 is 5, but there are 3 points"
        )),
        "{e}"
    );
    assert!(!png.exists());
}

/// `bench --load-to-first-frame`: a USD file and its OBJ twin, each parsed, planned and drawn
/// once per round; the table has one row per (method, file) with positive phase times, each
/// total over its OBJ twin's (1 for the OBJ itself, "-" for a file without a twin), and
/// --markdown writes it. Without --mesh it says what it needs.
#[test]
fn bench_times_load_to_first_frame() {
    let md = tmp("load.md");
    let (usd, obj, lone) = (
        data("cube_tags.usda"),
        data("cube_tags.obj"),
        data("two_meshes.usda"),
    );
    let o = succeeds(&[
        "bench",
        "--load-to-first-frame",
        "--mesh",
        &usd,
        "--mesh",
        &obj,
        "--mesh",
        &lone,
        "--methods",
        "flat,adaptive",
        "--segments",
        "4",
        "--size",
        "64x48",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--markdown",
        md.to_str().unwrap(),
    ]);
    let table = std::fs::read_to_string(&md).unwrap();
    assert!(String::from_utf8_lossy(&o.stdout).contains(&table));
    let rows: Vec<Vec<&str>> = table
        .lines()
        .filter(|l| l.starts_with("| flat") || l.starts_with("| adaptive"))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    assert_eq!(rows.len(), 6, "{table}");
    for (row, file) in rows.iter().zip([&usd, &obj, &lone, &usd, &obj, &lone]) {
        assert_eq!(row[1], file.as_str(), "{table}");
        for ms in &row[2..6] {
            assert!(ms.parse::<f64>().unwrap() > 0.0, "{table}");
        }
    }
    for method in rows.chunks(3) {
        let total = |r: &Vec<&str>| r[5].parse::<f64>().unwrap();
        // The ratio of the unrounded totals; the table's totals are rounded to 0.1 ms.
        let (a, b) = (total(&method[0]), total(&method[1]));
        let ratio: f64 = method[0][6].parse().unwrap();
        let slack = ratio * (0.05 / a + 0.05 / b) + 1e-3;
        assert!((ratio - a / b).abs() <= slack, "{table}");
        assert_eq!(method[1][6], "1.000");
        assert_eq!(method[2][6], "-");
    }

    let o = tessera(&["bench", "--load-to-first-frame"], &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--load-to-first-frame needs the files"));
}
