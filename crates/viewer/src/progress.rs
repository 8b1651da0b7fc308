//! Progress on the terminal for work that can take more than a second: benchmark rows, building
//! a technique's tables or plan, capturing and welding an export.
//!
//! Drawn with indicatif on stderr, and only when both stdout and stderr are terminals: output
//! that goes to a file or a pipe (tests, CI, `tessera bench > log`) gets no bars, no carriage
//! returns and no escape codes, just the lines it always had. The libraries report nothing
//! themselves: where the time goes inside `tess::build` is one call, so it gets a spinner with
//! the elapsed time rather than a callback threaded through `topology`; the benchmark, whose
//! steps are known in advance, reports them through [`tess::bench::BenchProgress`].
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// Whether progress is drawn at all.
pub fn on_terminal() -> bool {
    std::io::stdout().is_terminal() && std::io::stderr().is_terminal()
}

/// A spinner with `message` and the elapsed seconds, ticking on its own until finished (or
/// dropped); hidden when not [`on_terminal`].
pub fn spinner(message: impl Into<String>) -> ProgressBar {
    if !on_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner().with_message(message.into());
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        bar.set_style(style);
    }
    bar.enable_steady_tick(Duration::from_millis(120));
    bar
}

/// Runs `work` under a [`spinner`] saying `message`; the spinner is cleared when it returns.
pub fn during<T>(message: impl Into<String>, work: impl FnOnce() -> T) -> T {
    let bar = spinner(message);
    let out = work();
    bar.finish_and_clear();
    out
}

/// A bar over `len` steps with `message`, its position, the elapsed time and the estimate of
/// what is left; hidden when not [`on_terminal`].
pub fn bar(len: u64) -> ProgressBar {
    if !on_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} ({elapsed}, about {eta} left)")
    {
        bar.set_style(style);
    }
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}
