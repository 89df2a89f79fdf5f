#!/usr/bin/python3
"""Was a pressure-cell window stationary? Two uses (docs/model.md, "Steady state").

  stationarity_check.py store RESULTS_DIR... [--markdown]
      Every stored point: its run's verdict (`stationary`, `not_stationary`) where the run
      recorded one; for points run before the verdict existed, the one signal their summaries
      still hold, mu_top - mu_bottom against its error (the two walls' errors combined as if
      independent, an approximation). --markdown prints one table of all the stores' points
      with a verdict, for a generated block of the docs (tools/doc_tables.py).

  stationarity_check.py approach RUN_DIR [--window W] [--block B] [--z Z] [--tolerance T]
      A run's trajectory observables (H, mu_top, mu_bottom, net_drag_y, bulk_normal_load) in
      consecutive windows of W strain: the window means and the verdict of the same four
      signals as the run's own test, so that the strain at which a start reaches steady state
      can be read off.

  stationarity_check.py blocks RUN_DIR... [--sliding N [--z Z]] [--blocking]
      A finished run's measured window block by block, from its summary.json alone (no
      trajectory): the block means its error bars and its verdict were formed from
      (`window_blocks`), and the least-squares lines through H's (the run's H_change) and phi's
      block means, each as its change over the window +- its standard error. Runs finished
      before sheardiff wrote `window_blocks` are named as such. --sliding N adds the line
      through H's block means over every N consecutive blocks (a shorter window's H_change
      within a long one: N = 6 is a 20-strain window of 3-strain blocks), each with its z, and
      how many lie beyond Z (3, the run's own test) standard errors. --blocking adds, per
      signal, the lag-1 autocorrelation of the block means and the standard error of their mean
      from blocks merged in pairs and in fours over that from single blocks: ratios above 1
      mean the blocks are not independent and the run's error bars are that much too small
      (merged blocks are counted from the window's start; a leftover block is dropped). With
      several runs it ends with their lag-1 autocorrelations pooled per signal (mean +- its
      standard error over the runs) beside what independent blocks give on average, -1/n for
      n blocks (the estimator's own bias).
"""
import argparse
import math
import pathlib
import sys

import numpy as np

import rundir


SIGNALS = ("net_drag_y", "mu_top_minus_bottom", "H_change", "bulk_normal_load")


def signal_cells(s):
    """A summary's stationarity signals, each 'mean +- standard error' or '-'."""
    return ["{:+.3f} +- {:.3f}".format(s[k], s[k + "_err"]) if k in s and k + "_err" in s
            else "-" for k in SIGNALS]


def store(path):
    rows = []
    for point in rundir.Store(path).points():
        s, name = point.summary, point.path.name
        if "stationary" in s:
            verdict = "stationary" if s["stationary"] else "DRIFTING: " + s.get("not_stationary", "")
            signals = " | ".join(signal_cells(s))
            rows.append((s.get("J", math.nan), name,
                         "| {:.4f} | {} | {}".format(s.get("phi", math.nan), signals, verdict)))
            continue
        if not all(k in s for k in ("mu_top", "mu_bottom", "mu_top_err", "mu_bottom_err")):
            rows.append((s.get("J", math.nan), name, "no verdict: no steady window"))
            continue
        d = s["mu_top"] - s["mu_bottom"]
        e = math.hypot(s["mu_top_err"], s["mu_bottom_err"])
        z = d / e if e > 0 else math.inf
        verdict = "mu_top - mu_bottom = {:+.3f} +- {:.3f} (z = {:+.1f}): {}".format(
            d, e, z, "within noise" if abs(z) <= 3 else "DRIFTING")
        rows.append((s.get("J", math.nan), name, verdict + " (only signal stored)"))
    print("point | phi | " + " | ".join(SIGNALS) + " | verdict   (signals: window means +- "
          "their standard errors; the old summaries hold only the walls' mu)")
    for _, name, verdict in sorted(rows):
        print(f"{name:28s} {verdict}")


def markdown(paths):
    """One table of every point of the stores that recorded a verdict; points without one are
    named below it."""
    print("| store | point | phi | net y drag / P | mu_top - mu_bottom | H change / d "
          "| bulk normal load / P | verdict |")
    print("|---|---|---|---|---|---|---|---|")
    without = []
    for path in paths:
        rows = []
        for point in rundir.Store(path).points():
            s, name = point.summary, point.path.name
            if "stationary" not in s:
                without.append(f"{path}/{name}")
                continue
            cells = signal_cells(s)
            verdict = "stationary" if s["stationary"] else "drifting: " + s.get("not_stationary", "")
            rows.append((s.get("J", math.nan), name, "| {} | {} | {:.4f} | {} | {} |".format(
                pathlib.PurePath(path).name, name, s.get("phi", math.nan), " | ".join(cells),
                verdict)))
        for _, _, row in sorted(rows):
            print(row)
    if without:
        print("\nNo stationarity verdict recorded (run before the test existed): "
              + ", ".join(without) + ".")


BLOCK_COLUMNS = ("H", "phi", "mu", "mu_top_minus_bottom", "net_drag_y", "bulk_normal_load")


