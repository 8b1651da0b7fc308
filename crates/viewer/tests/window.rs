//! The window (`tessera view`) under Xvfb with the validation layer on, synchronization
//! validation included: runs that end without a screenshot (frames still in flight at exit),
//! every technique, an animated soak of every technique that animates whose GPU memory and live
//! Vulkan objects must stay constant after warm-up (HUD shown) and none of which is live at
//! exit, a screenshot onto a full disk, and windows driven by synthetic input
//! (xdotool: P screenshots, the level and the technique changed by keys, displacement by D and
//! ] on textured gregory, Esc; the HUD drawn, hidden by H, and its level control clicked).
//!
//! The soak runs in the window rather than through an offscreen `tess::Context` loop because
//! the window is where frames are not waited for (FIFO presentation, two frames in flight, the
//! retire queue deciding when objects die): the offscreen path waits on every frame and would
//! not exercise that. At 160x120 on lavapipe 1,000 frames take well under a minute.
#[path = "../../../tests/support/xvfb.rs"]
mod xvfb;

use std::path::Path;
use std::process::{Command, Output};
use std::sync::Mutex;

/// Displays of this test crate (cli.rs uses 90..120, vk-core's swapchain test 140..170).
const DISPLAYS: std::ops::Range<u32> = 170..200;

/// Held by each test while its server runs: two tests choosing a display at the same moment
/// could both see it free and start two servers on it.
static SERVER: Mutex<()> = Mutex::new(());

fn view(args: &[&str], display: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("view")
        .args(args)
        .args(["--validation", "--sync-validation", "--size", "160x120"])
        .env("DISPLAY", display)
        .env("WAYLAND_DISPLAY", "")
        .output()
        .expect("tessera runs")
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A window run that ends without a screenshot destroys nothing the GPU still uses: it exits 0
/// with validation on, for every technique, animated where the technique animates (the base
/// mesh rewritten every frame while the previous frame may still read it).
/// The reported defect: `view --validation --frames 5` failed with
/// VUID-vkDestroyPipeline-pipeline-00765, VUID-vkDestroyBuffer-buffer-00922 and
/// VUID-vkDestroyDescriptorPool-descriptorPool-00303 before objects were retired through
/// vk-core's deferred destruction.
#[test]
fn window_without_screenshot_exits_validation_clean() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let mut failures = Vec::new();
    for (method, animate) in [
        ("flat", false),
        ("phong", false),
        ("pn", false),
        ("bft", true),
        ("adaptive", true),
        ("gregory", true),
        ("acc", false),
    ] {
        for frames in ["1", "5"] {
            let mut args = vec!["--method", method, "--level", "4", "--frames", frames];
            if animate {
                args.push("--animate");
            }
            let o = view(&args, &server.display);
            let (_, err) = text(&o);
            if !o.status.success() || err.contains("VUID") || err.contains("SYNC-") {
                failures.push(format!("{method} {frames} frames: {err}"));
            }
        }
    }
    drop(server);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `(bytes allocated, live Vulkan objects)` of each `--stats` line, with its label.
fn stats(stdout: &str) -> Vec<(String, u64, u64)> {
    stdout
        .lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("stats: ")?;
            let (when, figures) = rest.split_once(": ")?;
            let mut words = figures.split_whitespace();
            let bytes = words.next()?.parse().ok()?;
            let live = words.nth(2)?.parse().ok()?;
            Some((when.to_owned(), bytes, live))
        })
        .collect()
}

/// Animated frames each technique that animates runs in the soak: BFT 1,000 (about 12 s at
/// 160x120 on lavapipe), Gregory and ACC-1 300 (about 10 s each), adaptive 120 (about 0.2 s a
/// frame there, 27 s). Enough for a per-frame leak to show: every report after warm-up must
/// equal the first.
fn soak_frames(method: &str) -> u32 {
    match method {
        "bft" => 1000,
        "adaptive" => 120,
        _ => 300,
    }
}

