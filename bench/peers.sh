#!/usr/bin/env bash
# PHOLD side by side: poolsim's kernel, ROSS and ROOT-Sim, on this machine.
#
# Usage: bench/peers.sh --ross DIR --rootsim DIR [--build DIR] [--poolsim PATH]
#          [--threads T] [--runs K] [--configs LIST] [--events N | --end T]
#          [--timeout S] [--retries R] [--ross-args "ARGS"] [--out DIR] [--no-build]
#
#   --ross DIR       a ROSS source tree (github ROSS-org/ROSS), built here with its models/phold
#   --rootsim DIR    a ROOT-Sim core 3.x source tree (github ROOT-Sim/core); bench/rootsim_phold.c
#                    is compiled against the library built from it
#   --build DIR      where the peers are built and the runs are kept (default target/peers)
#   --poolsim PATH   the poolsim binary (default target/release/poolsim; build it first with
#                    `cargo build --release`)
#   --threads T      workers / MPI ranks / threads of the parallel runs (default 2)
#   --runs K         runs of every kernel and configuration (default 5)
#   --configs LIST   space- or comma-separated OBJECTS:REMOTE:LOOKAHEAD triples (default: every
#                    combination of 1024 16384 x 0.1 0.5 x 0 0.1)
#   --events N       committed events aimed at per run (default 10000000); the end time of a
#                    configuration is N * (lookahead + 1) / (objects * 16)
#   --end T          one end time for every configuration instead (overrides --events)
#   --timeout S      seconds a run may take (default 600)
#   --retries R      reruns of a ROOT-Sim parallel run that hung (default 2; see bench/README.md)
#   --ross-args A    extra options for every ROSS run (e.g. "--gvt-interval=256"); default none,
#                    i.e. ROSS's own defaults
#   --out DIR        where results.csv, summary.txt and the logs go (default BUILD/results-DATE)
#   --no-build       use the peers already built in BUILD
#
# For every configuration and every round k = 1..K it runs, alternating kernels (each round starts
# one kernel later than the last, so that a drift of the machine's speed falls on all alike):
#   poolsim sequential (`--engine objects --partitions T`), poolsim Time Warp (T workers),
#   poolsim conservative (T workers; lookahead > 0 only), ROSS sequential (--synch=1), ROSS
#   optimistic (mpirun -np T, --synch=3), ROSS conservative (mpirun -np T, --synch=2; lookahead
#   > 0 only), ROOT-Sim serial runtime, ROOT-Sim parallel runtime (T threads).
# Committed events per second come from each tool's own output: poolsim's JSON (committed /
# wall_seconds), ROSS's "Net Events Processed" over its "Running Time", and the model's committed
# count over ROOT-Sim's "Simulation completed in S seconds". The table gives, per configuration and
# kernel, the median and the min-max of the rate, and each parallel run's speed-up (median over
# median) over its own kernel's sequential run and over poolsim's sequential run. How the models
# were matched is printed first; bench/README.md says more.
#
# Needs bash, coreutils, cmake, a C compiler, OpenMPI (mpicc, mpirun) and python3 (the summary;
# ROOT-Sim's build needs it too). On Debian: apt-get install -y cmake libopenmpi-dev openmpi-bin.
set -euo pipefail

# ---------------------------------------------------------------------------------------------
# Options
# ---------------------------------------------------------------------------------------------
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ROSS_SRC=""
ROOTSIM_SRC=""
BUILD="$REPO/target/peers"
POOLSIM="$REPO/target/release/poolsim"
THREADS=2
RUNS=5
CONFIGS="1024:0.1:0 1024:0.1:0.1 1024:0.5:0 1024:0.5:0.1 16384:0.1:0 16384:0.1:0.1 16384:0.5:0 16384:0.5:0.1"
EVENTS=10000000
END_FIXED=""
TIMEOUT=600
RETRIES=2
ROSS_ARGS=""
OUT=""
DO_BUILD=1
START_EVENTS=16 # messages each object starts with (poolsim's --events-per-object)
MEAN=1          # mean of the exponential part of the delay
JOBS=2          # parallel build jobs

