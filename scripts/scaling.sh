#!/usr/bin/env bash
# Time Warp scaling of poolsim on the machine it runs on.
#
# Usage: scripts/scaling.sh [--balls N] [--until T] [--phold-objects N] [--phold-end T]
#          [--phold-partitions N] [--phold-remote R] [--phold-lookahead L]
#          [--workers LIST | --max-workers N] [--repeats N]
#          [--models gas,phold] [--mpi] [--cpus LIST] [--timeout S]
#          [--no-build | --binary PATH] [--out FILE]
#
# Run from anywhere inside a checkout on Linux; needs bash, coreutils, python3 (JSON parsing and
# the summary) and, to build, cargo. It
#   1. builds target/release/poolsim (`cargo build --release`, with `--features mpi` when --mpi is
#      given and `mpirun` is on the PATH; without mpirun the MPI rows are skipped);
#   2. measures, each run a fresh process:
#      - the sectored gas, `poolsim run gas --balls N --until T --sectors auto --json --quiet`
#        (default 99,856 balls to t = 0.5), on the sequential objects engine (`--engine
#        objects`) and on Time Warp (`--engine time-warp --workers W`);
#      - PHOLD, `poolsim phold --objects N --end T --partitions P --json` (default 16,384 objects
#        x 16 messages, remote 0.1, to t = 10), on the sequential kernel and on Time Warp. P is
#        the same in every row (default: the largest worker or rank count, at least 2), so that
#        every row runs one model and ends in one digest;
#      - with --mpi, both models on R MPI ranks x 1 worker as well;
#      with W = 1, 2, 4, 8, ... up to the cores (the core count itself added when it is no
#      power of two), and R the same counts from 2 on;
#   3. repeats every configuration --repeats times (default 3). Each repeat runs all
#      configurations of a model once, starting one place later in the list than the repeat
#      before, so that a drift in the machine's speed falls on every configuration alike;
#   4. writes one TSV line per run and prints, per configuration, the median time, its range,
#      the speed-up over the sequential run (median over median) and the median of the ratios
#      within each repeat, efficiency, share of batches run as final and GVT rounds. It checks
#      that every run of a model gave the same final-state digest (the sequential engine's) and
#      exits with status 1 when one did not or a run failed.
#
# Options:
#   --balls N             gas balls, a square number (default 99856)
#   --until T             gas end time (default 0.5; 1.5 measures more of the steady state)
#   --phold-objects N     PHOLD objects (default 16384)
#   --phold-end T         PHOLD end time (default 10)
#   --phold-partitions N  PHOLD partitions in every row (default: the largest worker/rank count, >= 2)
#   --phold-remote R      PHOLD's probability of a message to another partition (default 0.1)
#   --phold-lookahead L   PHOLD's minimum delay (default 0.1)
#   --workers LIST        worker (and rank) counts, e.g. 1,2,4,8,12,16 (default: as above)
#   --max-workers N       largest count of the default list (default: the cores available)
#   --repeats N           runs of each configuration (default 3)
#   --models LIST         gas, phold or both (default gas,phold)
#   --mpi                 build with the `mpi` feature and add the MPI rows
#   --conservative        add PHOLD rows on the conservative executor (`--engine conservative
#                         --workers W`, the same counts; needs a positive --phold-lookahead)
#   --cpus LIST           run every measured process on these CPUs only (e.g. 2,3 or 0-7, through
#                         python3's os.sched_setaffinity); the cores counted are these
#   --timeout S           limit for one run, seconds (default 600); a run past it counts as failed
#   --no-build            use target/release/poolsim as it is
#   --binary PATH         use this poolsim binary (implies --no-build)
#   --out FILE            the TSV (default target/scaling/scaling-HOST-YYYYmmdd-HHMMSS.tsv)
# Environment: MPIRUN replaces the MPI launcher (default for Open MPI: mpirun --oversubscribe
# --bind-to none --mca btl self,vader --mca pml ob1 --mca btl_vader_single_copy_mechanism none,
# plus --allow-run-as-root as root; for other MPIs: mpirun); `-np R` and the command follow it.
# POOLSIM_CHAOS is unset for every run.
#
# The TSV: lines starting with '#' describe the machine, the binary and the command line; then
# one header line and one line per run, tab-separated, in this order:
#   model          gas or phold
#   size           balls (gas) or objects (phold)
#   until          the run's end time (--until or --end)
#   executor       seq (sequential objects engine / kernel), tw (Time Warp on threads), mpi,
#                  cons (the conservative executor, PHOLD only)
#   ranks          MPI ranks (1 for seq, tw and cons)
#   workers        Time Warp or conservative workers per rank (0 for seq)
#   cores          ranks x workers (1 for seq)
#   repeat         1 .. --repeats
#   slot           the run's place within its repeat (1 = first)
#   status         ok, or failed:RC, timeout, no-json, ranks:N (an MPI run that did not run on
#                  the ranks asked for: the binary lacks the `mpi` feature)
#   process_s      whole-process wall time, measured here (seconds)
#   wall_s         the summary's wall_seconds (gas: the run without loading the scenario;
#                  phold: the whole run); the summary below is computed on this column
#   setup_s        gas: the summary's setup_seconds; empty for phold
#   events         gas: physical events (events.total); phold: committed events
#   events_per_s   the summary's events_per_second
#   batches        committed batches (time_warp.committed, or engine_stats.batches on the
#                  sequential gas); empty for sequential PHOLD
#   efficiency     time_warp committed / processed; empty for seq
#   final_share    time_warp final_batches / committed; empty for seq
#   remote_fraction time_warp remote_messages / messages; empty for seq
#   gvt_rounds     time_warp.gvt_rounds (cons: conservative.windows); empty for seq
#   rollbacks      time_warp.rollbacks; empty for seq
#   peak_rss_mib   time_warp.peak_rss_mib (gas on Time Warp only); empty otherwise
#   digest         final_state_digest
#   summary        the run's whole --json summary, on one line
# The fields are those of docs/formats.md ("Run summary" and "Other outputs").

