#!/bin/bash
# The optimism window's span (1,024, 4,096, 8,192 batches' worth) on the device. Usage: horizon.sh OUTDIR
set -u
O=$1; chmod +x .dev/h*
R=$O/results.tsv; : > $R
exec > >(tee -a $O/log.txt) 2>&1
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout $t "$@" 2>$O/err.tmp | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> $R
  printf '%-26s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"rollbacks":[0-9]*\|"efficiency":[0-9.]*' | tr '\n' ' ')"
  [ -s $O/err.tmp ] && head -c 600 $O/err.tmp; }
G="--sectors auto --json --quiet"
H="1024 4096 8192"
date +%T
for k in 1 2 3; do for w in 2 8 16; do for h in $H; do
  r "gas99856 h$h w$w #$k" 60 .dev/h$h run gas --balls 99856 --until 0.5 --engine time-warp --workers $w $G
done; done; done
date +%T
for k in 1 2; do for w in 8 16; do for h in $H; do
  r "gas399424 h$h w$w #$k" 90 .dev/h$h run gas --balls 399424 --until 0.25 --engine time-warp --workers $w $G
done; done; done
date +%T
for w in 16 8; do for h in $H; do
  r "gas1000000 h$h w$w" 120 .dev/h$h run gas --balls 1000000 --until 0.1 --engine time-warp --workers $w $G
done; done
date +%T
for k in 1 2 3; do for h in $H; do
  r "gas36 h$h w2 #$k" 30 .dev/h$h run gas --balls 36 --engine time-warp --workers 2 $G
  r "phold h$h w16 #$k" 60 .dev/h$h phold --objects 16384 --end 10 --partitions 16 --engine time-warp --workers 16 --json
done; done
date +%T
