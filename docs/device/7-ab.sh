#!/bin/bash
# Twenty-first session, second call: the committed code (.dev/run/new, d2b1b65) against the nineteenth
# session's fifth-call binary (.dev/run/old) in alternating pairs, and what the Time Warp executor
# costs per batch on one dedicated core (1 worker: all batches final; --tw-pure: none).
set -u
O=$1; B=$PWD/.dev/run/new; OLD=$PWD/.dev/run/old; chmod +x $B $OLD
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-30s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"efficiency":[0-9.]*' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
G="--sectors auto --json --quiet"
date +%T
for k in 1 2 3 4; do
  for w in 16 2; do
    if [ $((k % 2)) = 1 ]; then
      r "ab new w$w #$k" 60 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
      r "ab old w$w #$k" 60 $OLD run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
    else
      r "ab old w$w #$k" 60 $OLD run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
      r "ab new w$w #$k" 60 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
    fi
  done
done
date +%T
for k in 1 2; do
  r "core1 t1.5 seq #$k" 60 taskset -c 2 $B run gas --balls 99856 --until 1.5 --engine objects $G
  r "core1 t1.5 tw w1 #$k" 60 taskset -c 2 $B run gas --balls 99856 --until 1.5 --engine time-warp --workers 1 $G
  r "core1 t1.5 tw w1 pure #$k" 60 taskset -c 2 $B run gas --balls 99856 --until 1.5 --engine time-warp --workers 1 --tw-pure $G
  r "core1 t0.5 seq #$k" 60 taskset -c 2 $B run gas --balls 99856 --until 0.5 --engine objects $G
  r "core1 t0.5 tw w1 #$k" 60 taskset -c 2 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 1 $G
  r "cores2 t1.5 tw w2 #$k" 60 taskset -c 2,3 $B run gas --balls 99856 --until 1.5 --engine time-warp --workers 2 $G
done
date +%T
