#!/usr/bin/python3
"""Draw the seed paper's panels from a finished sweep (DIR/sweep.csv, DIR/fits.json and each
point's analysis.h5), one series per ktilde (and N), the seed's power law drawn dashed:

  (a) MSD in the gradient direction against strain, all J     (seed fig. 1c)
  (b) the same against t / Psi                                (seed fig. 1c inset)
  (c) D / (gammadot d^2) against J                            (seed fig. 1d)
  (d) phi against J                                           (seed fig. 2a)
  (e) phi_c - phi against J, with the fitted law              (seed fig. 2a inset)
  (f) D against phi_c - phi                                   (seed fig. 2b)
  (g) dv / (gammadot d) and Psi gammadot against J            (seed fig. 3a)
  (h) mu against J

    /usr/bin/python3 tools/plot_sweep.py SWEEP_DIR [--out SWEEP_DIR/sweep.png]
"""
import argparse
import csv
import json
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

try:
    import h5py
except ImportError:  # the MSD panels need it; the others do not
    h5py = None

SEED = {  # seed Table 1 (suspensions) and eq. (3.3)
    "D": (0.024, -0.26), "dv": (0.258, -0.25), "psi": (0.35, 0.24),
    "D_phi": (0.019, -0.61), "phi_c": 0.81, "phi_a": 0.64, "phi_b": 0.5,
}


def series_label(axes):
    return ", ".join(f"{k.split('.')[-1]} = {v:g}" if isinstance(v, (int, float)) else f"{k}={v}"
                     for k, v in axes.items()) or "all points"


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sweep", type=pathlib.Path)
    ap.add_argument("--out", type=pathlib.Path)
    args = ap.parse_args()
    fits = json.loads((args.sweep / "fits.json").read_text())
    rows = [r for r in csv.DictReader(open(args.sweep / "sweep.csv")) if r["status"] == "done"]

    fig, ax = plt.subplots(2, 4, figsize=(18, 8.5))
    ax = ax.ravel()
    jgrid = np.logspace(-4.2, 0, 50)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = "osD^v<>"

    # (a), (b): MSD curves of every finished point, coloured by J.
    if h5py is not None:
        js = sorted({float(r["J"]) for r in rows})
        cmap = plt.get_cmap("viridis")
        for r in rows:
            f = args.sweep / "points" / r["point"] / "analysis.h5"
            if not f.exists():
                continue
            with h5py.File(f, "r") as h:
                lag, msd = h["msd/lag"][()], h["msd/msd"][()]
            ok = lag > 0
            c = cmap(js.index(float(r["J"])) / max(len(js) - 1, 1))
            ax[0].loglog(lag[ok], msd[ok], color=c, lw=1)
            psi = float(r["psi"]) if r.get("psi") else math.nan
            if psi > 0:
                ax[1].loglog(lag[ok] / psi, msd[ok], color=c, lw=1)
        sm = plt.cm.ScalarMappable(cmap=cmap, norm=matplotlib.colors.LogNorm(min(js), max(js)))
        fig.colorbar(sm, ax=ax[1], label="J")
    ax[0].set(xlabel=r"strain $\dot\gamma t$", ylabel=r"$\langle\Delta y^2\rangle / d^2$",
              title="(a) MSD, gradient direction")
    ax[1].set(xlabel=r"$t / \Psi$", ylabel=r"$\langle\Delta y^2\rangle / d^2$",
              title="(b) MSD against t / Psi")

    for gi, g in enumerate(fits["groups"]):
        c, m = colours[gi % len(colours)], markers[gi % len(markers)]
        lab = series_label(g["axes"])
        rr = sorted(g["rows"], key=lambda r: r["J"])
        J = np.array([r["J"] for r in rr])
        get = lambda k: np.array([r.get(k) if r.get(k) is not None else np.nan for r in rr])  # noqa
        f = g["fits"]
        ax[2].loglog(J, get("D"), m, color=c, label=lab)
        if "a" in f["D_vs_J"]:
            ax[2].loglog(jgrid, f["D_vs_J"]["a"] * jgrid ** f["D_vs_J"]["b"], "-", color=c, lw=0.8,
                         label=f"fit: {f['D_vs_J']['a']:.3g} J^{f['D_vs_J']['b']:.2f}")
        ax[3].semilogx(J, get("phi"), m, color=c, label=lab)
        pf = f["phi_of_J"]
        if "phi_c" in pf:
            ax[3].semilogx(jgrid, pf["phi_c"] - pf["a"] * jgrid ** pf["b"], "-", color=c, lw=0.8,
                           label=f"fit: {pf['phi_c']:.3f} - {pf['a']:.2f} J^{pf['b']:.2f}")
            x = pf["phi_c"] - get("phi")
            ax[4].loglog(J, x, m, color=c, label=lab)
            ax[4].loglog(jgrid, pf["a"] * jgrid ** pf["b"], "-", color=c, lw=0.8)
            ax[5].loglog(x, get("D"), m, color=c, label=lab)
            if "a" in f["D_vs_phic_minus_phi"]:
                xs = np.logspace(-3, 0, 40)
                fd = f["D_vs_phic_minus_phi"]
                ax[5].loglog(xs, fd["a"] * xs ** fd["b"], "-", color=c, lw=0.8,
                             label=f"fit: {fd['a']:.3g} x^{fd['b']:.2f}")
        ax[6].loglog(J, get("dv"), m, color=c, label=f"dv, {lab}")
        ax[6].loglog(J, get("psi"), m, color=c, mfc="none", label=f"Psi, {lab}")
        ax[7].semilogx(J, get("mu"), m, color=c, label=lab)

    a, b = SEED["D"]
    ax[2].loglog(jgrid, a * jgrid ** b, "k--", label=f"seed: {a} J^{b}")
    ax[3].semilogx(jgrid, SEED["phi_c"] - SEED["phi_a"] * jgrid ** SEED["phi_b"], "k--",
                   label="seed: 0.81 - 0.64 J^0.5")
    ax[4].loglog(jgrid, SEED["phi_a"] * jgrid ** SEED["phi_b"], "k--", label="seed: 0.64 J^0.5")
    xs = np.logspace(-3, 0, 40)
    ax[5].loglog(xs, SEED["D_phi"][0] * xs ** SEED["D_phi"][1], "k--", label="seed: 0.019 x^-0.61")
    for k, style in (("dv", "k--"), ("psi", "k:")):
        a, b = SEED[k]
        ax[6].loglog(jgrid, a * jgrid ** b, style, label=f"seed {k}: {a} J^{b}")
    ax[2].set(xlabel="J", ylabel=r"$D / \dot\gamma d^2$", title="(c) diffusion coefficient")
    ax[3].set(xlabel="J", ylabel=r"$\phi$", title="(d) dilatancy")
    ax[4].set(xlabel="J", ylabel=r"$\phi_c - \phi$", title=r"(e) $\phi_c - \phi$ (fitted $\phi_c$)")
    ax[5].set(xlabel=r"$\phi_c - \phi$", ylabel=r"$D / \dot\gamma d^2$", title="(f) D against distance to jamming")
    ax[6].set(xlabel="J", ylabel=r"$\delta v/\dot\gamma d$ (filled), $\Psi\dot\gamma$ (open)",
              title="(g) fluctuations and persistence")
    ax[7].set(xlabel="J", ylabel=r"$\mu = \tau / P$", title="(h) effective friction")
    for a_ in ax[2:]:
        a_.legend(fontsize=7)
    fig.suptitle(f"{args.sweep}: {fits['finished']}/{fits['points']} points")
    fig.tight_layout()
    out = args.out or args.sweep / "sweep.png"
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
