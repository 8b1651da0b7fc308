#!/usr/bin/env bash
# Runs every test (CPU and GPU on lavapipe, validation layer on, the window under Xvfb), in two
# tiers, and prints each tier's wall time:
#   checks  every test but the sweeps (`cargo test`'s default set)
#   sweeps  the heavy sweeps, marked `#[ignore = "sweep tier ..."]`: every level × spacing,
#           whole shape sets, 1M faces (`cargo test -- --ignored`)
# `bash tools/test.sh` runs both; `bash tools/test.sh checks` or `... sweeps` runs one. Extra
# arguments after the tier go to cargo test (before its `--`).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
# The window test must not be skipped where this script runs: Xvfb is installed by setup.sh.
export TESSERA_REQUIRE_XVFB=1

tier="${1:-all}"
case "$tier" in
all | checks | sweeps) shift $(($# > 0 ? 1 : 0)) ;;
-*) tier=all ;;
*)
    echo "tools/test.sh: unknown tier '$tier' (expected all, checks or sweeps)" >&2
    exit 2
    ;;
esac

status=0
times=()
run_tier() {
    local name="$1"
    shift
    local start=$SECONDS
    if ! cargo test --workspace --no-fail-fast "$@"; then
        status=1
    fi
    times+=("$name: $((SECONDS - start)) s")
}

# Build once, so each tier's time is its tests' time.
cargo test --workspace --no-run "$@"
if [[ "$tier" == all || "$tier" == checks ]]; then
    run_tier checks "$@"
fi
if [[ "$tier" == all || "$tier" == sweeps ]]; then
    run_tier sweeps "$@" -- --ignored
fi
printf 'tier time: %s\n' "${times[@]}"
exit "$status"
