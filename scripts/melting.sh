#!/usr/bin/env bash
# The hard-disk pressure near melting: BALLS disks in a periodic box at each area fraction of
# ETAS, from a triangular and from a square lattice, all runs side by side, each stopped by
# SIGINT after SECONDS of wall time (a stopped run keeps its summary and every whole block), Z
# in blocks of BLOCK time units. scripts/melting_table.py turns the summaries into a table.
#
# Usage: scripts/melting.sh OUT [SECONDS] [BALLS] [POOLSIM]
#   ETAS (default "0.698 0.702 0.706 0.710 0.714 0.718 0.722") and BLOCK (default 20) from the
#   environment.
set -euo pipefail
out=${1:?usage: scripts/melting.sh OUT [SECONDS] [BALLS] [POOLSIM]}
secs=${2:-400}
balls=${3:-65536}
bin=${4:-target/release/poolsim}
etas=${ETAS:-"0.698 0.702 0.706 0.710 0.714 0.718 0.722"}
mkdir -p "$out"
for eta in $etas; do
  for lattice in triangular square; do
    # --foreground: GNU timeout would otherwise signal its whole process group as well, and a
    # second SIGINT ends poolsim at once, without its summary
    timeout --foreground -s INT "$secs" "$bin" run disks --balls "$balls" --area-fraction "$eta" \
      --boundary periodic --lattice "$lattice" --until 1e9 --observe-every "${BLOCK:-20}" \
      --observe-from 0 --json >"$out/$eta-$lattice.json" 2>"$out/$eta-$lattice.err" &
  done
done
wait
