//! What the CLI test binaries share.
use std::process::{Command, Output};

/// Runs the `tessera` binary with `env` set; the GPU commands get `--validation
/// --sync-validation`, so their runs fail on any validation error, synchronization hazards
/// included.
pub fn tessera(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tessera"));
    c.args(args);
    if matches!(
        args.first(),
        Some(&"render" | &"view" | &"info" | &"export" | &"bench")
    ) {
        c.args(["--validation", "--sync-validation"]);
    }
    c.envs(env.iter().copied());
    c.output().expect("tessera runs")
}