set -uo pipefail

die() { echo "scaling.sh: $*" >&2; exit 2; }

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd) || die "cannot find the repository"

balls=99856 until=0.5 phold_objects=16384 phold_end=10 phold_partitions=
phold_remote=0.1 phold_lookahead=0.1
workers_list= max_workers= repeats=3 models=gas,phold use_mpi=0 use_cons=0 cpus= timeout_s=600
build=1 binary= out=
args_given=("$@")

while (($#)); do
  opt=$1 val=
  case $opt in
    --*=*) val=${opt#*=}; opt=${opt%%=*}; shift ;;
    --mpi|--conservative|--no-build|-h|--help) shift ;;
    --*) (($# >= 2)) || die "$opt: needs a value"; val=$2; shift 2 ;;
    *) die "unknown argument: $opt (see --help)" ;;
  esac
  case $opt in
    --balls) balls=$val ;;
    --until) until=$val ;;
    --phold-objects) phold_objects=$val ;;
    --phold-end) phold_end=$val ;;
    --phold-partitions) phold_partitions=$val ;;
    --phold-remote) phold_remote=$val ;;
    --phold-lookahead) phold_lookahead=$val ;;
    --workers) workers_list=$val ;;
    --max-workers) max_workers=$val ;;
    --repeats) repeats=$val ;;
    --models) models=$val ;;
    --mpi) use_mpi=1 ;;
    --conservative) use_cons=1 ;;
    --cpus) cpus=$val ;;
    --timeout) timeout_s=$val ;;
    --no-build) build=0 ;;
    --binary) binary=$val; build=0 ;;
    --out) out=$val ;;
    -h|--help)
      while IFS= read -r line; do
        [[ $line == '#!'* ]] && continue
        [[ $line == '#'* ]] || break
        line=${line#\#}; echo "${line# }"
      done < "${BASH_SOURCE[0]}"
      exit 0 ;;
    *) die "unknown option: $opt (see --help)" ;;
  esac
done

