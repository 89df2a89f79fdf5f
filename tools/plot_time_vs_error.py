#!/usr/bin/env python3
"""Run time against error from bench/time_vs_error's CSV: one panel per (J, ktilde), CPU seconds
per unit strain against the rms deviation from the reference after the strain window (top row)
and against |mu - mu_ref| (bottom row); each integrator's Pareto front is drawn as a line.

    /usr/bin/python3 tools/plot_time_vs_error.py bench_results/time_vs_error.csv \
        docs/figures/time_vs_error.png
    /usr/bin/python3 tools/plot_time_vs_error.py --table bench_results/time_vs_error.csv
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"euler": "tab:blue", "heun": "tab:orange", "implicit": "tab:green"}
MARKERS = {"adaptive": "o", "fixed": "s"}


def pareto(points):
    """Points (error, cost) not beaten in both by another point, sorted by error."""
    front, best = [], math.inf
    for e, c in sorted(points):
        if c < best:
            front.append((e, c))
            best = c
    return front


def main(path, out):
    rows = [r for r in csv.DictReader(open(path)) if r["status"] == "ok" and r["policy"] != "reference"]
    cases = sorted({(float(r["J"]), float(r["ktilde"])) for r in rows}, key=lambda c: (c[1], -c[0]))
    fig, axes = plt.subplots(2, len(cases), figsize=(4.2 * len(cases), 7.5), squeeze=False)
    for col, (j, k) in enumerate(cases):
        mine = [r for r in rows if float(r["J"]) == j and float(r["ktilde"]) == k]
        for row, (key, label) in enumerate([("rms_dev", "rms deviation after the window (d)"),
                                            ("mu_err", "|mu - mu_ref| over the window")]):
            ax = axes[row][col]
            for integ, colour in COLOURS.items():
                pts = []
                for r in mine:
                    if r["integrator"] != integ:
                        continue
                    err = abs(float(r[key]))
                    cost = float(r["cpu_s_per_strain"])
                    if not (math.isfinite(err) and err > 0 and math.isfinite(cost)):
                        continue
                    pts.append((err, cost))
                    ax.scatter(err, cost, color=colour, marker=MARKERS[r["policy"]], s=30)
                front = pareto(pts)
                if front:
                    ax.plot(*zip(*front), color=colour, label=integ)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(label)
            ax.set_ylabel("CPU s per unit strain")
            ax.set_title(f"J = {j:g}, ktilde = {k:g}")
            ax.grid(True, which="both", alpha=0.3)
            if col == 0 and row == 0:
                ax.legend(title="circles adaptive,\nsquares fixed dt", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(out)


def table(path):
    """The CSV as a markdown table (docs/performance.md)."""
    print("| J | ktilde | integrator | step policy | steps / strain | CPU s / strain | rms dev (d) "
          "| phi - ref | mu - ref | max overlap rel. | limited by |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in csv.DictReader(open(path)):
        if r["policy"] == "reference":
            policy = f"reference, md {float(r['md']):g}"
        elif r["policy"] == "adaptive":
            policy = f"md {float(r['md']):g}"
        else:
            policy = f"fixed J dt = {float(r['strain_step']):g}"
        if r["status"] != "ok":
            print(f"| {r['J']} | {r['ktilde']} | {r['integrator']} | {policy} | {r['status']} |||||||")
            continue
        f = lambda k, fmt: format(float(r[k]), fmt)
        print(f"| {r['J']} | {r['ktilde']} | {r['integrator']} | {policy} | {f('steps_per_strain', '.0f')} "
              f"| {f('cpu_s_per_strain', '.3g')} | {f('rms_dev', '.2g')} | {f('phi_err', '+.1e')} "
              f"| {f('mu_err', '+.3f')} | {f('overlap_rel_err', '+.2f')} | {r['limited_by']} |")


if __name__ == "__main__":
    if sys.argv[1] == "--table":
        table(sys.argv[2])
    else:
        main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "docs/figures/time_vs_error.png")
