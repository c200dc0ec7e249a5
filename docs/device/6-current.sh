#!/bin/bash
# Twenty-first session: the committed window rule and slab heap (.dev/run/new, d2b1b65) on 16 cores,
# against the nineteenth session's fifth-call binary (.dev/run/old, span one batch per object),
# plus the steady state (to t = 1.5) and 2 cores carved out with taskset.
. "$(dirname "$0")/lib.sh"
B=$PWD/.dev/run/new; OLD=$PWD/.dev/run/old; chmod +x $B $OLD
G="--sectors auto --json --quiet"
lscpu | grep -E 'Model name|^CPU\(s\)|Thread|Socket|NUMA node\(s\)'; free -g | head -2; date +%T
for k in 1 2; do
  r "gas99856 seq #$k" 60 $B run gas --balls 99856 --until 0.5 --engine objects $G
  for w in 1 2 4 8 12 16; do r "gas99856 tw w$w #$k" 60 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G; done
  for w in 2 16; do r "gas99856 old w$w #$k" 60 $OLD run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G; done
done
date +%T
for k in 1 2; do
  r "gas99856 t1.5 seq #$k" 60 $B run gas --balls 99856 --until 1.5 --engine objects $G
  for w in 2 16; do r "gas99856 t1.5 tw w$w #$k" 60 $B run gas --balls 99856 --until 1.5 --engine time-warp --workers $w $G; done
done
date +%T
T2="taskset -c 2,3"
for k in 1 2 3; do
  r "cores2 gas99856 seq #$k" 60 $T2 $B run gas --balls 99856 --until 0.5 --engine objects $G
  r "cores2 gas99856 tw w2 #$k" 60 $T2 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 2 $G
done
for k in 1 2; do
  r "cores2 t1.5 seq #$k" 60 $T2 $B run gas --balls 99856 --until 1.5 --engine objects $G
  r "cores2 t1.5 tw w2 #$k" 60 $T2 $B run gas --balls 99856 --until 1.5 --engine time-warp --workers 2 $G
done
date +%T
r "gas399424 seq" 90 $B run gas --balls 399424 --until 0.25 --engine objects $G
for k in 1 2; do for w in 8 16; do r "gas399424 tw w$w #$k" 90 $B run gas --balls 399424 --until 0.25 --engine time-warp --workers $w $G; done; done
r "gas1000000 tw w16" 120 $B run gas --balls 1000000 --until 0.1 --engine time-warp --workers 16 $G
date +%T
for p in 1 2 8 16; do
  r "phold p$p seq" 60 $B phold --objects 16384 --end 10 --partitions $p --engine objects --json
  r "phold p$p tw w$p" 60 $B phold --objects 16384 --end 10 --partitions $p --engine time-warp --workers $p --json
done
r "phold p16 tw w16 #2" 60 $B phold --objects 16384 --end 10 --partitions 16 --engine time-warp --workers 16 --json
r "gas99856 mpi r16xw1" 90 $MPI -np 16 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 1 $G
r "gas99856 mpi r4xw4" 90 $MPI -np 4 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 4 $G
r "gas99856 mpi r2xw8" 90 $MPI -np 2 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 8 $G
r "phold mpi r16xw1" 60 $MPI -np 16 $B phold --objects 16384 --end 10 --partitions 16 --engine time-warp --workers 1 --json
POOLSIM_CHAOS=7 r "gas99856 tw w16 chaos7" 90 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 16 $G
POOLSIM_CHAOS=7 r "gas99856 mpi r4xw4 chaos7" 90 $MPI -np 4 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 4 $G
date +%T
