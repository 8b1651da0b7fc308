#!/usr/bin/env bash
# Runs every test (CPU and GPU on lavapipe, validation layer on, the window under Xvfb).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
# The window test must not be skipped where this script runs: Xvfb is installed by setup.sh.
export TESSERA_REQUIRE_XVFB=1
cargo test --workspace --no-fail-fast "$@"
