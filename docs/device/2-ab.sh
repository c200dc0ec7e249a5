#!/bin/bash
# A/B of two binaries on the device machine. Usage: ab.sh OUTDIR
set -u
O=$1; chmod +x .dev/poolsim .dev/poolsim_new
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
declare -A BIN=([old]=$PWD/.dev/poolsim [new]=$PWD/.dev/poolsim_new)
MPI="mpirun --allow-run-as-root --oversubscribe --bind-to none --mca btl self,vader --mca pml ob1 --mca btl_vader_single_copy_mechanism none"
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-26s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"rollbacks":[0-9]*' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
G="--sectors auto --json --quiet"
date +%T
for k in 1 2 3; do for w in 2 4 8 12 16; do for b in old new; do
  r "gas99856 $b w$w #$k" 60 ${BIN[$b]} run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
done; done; done
date +%T
for k in 1 2; do for w in 4 8 16; do for b in old new; do
  r "gas399424 $b w$w #$k" 90 ${BIN[$b]} run gas --balls 399424 --until 0.25 --engine time-warp --workers $w $G
done; done; done
date +%T
for k in 1 2; do for p in 8 16; do for b in old new; do
  r "phold $b w$p #$k" 60 ${BIN[$b]} phold --objects 16384 --end 10 --partitions $p --engine time-warp --workers $p --json
done; done; done
date +%T
for b in old new; do
  r "gas99856 mpi $b r16xw1" 90 $MPI -np 16 ${BIN[$b]} run gas --balls 99856 --until 0.5 --engine time-warp --workers 1 $G
  r "gas99856 mpi $b r4xw4" 90 $MPI -np 4 ${BIN[$b]} run gas --balls 99856 --until 0.5 --engine time-warp --workers 4 $G
  r "phold mpi $b r16xw1" 60 $MPI -np 16 ${BIN[$b]} phold --objects 16384 --end 10 --partitions 16 --engine time-warp --workers 1 --json
done
date +%T
r "gas1000000 new w16" 120 ${BIN[new]} run gas --balls 1000000 --until 0.1 --engine time-warp --workers 16 $G
r "gas1000000 new w8" 120 ${BIN[new]} run gas --balls 1000000 --until 0.1 --engine time-warp --workers 8 $G
date +%T