die() { echo "peers.sh: $*" >&2; exit 1; }
usage() { sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit "${1:-0}"; }

parse_args() {
  while [[ $# -gt 0 ]]; do
    case "$1" in
      --ross) ROSS_SRC=$2; shift 2 ;;
      --rootsim) ROOTSIM_SRC=$2; shift 2 ;;
      --build) BUILD=$2; shift 2 ;;
      --poolsim) POOLSIM=$2; shift 2 ;;
      --threads) THREADS=$2; shift 2 ;;
      --runs) RUNS=$2; shift 2 ;;
      --configs) CONFIGS=${2//,/ }; shift 2 ;;
      --events) EVENTS=$2; shift 2 ;;
      --end) END_FIXED=$2; shift 2 ;;
      --timeout) TIMEOUT=$2; shift 2 ;;
      --retries) RETRIES=$2; shift 2 ;;
      --ross-args) ROSS_ARGS=$2; shift 2 ;;
      --out) OUT=$2; shift 2 ;;
      --no-build) DO_BUILD=0; shift ;;
      -h|--help) usage 0 ;;
      *) echo "unknown option: $1" >&2; usage 2 ;;
    esac
  done
  [[ -n $ROSS_SRC && -n $ROOTSIM_SRC ]] || die "--ross DIR and --rootsim DIR are required (see --help)"
  [[ -d $ROSS_SRC/models/phold ]] || die "$ROSS_SRC has no models/phold: not a ROSS tree?"
  [[ -f $ROOTSIM_SRC/src/ROOT-Sim.h ]] || die "$ROOTSIM_SRC has no src/ROOT-Sim.h: not a ROOT-Sim core tree?"
  [[ $THREADS =~ ^[0-9]+$ && $THREADS -ge 2 ]] || die "--threads must be at least 2"
  [[ $RUNS =~ ^[0-9]+$ && $RUNS -ge 1 ]] || die "--runs must be at least 1"
  ROSS_SRC=$(cd "$ROSS_SRC" && pwd)
  ROOTSIM_SRC=$(cd "$ROOTSIM_SRC" && pwd)
  mkdir -p "$BUILD"
  BUILD=$(cd "$BUILD" && pwd)
  [[ -n $OUT ]] || OUT="$BUILD/results-$(date +%Y%m%d-%H%M%S)"
  mkdir -p "$OUT/logs"
  OUT=$(cd "$OUT" && pwd)
}

