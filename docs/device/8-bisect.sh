#!/bin/bash
# Twenty-first session, third call: which commit since the nineteenth session's fifth-call binary
# (a619b3e, .dev/run/old) made 16 workers slower: 7406160 (span per message waiting), 7ee2969
# (samples and brake), f042694 (slab heap), d2b1b65 (.dev/run/new). Round robin, four rounds.
. "$(dirname "$0")/lib.sh"
D=$PWD/.dev/run; chmod +x $D/*
G="--sectors auto --json --quiet"
date +%T
BINS=(old b_7406160 b_7ee2969 b_f042694 new)
for k in 1 2 3 4; do
  for i in 0 1 2 3 4; do
    b=${BINS[$(( (i + k) % 5 ))]}
    r "w16 $b #$k" 60 $D/$b run gas --balls 99856 --until 0.5 --engine time-warp --workers 16 $G
  done
done
date +%T
for k in 1 2; do
  for b in old b_7406160 b_7ee2969 new; do
    r "w8 $b #$k" 60 $D/$b run gas --balls 99856 --until 0.5 --engine time-warp --workers 8 $G
  done
done
date +%T
