//! `tessera`: render, view and inspect subdivision surfaces drawn on the tessellation stage.
#![forbid(unsafe_code)]

/// `println!` that does not panic when stdout is closed early (`tessera info | head -1`): a
/// broken pipe ends the process quietly, as a pipeline expects; another write error ends it
/// with a message. `println!` panics on both.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::write_stdout(format_args!($($arg)*))
    };
}

mod bench;
mod cli;
mod commands;
mod export;
mod hud;
mod load_bench;
mod numbers;
mod output;
mod plot;
mod progress;
mod technique;
mod topo_cmds;
mod view;

use clap::Parser;
use std::io::Write;

fn write_stdout(line: std::fmt::Arguments) {
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = writeln!(stdout, "{line}").and_then(|()| stdout.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: cannot write to standard output: {e}");
        std::process::exit(1);
    }
}

fn main() -> std::process::ExitCode {
    // Freed preparation blocks go back to the system instead of staying resident; the heap's
    // top is not trimmed, so lavapipe's per-draw arrays do not fault their pages in each frame.
    vk_core::host_heap::return_freed_blocks();
    let args = cli::Cli::parse();
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or(if args.verbose { "info" } else { "warn" }),
    )
    .init();
    match commands::run(args) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", message(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// The command-line option of a parameter the library names.
fn option_of(p: tess::error::Param) -> &'static str {
    use tess::error::Param;
    match p {
        Param::Segments => "--segments",
        Param::Pixels => "--pixels",
        Param::Distance => "--distance",
        Param::TableLevel => "--table-level",
        Param::Isolation => "--isolation",
    }
}

/// `e` and its causes joined by ": " (anyhow's `{:#}`), leaving out a cause whose text the
/// message already shows: an error that embeds its source in its own message and also returns
/// it from `source()` (thiserror does both for a field named `source`) would otherwise say it
/// twice. Library errors that name a parameter name it by its command-line option.
fn message(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        // The library names a parameter by its field; here it is an option.
        let text = match cause.downcast_ref::<tess::TessError>() {
            Some(t) => t.worded(option_of),
            None => cause.to_string(),
        };
        if out.contains(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}
