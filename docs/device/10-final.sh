#!/bin/bash
# Twenty-first session, fifth call: the session's final code (cf979ca, with and without the `mpi`
# feature) against the nineteenth session's fifth-call binary (a619b3e, `mpi`), 10^5 balls to
# t = 0.5, round robin: the sequential engine and 2 and 16 workers.
. "$(dirname "$0")/lib.sh"
D=$PWD/.dev/run; chmod +x $D/*
G="--balls 99856 --until 0.5 --sectors auto --json --quiet"
date +%T
BINS=(old cur cur_mpi)
for k in 1 2 3 4 5 6; do
  for i in 0 1 2; do
    b=${BINS[$(( (i + k) % 3 ))]}
    r "w16 $b #$k" 60 $D/$b run gas $G --engine time-warp --workers 16
  done
done
for k in 1 2 3; do
  r "seq cur #$k" 60 $D/cur run gas $G --engine objects
  r "w2 cur #$k" 60 $D/cur run gas $G --engine time-warp --workers 2
  r "w8 cur #$k" 60 $D/cur run gas $G --engine time-warp --workers 8
  r "seq old #$k" 60 $D/old run gas $G --engine objects
done
date +%T
