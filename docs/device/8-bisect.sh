#!/bin/bash
# Twenty-first session, third call: which commit since the nineteenth session's fifth-call binary
# (a619b3e, .dev/run/old) made 16 workers slower: 7406160 (span per message waiting), 7ee2969
# (samples and brake), f042694 (slab heap), d2b1b65 (.dev/run/new). Round robin, four rounds.
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
