"""Benchmarks of the Python package against the command line (not run by the tests).

    python3 python/benchmarks/bench.py [--repeats 5] [--binary target/release/poolsim]

On the gas of 10^4 balls at area fraction 0.5 to t = 44 (about 10^6 events) it prints, for each
repeat in turn: the command line's engine time (its summary's wall_seconds) and the Python
call's whole time (the run, the event array and the final state), their ratio; the time to turn
the run's event columns into one structured array; and two threads each running the same
simulation at once against one thread alone. Medians at the end.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import threading
import time

import poolsim
from poolsim import _ask, _events, _native

ARGS = dict(balls=10_000, area_fraction=0.5, until=44.0)


def cli_engine_seconds(binary: str) -> float:
    cmd = [binary, "run", "gas", "--balls", "10000", "--area-fraction", "0.5", "--until", "44",
           "--json", "--quiet"]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True).stdout)["wall_seconds"]


def python_call_seconds() -> tuple[float, int]:
    t = time.perf_counter()
    r = poolsim.run("gas", **ARGS)
    return time.perf_counter() - t, len(r.events)


def array_seconds() -> float:
    spec, ask = _ask("gas", ARGS["until"], "event-list", None, None, None, False, None, True,
                     dict(balls=ARGS["balls"], area_fraction=ARGS["area_fraction"]))
    columns = _native.run(spec, ask)["events"]
    t = time.perf_counter()
    _events(columns)
    return time.perf_counter() - t


def threads_ratio() -> float:
    def one() -> None:
        poolsim.run("gas", events=False, **ARGS)

    t = time.perf_counter()
    one()
    alone = time.perf_counter() - t
    pair = [threading.Thread(target=one) for _ in range(2)]
    t = time.perf_counter()
    for th in pair:
        th.start()
    for th in pair:
        th.join()
    return (time.perf_counter() - t) / alone


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--binary", default="target/release/poolsim")
    a = p.parse_args()
    ratios, arrays, pairs = [], [], []
    for k in range(a.repeats):
        cli = cli_engine_seconds(a.binary)
        call, events = python_call_seconds()
        ratios.append(call / cli)
        arrays.append(array_seconds())
        pairs.append(threads_ratio())
        print(f"#{k + 1}: command line engine {cli:.3f} s, Python call {call:.3f} s "
              f"({events} events), ratio {ratios[-1]:.3f}; event array {1e3 * arrays[-1]:.1f} ms; "
              f"two threads / one {pairs[-1]:.2f}")
    print(f"medians: Python call / command line engine {statistics.median(ratios):.3f}, "
          f"event array {1e3 * statistics.median(arrays):.1f} ms, "
          f"two threads / one {statistics.median(pairs):.2f}")


if __name__ == "__main__":
    main()
