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
    }
}

/// Starts Xvfb on the first free display of `displays` (test crates use disjoint ranges, as
/// they run in parallel); None when Xvfb is not installed.
pub fn start(displays: std::ops::Range<u32>) -> Option<Xvfb> {
    for n in displays {
        let socket = format!("/tmp/.X11-unix/X{n}");
        if Path::new(&socket).exists() || Path::new(&format!("/tmp/.X{n}-lock")).exists() {
            continue;
        }
        let display = format!(":{n}");
        let child = Command::new("Xvfb")
            .args([&display, "-screen", "0", "640x480x24", "-nolisten", "tcp"])
            .spawn()
            .ok()?;
        for _ in 0..100 {
            if Path::new(&socket).exists() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        return Some(Xvfb { child, display });
    }
    None
}

/// [`start`], or None after saying the test is skipped; fails where `TESSERA_REQUIRE_XVFB` is
/// set (the README's test command installs Xvfb and sets it, so CI never skips).
pub fn start_or_skip(displays: std::ops::Range<u32>) -> Option<Xvfb> {
    let server = start(displays);
    if server.is_none() {
        assert!(
            std::env::var_os("TESSERA_REQUIRE_XVFB").is_none(),
            "Xvfb is required here but not installed"
        );
        eprintln!("skipping: Xvfb not installed");
    }
    server
}
