#!/usr/bin/python3
"""Plot the diffusion analysis of one run: MSD in the gradient direction against strain (with
the fit window and the fitted line 2 D t + c) and the velocity autocorrelation C(tau)/C(0) (with
the persistence time Psi), from RUN/analysis.h5 and RUN/summary.json.

    /usr/bin/python3 tools/plot_run.py RUN_DIR [--out RUN_DIR/analysis.png]
"""
import argparse
import json
import pathlib

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path)
    ap.add_argument("--out", type=pathlib.Path)
    args = ap.parse_args()
    summary = json.loads((args.run / "summary.json").read_text())
    with h5py.File(args.run / "analysis.h5", "r") as f:
        lag, msd = f["msd/lag"][()], f["msd/msd"][()]
        tau, c = f["vacf/lag"][()], f["vacf/c"][()]
        d, intercept = f.attrs["D"], f.attrs["msd_intercept"]
        lo, hi = f.attrs["msd_window_lo"], f.attrs["msd_window_hi"]
        psi = f.attrs["psi"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ok = lag > 0
    ax1.loglog(lag[ok], msd[ok], "-", label="MSD")
    t = np.linspace(lo, hi, 50)
    ax1.loglog(t, 2 * d * t + intercept, "k--", label=f"fit: D = {d:.3g} $\\dot\\gamma d^2$")
    ax1.axvspan(lo, hi, color="0.9")
    ax1.set_xlabel(r"strain $\dot\gamma t$")
    ax1.set_ylabel(r"$\Delta_y^2 / d^2$")
    ax1.set_title(f"J = {summary['J']:g}, N = {summary['N']}, ktilde = {summary['ktilde']:g}")
    ax1.legend()
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
    out = args.out or args.run / "analysis.png"
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
