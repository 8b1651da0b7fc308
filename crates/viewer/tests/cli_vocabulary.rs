//! One vocabulary: every command that takes a tessellation factor calls it
//! `--segments` (the old `--level` of render and view is a hidden alias), every command that
//! takes a mesh defaults to the embedded spot, and what the commands print reads as prose, with
//! no Rust debug formatting.
mod common;
use std::process::Output;

/// Runs `tessera` (GPU commands with validation and synchronization validation on).
fn tessera(args: &[&str]) -> Output {
    common::tessera(args, &[])
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn succeeds(args: &[&str]) -> (String, String) {
    let o = tessera(args);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{args:?}: {err}");
    (out, err)
}

fn tmp(name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("tessera-vocabulary-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name).to_str().unwrap().to_owned()
}

/// Text a user reads: no struct or enum as `{:?}` prints it (`Uniform { segments: 16 }`,
/// `Some(..)`, `[4, 16]`, `Gregory`).
fn assert_prose(what: &str, text: &str) {
    for debug in [
        "Uniform {",
        "Screen {",
        "Distance {",
        "Some(",
        "None",
        "{ ",
        " }",
        "[4",
        "[\"",
        "Gregory end",
        "Bilinear end",
        "CatmullClark",
        "On\n",
        "Off\n",
    ] {
        assert!(
            !text.contains(debug),
            "{what} shows debug formatting ({debug:?}): {text}"
        );
    }
}

/// The commands that draw name the factor `--segments` in their help, and none shows
/// `--level`; the subdivision level of `subdivide` keeps its own `--level`.
#[test]
fn help_says_segments_everywhere() {
    for command in ["render", "view", "export", "bench"] {
        let (help, _) = succeeds(&[command, "--help"]);
        assert!(help.contains("--segments <"), "{command} --help: {help}");
        assert!(!help.contains("--level"), "{command} --help: {help}");
        assert!(
            help.contains("Segments per base edge"),
            "{command} --help: {help}"
        );
    }
    let (help, _) = succeeds(&["subdivide", "--help"]);
    assert!(help.contains("--level <"), "{help}");
}

/// Every command that takes a mesh shows it as optional and says the embedded one is used
/// without it.
#[test]
fn mesh_is_optional_everywhere() {
    for (command, usage) in [
        ("render", "[MESH]"),
        ("view", "[MESH]"),
        ("export", "[INPUT]"),
        ("subdivide", "[INPUT]"),
        ("limit", "[INPUT]"),
    ] {
        let (help, _) = succeeds(&[command, "--help"]);
        assert!(help.contains(usage), "{command} --help: {help}");
        assert!(
            help.contains("the embedded spot control mesh when absent"),
            "{command} --help: {help}"
        );
    }
}

/// The old spelling still works (hidden alias), and messages name the one spelling.
#[test]
fn level_is_a_hidden_alias_of_segments() {
    for option in ["--segments", "--level"] {
        let o = tessera(&["render", option, "0", "-o", &tmp("never.png")]);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains("--segments 0"), "{err}");
        assert!(!err.contains("--level"), "{err}");
    }
    let o = tessera(&["export", "--level", "0", "-o", &tmp("never.obj")]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--segments 0"), "{err}");
    let o = tessera(&["bench", "--level", "0", "--methods", "flat"]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--segments 0"), "{err}");
}

/// `render` with the alias and `export`, `subdivide` with no mesh at all: the embedded spot,
/// and their reports in prose.
#[test]
fn commands_default_to_the_embedded_mesh_and_report_in_prose() {
    let png = tmp("spot.png");
    let (out, err) = succeeds(&[
        "render", "--method", "flat", "--level", "2", "--size", "64x48", "-o", &png,
    ]);
    assert!(out.contains("(64x48, flat, 2 segments per edge, "), "{out}");
    assert_prose("render", &format!("{out}{err}"));

    let obj = tmp("spot.obj");
    let (out, err) = succeeds(&[
        "export",
        "--method",
        "flat",
        "--segments",
        "2",
        "--size",
        "64x48",
        "-o",
        &obj,
    ]);
    assert!(out.contains("flat, 2 segments per edge"), "{out}");
    assert!(out.contains("cracks"), "{out}");
    assert!(std::fs::metadata(&obj).unwrap().len() > 1000);
    assert_prose("export", &format!("{out}{err}"));

    let sub = tmp("spot_level1.obj");
    let (out, err) = succeeds(&[
        "subdivide",
        "--scheme",
        "catmull-clark",
        "--level",
        "1",
        "-o",
        &sub,
    ]);
    assert!(out.contains("catmull-clark"), "{out}");
    assert_prose("subdivide", &format!("{out}{err}"));

    let (out, err) = succeeds(&[
        "limit",
        "--scheme",
        "catmull-clark",
        "--face",
        "1",
        "--uv",
        "0.5,0.5",
    ]);
    assert_prose("limit", &format!("{out}{err}"));

    let (out, err) = succeeds(&["info"]);
    assert!(out.contains("validation layer: "), "{out}");
    assert_prose("info", &format!("{out}{err}"));
}
