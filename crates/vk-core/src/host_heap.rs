//! The host heap's policy for large transient arrays.
//!
//! Preparing a surface builds arrays of hundreds of megabytes in parallel blocks and frees each
//! once it is packed and uploaded (and lavapipe's "device" memory lives on the same heap). glibc
//! raises its mmap threshold to the size of each mmapped block that is freed (up to 32 MiB), so
//! the next blocks of that size come from the arenas instead, and freeing them keeps their pages
//! resident: at 1M faces ~450 MB of freed BFT blocks stayed in the process
//! (docs/benchmarks.md, Scale). A fixed threshold keeps every block of 128 KiB and more mapped
//! on its own, returned to the system when it is freed.
//!
//! Smaller blocks come from the heap, and glibc trims the heap's free top back to the system
//! once it passes 128 KiB (the trim threshold, which no longer follows the mmap threshold once
//! that is fixed). lavapipe's draw module allocates and frees its vertex and primitive arrays
//! on every draw, so a frame could give pages back and fault them in again, draw after draw,
//! depending on what the heap's top held: Flat's frame on the spot control mesh took 74-80 ms
//! when BFT's frames were interleaved in the same process and 55-63 ms alone or with trimming
//! off, while BFT's stayed at 93 (docs/benchmarks.md, "Devices, and how to read the figures"). The heap's top is
//! therefore never trimmed; the large blocks above still leave the process when freed.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether [`return_freed_blocks`] took effect in this process.
static APPLIED: AtomicBool = AtomicBool::new(false);

/// glibc's default threshold, fixed so it no longer rises.
pub const MMAP_THRESHOLD: usize = 128 * 1024;

/// The heap's free top is kept, whatever its size.
pub const TRIM_THRESHOLD: libc::c_int = libc::c_int::MAX;

/// Fixes the mmap threshold and turns heap trimming off (glibc on Linux; elsewhere nothing to
/// do). For a program's own process, called once at start (a library linked into a host
/// program leaves the host's heap alone). Returns whether the policy was applied.
pub fn return_freed_blocks() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: `mallopt` sets an allocator tunable under the allocator's own lock; it is
        // valid at any time from any thread and touches no memory of ours.
        let applied = unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD as libc::c_int) == 1
                && libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1
        };
        APPLIED.store(applied, Ordering::Relaxed);
        applied
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

/// The policy in force, for a benchmark report to state (`None` where it was not applied: the
/// heap's own defaults).
pub fn policy() -> Option<&'static str> {
    APPLIED.load(Ordering::Relaxed).then_some(
        "glibc mmap threshold fixed at 128 KiB, heap top never trimmed \
         (vk_core::host_heap: lavapipe's per-draw arrays keep their pages)",
    )
}

#[cfg(test)]
mod tests {
    #[test]
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    fn glibc_accepts_the_threshold() {
        assert!(super::return_freed_blocks());
        assert!(super::policy().is_some_and(|p| p.contains("never trimmed")));
    }
}
