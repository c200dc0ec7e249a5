#!/usr/bin/env python3
"""The table of scripts/melting.sh's summaries: for each run, Z and the reduced pressure
beta P sigma^2 = Z 4 eta / pi averaged over the blocks of the last half of the run, with the
standard error of those blocks' mean, and the first half's mean beside it (a drift between the
two halves means the run had not equilibrated).

Usage: scripts/melting_table.py DIR"""

import json
import math
import sys
from pathlib import Path


def mean_error(xs):
    m = sum(xs) / len(xs)
    if len(xs) < 2:
        return m, float("nan")
    var = sum((x - m) ** 2 for x in xs) / (len(xs) - 1)
    return m, math.sqrt(var / len(xs))


def main(folder):
    print("| area fraction | start | disks | time | collisions per disk | Z, first half | Z, last half | beta P sigma^2, last half |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    for path in sorted(Path(folder).glob("*.json")):
        eta, start = path.stem.split("-")
        d = json.loads(path.read_text())
        series = [b["z"] for b in d["observables"]["series"]]
        half = len(series) // 2
        if half < 2:
            continue
        first, _ = mean_error(series[:half])
        z, err = mean_error(series[half:])
        f = 4 * float(eta) / math.pi
        end = d["observables"]["series"][-1]["end"]
        per_disk = 2 * d["events"]["ball-ball"] / d["balls"]
        print(f"| {eta} | {start} | {d['balls']} | {end:.0f} | {per_disk:.0f} | {first:.4f} | "
              f"{z:.4f} ± {err:.4f} | {z * f:.4f} ± {err * f:.4f} |")


if __name__ == "__main__":
    main(sys.argv[1])