def fmt_num(x, spec):
    """x formatted, or '-' where the summary holds null (an empty block) or NaN."""
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def window_line(t, y, span=None):
    """The least-squares line through block means y at midpoints t: its change over the window
    (slope x window length, as the run's H_change) and that change's standard error from the
    scatter about the line, the run's own estimate (src/analysis/stationarity.cpp). span, the
    window's length, defaults to the blocks' count times their spacing."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    span = len(t) * (t[1] - t[0]) if span is None else span
    tc = t - t.mean()
    slope = (tc @ (y - y.mean())) / (tc @ tc)
    resid = y - y.mean() - slope * tc
    err = math.sqrt((resid @ resid) / (len(t) - 2) / (tc @ tc)) if len(t) > 2 else math.nan
    return slope * span, err * span


def sliding_lines(t, h, n, z):
    """The line through H's block means h (midpoints t) over every n consecutive blocks, as
    printed lines, and how many of them lie beyond z standard errors. A window holding an empty
    block (null) is skipped."""
    spacing = t[1] - t[0]
    out, beyond, judged = [], 0, 0
    for i in range(len(t) - n + 1):
        if any(x is None for x in h[i:i + n]):
            continue
        change, err = window_line(t[i:i + n], h[i:i + n])
        judged += 1
        beyond += abs(change) > z * err
        out.append(f"  strains {t[i] - spacing / 2:6.1f} - {t[i + n - 1] + spacing / 2:6.1f}: "
                   f"{change:+.3f} +- {err:.3f} d (z {fmt_num(change / err if err > 0 else math.nan, '+.1f')})")
    out.append(f"  {beyond} of {judged} beyond {z:g} standard errors")
    return out


def blocking(x):
    """(lag-1 autocorrelation, sem from pairs / sem, sem from fours / sem) of block means x; NaN
    where too few blocks (fewer than 3 merged means) or a null block."""
    if any(v is None for v in x):
        return math.nan, math.nan, math.nan
    x = np.asarray(x, float)
    d = x - x.mean()
    lag1 = (d[1:] @ d[:-1]) / (d @ d) if d @ d > 0 else math.nan

    single = rundir.mean_sem(x.tolist())[1]

    def ratio(m):
        k = len(x) // m
        if k < 3 or not single:
            return math.nan
        return rundir.mean_sem(x[:k * m].reshape(k, m).mean(axis=1).tolist())[1] / single

    return lag1, ratio(2), ratio(4)


def blocks(paths, sliding=None, z=3.0, show_blocking=False):
    """Each run's window_blocks as a table, and the lines through H's and phi's block means (the
    first is the run's H_change); with sliding, the lines through every `sliding` consecutive
    blocks of H too; with show_blocking over several runs, their lag-1 autocorrelations
    pooled."""
    lag1s = {c: [] for c in BLOCK_COLUMNS}  # (lag-1, number of blocks) per signal
    for path in map(pathlib.Path, paths):
        run = rundir.Run(path)
        if not run.finished:
            print(f"{path}: no summary.json (not a finished run)\n")
            continue
        s = run.summary
        b = s.get("window_blocks")
        if not b:
            print(f"{path}: no window_blocks (a run finished before sheardiff wrote them, "
                  "or one without a steady window)\n")
            continue
        if "stationary" not in s:
            verdict = "no verdict (a run recorded before the stationarity signals)"
        else:
            verdict = ("stationary" if s["stationary"]
                       else "DRIFTING: " + (s.get("not_stationary") or "?"))
        print(f"{path}: {len(b['strain'])} blocks, verdict {verdict}, H_change "
              f"{fmt_num(s.get('H_change'), '+.3f')} +- {fmt_num(s.get('H_change_err'), '.3f')} d")
        print("strain | " + " | ".join(BLOCK_COLUMNS))
        for k, t in enumerate(b["strain"]):
            cells = ["-" if b.get(c) is None else fmt_num(b[c][k], ".4f") for c in BLOCK_COLUMNS]
            print(f"{t:7.2f} | " + " | ".join(cells))
        for name, unit in (("H", " d"), ("phi", "")):
            if b.get(name) is not None and len(b["strain"]) > 1:
                change, err = window_line(b["strain"], b[name])
                print(f"line through {name}'s block means: {fmt_num(change, '+.4f')} +- "
                      f"{fmt_num(err, '.4f')}{unit} over the window")
        if sliding and b.get("H") is not None and len(b["strain"]) >= sliding:
            print(f"lines through H's block means over every {sliding} consecutive blocks:")
            print("\n".join(sliding_lines(b["strain"], b["H"], sliding, z)))
        if show_blocking:
            print("signal | lag-1 autocorrelation | sem from pairs / sem | sem from fours / sem")
            for c in BLOCK_COLUMNS:
                if b.get(c) is not None:
                    stats = blocking(b[c])
                    if not math.isnan(stats[0]):
                        lag1s[c].append((stats[0], len(b[c])))
                    print(f"{c} | " + " | ".join(fmt_num(v, "+.2f" if i == 0 else ".2f")
                                                 for i, v in enumerate(stats)))
        print()
    runs = max(len(v) for v in lag1s.values())
    if show_blocking and runs >= 2:
        print(f"lag-1 autocorrelation pooled over the runs ({runs}):")
        print("signal | runs | mean +- standard error | independent blocks: mean of -1/n")
        for c in BLOCK_COLUMNS:
            if len(lag1s[c]) >= 2:
                m, e = rundir.mean_sem([r for r, _ in lag1s[c]])
                expect = sum(-1.0 / n for _, n in lag1s[c]) / len(lag1s[c])
                print(f"{c} | {len(lag1s[c])} | {m:+.2f} +- {e:.2f} | {expect:+.2f}")
        print()


def block_stats(x, t, lo, hi, blocks):
    edges = np.linspace(lo, hi, blocks + 1)
    means = []
    for a, b in zip(edges[:-1], edges[1:]):
        m = (t >= a) & (t < b)
        if m.any():
            means.append(x[m].mean())
    means = np.array(means)
    if len(means) < 2:
        return math.nan, math.nan, means
    return means.mean(), means.std(ddof=1) / math.sqrt(len(means)), means


def approach(run, window, block, z, tolerance):

    cfg_j = rundir.Run(run).config["flow"]["J"]
    with rundir.Run(run).open("trajectory") as f:
        o = f["observables"]
        # Time is in eta / P; strain = gammadot t = J t in these units (docs/units.md).
        t = o["H/time"][:] * cfg_j
        series = {n: o[n + "/value"][:] for n in
                  ("H", "phi", "mu_top", "mu_bottom", "net_drag_y", "bulk_normal_load")}
    n = min(len(t), *(len(v) for v in series.values()))
    t = t[:n]
    series = {k: v[:n] for k, v in series.items()}
    blocks = max(4, int(window / block))
    print(f"{run}: J = {cfg_j:g}, windows of {window:g} strain, {blocks} blocks each, z = {z:g}")
    print(" from   to     phi      H      net_drag_y        mu_t-mu_b       H change       bulk load  verdict")
    lo = 0.0
    while lo + window <= t[-1] + 1e-9:
        hi = lo + window
        failed = []
        drag, drag_e, _ = block_stats(series["net_drag_y"], t, lo, hi, blocks)
        dmu, dmu_e, _ = block_stats(series["mu_top"] - series["mu_bottom"], t, lo, hi, blocks)
        _, _, hb = block_stats(series["H"], t, lo, hi, blocks)
        mid = lo + (np.arange(len(hb)) + 0.5) * (window / blocks)
        hchange, hchange_e = window_line(mid, hb, window)
        load, load_e, _ = block_stats(series["bulk_normal_load"], t, lo, hi, blocks)
        if abs(drag) > z * drag_e:
            failed.append("net_drag_y")
        if abs(dmu) > z * dmu_e:
            failed.append("mu_top_minus_bottom")
        if abs(hchange) > z * hchange_e:
            failed.append("H_change")
        if abs(load - 1.0) > tolerance:
            failed.append("bulk_normal_load")
        m = (t >= lo) & (t < hi)
        print(f"{lo:5.1f} {hi:5.1f}  {series['phi'][m].mean():.4f} {series['H'][m].mean():6.2f}"
              f"  {drag:+.3f} +- {drag_e:.3f}  {dmu:+.3f} +- {dmu_e:.3f}"
              f"  {hchange:+.2f} +- {hchange_e:.2f}  {load:.3f} +- {load_e:.3f}  "
              + ("stationary" if not failed else "DRIFTING: " + ", ".join(failed)))
        lo = hi


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="what", required=True)
    s = sub.add_parser("store")
    s.add_argument("results", nargs="+")
    s.add_argument("--markdown", action="store_true")
    b = sub.add_parser("blocks")
    b.add_argument("runs", nargs="+")
    b.add_argument("--sliding", type=int, default=None)
    b.add_argument("--z", type=float, default=3.0)
    b.add_argument("--blocking", action="store_true")
    a = sub.add_parser("approach")
    a.add_argument("run")
    a.add_argument("--window", type=float, default=10.0)
    a.add_argument("--block", type=float, default=1.0)
    a.add_argument("--z", type=float, default=3.0)
    a.add_argument("--tolerance", type=float, default=0.05)
    args = ap.parse_args()
    if args.what == "store":
        if args.markdown:
            markdown(args.results)
        else:
            for path in args.results:
                store(path)
    elif args.what == "blocks":
        if args.sliding is not None and args.sliding < 3:
            sys.exit("stationarity_check.py blocks: --sliding must be >= 3 (a line and its error)")
        if not args.z > 0:
            sys.exit("stationarity_check.py blocks: --z must be > 0")
        blocks(args.runs, args.sliding, args.z, args.blocking)
    else:
        if not (args.window > 0 and args.block > 0 and args.z > 0 and args.tolerance > 0):
            sys.exit("stationarity_check.py: --window, --block, --z and --tolerance must be > 0")
        approach(args.run, args.window, args.block, args.z, args.tolerance)


if __name__ == "__main__":
    main()
