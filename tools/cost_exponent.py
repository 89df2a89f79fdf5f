#!/usr/bin/env python3
"""Fitted exponent b of cost = a N^b for every benchmark family of bench_step's JSON output
(the default frictional variant at N = 250, 1000, 4000) or of bench_step_3d's (spheres at
N = 500, 1000, 2000; its benchmarks carry no variant label), least squares in log-log space.
From output with repetitions aggregated only (--benchmark_report_aggregates_only) the medians
are fitted.

    OMP_THREAD_LIMIT=1 build/bench/bench_step --benchmark_format=json > step.json
    /usr/bin/python3 tools/cost_exponent.py step.json
"""
import json
import sys

import numpy as np


def families(data):
    """{family: [(N, real time, cpu time), ...] sorted by N} of one Google Benchmark JSON output."""
    benchmarks = [b for b in data.get("benchmarks", []) if "N" in b]
    runs = [b for b in benchmarks if b.get("run_type") != "aggregate"]
    if not runs:  # --benchmark_report_aggregates_only: the medians of the repetitions
        runs = [dict(b, name=b["name"].removesuffix("_median"))
                for b in benchmarks if b.get("aggregate_name") == "median"]
    # bench_step labels its variants (the frictional one is fitted); bench_step_3d has one variant.
    labelled = any(b.get("label") for b in runs)
    fams = {}
    for b in runs:
        if labelled and b.get("label") != "frictional":
            continue
        fams.setdefault(b["name"].split("/")[0], []).append(
            (b["N"], b["real_time"], b.get("cpu_time", b["real_time"])))
    return {name: sorted(pts) for name, pts in fams.items()}


def exponent(pts):
    """b of cpu time = a N^b, least squares in log-log space (nan for a single N)."""
    if len(pts) < 2:
        return float("nan")
    n = np.array([p[0] for p in pts])
    cpu = np.array([p[2] for p in pts])
    return np.polyfit(np.log(n), np.log(cpu), 1)[0]


def main(path):
    fams = families(json.load(open(path)))
    if not fams:
        sys.exit(f"cost_exponent: {path} holds no benchmark with an N counter "
                 "(give bench_step's or bench_step_3d's --benchmark_format=json output)")
    ns = sorted({p[0] for p in next(iter(fams.values()))})
    print(f"{'benchmark':24s} " + " ".join(f"{'N=' + str(int(n)):>10s}" for n in ns) + "   exponent (cpu)")
    for name, pts in fams.items():  # repetitions: the median at each N is shown, all are fitted
        cells = [np.median([p[2] for p in pts if p[0] == n]) for n in sorted({p[0] for p in pts})]
        print(f"{name:24s} " + " ".join(f"{c:8.3f}ms" for c in cells) + f"   {exponent(pts):.2f}")

if __name__ == "__main__":
    main(sys.argv[1])
