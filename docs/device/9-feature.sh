#!/bin/bash
# Twenty-first session, fourth call: is the committed code slower on 16 workers because of its last
# commits (f005235, d2b1b65) or because the carried binary was built with the `mpi` feature?
# new: d2b1b65 with `--features mpi`; head_nompi: d2b1b65 without; b_f042694: f042694 without;
# old: a619b3e with `mpi`. Round robin, five rounds, 16 and 8 workers.
set -u
O=$1; D=$PWD/.dev/run; chmod +x $D/*
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-30s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"efficiency":[0-9.]*' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
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
