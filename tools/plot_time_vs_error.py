#!/usr/bin/env python3
"""Run time against error from bench/time_vs_error's CSV: one panel per (J, ktilde), CPU seconds
per unit strain against the rms deviation from the reference after the strain window (top row)
and against |mu - mu_ref| (bottom row); each integrator's Pareto front is drawn as a line.

    /usr/bin/python3 tools/plot_time_vs_error.py bench_results/time_vs_error.csv \
        docs/figures/time_vs_error.png
    /usr/bin/python3 tools/plot_time_vs_error.py --table bench_results/time_vs_error.csv
    /usr/bin/python3 tools/plot_time_vs_error.py --front bench_results/time_vs_error_full.csv

More than four (J, ktilde) cases (the --full grid) are drawn as one row per ktilde and one
column per J, against |mu - mu_ref| only. --front prints, for each case and integrator, the
cheapest setting whose window averages are within the tolerances given in front() (the
statistical scatter of a steady-state average is larger than all of them).
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
    metrics = [("rms_dev", "rms deviation after the window (d)"),
               ("mu_err", "|mu - mu_ref| over the window")]
    if len(cases) <= 4:
        fig, axes = plt.subplots(2, len(cases), figsize=(4.2 * len(cases), 7.5), squeeze=False)
        panels = [(axes[row][col], case, metric) for col, case in enumerate(cases)
                  for row, metric in enumerate(metrics)]
    else:
        js = sorted({c[0] for c in cases}, reverse=True)
        ks = sorted({c[1] for c in cases})
        fig, axes = plt.subplots(len(ks), len(js), figsize=(4.2 * len(js), 3.6 * len(ks)), squeeze=False)
        panels = [(axes[ks.index(k)][js.index(j)], (j, k), metrics[1]) for j, k in cases]
        for kk in range(len(ks)):
            for jj in range(len(js)):
                if (js[jj], ks[kk]) not in cases:
                    axes[kk][jj].set_visible(False)
    first = True
    for ax, (j, k), (key, label) in panels:
        mine = [r for r in rows if float(r["J"]) == j and float(r["ktilde"]) == k]
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
        if first:
            ax.legend(title="circles adaptive,\nsquares fixed dt", fontsize=8)
            first = False
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


def front(path, mu_tol=0.005, phi_tol=1e-3, overlap_tol=0.1):
    """Per (ktilde, J): each integrator's cheapest setting with |mu - ref| <= mu_tol,
    |phi - ref| <= phi_tol and |max overlap / ref - 1| <= overlap_tol, and the implicit
    integrator's speed-up over the cheapest explicit one."""
    rows = [r for r in csv.DictReader(open(path)) if r["status"] == "ok" and r["policy"] != "reference"]
    print(f"Cheapest setting within |mu - ref| <= {mu_tol:g}, |phi - ref| <= {phi_tol:g}, "
          f"max overlap within {overlap_tol:.0%} of the reference's:\n")
    print("| ktilde | J | Euler | Heun | implicit | implicit vs best explicit |")
    print("|---|---|---|---|---|---|")
    cases = sorted({(float(r["ktilde"]), float(r["J"])) for r in rows}, key=lambda c: (c[0], -c[1]))
    skipped = {(float(r["ktilde"]), float(r["J"]), r["integrator"])
               for r in csv.DictReader(open(path)) if r["status"].startswith("skipped")}
    for k, j in cases:
        best = {}
        for r in rows:
            if float(r["ktilde"]) != k or float(r["J"]) != j:
                continue
            ok = (abs(float(r["mu_err"])) <= mu_tol and abs(float(r["phi_err"])) <= phi_tol
                  and abs(float(r["overlap_rel_err"])) <= overlap_tol)
            cost = float(r["cpu_s_per_strain"])
            if ok and (r["integrator"] not in best or cost < best[r["integrator"]][0]):
                setting = (f"md {float(r['md']):g}" if r["policy"] == "adaptive"
                           else f"J dt {float(r['strain_step']):g}")
                best[r["integrator"]] = (cost, setting, float(r["steps_per_strain"]))
        cells = []
        for integ in ("euler", "heun", "implicit"):
            if integ in best:
                c, setting, steps = best[integ]
                cells.append(f"{c:.3g} s ({setting}, {steps:.0f} steps)")
            elif (k, j, integ) in skipped:
                cells.append("skipped (> --max-steps)")
            else:
                cells.append("none within tolerance")
        explicit = [best[i][0] for i in ("euler", "heun") if i in best]
        ratio = f"{min(explicit) / best['implicit'][0]:.1f}x" if explicit and "implicit" in best else "-"
        print(f"| {k:g} | {j:g} | " + " | ".join(cells) + f" | {ratio} |")


if __name__ == "__main__":
    if sys.argv[1] == "--table":
        table(sys.argv[2])
    elif sys.argv[1] == "--front":
        front(sys.argv[2])
    else:
        main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "docs/figures/time_vs_error.png")
