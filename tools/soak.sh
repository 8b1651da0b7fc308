#!/usr/bin/env bash
# Soak: an animated window run of FRAMES frames (default 10,000) under Xvfb with the validation
# layer on, printing the GPU memory allocated and the live Vulkan objects after warm-up, every
# 1,000 frames and at exit (`tessera view --stats`), the wall time and the validation messages.
# Fails when either figure changes after warm-up or the layer reports anything.
#
#   tools/soak.sh [FRAMES] [extra `tessera view` options...]
#   TESSERA_BIN=target/debug/tessera tools/soak.sh 2000      # another build
#   SOAK_VALIDATION=--sync-validation tools/soak.sh          # synchronization validation too
#   SOAK_SIZE=160x120 SOAK_LEVEL=4 tools/soak.sh             # a smaller window and level
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
frames="${1:-10000}"
shift || true
bin="${TESSERA_BIN:-}"
if [[ -z "$bin" ]]; then
    cargo build --release -p tessera-viewer
    bin="${CARGO_TARGET_DIR:-target}/release/tessera"
fi
log="$(mktemp -d)/soak"
start=$(date +%s.%N)
status=0
xvfb-run -a "$bin" view ${SOAK_VALIDATION:---validation} --method bft --animate \
    --segments "${SOAK_LEVEL:-8}" --size "${SOAK_SIZE:-640x480}" --frames "$frames" --stats "$@" >"$log.out" 2>"$log.err" || status=$?
end=$(date +%s.%N)
cat "$log.out"
errors=$(grep -c -E 'VUID|SYNC-|Validation Error' "$log.err" || true)
echo "frames: $frames, wall time: $(echo "$end - $start" | bc) s, exit status: $status, validation messages: $errors"
if [[ $status -ne 0 || $errors -ne 0 ]]; then
    cat "$log.err" >&2
    exit 1
fi
# Every report after warm-up (not the one at exit) must equal the first.
figures=$(grep '^stats: frame' "$log.out" | sed -E 's/^stats: frame [0-9]+: ([0-9]+) bytes allocated, ([0-9]+) live.*/\1 \2/' | sort -u | wc -l)
if [[ $figures -ne 1 ]]; then
    echo "soak: memory or live objects changed after warm-up" >&2
    exit 1
fi
echo "soak: constant after warm-up"
