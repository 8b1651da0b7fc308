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
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
