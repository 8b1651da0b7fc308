//! `tessera`: render, view and inspect subdivision surfaces drawn on the tessellation stage.
#![forbid(unsafe_code)]
mod bench;
mod cli;
mod commands;
mod export;
mod technique;
mod topo_cmds;
mod view;

use clap::Parser;

fn main() -> std::process::ExitCode {
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

/// `e` and its causes joined by ": " (anyhow's `{:#}`), leaving out a cause whose text the
/// message already shows: an error that embeds its source in its own message and also returns
/// it from `source()` (thiserror does both for a field named `source`) would otherwise say it
/// twice.
fn message(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
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
