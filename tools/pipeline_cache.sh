#!/usr/bin/env bash
# The pipeline cache's effect on the first frame: `tessera render` (one frame, every pipeline
# it needs built on the way) with a cold cache (a fresh, empty cache directory) and a warm one
# (the directory a first, untimed run filled), interleaved cold, warm, cold, warm ... so both
# see the same machine load. Prints each run's wall time, the medians and warm / cold.
#
#   tools/pipeline_cache.sh [TESSERA_BINARY] [RUNS] [-- render options...]
#   e.g. tools/pipeline_cache.sh target/release/tessera 10 -- --method gregory
#
# Mesa's own shader cache is turned off (MESA_SHADER_CACHE_DISABLE) and so is NVIDIA's
# (__GL_SHADER_DISK_CACHE=0), so only Tessera's VkPipelineCache differs between the two.
set -euo pipefail
bin=${1:-target/release/tessera}
runs=${2:-10}
shift $(( $# > 2 ? 2 : $# ))
[[ ${1:-} == -- ]] && shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export MESA_SHADER_CACHE_DISABLE=true __GL_SHADER_DISK_CACHE=0
unset TESSERA_PIPELINE_CACHE

once() { # cache-home -> seconds
  local t0 t1
  t0=$(date +%s.%N)
  XDG_CACHE_HOME=$1 "$bin" render -o "$work/frame.png" "${@:2}" >/dev/null
  t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc -l
}

XDG_CACHE_HOME="$work/warm" "$bin" render -o "$work/frame.png" "$@" >/dev/null
ls -l "$work"/warm/tessera/pipelines/ | tail -n +2 | awk '{print "warm cache file: " $5 " bytes"}'
cold=() warm=()
for i in $(seq "$runs"); do
  rm -rf "$work/cold"
  cold+=("$(once "$work/cold" "$@")")
  warm+=("$(once "$work/warm" "$@")")
  printf 'run %2d: cold %.3f s, warm %.3f s\n' "$i" "${cold[-1]}" "${warm[-1]}"
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
mc=$(median "${cold[@]}")
mw=$(median "${warm[@]}")
printf 'median: cold %.3f s, warm %.3f s, warm / cold %.3f\n' "$mc" "$mw" "$(echo "$mw / $mc" | bc -l)"