# ---------------------------------------------------------------------------------------------
# Tools and builds
# ---------------------------------------------------------------------------------------------
check_tools() {
  local missing=()
  for t in cmake mpicc mpirun python3 timeout "${CC:-gcc}"; do
    command -v "$t" >/dev/null || missing+=("$t")
  done
  if [[ ${#missing[@]} -gt 0 ]]; then
    die "missing: ${missing[*]} (on Debian: apt-get install -y cmake libopenmpi-dev openmpi-bin python3)"
  fi
  [[ -x $POOLSIM ]] || die "no poolsim binary at $POOLSIM (run: cargo build --release, or pass --poolsim)"
  MPIRUN=(mpirun -np "$THREADS")
  [[ $(id -u) -eq 0 ]] && MPIRUN+=(--allow-run-as-root)
  [[ $THREADS -gt $(nproc) ]] && MPIRUN+=(--oversubscribe)
  return 0
}

# The commit and nearest tag of a source tree, or "unknown" outside git.
git_version() {
  local dir=$1 sha desc
  sha=$(git -C "$dir" rev-parse HEAD 2>/dev/null) || { echo "unknown (not a git checkout)"; return; }
  desc=$(git -C "$dir" describe --tags --always --dirty 2>/dev/null || echo "?")
  echo "$sha ($desc)"
}

# ROSS with its own models, built as a release; only the phold target is needed.
build_ross() {
  local b=$BUILD/ross
  echo "== building ROSS ($ROSS_SRC) in $b"
  cmake -S "$ROSS_SRC" -B "$b" -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER=mpicc \
    -DROSS_BUILD_MODELS=ON -DROSS_BUILD_TESTING=OFF >"$b.configure.log" 2>&1 ||
    die "ROSS configure failed, see $b.configure.log"
  cmake --build "$b" --target phold -j "$JOBS" >"$b.build.log" 2>&1 ||
    die "ROSS build failed, see $b.build.log"
}

# ROOT-Sim's library (without MPI: one node, its threads share memory) and bench/rootsim_phold.c
# against it. Its CMakeLists always adds test/, which fetches a testing framework from the
# network at configure time; a local stub that defines the framework's two functions stands in
# for it, and only the library target is built.
build_rootsim() {
  local b=$BUILD/rootsim stub=$BUILD/rootsim-rstest-stub
  echo "== building ROOT-Sim ($ROOTSIM_SRC) in $b"
  mkdir -p "$stub"
  cat >"$stub/CMakeLists.txt" <<'EOF'
# Stand-in for ROOT-Sim's testing framework (fetched from the network otherwise); tests unused.
function(test_program name)
  add_executable(test_${name} EXCLUDE_FROM_ALL ${ARGN})
  add_test(NAME test_${name} COMMAND test_${name})
endfunction()
function(test_program_link_libraries name)
  target_link_libraries(test_${name} ${ARGN})
endfunction()
EOF
  cmake -S "$ROOTSIM_SRC" -B "$b" -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER="${CC:-gcc}" \
    -DWITH_MPI=OFF -DFETCHCONTENT_FULLY_DISCONNECTED=ON \
    -DFETCHCONTENT_SOURCE_DIR_RSTEST="$stub" >"$b.configure.log" 2>&1 ||
    die "ROOT-Sim configure failed, see $b.configure.log"
  cmake --build "$b" --target rscore -j "$JOBS" >"$b.build.log" 2>&1 ||
    die "ROOT-Sim build failed, see $b.build.log"
  # Same flags as ROOT-Sim's release build of its library: -O3 and link-time optimisation.
  "${CC:-gcc}" -std=gnu11 -O3 -DNDEBUG -flto -I"$ROOTSIM_SRC/src" "$REPO/bench/rootsim_phold.c" \
    "$b/src/librscore.a" -lm -lpthread -o "$b/rootsim_phold" >>"$b.build.log" 2>&1 ||
    die "compiling bench/rootsim_phold.c failed, see $b.build.log"
}

ROSS_BIN() { echo "$BUILD/ross/models/phold/phold"; }
ROOTSIM_BIN() { echo "$BUILD/rootsim/rootsim_phold"; }

# ---------------------------------------------------------------------------------------------
# The model, matched
# ---------------------------------------------------------------------------------------------
# End time of a configuration: with a constant population of objects * 16 messages, each in
# flight lookahead + Exp(1) on average, about objects * 16 / (lookahead + 1) events commit per
# unit of time.
end_time() {
  local objects=$1 lookahead=$2
  if [[ -n $END_FIXED ]]; then echo "$END_FIXED"; return; fi
  awk -v n="$objects" -v e="$START_EVENTS" -v l="$lookahead" -v m="$MEAN" -v t="$EVENTS" \
    'BEGIN { printf "%.6g\n", t * (l + m) / (n * e) }'
}

# ROSS's PHOLD sends with probability --remote to a uniform LP anywhere (its own rank included),
# else back to itself: the share that crosses ranks is remote * (T-1)/T. It is set to poolsim's
# share of messages to another partition.
ross_remote() {
  awk -v r="$1" -v t="$THREADS" 'BEGIN { x = r * t / (t - 1); if (x > 1) x = 1; printf "%.6g\n", x }'
}

print_matching() {
  cat <<EOF
How the models were matched
  poolsim (crates/pdes-kernel/src/phold.rs): N objects in P = $THREADS equal contiguous blocks (P is
    the same in the sequential run, so both runs are one model); each starts with $START_EVENTS
    messages to itself; handling one sends one, to another block with probability REMOTE
    (uniform block, then uniform object), else to a uniform object of its own block;
    delay = LOOKAHEAD + Exp(mean $MEAN).
  ROOT-Sim: bench/rootsim_phold.c, written against ROOT-Sim.h, is the same model with the same
    receiver rule and P = $THREADS in both runtimes (ROOT-Sim gives thread r the LPs r*N/T to
    (r+1)*N/T - 1, the same blocks); delay = LOOKAHEAD - $MEAN*ln(U). Its own repository has a PHOLD
    only as a test with compile-time sizes (test/integration/phold.c), not used. Committed events
    are counted by the model (events before the end time, in the rolled-back LP state).
  ROSS: its own models/phold, unchanged: --start-events=$START_EVENTS, --lookahead=LOOKAHEAD and
    --mean=$MEAN+LOOKAHEAD (phold.main.c subtracts the lookahead from --mean, so the delay is again
    LOOKAHEAD + Exp($MEAN)), --nlp=N (sequential) or N/$THREADS per rank. Its receiver rule differs and
    cannot be changed from the command line: with probability --remote a uniform LP anywhere
    (its own rank and itself included), else itself. --remote is set to REMOTE*T/(T-1), capped
    at 1, so that the share of messages that cross ranks equals poolsim's REMOTE (for T = $THREADS:
    0.1 -> $(ross_remote 0.1), 0.5 -> $(ross_remote 0.5)); the rest stay on the sender (poolsim, ROOT-Sim:
    a uniform object of the sender's block). Same value in ROSS's sequential run.
    ROSS options otherwise at their defaults${ROSS_ARGS:+, plus: $ROSS_ARGS}.
  End time: the same for the three kernels in a configuration, $( [[ -n $END_FIXED ]] &&
    echo "fixed at $END_FIXED" || echo "chosen so that about $EVENTS events commit:
    end = $EVENTS * (LOOKAHEAD + $MEAN) / (N * $START_EVENTS), the population N*$START_EVENTS being constant
    and each message in flight LOOKAHEAD + $MEAN on average").
    Each kernel counts the events it commits before the end time; the counts differ a little
    (different random streams) and the table shows them.
  Rate: committed events / the tool's own time: poolsim's wall_seconds (object setup and run),
    ROSS's "Running Time" (tw_run only, the slowest rank; setup not included), ROOT-Sim's
    "Simulation completed in" (from its initialisation, LP_INIT included, to the end of event
    processing). results.csv also has each process's outer wall time (process and MPI start-up).
EOF
}

# ---------------------------------------------------------------------------------------------
# Runs
# ---------------------------------------------------------------------------------------------
KERNELS=(poolsim-seq poolsim-tw poolsim-cons ross-seq ross-opt ross-cons rootsim-serial rootsim-par)
# the conservative executors need a positive lookahead: at lookahead 0 they are not run
CONSERVATIVE=(poolsim-cons ross-cons)

# run_kernel KERNEL OBJECTS REMOTE LOOKAHEAD END LOG TIMEOUT: runs one kernel once and prints
# "STATUS COMMITTED TOOL_SECONDS WALL_SECONDS" (the last: the process's outer wall time).
run_kernel() {
  local k=$1 n=$2 r=$3 l=$4 end=$5 log=$6 tmo=$7
  local cmd=() committed="" secs="" rc=0 t0 t1 wall
  case "$k" in
    poolsim-seq)
      cmd=("$POOLSIM" phold --objects "$n" --events-per-object "$START_EVENTS" --remote "$r"
        --lookahead "$l" --mean "$MEAN" --end "$end" --engine objects --partitions "$THREADS" --json) ;;
    poolsim-tw|poolsim-cons)
      local engine=time-warp
      [[ $k == poolsim-cons ]] && engine=conservative
      cmd=("$POOLSIM" phold --objects "$n" --events-per-object "$START_EVENTS" --remote "$r"
        --lookahead "$l" --mean "$MEAN" --end "$end" --engine "$engine" --workers "$THREADS"
        --partitions "$THREADS" --json) ;;
    ross-seq)
      # shellcheck disable=SC2206 # ROSS_ARGS is split into words on purpose
      cmd=("$(ROSS_BIN)" --synch=1 --nlp="$n" --start-events="$START_EVENTS" --remote="$(ross_remote "$r")"
        --lookahead="$l" --mean="$(awk -v l="$l" -v m="$MEAN" 'BEGIN { print l + m }')" --end="$end" $ROSS_ARGS) ;;
    ross-opt|ross-cons)
      local synch=3
      [[ $k == ross-cons ]] && synch=2
      # shellcheck disable=SC2206
      cmd=("${MPIRUN[@]}" "$(ROSS_BIN)" --synch="$synch" --nlp="$((n / THREADS))" --start-events="$START_EVENTS"
        --remote="$(ross_remote "$r")" --lookahead="$l"
        --mean="$(awk -v l="$l" -v m="$MEAN" 'BEGIN { print l + m }')" --end="$end" $ROSS_ARGS) ;;
    rootsim-serial|rootsim-par)
      local t=0
      [[ $k == rootsim-par ]] && t=$THREADS
      cmd=("$(ROOTSIM_BIN)" --lps "$n" --threads "$t" --partitions "$THREADS" --remote "$r"
        --lookahead "$l" --mean "$MEAN" --start-events "$START_EVENTS" --end "$end") ;;
  esac
  # ROSS writes ross.csv and ross_all_lp_stats/ into the working directory: keep them in BUILD.
  echo "+ ${cmd[*]}" >"$log"
  t0=$(date +%s.%N)
  (cd "$BUILD/scratch" && timeout -k 10 "$tmo" "${cmd[@]}") >>"$log" 2>&1 || rc=$?
  t1=$(date +%s.%N)
  wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
  if [[ $rc -eq 124 || $rc -eq 137 ]]; then echo "timeout - - $wall"; return; fi
  if [[ $rc -ne 0 ]]; then echo "fail(rc=$rc) - - $wall"; return; fi
  case "$k" in
    poolsim-*)
      # the first "committed" is the report's own (Time Warp's statistics have one too)
      committed=$(grep -o '"committed":[0-9]*' "$log" | head -1 | cut -d: -f2) || true
      secs=$(grep -o '"wall_seconds":[0-9.eE+-]*' "$log" | head -1 | cut -d: -f2) || true ;;
    ross-*)
      committed=$(awk '/Net Events Processed/ { print $NF }' "$log" | tail -1)
      secs=$(sed -n 's/.*Running Time = \([0-9.eE+-]*\) seconds.*/\1/p' "$log" | tail -1) ;;
    rootsim-*)
      committed=$(sed -n 's/^committed events: \([0-9]*\).*/\1/p' "$log" | tail -1)
      secs=$(tr '\r' '\n' <"$log" | sed -n 's/.*Simulation completed in \([0-9.]*\) seconds.*/\1/p' | tail -1) ;;
  esac
  if [[ -z $committed || -z $secs ]]; then echo "unparsed - - $wall"; return; fi
  echo "ok $committed $secs $wall"
}

