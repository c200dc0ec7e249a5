#!/bin/bash
# Confirmation on the device of the committed window rule (.dev/poolsim_new) against the session's first binary (.dev/poolsim).
set -u
O=$1; B=$PWD/.dev/poolsim_new; OLD=$PWD/.dev/poolsim; chmod +x $B $OLD
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
MPI="mpirun --allow-run-as-root --oversubscribe --bind-to none --mca btl self,vader --mca pml ob1 --mca btl_vader_single_copy_mechanism none"
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-26s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"efficiency":[0-9.]*' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
G="--sectors auto --json --quiet"
date +%T
for k in 1 2; do
  r "gas99856 seq #$k" 60 $B run gas --balls 99856 --until 0.5 --engine objects $G
  for w in 1 2 4 8 12 16; do r "gas99856 tw w$w #$k" 60 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G; done
  r "gas99856 old w16 #$k" 60 $OLD run gas --balls 99856 --until 0.5 --engine time-warp --workers 16 $G
done
date +%T
r "gas399424 seq" 90 $B run gas --balls 399424 --until 0.25 --engine objects $G
for k in 1 2; do for w in 8 16; do r "gas399424 tw w$w #$k" 90 $B run gas --balls 399424 --until 0.25 --engine time-warp --workers $w $G; done; done
for k in 1 2; do r "gas1000000 tw w16 #$k" 120 $B run gas --balls 1000000 --until 0.1 --engine time-warp --workers 16 $G; done
date +%T
r "phold p16 seq" 60 $B phold --objects 16384 --end 10 --partitions 16 --engine objects --json
for k in 1 2; do r "phold p16 tw w16 #$k" 60 $B phold --objects 16384 --end 10 --partitions 16 --engine time-warp --workers 16 --json; done
r "phold p8 tw w8" 60 $B phold --objects 16384 --end 10 --partitions 8 --engine time-warp --workers 8 --json
r "gas99856 mpi r16xw1" 90 $MPI -np 16 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 1 $G
r "gas99856 mpi r4xw4" 90 $MPI -np 4 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 4 $G
r "gas99856 mpi r2xw8" 90 $MPI -np 2 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 8 $G
r "phold mpi r16xw1" 60 $MPI -np 16 $B phold --objects 16384 --end 10 --partitions 16 --engine time-warp --workers 1 --json
POOLSIM_CHAOS=7 r "gas99856 tw w16 chaos7" 90 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 16 $G
date +%T
