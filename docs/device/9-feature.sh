#!/bin/bash
# Twenty-first session, fourth call: is the committed code slower on 16 workers because of its last
# commits (f005235, d2b1b65) or because the carried binary was built with the `mpi` feature?
# new: d2b1b65 with `--features mpi`; head_nompi: d2b1b65 without; b_f042694: f042694 without;
# old: a619b3e with `mpi`. Round robin, five rounds, 16 and 8 workers.
. "$(dirname "$0")/lib.sh"
D=$PWD/.dev/run; chmod +x $D/*
G="--sectors auto --json --quiet"
date +%T
BINS=(old b_f042694 head_nompi new)
for w in 16 8; do
  for k in 1 2 3 4 5; do
    for i in 0 1 2 3; do
      b=${BINS[$(( (i + k) % 4 ))]}
      r "w$w $b #$k" 60 $D/$b run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
    done
  done
done
date +%T
