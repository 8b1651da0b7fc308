//! Progress: `tessera bench` draws a bar over its groups, and `render`/`export` a
//! spinner while they build, on a terminal only. Without one (as here, under `cargo test`)
//! the output has no carriage return and no escape code; under a pseudo-terminal made by
//! util-linux's `script` the bar is drawn.
use std::path::Path;
use std::process::{Command, Stdio};

fn cube() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/opensubdiv/shapes/loop_cube.obj")
        .to_str()
        .unwrap()
        .to_owned()
}

fn bench_args(cube: &str) -> Vec<String> {
    [
        "bench",
        "--mesh",
        cube,
        "--segments",
        "2,4",
        "--methods",
        "flat",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--size",
        "64x48",
        "--validation",
        "--sync-validation",
    ]
    .map(str::to_owned)
    .to_vec()
}

fn assert_plain(what: &str, bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    assert!(
        !text.contains('\r') && !text.contains('\u{1b}'),
        "{what} has terminal control characters without a terminal: {text:?}"
    );
}

#[test]
fn no_progress_without_a_terminal() {
    let cube = cube();
    let o = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(bench_args(&cube))
        .output()
        .expect("tessera runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_plain("bench stdout", &o.stdout);
    assert_plain("bench stderr", &o.stderr);
    let err = String::from_utf8_lossy(&o.stderr);
    // The row lines are there as before the bar, one per row, and nothing else per group.
    assert_eq!(
        err.lines()
            .filter(|l| l.starts_with("  loop_cube, "))
            .count(),
        2,
        "{err}"
    );
    assert!(!err.contains("1/2"), "{err}");

    let png = std::env::temp_dir().join(format!("tessera-progress-{}.png", std::process::id()));
    let o = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(["render", &cube, "--method", "bft", "--segments", "4"])
        .args(["--size", "64x48", "--validation", "--sync-validation", "-o"])
        .arg(&png)
        .output()
        .expect("tessera runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_plain("render stdout", &o.stdout);
    assert_plain("render stderr", &o.stderr);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("building"));
}

/// Under a pseudo-terminal the bar shows the groups counted and the group being measured.
#[test]
fn bench_draws_a_bar_on_a_terminal() {
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("skipped: util-linux `script` is not installed");
        return;
    }
    let cube = cube();
    let mut line = String::from(env!("CARGO_BIN_EXE_tessera"));
    for a in bench_args(&cube) {
        line.push(' ');
        line.push_str(&a);
    }
    let o = Command::new("script")
        .args(["-qec", &line, "/dev/null"])
        .stdin(Stdio::null())
        .output()
        .expect("script runs");
    let text = String::from_utf8_lossy(&o.stdout);
    let err = String::from_utf8_lossy(&o.stderr);
    if !o.status.success() && err.contains("pseudo-terminal") {
        eprintln!("skipped: no pseudo-terminal here ({err})");
        return;
    }
    assert!(o.status.success(), "{text}{err}");
    assert!(text.contains("0/2 loop_cube"), "{text}");
    assert!(
        text.contains("1/2 loop_cube, 4 segments per edge"),
        "{text}"
    );
    assert!(text.contains('\u{1b}'), "{text}");
    // Rows are still printed whole, above the bar.
    assert!(text.contains("  loop_cube, 4 segments, flat: "), "{text}");
}
