//! The host heap's policy for large transient arrays.
//!
//! Preparing a surface builds arrays of hundreds of megabytes in parallel blocks and frees each
//! once it is packed and uploaded (and lavapipe's "device" memory lives on the same heap). glibc
//! raises its mmap threshold to the size of each mmapped block that is freed (up to 32 MiB), so
//! the next blocks of that size come from the arenas instead, and freeing them keeps their pages
//! resident: at 1M faces ~450 MB of freed BFT blocks stayed in the process
//! (docs/benchmarks.md, Scale). A fixed threshold keeps every block of 128 KiB and more mapped
//! on its own, returned to the system when it is freed.

/// glibc's default threshold, fixed so it no longer rises.
pub const MMAP_THRESHOLD: usize = 128 * 1024;

/// Fixes the mmap threshold (glibc on Linux; elsewhere nothing to do). For a program's own
/// process, called once at start (a library linked into a host program leaves the host's heap
/// alone). Returns whether the policy was applied.
pub fn return_freed_blocks() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: `mallopt` sets an allocator tunable under the allocator's own lock; it is
        // valid at any time from any thread and touches no memory of ours.
        unsafe { libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD as libc::c_int) == 1 }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    #[test]
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    fn glibc_accepts_the_threshold() {
        assert!(super::return_freed_blocks());
    }
}
