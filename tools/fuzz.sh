#!/usr/bin/env bash
# Build the cargo-fuzz targets in fuzz/ and run each for a fixed time; exit 1 if any target
# crashes (panic, failed assertion), hangs (one input over 10 s) or exceeds 2 GiB.
#
# Usage: tools/fuzz.sh [SECONDS_PER_TARGET (default 60)] [TARGET...]   (default: all targets)
#
# Safe to run again: it installs cargo-fuzz and the nightly toolchain only when missing,
# rebuilds incrementally, and grows libFuzzer's working corpus in fuzz/work/<target>
# (ignored by git) on top of the committed seeds in fuzz/corpus/<target>, which it never
# writes. A crashing input lands in fuzz/artifacts/<target>/; replay it with
#   cd fuzz && cargo +nightly fuzz run -s none -a <target> artifacts/<target>/<file>
#
# Design: no sanitizer (`-s none`): `topology` forbids `unsafe`, so AddressSanitizer would
# only halve the speed; debug assertions and overflow checks are on (`-a`). Each target runs
# on one thread (RAYON_NUM_THREADS=1 and the harness makes rayon run inline) and the
# targets run one after another, so the script holds one core.
set -euo pipefail

secs=${1:-60}
shift || true
case $secs in
'' | *[!0-9]*)
    echo "fuzz.sh: seconds must be a whole number, got '$secs'" >&2
    exit 2
    ;;
esac

root=$(cd "$(dirname "$0")/.." && pwd)
export PATH=$HOME/.cargo/bin:$PATH
toolchain=${FUZZ_TOOLCHAIN:-nightly}

if ! rustup run "$toolchain" rustc --version >/dev/null 2>&1; then
    rustup toolchain install "$toolchain" --profile minimal
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --version '^0.13' --locked
fi

cd "$root/fuzz"
if [ $# -gt 0 ]; then
    targets=("$@")
else
    mapfile -t targets < <(cargo "+$toolchain" fuzz list)
fi

cargo "+$toolchain" fuzz build -s none -a

failed=()
for t in "${targets[@]}"; do
    mkdir -p "work/$t" "corpus/$t"
    log="work/$t.log"
    echo "== $t: ${secs}s"
    if RAYON_NUM_THREADS=1 cargo "+$toolchain" fuzz run -s none -a "$t" "work/$t" "corpus/$t" -- \
        -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        >"$log" 2>&1; then
        grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -n 1 || true
        grep -E 'stat::(number_of_executed_units|average_exec_per_sec)' "$log" || true
    else
        echo "!! $t failed; last lines of $log:" >&2
        tail -n 40 "$log" >&2
        failed+=("$t")
    fi
done

if [ ${#failed[@]} -gt 0 ]; then
    echo "fuzz.sh: crashing targets: ${failed[*]}" >&2
    exit 1
fi
echo "fuzz.sh: ${#targets[@]} targets ran ${secs}s each without a crash"
