#!/bin/bash
# Twenty-first session, second call: the committed code (.dev/run/new, d2b1b65) against the nineteenth
# session's fifth-call binary (.dev/run/old) in alternating pairs, and what the Time Warp executor
# costs per batch on one dedicated core (1 worker: all batches final; --tw-pure: none).
. "$(dirname "$0")/lib.sh"
B=$PWD/.dev/run/new; OLD=$PWD/.dev/run/old; chmod +x $B $OLD
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
