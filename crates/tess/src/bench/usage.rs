//! The process's own CPU time and memory, for the preparation figures the techniques log
//! (the scale bench compares them with `subdivide`'s in the same run). Linux `/proc`;
//! `None` elsewhere.

/// User + system CPU seconds of the whole process (every thread) so far.
pub fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start at state, field 3.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let (utime, stime): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
    // `/proc` counts in USER_HZ, which Linux fixes at 100 for every user-visible interface.
    Some((utime + stime) / 100.0)
}

/// Resident and peak resident bytes (`VmRSS`, `VmHWM`).
pub fn resident_bytes() -> Option<(u64, u64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = status.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line[name.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// A stage clock: wall and CPU seconds since the last lap, and memory now.
pub struct Laps {
    wall: std::time::Instant,
    cpu: Option<f64>,
}

impl Default for Laps {
    fn default() -> Self {
        Self::new()
    }
}

impl Laps {
    pub fn new() -> Laps {
        Laps {
            wall: std::time::Instant::now(),
            cpu: cpu_seconds(),
        }
    }

    /// "`what` W s wall, C s CPU, RSS R MB (peak P MB)"; restarts the clock.
    pub fn lap(&mut self, what: &str) -> String {
        let wall = self.wall.elapsed().as_secs_f64();
        let cpu = cpu_seconds();
        let cpu_text = match (cpu, self.cpu) {
            (Some(now), Some(then)) => format!(", {:.2} s CPU", now - then),
            _ => String::new(),
        };
        let mem = match resident_bytes() {
            Some((rss, peak)) => format!(", RSS {} MB (peak {} MB)", rss >> 20, peak >> 20),
            None => String::new(),
        };
        self.wall = std::time::Instant::now();
        self.cpu = cpu;
        format!("{what} {wall:.2} s wall{cpu_text}{mem}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_own_usage_on_linux() {
        if cfg!(target_os = "linux") {
            // Burn a little CPU so the counter can move; it must never go backwards.
            let a = cpu_seconds().expect("cpu");
            let mut x = 0u64;
            for i in 0..20_000_000u64 {
                x = x.wrapping_mul(31).wrapping_add(i);
            }
            std::hint::black_box(x);
            let b = cpu_seconds().expect("cpu");
            assert!(b >= a, "{a} then {b}");
            let (rss, peak) = resident_bytes().expect("status");
            assert!(rss > 0 && peak >= rss, "{rss} {peak}");
            assert!(Laps::new().lap("x").starts_with("x "));
        }
    }
}