is_count() { [[ $1 =~ ^[1-9][0-9]*$ ]]; }
is_time() { [[ $1 =~ ^([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$ ]]; }
is_count "$balls" || die "--balls: a positive integer, got '$balls'"
is_count "$phold_objects" || die "--phold-objects: a positive integer, got '$phold_objects'"
is_count "$repeats" || die "--repeats: a positive integer, got '$repeats'"
is_count "$timeout_s" || die "--timeout: a positive integer, got '$timeout_s'"
is_time "$until" || die "--until: a positive number, got '$until'"
is_time "$phold_end" || die "--phold-end: a positive number, got '$phold_end'"
[[ -z $phold_partitions ]] || is_count "$phold_partitions" \
  || die "--phold-partitions: a positive integer, got '$phold_partitions'"
[[ -z $max_workers ]] || is_count "$max_workers" \
  || die "--max-workers: a positive integer, got '$max_workers'"

run_gas=0 run_phold=0
IFS=, read -ra model_names <<< "$models"
for m in "${model_names[@]}"; do
  case $m in
    gas) run_gas=1 ;;
    phold) run_phold=1 ;;
    *) die "--models: gas and/or phold, got '$m'" ;;
  esac
done
((run_gas || run_phold)) || die "--models: nothing to run"

command -v python3 >/dev/null || die "python3 is needed (JSON parsing and the summary)"
unset POOLSIM_CHAOS

