#!/bin/bash
# Time Warp scaling on the device machine, committed binary (.dev/poolsim_new) against the
# session's first (.dev/poolsim) in a few rows. Usage: final.sh OUTDIR
set -u
O=$1; B=$PWD/.dev/poolsim_new; OLD=$PWD/.dev/poolsim; chmod +x $B $OLD
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
echo "== machine"; nproc; lscpu | grep -E 'Model name|^CPU\(s\)|Thread|Socket|NUMA node'; free -g | head -2
head -2 /etc/os-release; uname -r; mpirun --version 2>&1 | head -1; $B --version
MPI="mpirun --allow-run-as-root --oversubscribe --bind-to none --mca btl self,vader --mca pml ob1 --mca btl_vader_single_copy_mechanism none"
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-26s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"rollbacks":[0-9]*' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
G="--sectors auto --json --quiet"
echo "== gas 99856 to 0.5"; date +%T
for k in 1 2 3; do
  r "gas99856 seq #$k" 60 $B run gas --balls 99856 --until 0.5 --engine objects $G
  for w in 1 2 4 8 12 16; do r "gas99856 tw w$w #$k" 60 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G; done
  for w in 12 16; do r "gas99856 old w$w #$k" 60 $OLD run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G; done
done
echo "== gas 399424 to 0.25"; date +%T
for k in 1 2; do
  r "gas399424 seq #$k" 90 $B run gas --balls 399424 --until 0.25 --engine objects $G
  for w in 1 2 4 8 16; do r "gas399424 tw w$w #$k" 90 $B run gas --balls 399424 --until 0.25 --engine time-warp --workers $w $G; done
  r "gas399424 old w16 #$k" 90 $OLD run gas --balls 399424 --until 0.25 --engine time-warp --workers 16 $G
done
echo "== phold 16384 objects to 10"; date +%T
for p in 1 2 4 8 16; do
  r "phold p$p seq" 60 $B phold --objects 16384 --end 10 --partitions $p --engine objects --json
  r "phold p$p tw w$p" 60 $B phold --objects 16384 --end 10 --partitions $p --engine time-warp --workers $p --json
done
echo "== mpi"; date +%T
for rk in 2 4 8 16; do r "gas99856 mpi r${rk}xw1" 90 $MPI -np $rk $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 1 $G; done
r "gas99856 mpi r2xw8" 90 $MPI -np 2 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 8 $G
r "gas99856 mpi r4xw4" 90 $MPI -np 4 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 4 $G
for rk in 2 4 8 16; do r "phold mpi r${rk}xw1" 60 $MPI -np $rk $B phold --objects 16384 --end 10 --partitions $rk --engine time-warp --workers 1 --json; done
echo "== chaos"; date +%T
POOLSIM_CHAOS=7 r "gas99856 tw w16 chaos7" 90 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 16 $G
r "gas99856 mpi r4xw4 chaos7" 90 $MPI -x POOLSIM_CHAOS=7 -np 4 $B run gas --balls 99856 --until 0.5 --engine time-warp --workers 4 $G
echo "== a million balls to 0.1"; date +%T
r "gas1000000 seq" 120 $B run gas --balls 1000000 --until 0.1 --engine objects $G
for w in 4 8 16; do r "gas1000000 tw w$w" 120 $B run gas --balls 1000000 --until 0.1 --engine time-warp --workers $w $G; done
echo "== end"; date +%T
