#!/usr/bin/python3
"""Draw the seed paper's figures 1c/d, 2a/b and 3a/b/c from a sweep, with error bars, from its
fits.json, sweep.csv and each point's analysis.h5 alone (a sweep folder, or the committed store
results/<name>/ that `sheardiff sweep ... --collect` writes). One series per group (ktilde, N,
...); error bars are the standard error of the mean over seeds (the seeds' scatter; where a J has
one seed, the run's own error bar, drawn with open caps); fits are drawn over the measured range
only; the seed's laws dashed black.

  (a) MSD in the gradient direction against strain, fit window shaded   (seed fig. 1c)
  (b) the same against t / Psi                                          (fig. 1c inset)
  (c) D / (gammadot d^2) against J                                      (fig. 1d)
  (d) phi against J, with phi_c - phi against J inset                  (fig. 2a)
  (e) D against phi_c - phi                                             (fig. 2b)
  (f) dv / (gammadot d) and Psi gammadot against J                      (fig. 3a)
  (g) the same against phi_c - phi                                      (fig. 3b)
  (h) step length dv Psi / d against phi_c - phi                        (fig. 3c)
  (i) mu against J with mu_c + a J^b
  (j) D / (dv^2 Psi) for each Psi definition: which one makes D = dv^2 Psi hold

A sweep of spheres (sweep.csv's dimension = 3) draws Boyer, Guazzelli & Pouliquen's (2011) fits
in (d) and (i), the 3D experiments' phi(J) and mu(J); the seed's laws stay in the other panels
as the 2D reference ("2D seed"). --discs STORE draws a discs' fitted store (its fits.json: the
per-J means over seeds, e.g. results/table1_n1000) in grey in (c), (f) and (i), so that the
spheres' D, dv, Psi and mu stand beside this code's discs, not only beside the seed's laws.

    /usr/bin/python3 tools/plot_sweep.py DIR [--out DIR/sweep.png] [--discs STORE]
"""
import argparse
import json
import math
import pathlib
import sys

import rundir  # tools/rundir.py: what every tool reads of a run

SEED = {  # seed Table 1 (suspensions) and eq. (3.3)
    "D": (0.024, -0.26), "dv": (0.258, -0.25), "psi": (0.35, 0.24),
    "D_phi": (0.019, -0.61), "dv_phi": (0.25, -0.54), "psi_phi": (0.37, 0.51),
    "phi_c": 0.81, "phi_a": 0.64, "phi_b": 0.5, "step": 0.09,
}
# Boyer, Guazzelli & Pouliquen, Phys. Rev. Lett. 107, 188301 (2011): pressure-imposed shear of
# spheres, phi = phi_m / (1 + J^1/2), mu = mu_1 + (mu_2 - mu_1) / (1 + J_0 / J) + J + 5/2 phi_m J^1/2.
BOYER = {"phi_m": 0.585, "mu_1": 0.32, "mu_2": 0.7, "J_0": 0.005}
# Densest packings: the hexagonal one of discs, the face-centred cubic one of spheres. A fitted
# phi_c above them is unphysical.
CLOSE_PACKING = {2: 0.9069, 3: 0.7405}


def boyer_phi(j):
    return BOYER["phi_m"] / (1.0 + j ** 0.5)


def boyer_mu(j):
    b = BOYER
    return b["mu_1"] + (b["mu_2"] - b["mu_1"]) / (1.0 + b["J_0"] / j) + j + 2.5 * b["phi_m"] * j ** 0.5


def series_label(axes):
    return ", ".join(f"{k.split('.')[-1]} = {v:g}" if isinstance(v, (int, float)) else f"{k}={v}"
                     for k, v in axes.items()) or "all points"


def column(rows, k):
    """A fits.json group's rows' values of k as floats, NaN where absent."""
    import numpy as np
    return np.array([r.get(k) if r.get(k) is not None else np.nan for r in rows], float)


