#!/usr/bin/python3
"""Plot one run: time series against strain from RUN/trajectory.h5 (any run, finished or not)
and, where RUN/analysis.h5 exists, the diffusion analysis.

    /usr/bin/python3 tools/plot_run.py RUN_DIR [--out RUN_DIR/timeseries.png]

timeseries.png: the friction coefficient mu, the solid fraction phi (area for discs, volume for
spheres), the gap H and the pressure on the top wall (pressure cell; a simple-shear run has the
particle pressure and no H) against
strain, a running mean over about one strain, the measured window shaded (pressure cell: from
summary.json's steady_detected_at, where the run's measurement starts; simple shear: after
run.transient_strain) and the window's mean +- error in each panel. These are the run's own
numbers: a finished pressure-cell run's means and error bars are summary.json's (phi, phi_err,
mu, mu_err, H, H_err, pressure_measured); otherwise the means are of the frames in the window
and the errors batch means over time blocks of analysis.error_block strain (at least 4 blocks),
as the run computes them, never the spread of correlated frames. --print writes them as text.
analysis.png (only with analysis.h5): the MSD in the gradient direction with the fit window and
the line 2 D t + c, and the velocity autocorrelation C(tau)/C(0) with the persistence time Psi.
"""
import argparse
import pathlib
import sys

import rundir  # tools/rundir.py: what every tool reads of a run

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy import ndimage, stats  # noqa: E402


def load_series(traj):
    with rundir.open_h5(traj) as f:
        obs = f["observables"]
        return {k: obs[k]["value"][()] for k in obs if "value" in obs[k]}


def panels(series, pressure_cell, phi_fixed):
    """(label, values) for the panels this run has."""
    out = []
    if pressure_cell:
        out.append((r"$\mu$", 0.5 * (series["mu_top"] + series["mu_bottom"])))
        out.append((r"$\phi$", series["phi"]))
        out.append((r"$H / d$", series["H"]))
        out.append((r"wall pressure / $P$", series["pressure_measured"]))
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            out.append((r"$\mu = \sigma_{xy} / \Pi$", series["shear_stress"] / series["pressure"]))
        if phi_fixed is not None:
            out.append((r"$\phi$ (fixed)", np.full_like(series["strain"], phi_fixed)))
        out.append((r"particle pressure $\Pi / P$", series["pressure"]))
    return out


def batch_means_error(t, x, t_from, t_to, block):
    """The run's error bar of a window's mean (src/analysis/uncertainty.cpp): blocks of `block`
    strain, at least 4, each frame in the block of its time; the standard error of the block means."""
    blocks = max(4, int((t_to - t_from) / block))
    width = (t_to - t_from) / blocks
    sel = (t >= t_from) & (t <= t_to) & np.isfinite(x)
    if not (t_to > t_from) or sel.sum() < 8:
        return float("nan")
    idx = np.minimum(blocks - 1, ((t[sel] - t_from) / width).astype(int))
    means = [x[sel][idx == b].mean() for b in range(blocks) if np.any(idx == b)]
    if len(means) < 2:
        return float("nan")
    return float(np.std(means, ddof=1) / np.sqrt(len(means)))


# A finished pressure-cell run's own numbers for each panel: (summary key, its error key).
SUMMARY_KEYS = {r"$\mu$": ("mu", "mu_err"), r"$\phi$": ("phi", "phi_err"), r"$H / d$": ("H", "H_err"),
                r"wall pressure / $P$": ("pressure_measured", None)}


def window_numbers(strain, rows, window, summary, block, pressure_cell):
    """Each panel's (mean, error, source) over the measured window."""
    out = {}
    for label, y in rows:
        if label.endswith("(fixed)"):
            continue  # a set value, not a measurement
        keys = SUMMARY_KEYS.get(label) if pressure_cell and summary.get("steady") else None
        if keys and keys[0] in summary:
            err = summary.get(keys[1]) if keys[1] else None
            out[label] = (summary[keys[0]], float("nan") if err is None else err, "summary.json")
            continue
        sel = (strain >= window[0]) & (strain <= window[1]) & np.isfinite(y)
        if sel.sum() >= 2:
            out[label] = (float(np.mean(y[sel])), batch_means_error(strain, y, window[0], window[1], block),
                          "frames, time blocks")
    return out


