//! A private X server for window tests, shared by the test crates that need one (included with
//! `#[path]`: test crates cannot share a module otherwise). The server stops when the guard
//! drops.
use std::path::Path;
use std::process::{Child, Command};

/// A running Xvfb and its `DISPLAY`.
pub struct Xvfb {
    child: Child,
    pub display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        // A killed server leaves its lock and socket behind; remove them so the display is
        // free for the next run.
        let n = self.display.trim_start_matches(':');
        let _ = std::fs::remove_file(format!("/tmp/.X{n}-lock"));
        let _ = std::fs::remove_file(format!("/tmp/.X11-unix/X{n}"));
    }
}

/// Whether display `n` is held by a live server: a lock file naming a running process (a
/// lock left by a killed server does not count; Xvfb replaces it).
fn display_taken(n: u32) -> bool {
    let Ok(text) = std::fs::read_to_string(format!("/tmp/.X{n}-lock")) else {
        return Path::new(&format!("/tmp/.X11-unix/X{n}")).exists();
    };
    match text.trim().parse::<u32>() {
        Ok(pid) => Path::new(&format!("/proc/{pid}")).exists(),
        Err(_) => true,
    }
}

/// The next display offset to try, shared by the tests of one crate: they run in parallel
/// threads, and two of them checking the same free display at once would both start a server
/// there; the second exits at once ("server already active"), and the first test's guard later
/// kills the server the second test's window is drawing on (winit: "Failed to set window
/// title: Connection(IoError)").
static NEXT_DISPLAY: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

/// Starts Xvfb on a free display of `displays` (test crates use disjoint ranges, as they run in
/// parallel; the threads of one crate take turns through [`NEXT_DISPLAY`]) and keeps it only if
/// the server is still running once its socket is up; None when Xvfb is not installed.
pub fn start(displays: std::ops::Range<u32>) -> Option<Xvfb> {
    let len = displays.end.saturating_sub(displays.start);
    for _ in 0..len {
        let n =
            displays.start + NEXT_DISPLAY.fetch_add(1, std::sync::atomic::Ordering::Relaxed) % len;
        let socket = format!("/tmp/.X11-unix/X{n}");
        if display_taken(n) {
            continue;
        }
        // Stale files of a killed server.
        let _ = std::fs::remove_file(format!("/tmp/.X{n}-lock"));
        let _ = std::fs::remove_file(&socket);
        let display = format!(":{n}");
        // -noreset: by default the server resets when its last client disconnects, and a
        // client connecting during the reset fails ("Failed to open connection to X server"),
        // which tests running the binary several times in a row hit.
        let child = Command::new("Xvfb")
            .args([
                &display,
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
                "-noreset",
            ])
            .spawn()
            .ok()?;
        let mut server = Xvfb { child, display };
        let mut running = true;
        for _ in 0..100 {
            running = matches!(server.child.try_wait(), Ok(None));
            if !running || Path::new(&socket).exists() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        if running && matches!(server.child.try_wait(), Ok(None)) {
            return Some(server);
        }
        // Another server holds the display: leave its files alone and try the next one.
        let _ = server.child.wait();
        std::mem::forget(server);
    }
    None
}

/// [`start`], or None after saying the test is skipped; fails where `TESSERA_REQUIRE_XVFB` is
/// set (the README's test command installs Xvfb and sets it, so CI never skips).
pub fn start_or_skip(displays: std::ops::Range<u32>) -> Option<Xvfb> {
    let server = start(displays.clone());
    if server.is_none() {
        assert!(
            std::env::var_os("TESSERA_REQUIRE_XVFB").is_none(),
            "Xvfb is required here but is not installed or every display of {displays:?} is held \
             by a running server"
        );
        eprintln!("skipping: Xvfb not installed or no free display");
    }
    server
}
