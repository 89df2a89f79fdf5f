#!/usr/bin/python3
"""D of each finished point of a store from its two MSD estimators, over the run's own fit window
(summary.json's msd_window): D, what the run fitted (the every-origin MSD of the coarse samples,
`/msd_coarse`; runs older than it fitted `/msd/msd`, which then reads a ratio of exactly 1), beside the multiple-tau MSD of every particle (`/msd/msd`) and of the bulk band's
alone (`/msd/msd_bulk`, what D_bulk is fitted to). Whether D_bulk / D is the bulk's own or the
estimators' difference: the multiple-tau D of every particle over D says how far the two
estimators part.

    /usr/bin/python3 tools/msd_estimators.py STORE [STORE ...]   # results/NAME or sweep folders
"""
import argparse
import pathlib

import numpy as np

import rundir  # tools/rundir.py: what every tool reads of a run


def slope_d(lag, msd, lo, hi):
    """Half the slope of a least-squares line through the MSD at lags in [lo, hi]."""
    s = (lag >= lo * (1 - 1e-9)) & (lag <= hi * (1 + 1e-9))
    if s.sum() < 2:
        return float("nan")
    return float(np.polyfit(lag[s], msd[s], 1)[0]) / 2


def point_row(run):
    js = run.summary
    lo, hi = js["msd_window"]
    with run.open("analysis") as f:
        lag = f["msd/lag"][()]
        every = slope_d(lag, f["msd/msd"][()], lo, hi)
        bulk = slope_d(lag, f["msd/msd_bulk"][()], lo, hi) if "msd/msd_bulk" in f else None
    return js["J"], js["D"], every, bulk


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("stores", nargs="+", type=pathlib.Path)
    a = ap.parse_args()
    rows = []
    for path in a.stores:
        for run in rundir.Store(path).points():
            js = run.summary
            if run.has("analysis") and js.get("msd_window") and js.get("D") is not None:
                rows.append((run.path.name, *point_row(run)))
    if not rows:
        raise SystemExit(f"{', '.join(map(str, a.stores))}: no finished point with an analysis.h5")
    print("| point | D (every origin) | D, multiple-tau, every particle | ratio | "
          "D_bulk, multiple-tau | D_bulk / multiple-tau D |")
    print("|---|---|---|---|---|---|")
    for name, _, d, every, bulk in sorted(rows, key=lambda r: (r[1], r[0])):
        b = "- | -" if bulk is None else f"{bulk:.4g} | {bulk / every:.3f}"
        print(f"| {name} | {d:.4g} | {every:.4g} | {every / d:.3f} | {b} |")
    ratios = np.array([every / d for _, _, d, every, _ in rows])
    print(f"\nmultiple-tau / every-origin D over {len(ratios)} points: mean {ratios.mean():.3f}, "
          f"range {ratios.min():.3f}-{ratios.max():.3f}")


if __name__ == "__main__":
    main()
