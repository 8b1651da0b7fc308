#!/usr/bin/env bash
# Reproduce (and extend) Table 1 of seed 003 (Schäfer et al., the texture reparameterization of
# Gregory patches): fit the corner block c0..c4 of Eq. 3 per valence by Levenberg–Marquardt on
# Eq. 2 over Catmull-Clark's characteristic map, check the fitted map does not fold, and print
# Eq. 1's texture error with and without it (and with the paper's rows) as Markdown tables.
# With --write it regenerates crates/topology/src/patches/reparam_table.rs, the committed table the
# GPU reads (valences 3..16); the test `committed_table_is_the_fit` in
# crates/topology/tests/reparam.rs fails when that file and a fresh fit disagree.
#
# Usage: tools/reparam_fit.sh [--write] [--max-valence N (default 16)]
#
#   tools/reparam_fit.sh                      # the table for valences 3..16 (a few seconds)
#   tools/reparam_fit.sh --max-valence 64     # also how the valence-16 row serves 20..64
#   tools/reparam_fit.sh --write              # regenerate reparam_table.rs after changing the
#                                             # Gregory points or the fit
#
# Offline and CPU only (crates/topology/examples/reparam_fit.rs, release build); see
# docs/approximations.md, "Texture reparameterization of Gregory patches".
set -euo pipefail

cd "$(dirname "$0")/.."
export PATH=$HOME/.cargo/bin:$PATH
exec cargo run --release --quiet -p topology --example reparam_fit -- "$@"
