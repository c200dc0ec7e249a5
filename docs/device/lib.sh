# Sourced by the device scripts from 6 on, with the output folder as $1: one line per run to
# $1/results.tsv (a label, a tab, the run's --json summary), and a log of both to $1/log.txt.
set -u
O=$1
R=$O/results.tsv; : > "$R"
exec > >(tee -a "$O/log.txt") 2>&1
MPI="mpirun --allow-run-as-root --oversubscribe --bind-to none --mca btl self,vader --mca pml ob1 --mca btl_vader_single_copy_mechanism none"
# r LABEL TIMEOUT COMMAND...: runs one, keeps its summary, shows its time, digest, rounds, efficiency
r() { local l=$1 t=$2; shift 2
  local j; j=$(timeout "$t" "$@" 2>"$O/err.tmp" | tail -1)
  printf '%s\t%s\n' "$l" "${j:-{\"failed\":true\}}" >> "$R"
  printf '%-30s %s\n' "$l" "$(echo "$j" | grep -o '"wall_seconds":[0-9.]*\|"final_state_digest":"[0-9a-f]*"\|"gvt_rounds":[0-9]*\|"efficiency":[0-9.]*' | tr '\n' ' ')"
  [ -s "$O/err.tmp" ] && head -c 600 "$O/err.tmp"; }