# The CPUs: all this process may use, or --cpus (checked against those).
pin=()
if [[ -n $cpus ]]; then
  cpu_csv=$(python3 - "$cpus" <<'EOF'
import os, sys
cpus = set()
for part in sys.argv[1].split(","):
    a, _, b = part.strip().partition("-")
    try:
        lo, hi = int(a), int(b or a)
    except ValueError:
        sys.exit(f"--cpus: not a CPU list: {sys.argv[1]!r}")
    cpus.update(range(lo, hi + 1))
allowed = os.sched_getaffinity(0)
if not cpus or not cpus <= allowed:
    sys.exit(f"--cpus: {sorted(cpus)} not among the CPUs this process may use, {sorted(allowed)}")
print(",".join(map(str, sorted(cpus))))
EOF
  ) || exit 2
  IFS=, read -ra cpu_ids <<< "$cpu_csv"
  cores=${#cpu_ids[@]}
  pin=(python3 -c 'import os, sys
os.sched_setaffinity(0, {int(c) for c in sys.argv[1].split(",")})
os.execvp(sys.argv[2], sys.argv[2:])' "$cpu_csv")
else
  cores=$(nproc)
fi

# Worker (and rank) counts.
if [[ -n $workers_list ]]; then
  IFS=, read -ra counts <<< "$workers_list"
  for w in "${counts[@]}"; do is_count "$w" || die "--workers: positive integers, got '$w'"; done
else
  top=${max_workers:-$cores}
  counts=()
  for ((w = 1; w <= top; w *= 2)); do counts+=("$w"); done
  [[ ${counts[-1]} == "$top" ]] || counts+=("$top")
fi
largest=1
for w in "${counts[@]}"; do
  ((w > largest)) && largest=$w
  ((w > cores)) && echo "scaling.sh: warning: $w workers on $cores cores (oversubscribed)" >&2
done
if [[ -z $phold_partitions ]]; then
  phold_partitions=$((largest < 2 ? 2 : largest))
fi
((phold_partitions <= phold_objects)) || die "--phold-partitions: at most --phold-objects"

# MPI.
mpi=()
if ((use_mpi)); then
  if ! command -v mpirun >/dev/null; then
    echo "scaling.sh: warning: --mpi without mpirun on the PATH: building without MPI, MPI rows skipped" >&2
    use_mpi=0
  elif [[ -n ${MPIRUN:-} ]]; then
    read -ra mpi <<< "$MPIRUN"
  else
    mpi=(mpirun)
    if mpirun --version 2>&1 | python3 -c 'import sys; sys.exit("Open MPI" not in sys.stdin.read())'; then
      mpi+=(--oversubscribe --bind-to none --mca btl self,vader --mca pml ob1
            --mca btl_vader_single_copy_mechanism none)
      ((EUID == 0)) && mpi+=(--allow-run-as-root)
    fi
  fi
fi

# The binary.
if [[ -n $binary ]]; then
  bin=$binary
else
  bin=$root/target/release/poolsim
fi
if ((build)); then
  command -v cargo >/dev/null || die "cargo not found (or pass --no-build / --binary)"
  features=()
  ((use_mpi)) && features=(--features mpi)
  echo "== building: cargo build --release ${features[*]:-}"
  (cd "$root" && cargo build --release ${features[@]+"${features[@]}"}) || die "the build failed"
fi
[[ -x $bin ]] || die "no executable poolsim at $bin"
version=$("$bin" --version 2>/dev/null) || die "$bin --version failed"

# The output.
if [[ -z $out ]]; then
  mkdir -p "$root/target/scaling" || die "cannot create $root/target/scaling"
  out=$root/target/scaling/scaling-$(uname -n)-$(date +%Y%m%d-%H%M%S).tsv
fi
: > "$out" || die "cannot write $out"
tmp=$(mktemp -d) || die "mktemp failed"
trap 'rm -rf "$tmp"' EXIT

machine=$(python3 - "$cores" <<'EOF'
import os, platform, sys
model = "unknown CPU"
try:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name") or line.startswith("Processor"):
            model = line.split(":", 1)[1].strip()
            break
except OSError:
    pass
mem = ""
try:
    for line in open("/proc/meminfo"):
        if line.startswith("MemTotal:"):
            mem = f", {int(line.split()[1]) / 2**20:.0f} GiB"
            break
except OSError:
    pass
print(f"{platform.node()}: {model}, {os.cpu_count()} logical CPUs ({sys.argv[1]} used){mem}, "
      f"{platform.system()} {platform.release()} {platform.machine()}")
EOF
)

{
  echo "# poolsim Time Warp scaling (scripts/scaling.sh), $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "# machine: $machine"
  echo "# binary: $bin ($version)${cpus:+, on CPUs $cpus}"
  echo "# command: scripts/scaling.sh ${args_given[*]:-}"
  echo "# gas: $balls balls to t = $until, --sectors auto; phold: $phold_objects objects to t = $phold_end, $phold_partitions partitions, remote $phold_remote, lookahead $phold_lookahead; counts: ${counts[*]}; repeats: $repeats${mpi:+; mpi: ${mpi[*]}}"
  printf '%s\t' model size until executor ranks workers cores repeat slot status process_s \
    wall_s setup_s events events_per_s batches efficiency final_share remote_fraction \
    gvt_rounds rollbacks peak_rss_mib digest
  printf 'summary\n'
} >> "$out"

# One run's TSV line from its output (the last line of stdout is its JSON summary).
cat > "$tmp/row.py" <<'EOF'
import json, sys
(outfile, model, size, until, executor, ranks, workers, repeat, slot, rc, process_us) = sys.argv[1:]
rc, ranks, workers = int(rc), int(ranks), int(workers)
lines = [l for l in open(outfile, errors="replace").read().splitlines() if l.strip()]
s = None
if lines:
    try:
        s = json.loads(lines[-1])
    except ValueError:
        s = None
status = "ok"
if rc == 124 or rc == 137:
    status = "timeout"
elif rc != 0:
    status = f"failed:{rc}"
elif not isinstance(s, dict):
    status = "no-json"
s = s if isinstance(s, dict) else {}
tw = s.get("time_warp") or {}
cons = s.get("conservative") or {}
if status == "ok" and executor == "mpi" and tw.get("ranks") != ranks:
    status = f"ranks:{tw.get('ranks')}"

def num(x, fmt="{:.6g}"):
    return "" if x is None else fmt.format(x)

if model == "gas":
    events = (s.get("events") or {}).get("total")
    setup = s.get("setup_seconds")
else:
    events = s.get("committed")
    setup = None
batches = tw.get("committed", (s.get("engine_stats") or {}).get("batches"))
eff = fin = remote = None
if tw:
    processed, committed = tw.get("processed"), tw.get("committed")
    eff = tw.get("efficiency", committed / processed if processed else 1.0)
    fin = tw["final_batches"] / committed if committed else None
    msgs = tw.get("messages")
    remote = tw.get("remote_fraction", tw.get("remote_messages", 0) / msgs if msgs else 0.0)
cores = 1 if executor == "seq" else ranks * workers
row = [model, size, until, executor, ranks, workers, cores, repeat, slot, status,
       "%.6f" % (int(process_us) / 1e6), num(s.get("wall_seconds")), num(setup),
       num(events, "{}"), num(s.get("events_per_second"), "{:.1f}"),
       num(None if batches is None else int(batches), "{}"), num(eff), num(fin), num(remote),
       num(tw.get("gvt_rounds", cons.get("windows")), "{}"), num(tw.get("rollbacks"), "{}"),
       num(tw.get("peak_rss_mib"), "{:.1f}"), s.get("final_state_digest", ""),
       json.dumps(s, separators=(",", ":")) if s else ""]
print("\t".join(map(str, row)))
what = {"seq": "sequential", "tw": f"{workers} worker{'s' * (workers > 1)}",
        "mpi": f"{ranks} ranks x {workers}", "cons": f"conservative, {workers}"}[executor]
extra = f" ({open(outfile + '.err', errors='replace').read().strip()[:300]})" if status != "ok" else ""
print(f"  {model} {what:<18} #{repeat}  {num(s.get('wall_seconds'), '{:8.3f}')} s  "
      f"{s.get('final_state_digest', '')}  {status}{extra}", file=sys.stderr)
EOF

# run_one MODEL EXECUTOR RANKS WORKERS REPEAT SLOT
run_one() {
  local model=$1 executor=$2 ranks=$3 workers=$4 repeat=$5 slot=$6 size end
  local -a cmd=() engine=(--engine objects)
  [[ $executor != seq ]] && engine=(--engine time-warp --workers "$workers")
  [[ $executor == cons ]] && engine=(--engine conservative --workers "$workers")
  # the pool's relays have no lookahead: the conservative executor runs PHOLD alone
  [[ $executor == cons && $model == gas ]] && return 0
  if [[ $model == gas ]]; then
    size=$balls end=$until
    cmd=("$bin" run gas --balls "$balls" --until "$until" --sectors auto "${engine[@]}" --json --quiet)
  else
    size=$phold_objects end=$phold_end
    cmd=("$bin" phold --objects "$phold_objects" --end "$phold_end" \
         --partitions "$phold_partitions" --remote "$phold_remote" \
         --lookahead "$phold_lookahead" "${engine[@]}" --json)
  fi
  [[ $executor == mpi ]] && cmd=("${mpi[@]}" -np "$ranks" "${cmd[@]}")
  local t0 t1 rc
  t0=$(date +%s%N)
  timeout "$timeout_s" ${pin[@]+"${pin[@]}"} "${cmd[@]}" > "$tmp/out" 2> "$tmp/out.err"
  rc=$?
  t1=$(date +%s%N)
  if ((rc == 2)); then
    echo "scaling.sh: poolsim refused the command (status 2):" >&2
    echo "  ${cmd[*]}" >&2
    cat "$tmp/out.err" >&2
    exit 2
  fi
  python3 "$tmp/row.py" "$tmp/out" "$model" "$size" "$end" "$executor" "$ranks" "$workers" \
    "$repeat" "$slot" "$rc" $(((t1 - t0) / 1000)) >> "$out"
}

# The configurations of a model, as "executor ranks workers".
configs=("seq 1 0")
for w in "${counts[@]}"; do configs+=("tw 1 $w"); done
if ((use_mpi)); then
  for r in "${counts[@]}"; do ((r >= 2)) && configs+=("mpi $r 1"); done
fi
if ((use_cons)); then
  for w in "${counts[@]}"; do configs+=("cons 1 $w"); done
fi

selected=()
((run_gas)) && selected+=(gas)
((run_phold)) && selected+=(phold)
n=${#configs[@]}
echo "== $machine"
echo "== $version; ${#selected[@]} model(s) x $n configurations x $repeats repeats = $((${#selected[@]} * n * repeats)) runs; TSV: $out"
for model in "${selected[@]}"; do
  if [[ $model == gas ]]; then
    echo "== gas: $balls balls to t = $until (--sectors auto)"
  else
    echo "== phold: $phold_objects objects to t = $phold_end, $phold_partitions partitions"
  fi
  for ((k = 1; k <= repeats; k++)); do
    for ((i = 0; i < n; i++)); do
      read -r executor ranks workers <<< "${configs[$(((i + k - 1) % n))]}"
      run_one "$model" "$executor" "$ranks" "$workers" "$k" $((i + 1))
    done
  done
done

# Medians and speed-ups.
python3 - "$out" <<'EOF'
import statistics, sys
from collections import defaultdict

path = sys.argv[1]
rows, header = [], None
for line in open(path):
    if line.startswith("#"):
        continue
    f = line.rstrip("\n").split("\t")
    if header is None:
        header = f
        continue
    rows.append(dict(zip(header, f)))

bad = 0
models = defaultdict(list)
for r in rows:
    models[(r["model"], r["size"], r["until"])].append(r)
for (model, size, until), rs in models.items():
    if model == "gas":
        print(f"\ngas: {int(size):,} balls to t = {until} (--sectors auto)")
    else:
        print(f"\nphold: {int(size):,} objects to t = {until}")
    ok = [r for r in rs if r["status"] == "ok"]
    failed = len(rs) - len(ok)
    digests = sorted({r["digest"] for r in ok})
    if len(digests) == 1:
        print(f"  digest {digests[0]} in every run that ended")
    elif digests:
        bad += 1
        print("  DIGESTS DIFFER: " + ", ".join(
            f"{d} ({sum(r['digest'] == d for r in ok)} runs)" for d in digests))
    if failed:
        bad += 1
        print(f"  {failed} run(s) failed: see the status column of {path}")
    confs = defaultdict(list)
    for r in ok:
        confs[(r["executor"], int(r["ranks"]), int(r["workers"]))].append(r)
    order = {"seq": 0, "tw": 1, "mpi": 2, "cons": 3}
    seq = confs.get(("seq", 1, 0), [])
    seq_med = statistics.median(float(r["wall_s"]) for r in seq) if seq else None
    seq_by_rep = {r["repeat"]: float(r["wall_s"]) for r in seq}
    cols = "  {:<24} {:>4} {:>9} {:>17} {:>8} {:>9} {:>6} {:>6} {:>11}"
    head = ["executor", "runs", "median s", "range s", "speed-up", "in-repeat", "effic.",
            "final", "GVT rounds"]
    if model == "phold":
        cols += " {:>10} {:>10}"
        head += ["M ev/s", "M/s/core"]
    print(cols.format(*head))
    for key in sorted(confs, key=lambda c: (order[c[0]], c[1] * c[2])):
        ex, ranks, workers = key
        cr = confs[key]
        t = sorted(float(r["wall_s"]) for r in cr)
        med = statistics.median(t)
        name = {"seq": "sequential", "tw": f"Time Warp, {workers} worker{'s' * (workers > 1)}",
                "mpi": f"MPI, {ranks} ranks x {workers}",
                "cons": f"conservative, {workers} w."}[ex]
        within = [seq_by_rep[r["repeat"]] / float(r["wall_s"]) for r in cr
                  if r["repeat"] in seq_by_rep and float(r["wall_s"]) > 0]
        speed = f"{seq_med / med:.2f}" if seq_med and med > 0 else ""
        inrep = f"{statistics.median(within):.2f}" if within and ex != "seq" else ""
        def span(field, fmt):
            v = sorted(float(r[field]) for r in cr if r[field])
            if not v:
                return ""
            return fmt.format(v[0]) if fmt.format(v[0]) == fmt.format(v[-1]) \
                else fmt.format(v[0]) + "-" + fmt.format(v[-1])
        cells = [name, len(cr), f"{med:.3f}", f"{t[0]:.3f}-{t[-1]:.3f}", speed, inrep,
                 span("efficiency", "{:.3f}"), span("final_share", "{:.2f}"),
                 span("gvt_rounds", "{:.0f}")]
        if model == "phold":
            rate = statistics.median(float(r["events_per_s"]) for r in cr) / 1e6
            cores = 1 if ex == "seq" else ranks * workers
            cells += [f"{rate:.2f}", f"{rate / cores:.2f}"]
        print(cols.format(*cells))
print(f"\nspeed-up: the sequential median over this row's median; in-repeat: the median over "
      f"repeats of the sequential run's time over this row's in the same repeat.\nTSV: {path}")
sys.exit(1 if bad else 0)
EOF