def plot_timeseries(run, out, print_numbers=False):
    r = rundir.Run(run)
    traj = r.file("trajectory")
    cfg, summary = r.config, r.summary
    series = load_series(traj)
    if "strain" not in series or len(series["strain"]) == 0:
        sys.exit(f"plot_run: {traj} holds no frames yet")
    strain = series["strain"]
    pressure_cell = "mu_top" in series
    window = None
    if pressure_cell and summary.get("steady"):
        window = (summary["steady_detected_at"], strain[-1])
    elif not pressure_cell:
        window = (cfg.get("run", {}).get("transient_strain", 0.0), strain[-1])
    block = cfg.get("analysis", {}).get("error_block", 3.0)
    rows = panels(series, pressure_cell, summary.get("phi"))
    numbers = window_numbers(strain, rows, window, summary, block, pressure_cell) if window else {}
    fig, axes = plt.subplots(len(rows), 1, figsize=(7, 2.1 * len(rows)), sharex=True)
    # A running mean over about one strain shows the drift through the fluctuations.
    width = max(1, int(round(1.0 / max(np.median(np.diff(strain)), 1e-12)))) if len(strain) > 1 else 1
    for ax, (label, y) in zip(np.atleast_1d(axes), rows):
        ax.plot(strain, y, "-", color="0.55", lw=0.8, label="frames")
        if width > 1 and len(y) > width:
            ax.plot(strain, ndimage.uniform_filter1d(y, width, mode="nearest"), "-", color="C0", lw=1.5,
                    label="running mean (1 strain)")
        if window is not None:
            ax.axvspan(*window, color="C2", alpha=0.12, lw=0)
        if label in numbers:
            m, e, source = numbers[label]
            err = f" $\\pm$ {e:.2g}" if np.isfinite(e) else ""
            ax.axhline(m, color="C2", lw=1, ls="--", label=f"measured: {m:.4g}{err} ({source})")
        if not label.endswith("(fixed)"):
            ax.legend(loc="best", fontsize=7, frameon=False)
        ax.set_ylabel(label)
        ax.ticklabel_format(axis="y", useOffset=False)
        finite = y[np.isfinite(y)]
        if finite.size and np.ptp(finite) <= 1e-6 * max(abs(finite.mean()), 1e-12):
            ax.set_ylim(finite.mean() * 0.99, finite.mean() * 1.01)  # held to round-off
    np.atleast_1d(axes)[-1].set_xlabel(r"strain $\dot\gamma t$")
    scene = "pressure cell" if pressure_cell else "simple shear"
    title = f"{run.name}: {scene}, J = {cfg.get('flow', {}).get('J', float('nan')):g}, N = {cfg.get('particles', {}).get('N', '?')}"
    if pressure_cell and not summary.get("steady"):
        title += " (no steady state" + (" yet)" if not summary else ")")
    np.atleast_1d(axes)[0].set_title(title)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    print(out)
    if print_numbers:
        for label, (m, e, source) in numbers.items():
            name = label.replace("$", "").replace("\\", "")
            print(f"{name}: {m:.10g} +- {e:.10g} ({source})")


def plot_analysis(run, out):
    summary = rundir.Run(run).summary
    with rundir.Run(run).open("analysis") as f:
        lag, msd = f["msd/lag"][()], f["msd/msd"][()]
        tau, c = f["vacf/lag"][()], f["vacf/c"][()]
        d, intercept = f.attrs["D"], f.attrs["msd_intercept"]
        lo, hi = f.attrs["msd_window_lo"], f.attrs["msd_window_hi"]
        psi = f.attrs["psi"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ok = lag > 0
    ax1.loglog(lag[ok], msd[ok], "-", label="MSD")
    t = np.linspace(lo, hi, 50)
    d_err = summary.get("D_err")
    err = f" $\\pm$ {d_err:.2g}" if isinstance(d_err, (int, float)) else ""
    ax1.loglog(t, 2 * d * t + intercept, "k--", label=f"fit: D = {d:.3g}{err} $\\dot\\gamma d^2$")
    ax1.axvspan(lo, hi, color="0.9")
    ax1.set_xlabel(r"strain $\dot\gamma t$")
    ax1.set_ylabel(r"$\Delta_y^2 / d^2$")
    ax1.set_title(f"J = {summary['J']:g}, N = {summary['N']}, ktilde = {summary['ktilde']:g}")
    # The run's own warning about the fit (summary.json): a D from a window that is not yet
    # diffusive is not a diffusion coefficient.
    warn = [w for w in summary.get("analysis_warnings", []) if "not diffusive" in w]
    if warn:
        ax1.text(0.02, 0.98, "warning: " + warn[0], transform=ax1.transAxes, va="top", fontsize=6,
                 color="C3", wrap=True)
    ax1.legend(loc="lower right")
    ax2.plot(tau, c / c[0], "-")
    ax2.axhline(0, color="0.6", lw=0.5)
    ax2.axhline(np.exp(-1), color="0.6", lw=0.5, ls=":")
    ax2.axvline(psi, color="k", ls="--", label=fr"$\Psi\dot\gamma$ = {psi:.3g}")
    ax2.set_xlim(0, min(tau[-1], 10 * psi))
    ax2.set_xlabel(r"lag $\dot\gamma \tau$")
    ax2.set_ylabel(r"$C(\tau)/C(0)$")
    ax2.set_title(f"dv = {summary['dv']:.3g} $\\dot\\gamma d$")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    print(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path)
    ap.add_argument("--out", type=pathlib.Path, help="time-series PNG (default RUN/timeseries.png)")
    ap.add_argument("--print", action="store_true", help="also print each panel's mean +- error and its source")
    args = ap.parse_args()
    run = rundir.Run(args.run)
    if not run.has("trajectory"):
        sys.exit(f"plot_run: no trajectory at {run.file('trajectory')} (run with output.trajectory = true)")
    try:
        plot_timeseries(args.run, args.out or args.run / "timeseries.png", args.print)
        if run.has("analysis") and run.finished:
            plot_analysis(args.run, args.run / "analysis.png")
    except (OSError, KeyError) as e:
        sys.exit(f"plot_run: {args.run}: cannot read the run ({type(e).__name__}: {e})")


if __name__ == "__main__":
    main()