/// The CI soak: every technique that declares animation (the registry's, so a new one is
/// soaked too) runs animated frames in the window. GPU memory and live Vulkan objects after
/// warm-up equal those at every later report; at exit no memory is held and no object is live
/// (the device's idle one-shot command pools released first); the validation layer reports
/// nothing.
#[test]
fn thousand_animated_frames_hold_memory_and_objects_constant() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let animated = tess::techniques::names_with(|f| f.animation);
    assert!(
        animated.contains(&"bft") && animated.len() >= 4,
        "{animated:?}"
    );
    let mut failures = Vec::new();
    for method in animated {
        let frames = soak_frames(method).to_string();
        let start = std::time::Instant::now();
        let o = view(
            &[
                "--method",
                method,
                "--level",
                "4",
                "--animate",
                "--frames",
                &frames,
                "--stats",
            ],
            &server.display,
        );
        println!(
            "{method}: {frames} frames in {:.1} s",
            start.elapsed().as_secs_f64()
        );
        if let Err(e) = soak_held(&o, &frames) {
            failures.push(format!("{method}: {e}"));
        }
    }
    drop(server);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Whether a `--stats` soak of `frames` frames held its memory and objects (see above).
fn soak_held(o: &Output, frames: &str) -> Result<(), String> {
    let (out, err) = text(o);
    if !o.status.success() || err.contains("VUID") || err.contains("SYNC-") {
        return Err(format!("view failed: {err}"));
    }
    let s = stats(&out);
    let labels: Vec<&str> = s.iter().map(|r| r.0.as_str()).collect();
    let last = format!("frame {frames}");
    if labels != ["frame 10", last.as_str(), "exit"] {
        return Err(format!("reports {labels:?}: {out}"));
    }
    let (_, bytes, live) = &s[0];
    if !(*bytes > 0 && *live > 0) {
        return Err(format!("nothing allocated after warm-up: {out}"));
    }
    if (s[1].1, s[1].2) != (*bytes, *live) {
        return Err(format!("grew after warm-up: {out}"));
    }
    if s[2].1 != 0 {
        return Err(format!("memory held at exit: {out}"));
    }
    if !(s[2].2 < *live && s[2].2 <= 4) || s[2].2 != 0 {
        return Err(format!("objects live at exit: {out}"));
    }
    Ok(())
}

/// Every technique, one frame with `--stats`: nothing allocated and no Vulkan object live at
/// exit. Adaptive and Gregory reported "1 live Vulkan objects" (the one-shot command pool their
/// uploads left cached) where flat and BFT reported 0.
#[test]
fn no_vulkan_object_is_live_at_exit() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let mut failures = Vec::new();
    for info in tess::techniques::registry() {
        let method = info.id.name();
        let o = view(
            &[
                "--method", method, "--level", "4", "--frames", "1", "--stats",
            ],
            &server.display,
        );
        let (out, err) = text(&o);
        let exit = stats(&out).into_iter().find(|r| r.0 == "exit");
        if !o.status.success() || exit.as_ref().map(|r| (r.1, r.2)) != Some((0, 0)) {
            failures.push(format!("{method}: {exit:?}: {out}{err}"));
        }
    }
    drop(server);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `view --screenshot` onto a full disk: exit 1 naming the file and the OS reason, nothing
