#!/bin/bash
# Time Warp scaling on the device machine. Usage: scale.sh OUTDIR [quick]
set -u
O=$1; Q=${2:-}
B=$PWD/.dev/poolsim; chmod +x $B
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
echo "== machine"; nproc; lscpu | grep -E 'Model name|^CPU\(s\)|Thread|Socket|MHz|NUMA node' ; free -g | head -2
head -2 /etc/os-release; ldd --version | head -1; uname -r
echo "== mpi install"; date +%T
tar -xzf .dev/mpi.tgz -P --skip-old-files 2>&1 | tail -3; ldconfig 2>&1 | tail -2
ldd $B | grep 'not found'; command -v mpirun; mpirun --version 2>&1 | head -1
MPI="mpirun --allow-run-as-root --oversubscribe --bind-to none --mca btl self,vader --mca pml ob1 --mca btl_vader_single_copy_mechanism none"
unset POOLSIM_CHAOS
# one run: label, limit seconds, command...; appends "label<TAB>json" to results
r() { local l=$1 t=$2; shift 2; local s=$(date +%s.%N)
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1); local rc=$?
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-28s %6.2fs %s\n' "$l" "$(echo "$(date +%s.%N) - $s" | bc)" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
gas() { echo "$@ --sectors auto --json --quiet"; }
REP=3; WS="1 2 4 8 12 16"; [ -n "$Q" ] && { REP=1; WS="1 2"; }
echo "== gas 99856 to 0.5"; date +%T
N=99856; U=0.5; [ -n "$Q" ] && N=10000
for k in $(seq $REP); do
  r "gas$N seq #$k" 60 $B run gas --balls $N --until $U --engine objects $(gas)
  for w in $WS; do r "gas$N tw w$w #$k" 60 $B run gas --balls $N --until $U --engine time-warp --workers $w $(gas); done
done
echo "== gas 399424 to 0.25"; date +%T
N=399424; U=0.25; [ -n "$Q" ] && N=40000
for k in 1 2; do
  r "gas$N seq #$k" 90 $B run gas --balls $N --until $U --engine objects $(gas)
  for w in 1 2 4 8 16; do r "gas$N tw w$w #$k" 90 $B run gas --balls $N --until $U --engine time-warp --workers $w $(gas); done
done
echo "== phold 16384 objects to 20"; date +%T
for p in 1 2 4 8 16; do
  r "phold p$p seq" 60 $B phold --objects 16384 --end 10 --partitions $p --engine objects --json
  r "phold p$p tw w$p" 60 $B phold --objects 16384 --end 10 --partitions $p --engine time-warp --workers $p --json
done
echo "== mpi"; date +%T
N=99856; [ -n "$Q" ] && N=10000
for rk in 2 4 8 16; do r "gas$N mpi r${rk}xw1" 90 $MPI -np $rk $B run gas --balls $N --until 0.5 --engine time-warp --workers 1 $(gas); done
r "gas$N mpi r2xw8" 90 $MPI -np 2 $B run gas --balls $N --until 0.5 --engine time-warp --workers 8 $(gas)
r "gas$N mpi r4xw4" 90 $MPI -np 4 $B run gas --balls $N --until 0.5 --engine time-warp --workers 4 $(gas)
for rk in 2 4 8 16; do r "phold mpi r${rk}xw1" 60 $MPI -np $rk $B phold --objects 16384 --end 10 --partitions $rk --engine time-warp --workers 1 --json; done
echo "== chaos"; date +%T
POOLSIM_CHAOS=7 r "gas$N tw w16 chaos7" 90 $B run gas --balls $N --until 0.5 --engine time-warp --workers 16 $(gas)
r "gas$N mpi r4xw4 chaos7" 90 $MPI -x POOLSIM_CHAOS=7 -np 4 $B run gas --balls $N --until 0.5 --engine time-warp --workers 4 $(gas)
echo "== done"; date +%T
echo "== a million balls to 0.1"; date +%T
r "gas1000000 seq" 120 $B run gas --balls 1000000 --until 0.1 --engine objects $(gas)
r "gas1000000 tw w16" 120 $B run gas --balls 1000000 --until 0.1 --engine time-warp --workers 16 $(gas)
r "gas1000000 tw w4" 120 $B run gas --balls 1000000 --until 0.1 --engine time-warp --workers 4 $(gas)
echo "== end"; date +%T