run_all() {
  local csv=$OUT/results.csv cfg_i=0 n r l end round k i status committed secs wall log
  local tries tmo serial_wall
  echo "config,objects,remote,lookahead,end,round,kernel,status,committed,tool_seconds,wall_seconds,events_per_second,tries,log" >"$csv"
  mkdir -p "$BUILD/scratch"
  for cfg in $CONFIGS; do
    cfg_i=$((cfg_i + 1))
    IFS=: read -r n r l <<<"$cfg"
    [[ -n $n && -n $r && -n $l ]] || die "bad configuration '$cfg' (want OBJECTS:REMOTE:LOOKAHEAD)"
    (( n % THREADS == 0 )) || die "objects ($n) must be a multiple of --threads ($THREADS) for ROSS"
    end=$(end_time "$n" "$l")
    echo "== configuration $cfg_i: objects $n, remote $r, lookahead $l, end $end (ROSS --remote=$(ross_remote "$r"))"
    serial_wall="" # the latest ROOT-Sim serial run's wall time in this configuration
    for ((round = 1; round <= RUNS; round++)); do
      for ((i = 0; i < ${#KERNELS[@]}; i++)); do
        k=${KERNELS[$(((i + round - 1) % ${#KERNELS[@]}))]}
        if [[ " ${CONSERVATIVE[*]} " == *" $k "* ]] && awk -v l="$l" 'BEGIN { exit !(l <= 0) }'; then
          continue
        fi
        tries=0
        while :; do
          tries=$((tries + 1))
          log=$OUT/logs/c${cfg_i}-r${round}-${k}-t${tries}.log
          tmo=$TIMEOUT
          # ROOT-Sim 3.0.0's parallel runtime can deadlock at termination (bench/README.md):
          # give it 30 s plus ten times its serial run (once one is known) and rerun it if it
          # hangs.
          if [[ $k == rootsim-par && -n $serial_wall ]]; then
            tmo=$(awk -v s="$serial_wall" -v m="$TIMEOUT" 'BEGIN { t = int(30 + 10 * s); print (t < m ? t : m) }')
          fi
          if ! read -r status committed secs wall < <(run_kernel "$k" "$n" "$r" "$l" "$end" "$log" "$tmo"); then
            status=error committed=- secs=- wall=-
          fi
          [[ $k == rootsim-par && $status == timeout && $tries -le $RETRIES ]] || break
          echo "   round $round $k: timed out after ${tmo}s (try $tries), rerunning"
        done
        [[ $k == rootsim-serial && $status == ok ]] && serial_wall=$wall
        local eps="-"
        [[ $status == ok ]] && eps=$(awk -v c="$committed" -v s="$secs" 'BEGIN { printf "%.1f", c / s }')
        printf '   round %d %-15s %-8s committed %-10s tool %9s s  wall %9s s  %s ev/s\n' \
          "$round" "$k" "$status" "$committed" "$([[ $secs == - ]] && echo - || printf '%.4f' "$secs")" "$wall" "$eps"
        echo "$cfg_i,$n,$r,$l,$end,$round,$k,$status,$committed,$secs,$wall,$eps,$tries,${log#"$OUT"/}" >>"$csv"
      done
    done
  done
}

# ---------------------------------------------------------------------------------------------
# Summary
# ---------------------------------------------------------------------------------------------
summarize() {
  python3 - "$OUT/results.csv" "$THREADS" <<'EOF'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
T = sys.argv[2]
names = {
    "poolsim-seq": "poolsim sequential", "poolsim-tw": f"poolsim Time Warp x{T}",
    "poolsim-cons": f"poolsim conservative x{T}",
    "ross-seq": "ROSS sequential", "ross-opt": f"ROSS optimistic x{T} ranks",
    "ross-cons": f"ROSS conservative x{T} ranks",
    "rootsim-serial": "ROOT-Sim serial", "rootsim-par": f"ROOT-Sim parallel x{T} thr",
}
own_seq = {"poolsim-tw": "poolsim-seq", "poolsim-cons": "poolsim-seq", "ross-opt": "ross-seq",
           "ross-cons": "ross-seq", "rootsim-par": "rootsim-serial"}
def fmt(x): return f"{x / 1e6:7.3f}"
configs = []
for r in rows:
    key = (r["config"], r["objects"], r["remote"], r["lookahead"], r["end"])
    if key not in configs: configs.append(key)
print("Committed events per second, in millions: median [min - max] over the runs that finished;")
print("speed-ups are median over median.")
for (c, n, rem, la, end) in configs:
    print(f"\nconfiguration {c}: objects {n}, remote {rem}, lookahead {la}, end {end}")
    print(f"  {'kernel':<27}{'ok':>5}  {'committed (med)':>15}  {'Mev/s':>7}  {'[min  -  max]':>17}"
          f"  {'vs own seq':>10}  {'vs poolsim seq':>14}")
    med = {}
    for k in names:
        rs = [r for r in rows if r["config"] == c and r["kernel"] == k]
        ok = [r for r in rs if r["status"] == "ok"]
        eps = [float(r["events_per_second"]) for r in ok]
        if eps: med[k] = statistics.median(eps)
    for k, name in names.items():
        rs = [r for r in rows if r["config"] == c and r["kernel"] == k]
        ok = [r for r in rs if r["status"] == "ok"]
        if not rs:
            continue  # a conservative kernel at lookahead 0
        hung = sum(int(r["tries"]) - 1 for r in rs)
        note = f"  ({hung} hung run(s) rerun)" if hung else ""
        if not ok:
            bad = ",".join(sorted({r["status"] for r in rs})) or "not run"
            print(f"  {name:<27}{0:>2}/{len(rs):<2}  {bad}{note}")
            continue
        eps = [float(r["events_per_second"]) for r in ok]
        com = statistics.median(int(r["committed"]) for r in ok)
        vs_own = f"{med[k] / med[own_seq[k]]:10.2f}" if k in own_seq and own_seq[k] in med else f"{'':>10}"
        vs_pool = f"{med[k] / med['poolsim-seq']:14.2f}" if "poolsim-seq" in med else f"{'-':>14}"
        print(f"  {name:<27}{len(ok):>2}/{len(rs):<2}  {com:>15.0f}  {fmt(med[k])}  [{fmt(min(eps))} - {fmt(max(eps))}]"
              f"  {vs_own}  {vs_pool}{note}")
EOF
}

print_header() {
  echo "PHOLD, poolsim vs ROSS vs ROOT-Sim -- $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "machine: $(nproc) cores, $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1), $(uname -sr)"
  echo "poolsim:  $POOLSIM ($(git_version "$REPO"))"
  echo "ROSS:     $ROSS_SRC, commit $(git_version "$ROSS_SRC")"
  echo "ROOT-Sim: $ROOTSIM_SRC, commit $(git_version "$ROOTSIM_SRC")"
  echo "compilers: $("${CC:-gcc}" --version | head -1); $(mpirun --version 2>/dev/null | head -1)"
  echo "parallel runs: $THREADS workers / ranks / threads; $RUNS run(s) each; timeout ${TIMEOUT}s"
  echo "results: $OUT"
  echo
  print_matching
  echo
}

main() {
  parse_args "$@"
  check_tools
  if [[ $DO_BUILD -eq 1 ]]; then
    build_ross
    build_rootsim
  fi
  [[ -x $(ROSS_BIN) ]] || die "no ROSS phold at $(ROSS_BIN)"
  [[ -x $(ROOTSIM_BIN) ]] || die "no ROOT-Sim phold at $(ROOTSIM_BIN)"
  print_header | tee "$OUT/summary.txt"
  run_all
  echo
  summarize | tee -a "$OUT/summary.txt"
  echo
  echo "raw runs: $OUT/results.csv; logs: $OUT/logs; this summary: $OUT/summary.txt"
}

main "$@"