/// reported written (it printed "wrote" and exited 0); a screenshot not named .png is refused
/// before the window opens.
#[test]
fn a_failed_screenshot_is_an_error() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("tessera-window-full-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let full = dir.join("full.png");
    let _ = std::fs::remove_file(&full);
    std::os::unix::fs::symlink("/dev/full", &full).unwrap();
    let full = full.to_str().unwrap();
    let mut failures = Vec::new();
    for method in ["flat", "adaptive", "bft"] {
        let o = view(
            &[
                "--method",
                method,
                "--level",
                "4",
                "--frames",
                "2",
                "--screenshot",
                full,
            ],
            &server.display,
        );
        let (out, err) = text(&o);
        let said = format!("cannot write {full}: ");
        if o.status.code() != Some(1)
            || !err.contains(&said)
            || !err.contains("os error 28")
            || out.contains("wrote")
        {
            failures.push(format!("{method}: {:?}: {out}{err}", o.status.code()));
        }
    }
    let jpg = dir.join("shot.jpg");
    let jpg = jpg.to_str().unwrap();
    let o = view(&["--frames", "1", "--screenshot", jpg], &server.display);
    let (_, err) = text(&o);
    let said = format!("--screenshot {jpg}: give a file name ending in .png");
    if o.status.code() != Some(1) || !err.contains(&said) || Path::new(jpg).exists() {
        failures.push(format!("shot.jpg: {err}"));
    }
    drop(server);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Runs `xdotool` with `args` (its XTEST input reaches the focused window, as a keyboard's
/// would); returns its stdout.
fn xdotool(display: &str, args: &[&str]) -> String {
    let o = Command::new("timeout")
        .arg("30")
        .arg("xdotool")
        .args(args)
        .env("DISPLAY", display)
        .output()
        .expect("xdotool runs");
    assert!(
        o.status.success(),
        "xdotool {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Waits for `path` to be written whole (the PNG decodes).
/// `tessera view` with `args`, validation on (synchronization too), in `dir` (where P saves its
/// screenshots) on `display`; returns the process and its window id, focused for xdotool.
fn focused_view(
    display: &str,
    dir: &std::path::Path,
    args: &[&std::ffi::OsStr],
) -> (std::process::Child, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("view")
        .args(args)
        .args(["--validation", "--sync-validation"])
        .current_dir(dir)
        .env("DISPLAY", display)
        .env("WAYLAND_DISPLAY", "")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("tessera runs");
    let window = xdotool(
        display,
        &["search", "--sync", "--onlyvisible", "--name", "tessera"],
    );
    let window = window.lines().next().expect("a window").trim().to_owned();
    xdotool(display, &["windowfocus", "--sync", &window]);
    (child, window)
}

fn wait_for_png(path: &std::path::Path) -> image::RgbaImage {
    let start = std::time::Instant::now();
    loop {
        if let Ok(img) = image::open(path) {
            return img.to_rgba8();
        }
        assert!(
            start.elapsed().as_secs() < 60,
            "{} was not written",
            path.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
}

/// Pixels whose colour differs between `a` and `b`, and the mean brightness of each.
fn compare(a: &image::RgbaImage, b: &image::RgbaImage) -> (usize, f64, f64) {
    let mean = |img: &image::RgbaImage| {
        img.pixels()
            .map(|p| f64::from(p.0[0]) + f64::from(p.0[1]) + f64::from(p.0[2]))
            .sum::<f64>()
            / (3.0 * img.pixels().len() as f64)
    };
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    (differing, mean(a), mean(b))
}

/// Synthetic key presses: P saves the frame; ArrowUp doubles the segments (2 → 4, visible as
/// more wireframe lines: a darker picture); 3 switches to PN (another surface); Esc ends the
/// window, validation-clean. The HUD is off (`--no-hud`): at 160x120 it would cover the scene.
#[test]
fn keys_change_level_and_technique_and_p_saves_screenshots() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    if Command::new("xdotool").arg("version").output().is_err() {
        eprintln!("skipped: xdotool is not installed (tools/setup.sh installs it)");
        return;
    }
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("tessera-window-keys-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let args = [
        "--method",
        "flat",
        "--segments",
        "2",
        "--wireframe",
        "--no-hud",
        "--size",
        "160x120",
    ]
    .map(std::ffi::OsStr::new);
    let (child, _) = focused_view(&server.display, &dir, &args);
    let d = server.display.clone();
    let shot = |n: u32| wait_for_png(&dir.join(format!("tessera-screenshot-{n}.png")));
    xdotool(&d, &["key", "p"]);
    let level2 = shot(1);
    xdotool(&d, &["key", "Up", "p"]);
    let level4 = shot(2);
    xdotool(&d, &["key", "3", "p"]);
    let pn4 = shot(3);
    xdotool(&d, &["key", "Escape"]);
    let o = child.wait_with_output().expect("tessera ends");
    drop(server);
    let (out, err) = text(&o);
    assert!(o.status.success(), "view failed: {err}");
    assert!(!err.contains("VUID") && !err.contains("SYNC-"), "{err}");
    for n in 1..=3 {
        assert!(
            out.contains(&format!("wrote tessera-screenshot-{n}.png (P)")),
            "{out}"
        );
    }
    assert_eq!(level2.dimensions(), (160, 120));
    let (changed, before, after) = compare(&level2, &level4);
    assert!(changed > 300, "ArrowUp changed {changed} pixels");
    assert!(
        after < before,
        "4 segments per edge should draw more wireframe (darker) than 2: {after} vs {before}"
    );
    let (changed, _, _) = compare(&level4, &pn4);
    assert!(changed > 100, "key 3 (PN) changed {changed} pixels");
}

/// The surface keys on textured gregory: D displaces (the default scale, 2% of the diagonal:
/// the picture changes), D again brings the undisplaced picture back, ] displaces at 1.25 times
/// the scale (another picture); R switches the reparameterization without error (its effect,
/// a shift of a few texels, is measured by tests/golden.rs); V recolours the surface by the
/// parameter shift, V again by the Eq. 1 error (its lattice built on the key).
#[test]
fn surface_keys_displace_and_restore() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    if Command::new("xdotool").arg("version").output().is_err() {
        eprintln!("skipped: xdotool is not installed (tools/setup.sh installs it)");
        return;
    }
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("tessera-window-surface-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let (mesh, texture) = (
        assets.join("spot_control_mesh.obj"),
        assets.join("spot_texture.png"),
    );
    let mut args = vec![mesh.as_os_str(), "--texture".as_ref(), texture.as_os_str()];
    args.extend(
        [
            "--method",
            "gregory",
            "--segments",
            "4",
            "--no-hud",
            "--size",
            "160x120",
        ]
        .map(std::ffi::OsStr::new),
    );
    let (child, _) = focused_view(&server.display, &dir, &args);
    let d = server.display.clone();
    let shot = |n: u32| wait_for_png(&dir.join(format!("tessera-screenshot-{n}.png")));
    xdotool(&d, &["key", "p"]);
    let plain = shot(1);
    xdotool(&d, &["key", "d", "p"]);
    let displaced = shot(2);
    xdotool(&d, &["key", "d", "p"]);
    let restored = shot(3);
    xdotool(&d, &["key", "bracketright", "p"]);
    let scaled = shot(4);
    xdotool(&d, &["key", "r", "p"]);
    let reparam_off = shot(5);
    // V twice: the parameter-shift view, then the Eq. 1 error view (the surface is rebuilt
    // with its error lattice); both recolour the whole surface.
    xdotool(&d, &["key", "v", "p"]);
    let shift_view = shot(6);
    xdotool(&d, &["key", "v", "p"]);
    let error_view = shot(7);
    xdotool(&d, &["key", "Escape"]);
    let o = child.wait_with_output().expect("tessera ends");
    drop(server);
    let (_, err) = text(&o);
    assert!(o.status.success(), "view failed: {err}");
    assert!(!err.contains("VUID") && !err.contains("SYNC-"), "{err}");
    let (on, _, _) = compare(&plain, &displaced);
    let (back, _, _) = compare(&plain, &restored);
    let (more, _, _) = compare(&displaced, &scaled);
    eprintln!("D changed {on} pixels, D again left {back}, ] changed {more}");
    assert!(on > 300, "D changed {on} pixels");
    assert_eq!(back, 0, "D twice should give the undisplaced picture back");
    assert!(more > 100, "] changed {more} pixels");
    let (shift, _, _) = compare(&reparam_off, &shift_view);
    let (error, _, _) = compare(&shift_view, &error_view);
    eprintln!("V changed {shift} pixels, V again {error}");
    assert!(
        shift > 300 && error > 300,
        "V: {shift}, then {error} pixels"
    );
}

/// Where the HUD's "×2 (Up)" level button is in the window (egui's layout at scale 1, the
/// panel anchored at (6, 6), Flat's rows): read from a screenshot of the HUD; the test fails if
/// a click there does not double the level.
const DOUBLE_LEVEL_BUTTON: (u32, u32) = (155, 117);

/// The HUD: drawn into P screenshots while shown (the panel's region differs from the same frame
/// with the HUD hidden by H, and the rest of the picture does not); its "×2" control doubles
/// the level (2 → 4 segments: more wireframe lines, darker); Esc ends the window,
/// validation-clean (the overlay's texture upload and draws included).
#[test]
fn hud_is_drawn_hidden_by_h_and_its_level_control_acts() {
    let _one = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    if Command::new("xdotool").arg("version").output().is_err() {
        eprintln!("skipped: xdotool is not installed (tools/setup.sh installs it)");
        return;
    }
    let Some(server) = xvfb::start_or_skip(DISPLAYS) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("tessera-window-hud-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let args = [
        "--method",
        "flat",
        "--segments",
        "2",
        "--wireframe",
        "--size",
        "640x480",
    ]
    .map(std::ffi::OsStr::new);
    let (child, window) = focused_view(&server.display, &dir, &args);
    let d = server.display.clone();
    let shot = |n: u32| wait_for_png(&dir.join(format!("tessera-screenshot-{n}.png")));
    // A first screenshot only to know a frame is up: egui lays a panel out unseen on its first
    // frame (a sizing pass), and on a loaded machine the first P can come before any frame was
    // drawn, so that shot had no HUD to compare (0 pixels; seen once in a full test run).
    xdotool(&d, &["key", "p"]);
    shot(1);
    xdotool(&d, &["key", "p"]);
    let with_hud = shot(2);
    xdotool(&d, &["key", "h", "p"]);
    let without_hud = shot(3);
    xdotool(&d, &["key", "h"]);
    let (x, y) = DOUBLE_LEVEL_BUTTON;
    let (x, y) = (x.to_string(), y.to_string());
    xdotool(
        &d,
        &["mousemove", "--window", &window, &x, &y, "click", "1"],
    );
    xdotool(&d, &["key", "h", "p"]);
    let doubled = shot(4);
    xdotool(&d, &["key", "Escape"]);
    let o = child.wait_with_output().expect("tessera ends");
    drop(server);
    let (out, err) = text(&o);
    assert!(o.status.success(), "view failed: {err}");
    assert!(!err.contains("VUID") && !err.contains("SYNC-"), "{err}");
    assert_eq!(with_hud.dimensions(), (640, 480));
    // The HUD's pixels: many, and all inside the panel at the top left.
    let differing: Vec<(u32, u32)> = with_hud
        .enumerate_pixels()
        .filter(|(x, y, p)| without_hud.get_pixel(*x, *y) != *p)
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(
        differing.len() > 5000,
        "the HUD changed only {} pixels",
        differing.len()
    );
    let right = differing.iter().map(|p| p.0).max().unwrap();
    let (left, top) = (
        differing.iter().map(|p| p.0).min().unwrap(),
        differing.iter().map(|p| p.1).min().unwrap(),
    );
    assert!(
        left <= 10 && top <= 10 && right < 320,
        "HUD pixels from ({left}, {top}) to x = {right}: not a panel at the top left"
    );
    let (changed, before, after) = compare(&without_hud, &doubled);
    assert!(
        changed > 300,
        "the HUD's ×2 changed {changed} pixels: {out}"
    );
    assert!(
        after < before,
        "4 segments per edge should draw more wireframe (darker) than 2: {after} vs {before}"
    );
}
