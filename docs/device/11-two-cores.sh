#!/bin/bash
# Twenty-first session, sixth call: the 2-core target on two dedicated cores (taskset -c 2,3) with
# the session's final code (abc97e0, .dev/run/fin) and cf979ca (.dev/run/cur, before the boxed log
# records), sequential engine and 2 workers in turn, 10^5 balls.
. "$(dirname "$0")/lib.sh"
D=$PWD/.dev/run; chmod +x $D/*
G="--balls 99856 --sectors auto --json --quiet"
T2="taskset -c 2,3"
date +%T
for k in 1 2 3 4; do
  for b in fin cur; do
    r "t0.5 seq $b #$k" 60 $T2 $D/$b run gas $G --until 0.5 --engine objects
    r "t0.5 w2 $b #$k" 60 $T2 $D/$b run gas $G --until 0.5 --engine time-warp --workers 2
  done
done
for k in 1 2; do
  for b in fin cur; do
    r "t1.5 seq $b #$k" 60 $T2 $D/$b run gas $G --until 1.5 --engine objects
    r "t1.5 w2 $b #$k" 60 $T2 $D/$b run gas $G --until 1.5 --engine time-warp --workers 2
  done
done
date +%T