def num(r, k):
    v = r.get(k)
    try:
        return float(v) if v not in (None, "") else math.nan
    except (TypeError, ValueError):
        return math.nan


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sweep", type=pathlib.Path)
    ap.add_argument("--out", type=pathlib.Path)
    ap.add_argument("--discs", type=pathlib.Path,
                    help="a discs' store with fits.json, drawn in grey in (c), (f) and (i)")
    args = ap.parse_args()
    if args.discs is not None and not (args.discs / "fits.json").exists():
        sys.exit(f"--discs {args.discs}: no fits.json (a store that `sheardiff fit` wrote)")
    for f in ("fits.json", "sweep.csv"):
        if not (args.sweep / f).exists():
            sys.exit(f"{args.sweep}: no {f} (run `sheardiff sweep SWEEP.toml --out DIR --collect` "
                     f"first)")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    try:
        import h5py
    except ImportError:
        h5py = None
        print("warning: no h5py: the MSD panels are left empty", file=sys.stderr)

    fits = json.loads((args.sweep / "fits.json").read_text())
    store = rundir.Store(args.sweep)
    rows = store.fitted_rows()
    dims = {int(num(r, "dimension")) for r in store.rows(done=True)
            if math.isfinite(num(r, "dimension"))}
    if len(dims) > 1:
        sys.exit(f"{args.sweep}: discs and spheres in one table; plot them apart")
    dim = dims.pop() if dims else 2
    ref = "seed" if dim == 2 else "2D seed"
    fig, ax = plt.subplots(3, 4, figsize=(19, 13))
    ax = ax.ravel()
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = "osD^v<>"

    # (a), (b): every finished point's MSD, coloured by J.
    js = sorted({num(r, "J") for r in rows})
    cmap = plt.get_cmap("viridis")
    window = None
    if h5py is not None and js:
        for r in rows:
            # A fit over several stores (`sheardiff fit`) names each point's store.
            base = args.sweep / r["store"] if r.get("store") else args.sweep
            f = base / "points" / r["point"].split("/")[-1] / "analysis.h5"
            if not f.exists():
                continue
            with rundir.open_h5(f) as h:
                lag, msd = h["msd/lag"][()], h["msd/msd"][()]
                window = (h.attrs.get("msd_window_lo"), h.attrs.get("msd_window_hi"))
            ok = lag > 0
            c = cmap(js.index(num(r, "J")) / max(len(js) - 1, 1))
            ax[0].loglog(lag[ok], msd[ok], color=c, lw=0.8)
            psi = num(r, "psi")
            if psi > 0:
                ax[1].loglog(lag[ok] / psi, msd[ok], color=c, lw=0.8)
        sm = plt.cm.ScalarMappable(cmap=cmap, norm=matplotlib.colors.LogNorm(min(js), max(js)))
        fig.colorbar(sm, ax=ax[0], label="J")
        if window and window[0] is not None:
            ax[0].axvspan(window[0], window[1], color="0.9", zorder=0, label="fit window")
            ax[0].legend(fontsize=7)
    ax[0].set(xlabel=r"strain $\dot\gamma t$", ylabel=r"$\langle\Delta y^2\rangle / d^2$",
              title="(a) MSD, gradient direction (fig. 1c)")
    ax[1].set(xlabel=r"$t / \Psi$", ylabel=r"$\langle\Delta y^2\rangle / d^2$",
              title="(b) MSD against t / Psi (fig. 1c inset)")
    # Lower left: phi falls with J, so that corner stays clear of the points (upper right hid
    # J = 1e-2); the legend goes to the upper right.
    inset = ax[3].inset_axes([0.24, 0.17, 0.34, 0.34])

    def errbar(a, x, y, e, e_open, c, m, label):
        """Seed-scatter error bars filled; run-own error bars (one seed) open."""
        has_sem = ~np.isnan(e)
        if has_sem.any():
            a.errorbar(x[has_sem], y[has_sem], yerr=e[has_sem], fmt=m, color=c, ms=5, capsize=3,
                       label=label)
        if (~has_sem).any():
            a.errorbar(x[~has_sem], y[~has_sem], yerr=e_open[~has_sem], fmt=m, color=c, mfc="none",
                       ms=5, capsize=2, label=None if has_sem.any() else label)

    def line(a, xs, f, c, fmt_label):
        if "a" not in f:
            return
        x = np.logspace(np.log10(np.nanmin(xs)), np.log10(np.nanmax(xs)), 40)
        a.loglog(x, f["a"] * x ** f["b"], "-", color=c, lw=0.9, label=fmt_label.format(**f))

    for gi, g in enumerate(fits["groups"]):
        c, m = colours[gi % len(colours)], markers[gi % len(markers)]
        lab = series_label(g["axes"])
        rr = sorted(g["rows"], key=lambda r: r["J"])
        J = np.array([r["J"] for r in rr])

        def get(k):
            return column(rr, k)

        f = g["fits"]
        errbar(ax[2], J, get("D"), get("D_sem"), get("D_run_err"), c, m, lab)
        line(ax[2], J, f["D_vs_J"], c, "fit: {a:.3g} J^{b:.2f}")
        errbar(ax[3], J, get("phi"), get("phi_sem"), get("phi_run_err"), c, m, lab)
        pf = f["phi_of_J"]
        x = None
        if "phi_c" in pf:
            if pf["phi_c"] > CLOSE_PACKING[dim]:
                print(f"warning: {lab}: fitted phi_c = {pf['phi_c']:.3f} is above the {dim}D "
                      f"close packing {CLOSE_PACKING[dim]}: the dilatancy fit is unphysical",
                      file=sys.stderr)
            jj = np.logspace(np.log10(J.min()), np.log10(J.max()), 40)
            ax[3].semilogx(jj, pf["phi_c"] - pf["a"] * jj ** pf["b"], "-", color=c, lw=0.9,
                           label=f"fit: {pf['phi_c']:.3f} - {pf['a']:.2f} J^{pf['b']:.2f}")
            x = pf["phi_c"] - get("phi")
            inset.loglog(J, x, m, color=c, ms=4)
            inset.loglog(jj, pf["a"] * jj ** pf["b"], "-", color=c, lw=0.8)
            errbar(ax[4], x, get("D"), get("D_sem"), get("D_run_err"), c, m, lab)
            line(ax[4], x, f["D_vs_phic_minus_phi"], c, "fit: {a:.3g} x^{b:.2f}")
        errbar(ax[5], J, get("dv"), get("dv_sem"), get("dv_run_err"), c, m, f"dv, {lab}")
        line(ax[5], J, f["dv_vs_J"], c, "{a:.3g} J^{b:.2f}")
        errbar(ax[5], J, get("psi"), get("psi_sem"), get("psi_run_err"), c, "^", f"Psi, {lab}")
        line(ax[5], J, f["psi_vs_J"], c, "{a:.3g} J^{b:.2f}")
        if x is not None:
            errbar(ax[6], x, get("dv"), get("dv_sem"), get("dv_run_err"), c, m, f"dv, {lab}")
            errbar(ax[6], x, get("psi"), get("psi_sem"), get("psi_run_err"), c, "^", f"Psi, {lab}")
            line(ax[6], x, f["dv_vs_phic_minus_phi"], c, "{a:.3g} x^{b:.2f}")
            line(ax[6], x, f["psi_vs_phic_minus_phi"], c, "{a:.3g} x^{b:.2f}")
        errbar(ax[8], J, get("mu"), get("mu_sem"), get("mu_run_err"), c, m, lab)
        mf = f["mu_of_J"]
        if "mu_c" in mf:
            jj = np.logspace(np.log10(J.min()), np.log10(J.max()), 40)
            ax[8].semilogx(jj, mf["mu_c"] + mf["a"] * jj ** mf["b"], "-", color=c, lw=0.9,
                           label=f"fit: {mf['mu_c']:.3f} + {mf['a']:.2f} J^{mf['b']:.2f}")

    if args.discs is not None:
        discs = json.loads((args.discs / "fits.json").read_text())
        grey, drawn = "0.55", 0
        for g in discs["groups"]:
            rr = sorted(g["rows"], key=lambda r: r["J"])
            J = np.array([r["J"] for r in rr])

            def dget(k):
                return column(rr, k)

            lab = f"discs ({args.discs.name})"
            errbar(ax[2], J, dget("D"), dget("D_sem"), dget("D_run_err"), grey, "s", lab)
            errbar(ax[5], J, dget("dv"), dget("dv_sem"), dget("dv_run_err"), grey, "s", f"dv, {lab}")
            errbar(ax[5], J, dget("psi"), dget("psi_sem"), dget("psi_run_err"), grey, "v",
                   f"Psi, {lab}")
            errbar(ax[8], J, dget("mu"), dget("mu_sem"), dget("mu_run_err"), grey, "s", lab)
            drawn += len(J)
        print(f"--discs: {drawn} J of {args.discs} drawn in (c), (f) and (i)")

    # Per-point panels from sweep.csv: step length and the Psi definitions.
    pts = {}
    for r in rows:
        pts.setdefault(num(r, "J"), []).append(r)
    phic = next((g["fits"]["phi_of_J"].get("phi_c") for g in fits["groups"]), None)
    for k, (key, style, lab) in enumerate((("psi", "o", "integral to first zero (psi)"),
                                           ("psi_e", "s", "1/e time (psi_e)"),
                                           ("psi_full", "D", "full integral (psi_full)"),
                                           ("psi_zero", "v", "first zero crossing (psi_zero)"))):
        xs, ys = [], []
        for j, rs in pts.items():
            for r in rs:
                v = num(r, "D") / (num(r, "dv") ** 2 * num(r, key))
                if math.isfinite(v):
                    xs.append(j), ys.append(v)
        if xs:
            ax[9].semilogx(xs, ys, style, mfc="none", color=colours[k], label=lab)
    if phic is not None:
        for j, rs in pts.items():
            for r in rs:
                ax[7].loglog(phic - num(r, "phi"), num(r, "dv") * num(r, "psi"), "o",
                             color=colours[0], mfc="none", ms=5)
    ax[9].axhline(1.0, color="k", lw=0.8)
    if phic is None:
        # Without a fitted phi_c the points have no abscissa here: say why the panel is empty.
        why = next((g["fits"]["phi_of_J"].get("error") for g in fits["groups"]), None)
        for a_ in (ax[4], ax[6], ax[7]):
            a_.text(0.5, 0.5, "no points: phi_c not fitted\n" + (why or ""), ha="center",
                    va="center", fontsize=7, transform=a_.transAxes, wrap=True)

    jg = np.logspace(-4, -1, 40)
    a, b = SEED["D"]
    ax[2].loglog(jg, a * jg ** b, "k--", label=f"{ref}: {a} J^{b}")
    if dim == 2:
        ax[3].semilogx(jg, SEED["phi_c"] - SEED["phi_a"] * jg ** SEED["phi_b"], "k--",
                       label="seed: 0.81 - 0.64 J^0.5")
        inset.loglog(jg, SEED["phi_a"] * jg ** SEED["phi_b"], "k--")
    else:
        ax[3].semilogx(jg, boyer_phi(jg), "k--", label="Boyer et al. 2011: 0.585 / (1 + J^0.5)")
        inset.loglog(jg, BOYER["phi_m"] - boyer_phi(jg), "k--")
        ax[8].semilogx(jg, boyer_mu(jg), "k--", label="Boyer et al. 2011")
    inset.set(xlabel="J", ylabel=r"$\phi_c-\phi$")
    xg = np.logspace(np.log10(0.02), np.log10(0.25), 40)
    ax[4].loglog(xg, SEED["D_phi"][0] * xg ** SEED["D_phi"][1], "k--",
                 label=f"{ref}: 0.019 x^-0.61")
    for key, style in (("dv", "k--"), ("psi", "k:")):
        a, b = SEED[key]
        ax[5].loglog(jg, a * jg ** b, style, label=f"{ref} {key}: {a} J^{b}")
        a, b = SEED[key + "_phi"]
        ax[6].loglog(xg, a * xg ** b, style, label=f"{ref} {key}: {a} x^{b}")
    ax[7].axhline(SEED["step"], color="k", ls="--", label=f"{ref}: 0.09 d")
    ax[2].set(xlabel="J", ylabel=r"$D / \dot\gamma d^2$", title="(c) diffusion coefficient (fig. 1d)")
    ax[3].set(xlabel="J", ylabel=r"$\phi$", title="(d) dilatancy (fig. 2a)")
    ax[4].set(xlabel=r"$\phi_c - \phi$", ylabel=r"$D / \dot\gamma d^2$", title="(e) D against distance to jamming (fig. 2b)")
    ax[5].set(xlabel="J", ylabel=r"$\delta v/\dot\gamma d$, $\Psi\dot\gamma$ (triangles)",
              title="(f) fluctuations and persistence (fig. 3a)")
    ax[6].set(xlabel=r"$\phi_c - \phi$", ylabel=r"$\delta v/\dot\gamma d$, $\Psi\dot\gamma$ (triangles)",
              title="(g) the same against phi_c - phi (fig. 3b)")
    ax[7].set(xlabel=r"$\phi_c - \phi$", ylabel=r"$\ell / d = \delta v \Psi / d$",
              title="(h) step length, every run (fig. 3c)")
    ax[8].set(xlabel="J", ylabel=r"$\mu = \tau / P$", title="(i) effective friction")
    ax[9].set(xlabel="J", ylabel=r"$D / (\delta v^2 \Psi)$", title="(j) D = dv^2 Psi for each Psi definition")
    ax[10].axis("off")
    ax[11].axis("off")
    for a_ in ax[2:10]:
        if a_.get_legend_handles_labels()[0]:
            a_.legend(fontsize=7, loc="upper right" if a_ is ax[3] else "best")
    fig.suptitle(f"{args.sweep}: {fits['finished']}/{fits['points']} points; error bars: standard "
                 "error over seeds (open: one run's own error)")
    fig.tight_layout()
    out = args.out or args.sweep / "sweep.png"
    fig.savefig(out, dpi=100)
    print(out)


if __name__ == "__main__":
    main()
