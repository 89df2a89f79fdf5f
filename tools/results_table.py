#!/usr/bin/python3
"""Markdown tables of a sweep for docs/results.md, from its fits.json and sweep.csv alone (a
sweep folder, or the committed store results/<name>/ that `sheardiff sweep ... --collect`
writes). Per group (ktilde, N, ...):

  * every J: the mean over seeds of phi, mu, D, dv, Psi with the standard error of that mean
    from the seeds' scatter (n seeds), and what the runs' own error bars predict for it;
  * the seed paper's Table 1 side by side, row by row: our a, b with errors from a bootstrap
    over seeds, the seed's, and the verdict (difference in combined standard errors);
  * every J against the seed's laws evaluated there (ours over theirs);
  * the diagnostics of the candidate causes of docs/results.md, and the cost per run.

    /usr/bin/python3 tools/results_table.py DIR
    /usr/bin/python3 tools/results_table.py --laws DIR     # only the laws table (one group)
    /usr/bin/python3 tools/results_table.py --every-j DIR  # only every J against the seed's laws
    /usr/bin/python3 tools/results_table.py --means DIR    # only the means over seeds at every J
    /usr/bin/python3 tools/results_table.py --boyer DIR    # only every J against Boyer et al.
    /usr/bin/python3 tools/results_table.py --ranges DIR   # only the exponents over parts of
                                                           # the J range
    /usr/bin/python3 tools/results_table.py --discs DISC_DIR DIR   # spheres' D, dv, Psi, mu
                                                                   # against the discs'
    /usr/bin/python3 tools/results_table.py --error-check DIR [J_MIN J_MAX]  # the runs' own
                                                   # error bars against the seeds' scatter
    /usr/bin/python3 tools/results_table.py --steps DIR    # the exponents between neighbouring
                                                           # J
    /usr/bin/python3 tools/results_table.py --bulk DIR     # D of every particle against D of
                                                           # the bulk band's spheres alone

--error-check asks whether one run's error bars (from its time blocks) hold the scatter between
seeds. Per quantity and J (the stationary windows the fits used, two seeds or more): chi2 =
sum_i (x_i - xbar)^2 / sigma_i^2 about the inverse-variance mean, n - 1 degrees of freedom, then
summed over the J. What right bars would give is drawn (40,000 draws, a fixed generator): values
scattering as their bars say, and each bar itself an estimate from its run's `error_blocks`
blocks (its variance scattering as chi2 with blocks - 1 degrees of freedom), which makes large
chi2 likelier than the exact chi2 law says. R is the factor that puts the measured chi2 at the
median of those draws (1 where the bars are right; above 1, a run's bars are too small by about
R), with the 68 % interval from the draws' 16 and 84 % points and P, the share of draws at least
as large as the measured chi2. Each J's cell is its own R.

A sweep of spheres (sweep.csv's dimension = 3) adds every J against the 3D experiments of Boyer,
Guazzelli & Pouliquen (2011): phi and mu with their fits evaluated there. The seed's laws are
then the 2D reference for D, dv and Psi (the seed's phi law is a 2D one: not a reference).

With --compare, single runs against a reference run (the checks of docs/results.md: one seed of
another N, ktilde, mixing rule, ... against a point of the same seed): each quantity with the
run's own error bar, the ratio to the reference and the difference in combined standard errors.

    /usr/bin/python3 tools/results_table.py --compare REF_POINT POINT [POINT ...]

(a POINT is a folder holding a summary.json, e.g. results/size_check/points/J=0.01_N=500_seed=1)
"""
import math
import pathlib
import re
import sys

import numpy as np

import rundir


def fmt(x, p=3):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{p}g}"


def pm(x, e, p=3):
    if x is None:
        return "-"
    return f"{x:.{p}g}" + (f" +- {e:.2g}" if e is not None else "")


def z_score(x, e, ref, ref_e):
    """(x - ref) in combined standard errors; inf-signed when both errors are 0."""
    s = math.hypot(e, ref_e or 0.0)
    return (x - ref) / s if s > 0 else math.copysign(math.inf, x - ref)


def verdict(x, e, ref, ref_e):
    """How many combined standard errors apart; 'agrees' within 2."""
    if x is None or e is None:
        return "no error bar (one seed)"
    z = abs(z_score(x, e, ref, ref_e))
    return f"agrees ({z:.1f} sigma)" if z <= 2 else f"differs ({z:.1f} sigma)"


def law(f):
    if "error" in f:
        return f"not fitted ({f['error']})"
    e = f.get("b_stderr")
    return f"{pm(f['a'], f.get('a_stderr'))}, {f['b']:+.3f}" + (
        "" if e is None else f" +- {e:.3f}" if e >= 0.001 else f" +- {e:.1g}")


# Quantities of a run compared by --compare: summary key, its error key (None: no error bar).
COMPARED = (("phi", "phi_err"), ("mu", "mu_err"), ("D", "D_err"), ("dv", "dv_err"),
            ("psi", "psi_err"), ("max_overlap", None), ("bulk_shear_rate_ratio", None))


def compare(paths):
    """Markdown table: each run's quantities against the first run's (the reference)."""
    runs = []
    for p in paths:
        run = rundir.Run(p)
        if not run.finished:
            sys.exit(f"{p}: no summary.json (a finished run's folder)")
        runs.append(run.summary)
    ref = runs[0]
    print("| run | " + " | ".join(k for k, _ in COMPARED) + " |")
    print("|---" * (len(COMPARED) + 1) + "|")
    for p, r in zip(paths, runs):
        cells = []
        for k, e in COMPARED:
            x, x0 = r.get(k), ref.get(k)
            if x is None:
                cells.append("-")
                continue
            text = pm(x, r.get(e) if e else None, 4)
            if r is not ref and x0:
                text += f" ({x / x0:.3f}"
                if e and r.get(e) is not None and ref.get(e) is not None:
                    z = z_score(x, r[e], x0, ref[e])
                    text += f", z {z:+.1f}" if math.isfinite(z) else ""
                text += ")"
            cells.append(text)
        print(f"| {'reference: ' if r is ref else ''}{p} | " + " | ".join(cells) + " |")


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "--compare":
        if len(sys.argv) < 4:
            sys.exit(f"usage: {sys.argv[0]} --compare REF_POINT POINT [POINT ...]")
        compare(sys.argv[2:])
        return
    if len(sys.argv) >= 2 and sys.argv[1] == "--discs":
        if len(sys.argv) != 4:
            sys.exit(f"usage: {sys.argv[0]} --discs DISC_DIR DIR (two fit or sweep folders)")
        against_discs(one_group_rows(sys.argv[2]), one_group_rows(sys.argv[3]))
        return
    if len(sys.argv) >= 2 and sys.argv[1] == "--error-check":
        if len(sys.argv) not in (3, 5):
            sys.exit(f"usage: {sys.argv[0]} --error-check DIR [J_MIN J_MAX] (a fit or sweep "
                     f"folder; only the J within [J_MIN, J_MAX] if given)")
        store = rundir.Store(pathlib.Path(sys.argv[2]))
        if not store.has_table():
            sys.exit(f"{sys.argv[2]}: no fits.json / sweep.csv")
        rows = store.fitted_rows()
        if len(sys.argv) == 5:
            try:
                lo, hi = float(sys.argv[3]), float(sys.argv[4])
            except ValueError:
                sys.exit(f"--error-check: J_MIN and J_MAX must be numbers, not "
                         f"{sys.argv[3]!r} {sys.argv[4]!r}")
            rows = [r for r in rows if lo <= (cell(r, "J") or math.nan) <= hi]
        error_check(rows)
        return
    modes = ("--laws", "--every-j", "--means", "--boyer", "--ranges", "--steps", "--bulk")
    only = sys.argv[1] if len(sys.argv) == 3 and sys.argv[1] in modes else None
    if only:
        del sys.argv[1]
    if len(sys.argv) != 2:
        sys.exit(f"usage: {sys.argv[0]} [{' | '.join(modes)}] DIR (a sweep folder or "
                 f"results/<name>)")
    out = pathlib.Path(sys.argv[1])
    if not out.is_dir():
        sys.exit(f"{out}: not a directory")
    store = rundir.Store(out)
    if not store.has_table():
        sys.exit(f"{out}: no fits.json / sweep.csv (run `sheardiff sweep SWEEP.toml --out DIR "
                 f"--collect` first)")
    fits, rows = store.fits, store.rows()
    if not fits.get("groups"):
        sys.exit(f"{out}: fits.json has no J fits (a sweep without a flow.J axis, such as "
                 f"channel cases over seeds: tools/channel_table.py reads those)")
    seed = fits["seed_table1"]
    dims = {r.get("dimension") for r in rows if r.get("dimension")}
    if len(dims) > 1:
        sys.exit(f"{out}: the store mixes discs and spheres (dimensions {sorted(dims)}); their "
                 f"laws differ, so tabulate each from its own store")
    spheres = dims == {"3"}
    dimension = 3 if spheres else 2
    if only:
        if len(fits["groups"]) != 1:
            sys.exit(f"{out}: {only} needs one group of points, not {len(fits['groups'])}")
        g = fits["groups"][0]
        if only == "--laws":
            law_table(g["fits"], seed, dimension=dimension)
        elif only == "--every-j":
            against_seed_laws(g["rows"], False, dimension=dimension)
        elif only == "--means":
            means_table(g["rows"])
        elif only == "--ranges":
            subrange_fits(store.fitted_rows(), heading=False)
        elif only == "--steps":
            local_exponents(g["rows"])
        elif only == "--bulk":
            bulk_table(store.fitted_rows())
        else:
            against_boyer(g["rows"], False)
        return
    # Measurements that enter the fits; every finished run counts for the cost.
    # (`sheardiff fit --include-not-stationary` fits the flagged windows too: so does this.)
    done = store.fitted_rows()
    finished = [r for r in rows if r["status"].startswith("done")]
    cpu = sum(float(r["wall_seconds"]) for r in finished if r.get("wall_seconds"))
    print(f"{fits['finished']} of {fits['points']} points finished; summed run time "
          f"{cpu / 3600:.2f} h.\n")
    for g in fits["groups"]:
        axes = ", ".join(f"{k} = {v}" for k, v in g["axes"].items()) or "all points"
        print(f"#### {axes}\n")
        print("Each cell: mean over seeds +- standard error of that mean (from the seeds' "
              "scatter); [the runs' own error bars, rms / sqrt(n)].\n")
        means_table(g["rows"])
        print()
        law_table(g["fits"], seed, dimension=dimension)
        print()
        against_seed_laws(g["rows"], dimension=dimension)
        if spheres:
            against_boyer(g["rows"])
    causes(done)
    cost(finished)
    if len(fits["groups"]) == 1:
        subrange_fits(done)


# Densest packings: hexagonal discs, face-centred cubic spheres.
CLOSE_PACKING = {2: 0.9069, 3: 0.7405}


def means_table(rows):
    """Per J: phi, mu, D, dv, Psi, each the mean over seeds +- sem [the runs' own error]."""
    print("| J | seeds | phi | mu | D / (gammadot d^2) | dv / (gammadot d) | Psi gammadot |")
    print("|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: r["J"]):
        cells = []
        for q, p in (("phi", 4), ("mu", 3), ("D", 3), ("dv", 3), ("psi", 3)):
            c = pm(r.get(q), r.get(q + "_sem"), p)
            if r.get(q + "_run_err") is not None:
                c += f" [{r[q + '_run_err']:.2g}]"
            cells.append(c)
        print(f"| {r['J']:g} | {r['runs']} | " + " | ".join(cells) + " |")


def law_table(f, seed, dimension=2):
    """The fitted laws of one group against the seed's Table 1 (spheres' phi: Boyer et al.), with
    verdicts."""
    ref = "seed Table 1 (phi: Boyer et al.): a, b" if dimension == 3 else "seed Table 1: a, b"
    print(f"| law | sheardiff: a, b (seed-bootstrap errors) | {ref} | a | b |")
    print("|---|---|---|---|---|")
    for key, name in (("D_vs_J", "D/(gammadot d^2) = a J^b"),
                      ("dv_vs_J", "dv/(gammadot d) = a J^b"),
                      ("psi_vs_J", "Psi gammadot = a J^b"),
                      ("D_vs_phic_minus_phi", "D/(gammadot d^2) = a (phi_c - phi)^b"),
                      ("dv_vs_phic_minus_phi", "dv/(gammadot d) = a (phi_c - phi)^b"),
                      ("psi_vs_phic_minus_phi", "Psi gammadot = a (phi_c - phi)^b")):
        s, ff = seed[key], f[key]
        va = verdict(ff.get("a"), ff.get("a_stderr"), s["a"], s["a_stderr"]) if "a" in ff else "-"
        vb = verdict(ff.get("b"), ff.get("b_stderr"), s["b"], s["b_stderr"]) if "b" in ff else "-"
        print(f"| {name} | {law(ff)} | {s['a']} +- {s['a_stderr']}, {s['b']} +- "
              f"{s['b_stderr']} | {va} | {vb} |")
    p = f["phi_of_J"]
    if "phi_c" in p:
        e = p.get("phi_c_stderr")
        phi_c = f"{p['phi_c']:.4f}" + ("" if e is None else f" +- {e:.4f}")
        cp = CLOSE_PACKING[dimension]
        warn = (f" (above the {dimension}D close packing {cp}: unphysical)" if p["phi_c"] > cp
                else "")
        # Spheres have no law of the seed's: their reference is Boyer et al.'s phi_m / (1 + J^1/2),
        # which tends to phi_m (1 - J^1/2) as J -> 0 (phi_c = phi_m, b = 1/2; no error given).
        ref, ref_phi_c, ref_err = (("Boyer et al. (J -> 0): phi_c = phi_m = 0.585, a = 0.585, b = 0.5",
                                    0.585, 0.0) if dimension == 3
                                   else ("phi_c = 0.81 +- 0.01, a = 0.64, b = 0.5", 0.81, 0.01))
        print(f"| phi = phi_c - a J^b | phi_c = {phi_c}"
              f"{warn}, a = {pm(p['a'], p.get('a_stderr'))}, b = {pm(p['b'], p.get('b_stderr'))} "
              f"| {ref} | phi_c: "
              f"{verdict(p['phi_c'], p.get('phi_c_stderr'), ref_phi_c, ref_err)} | "
              f"{verdict(p['b'], p.get('b_stderr'), 0.5, 0.0)} |")
    m = f["mu_of_J"]
    if "mu_c" in m:
        print(f"| mu = mu_c + a J^b | mu_c = {pm(m['mu_c'], m.get('mu_c_stderr'))}, "
              f"a = {pm(m['a'], m.get('a_stderr'))}, b = {pm(m['b'], m.get('b_stderr'))} "
              f"| - | - | - |")


# The seed's laws (its Table 1 and eq. 3.3), evaluated at each of our J.
SEED_LAWS = {"phi": lambda J: 0.81 - 0.64 * math.sqrt(J), "D": lambda J: 0.024 * J ** -0.26,
             "dv": lambda J: 0.258 * J ** -0.25, "psi": lambda J: 0.35 * J ** 0.24}


# Boyer, Guazzelli & Pouliquen, Phys. Rev. Lett. 107, 188301 (2011): spheres in pressure-imposed
# shear; phi_m = 0.585, mu_1 = 0.32, mu_2 = 0.7, J_0 = 0.005.
def boyer_contact_term(J):
    """Boyer et al.'s mu_1 + (mu_2 - mu_1) / (1 + J_0 / J): the contact term of their mu(J)."""
    return 0.32 + 0.38 / (1.0 + 0.005 / J)


def boyer_hydrodynamic_term(J):
    """Boyer et al.'s (5/2) phi_m J^1/2: the hydrodynamic term of their mu(J)."""
    return 2.5 * 0.585 * math.sqrt(J)


BOYER_LAWS = {"phi": lambda J: 0.585 / (1.0 + math.sqrt(J)),
              "mu": lambda J: boyer_contact_term(J) + J + boyer_hydrodynamic_term(J)}


def against_boyer(rows, heading=True):
    """Spheres: per J, phi and mu (mean over seeds +- sem) against Boyer et al.'s fits there."""
    if heading:
        print("#### Every J against Boyer, Guazzelli & Pouliquen (2011)\n")
        print("Ours: mean over seeds +- standard error from their scatter (one seed: the run's "
              "own error bar, in brackets); Boyer: phi_m / (1 + J^1/2) and mu_1 + (mu_2 - mu_1) / (1 + "
              "J_0 / J) + J + 5/2 phi_m J^1/2 at the same J; ratio: ours / Boyer's.\n")
    print("| J | seeds | phi | Boyer | ratio | mu | Boyer | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: r["J"]):
        J = r["J"]
        cells = []
        for q, p in (("phi", 4), ("mu", 3)):
            x, ref = r.get(q), BOYER_LAWS[q](J)
            if x is None:
                cells += ["-", fmt(ref, p), "-"]
                continue
            e = r.get(q + "_sem")
            c = pm(x, e, p) if e is not None else pm(x, None, p) + (
                f" [{r[q + '_run_err']:.2g}]" if r.get(q + "_run_err") is not None else "")
            cells += [c, f"{ref:.{p}g}", f"{x / ref:.3f}"]
        print(f"| {J:g} | {r['runs']} | " + " | ".join(cells) + " |")
    print()


def one_group_rows(path):
    """The per-J rows of a store with one group of points."""
    store = rundir.Store(pathlib.Path(path))
    if not store.has_table():
        sys.exit(f"{path}: no fits.json / sweep.csv")
    groups = store.fits.get("groups") or []
    if len(groups) != 1:
        sys.exit(f"{path}: needs one group of points, not {len(groups)}")
    return groups[0]["rows"]


def standard_error(r, q):
    """The larger of the seeds' scatter over sqrt(n) and the runs' own error bars over sqrt(n):
    a scatter of two or three seeds is itself uncertain by 50-70 %."""
    errs = [e for e in (r.get(q + "_sem"), r.get(q + "_run_err")) if e is not None]
    return max(errs) if errs else None


def interpolated(rows, q, J):
    """q of a store at J: the row's at that J, else a power law between the two neighbouring J
    (both values and their standard errors; None outside the store's J range)."""
    pts = sorted((r["J"], r[q], standard_error(r, q)) for r in rows if r.get(q) is not None)
    for (j0, x0, e0), (j1, x1, e1) in zip(pts, pts[1:]):
        if j0 <= J <= j1:
            if J == j0:
                return x0, e0, "measured"
            if J == j1:
                return x1, e1, "measured"
            w = math.log(J / j0) / math.log(j1 / j0)
            x = math.exp((1 - w) * math.log(x0) + w * math.log(x1))
            e = x * math.hypot((1 - w) * e0 / x0, w * e1 / x1) if e0 and e1 else None
            return x, e, f"between J = {j0:g} and {j1:g}"
    if pts and J == pts[-1][0]:
        return pts[-1][1], pts[-1][2], "measured"
    return None, None, "outside the discs' J"


def against_discs(disc_rows, sphere_rows):
    """Spheres against discs at the same J: D, dv, Psi and mu, each the mean over seeds +- its
    standard error (standard_error), the discs' interpolated as power laws in J between their two
    neighbouring J where they have no point at that J."""
    print("| J | seeds | D / (gammadot d^2) | discs | ratio | dv / (gammadot d) | discs | ratio "
          "| Psi gammadot | discs | ratio | mu | discs | ratio | discs' value |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(sphere_rows, key=lambda r: r["J"]):
        J, cells, hows = r["J"], [], []
        for q, p in (("D", 3), ("dv", 3), ("psi", 3), ("mu", 3)):
            x = r.get(q)
            e = standard_error(r, q)
            ref, ref_e, how = interpolated(disc_rows, q, J)
            if ref is not None and how not in hows:
                hows.append(how)
            if x is None or ref is None:
                cells += [pm(x, e, p), pm(ref, ref_e, p), "-"]
                continue
            ratio = x / ref
            ratio_e = ratio * math.hypot((e or 0) / x, (ref_e or 0) / ref)
            cells += [pm(x, e, p), pm(ref, ref_e, p), f"{ratio:.3f} +- {ratio_e:.3f}"]
        print(f"| {J:g} | {r['runs']} | " + " | ".join(cells) + f" | {'; '.join(hows) or '-'} |")


def against_seed_laws(rows, heading=True, dimension=2):
    """Per J: ours (mean over seeds +- sem), the seed's law there, and ours over the seed's."""
    if heading and dimension == 3:
        print("#### Every J against the seed's (2D) laws\n")
        print("Spheres against the discs' laws: D, dv and Psi compare the two dimensions. phi is "
              "not compared here (the seed's phi_c is that of discs): see Boyer et al.'s "
              "phi(J) below.\n")
    elif heading:
        print("#### Every J against the seed's laws\n")
        print("Ours: mean over seeds +- standard error from their scatter; seed: its Table 1 law "
              "(phi: eq. 3.3, 0.81 - 0.64 J^1/2) at the same J; ratio: ours / seed's (phi: the "
              "difference).\n")
    print("| J | phi | seed | ours - seed | D | seed | ratio | dv | seed | ratio | Psi | seed | "
          "ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: r["J"]):
        J = r["J"]
        cells = []
        for q, p in (("phi", 4), ("D", 3), ("dv", 3), ("psi", 3)):
            x, e, ref = r.get(q), r.get(q + "_sem"), SEED_LAWS[q](J)
            if x is None:
                cells += ["-", fmt(ref, p), "-"]
                continue
            if q == "phi" and dimension == 3:
                cells += [pm(x, e, 4), "-", "-"]
            elif q == "phi":
                cells += [pm(x, e, 4), f"{ref:.4f}", f"{x - ref:+.4f}"]
            else:
                cells += [pm(x, e, 3), f"{ref:.3g}",
                          f"{x / ref:.2f}" + (f" +- {e / ref:.2f}" if e is not None else "")]
        print(f"| {J:g} | " + " | ".join(cells) + " |")
    print()


def subrange_fits(done, replicates=2000, heading=True):
    """The exponents over parts of the J range: which J drive a fit. OLS in log-log space on the
    seeds' means (the seed's Appendix B) and phi = phi_c - a J^b by least squares (not the
    seed's alignment procedure: a check of where the curvature sits, not a Table 1 value);
    errors from a bootstrap over seeds, each J's runs widened about their mean by sqrt(n/(n-1))
    as in `sheardiff sweep --collect`."""
    from scipy.optimize import curve_fit

    by_j = {}
    for r in done:
        try:
            v = {q: float(r[q]) for q in ("D", "dv", "psi", "phi")}
        except (KeyError, ValueError):
            continue
        # A run without the diffusion analysis has no D, dv, Psi to fit.
        if all(math.isfinite(x) for x in v.values()):
            by_j.setdefault(float(r["J"]), []).append(v)
    js = sorted(by_j)
    if len(js) < 4:
        return
    rng = np.random.default_rng(12345)

    def fit(sample):
        x = np.log([j for j, _ in sample])
        out = {}
        for q in ("D", "dv", "psi"):
            out[q] = np.polyfit(x, np.log([np.mean([r[q] for r in runs]) for _, runs in sample]),
                                1)[0]
        J = np.array([j for j, _ in sample])
        phi = np.array([np.mean([r["phi"] for r in runs]) for _, runs in sample])
        try:
            p, _ = curve_fit(lambda J, pc, a, b: pc - a * J ** b, J, phi, p0=[0.81, 0.5, 0.5],
                             maxfev=5000)
            out["phi_c"], out["a"], out["b"] = p
        except RuntimeError:
            out["phi_c"] = out["a"] = out["b"] = math.nan
        return out

    def widened(runs):
        n = len(runs)
        if n < 2:
            return runs
        w = math.sqrt(n / (n - 1))
        m = {q: np.mean([r[q] for r in runs]) for q in runs[0]}
        return [{q: m[q] + w * (r[q] - m[q]) for q in r} for r in runs]

    if heading:
        print("#### Exponents over parts of the J range (seed-bootstrap errors)\n")
    print("| J range | J values | D: b | dv: b | Psi: b | phi = phi_c - a J^b (least squares) |")
    print("|---|---|---|---|---|---|")
    for lo, hi in ((js[0], js[-1]), (js[0], js[-2]), (js[1], js[-2]), (js[0], js[-3])):
        part = [(j, by_j[j]) for j in js if lo <= j <= hi]
        if len(part) < 4:
            continue
        best = fit(part)
        reps = []
        for _ in range(replicates):
            sample = []
            for j, runs in part:
                w = widened(runs)
                sample.append((j, [w[k] for k in rng.integers(0, len(w), len(w))]))
            reps.append(fit(sample))
        err = {k: (float(np.nanstd([r[k] for r in reps], ddof=1))
                   if all(len(runs) > 1 for _, runs in part) else None) for k in best}
        print(f"| {lo:g} - {hi:g} | {len(part)} | "
              + " | ".join(pm(best[q], err[q]) for q in ("D", "dv", "psi"))
              + f" | phi_c = {pm(best['phi_c'], err['phi_c'], 4)}, a = {pm(best['a'], err['a'])}, "
              f"b = {pm(best['b'], err['b'])} |")
    if heading:
        print()


def cell(r, k):
    """A sweep.csv cell (summary key k) as a float, None where empty or not a number."""
    try:
        return float(r[k]) if r.get(rundir.key(k)) not in (None, "") else None
    except ValueError:
        return None


def runs_by_j(done):
    by_j = {}
    for r in done:
        by_j.setdefault(cell(r, "J"), []).append(r)
    return by_j


def local_exponents(rows):
    """The exponent b of q ~ J^b between each pair of neighbouring J, from the means over seeds,
    with the error of ln(q2 / q1) / ln(J2 / J1) from each mean's standard error (the larger of
    the seeds' scatter and the runs' own bars, `standard_error`): where along the J range a law
    steepens or flattens, which one fit over the range averages away."""
    print("| J from - to | D: b | dv: b | Psi: b |")
    print("|---|---|---|---|")
    rows = sorted(rows, key=lambda r: r["J"])
    for a, b in zip(rows, rows[1:]):
        span = math.log(b["J"] / a["J"])
        cells = []
        for q in ("D", "dv", "psi"):
            if a.get(q) is None or b.get(q) is None:
                cells.append("-")
                continue
            ea, eb = standard_error(a, q), standard_error(b, q)
            err = (math.hypot(ea / a[q], eb / b[q]) / abs(span)
                   if ea is not None and eb is not None else None)
            slope = math.log(b[q] / a[q]) / span
            cells.append(f"{slope:+.3f}" + (f" +- {err:.3f}" if err is not None else ""))
        print(f"| {a['J']:g} - {b['J']:g} | " + " | ".join(cells) + " |")


def bulk_table(done):
    """Per J over the windows the fits used: D from every particle's MSD and D_bulk from the MSD
    of those in the bulk band alone (observables.wall_exclusion, 3 d by default, inside each
    wall line), each the mean over seeds +- the seeds' scatter over sqrt(n), and their ratio per
    run. D_bulk has no error bar of its own; the last column is one the size of the runs' own D
    bars, each scaled by its run's D_bulk / D, rms over sqrt(n). Whether the spheres next to the
    walls set how D changes with J: the bulk's D would then change otherwise."""
    print("| J | seeds | D / (gammadot d^2), every particle | D_bulk, the bulk band's | "
          "D_bulk / D | D_bulk's error from the runs' D bars |")
    print("|---|---|---|---|---|---|")
    by_j = runs_by_j(done)
    for J in sorted(j for j in by_j if j is not None):
        runs = [r for r in by_j[J] if cell(r, "D") is not None and cell(r, "D_bulk") is not None]
        if not runs:
            continue
        n = len(runs)
        d = np.array([cell(r, "D") for r in runs])
        bulk = np.array([cell(r, "D_bulk") for r in runs])
        ratio = bulk / d

        def sem(x):
            return float(np.std(x, ddof=1) / math.sqrt(n)) if n > 1 else None

        errs = [cell(r, "D_err") for r in runs]
        scaled = (float(np.sqrt(np.mean((np.array(errs) * ratio) ** 2)) / math.sqrt(n))
                  if None not in errs else None)
        print(f"| {J:g} | {n} | {pm(d.mean(), sem(d))} | {pm(bulk.mean(), sem(bulk))} | "
              f"{pm(ratio.mean(), sem(ratio))} | {fmt(scaled, 2)} |")


ERROR_CHECKED = (("phi", "phi"), ("mu", "mu"), ("D", "D / (gammadot d^2)"),
                 ("dv", "dv / (gammadot d)"), ("psi", "Psi gammadot"))
ERROR_CHECK_DRAWS = 40000


def seeds_chi2(xs, errs):
    """chi2 of values xs (last axis) with error bars errs about their inverse-variance mean."""
    w = 1.0 / np.square(errs)
    mean = (w * xs).sum(axis=-1, keepdims=True) / w.sum(axis=-1, keepdims=True)
    return (w * np.square(xs - mean)).sum(axis=-1)


def right_bars_chi2(errs, blocks, rng):
    """ERROR_CHECK_DRAWS draws of seeds_chi2 for seeds whose bars are right: values drawn with the
    bars errs, and each bar itself an estimate from its run's blocks (variance scattering as
    chi2 with blocks - 1 degrees of freedom; exact where blocks is None)."""
    errs = np.asarray(errs, float)
    xs = rng.normal(size=(ERROR_CHECK_DRAWS, len(errs))) * errs
    est = np.tile(errs, (ERROR_CHECK_DRAWS, 1))
    for i, b in enumerate(blocks):
        if b is not None and b > 1:
            est[:, i] *= np.sqrt(rng.chisquare(b - 1, ERROR_CHECK_DRAWS) / (b - 1))
    return seeds_chi2(xs, est)


def error_check(done):
    """Per quantity: R, the factor by which the seeds scatter beyond their runs' own error bars,
    at each J and pooled over J (see the module's docstring)."""
    rng = np.random.default_rng(20261207)
    groups = {}
    for r in done:
        # One group per point name less its seed and its store (the other axes stay apart).
        name = re.sub(r"(^|_)seed=[^_/]*", "", r["point"].rsplit("/", 1)[-1]) or "-"
        groups.setdefault((cell(r, "J"), name), []).append(r)
    keys = sorted((k for k, rs in groups.items() if len(rs) >= 2),
                  key=lambda k: (k[0] is None, k[0] or 0.0, k[1]))
    if not keys:
        sys.exit("--error-check: no J with two or more stationary seeds")
    heads = [f"J = {j:g}" + (f" ({n})" if not n.startswith("J=") and n != "-" else "")
             + f", {len(groups[(j, n)])} seeds" for j, n in keys]
    print("| quantity | " + " | ".join(heads) + " | pooled R [68 % interval] | dof | "
          "P(chi2 >= measured) |")
    print("|---|" + "---|" * len(keys) + "---|---|---|")
    for q, label in ERROR_CHECKED:
        chi2, dof, null, cells = 0.0, 0, np.zeros(ERROR_CHECK_DRAWS), []
        for k in keys:
            runs = [(cell(r, q), cell(r, q + "_err"), cell(r, "error_blocks"))
                    for r in groups[k]]
            runs = [t for t in runs if t[0] is not None and t[1]]
            if len(runs) < 2:
                cells.append("-")
                continue
            xs, errs, blocks = zip(*runs)
            c = float(seeds_chi2(np.array(xs), np.array(errs)))
            t = right_bars_chi2(errs, [None if b is None else int(b) for b in blocks], rng)
            chi2, dof, null = chi2 + c, dof + len(runs) - 1, null + t
            cells.append(f"{math.sqrt(c / np.median(t)):.2f}")
        if not dof:
            continue
        # A larger chi2 of right bars needs a smaller R: the 84 % point bounds R from below.
        q84, median, q16 = np.quantile(null, [0.84, 0.5, 0.16])
        p = float(np.mean(null >= chi2))
        p_cell = f"{p:.2g}" if p > 0 else f"< {1 / ERROR_CHECK_DRAWS:.1g}"
        print(f"| {label} | " + " | ".join(cells) + f" | {math.sqrt(chi2 / median):.2f} "
              f"[{math.sqrt(chi2 / q84):.2f}, {math.sqrt(chi2 / q16):.2f}] | {dof} | {p_cell} |")


def cost(done):
    """Per J: steps per strain and wall time per run, from each run's summary."""
    by_j = runs_by_j(done)
    print("#### Cost per run (mean over seeds; wall time depends on what else shared the cores)\n")
    print("| J | runs | steps per strain | ms per step | strains run | wall h per run |")
    print("|---|---|---|---|---|---|")
    for j in sorted(k for k in by_j if k is not None):
        rs = by_j[j]
        vals = [rundir.mean_sem([cell(r, k) for r in rs])[0]
                for k in ("steps_per_strain", "ms_per_step", "strain", "wall_seconds")]
        v = [x if x is not None else float("nan") for x in vals]
        print(f"| {j:g} | {len(rs)} | {v[0]:.0f} | {v[1]:.1f} | {v[2]:.1f} | {v[3] / 3600:.2f} |")
    print()


def causes(done):
    """Per J (mean over seeds +- sem): the diagnostics of docs/results.md's candidate causes."""
    by_j = runs_by_j(done)
    if not any(r.get("D_bulk") for r in done):
        return
    print("#### Diagnostics of the candidate causes (per J: mean over seeds +- sem)\n")
    print("(b) bulk only / all the mobile particles; (c) shear rate of the bulk over V/H and mu_top - mu_bottom; "
          "(e) D / (dv^2 Psi) for each definition of Psi.\n")
    print("| J | D_bulk / D | dv_bulk / dv | Psi_bulk / Psi | bulk shear rate / (V/H) | "
          "mu_top - mu_bottom | D/(dv^2 psi) | D/(dv^2 psi_e) | D/(dv^2 psi_full) | "
          "D/(dv^2 psi_zero) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for j in sorted(k for k in by_j if k is not None):
        rs = by_j[j]
        cells = []
        for num_k, den_k in (("D_bulk", "D"), ("dv_bulk", "dv"), ("psi_bulk", "psi")):
            cells.append(rundir.mean_sem([cell(r, num_k) / cell(r, den_k) if cell(r, num_k) and cell(r, den_k)
                                   else None for r in rs]))
        cells.append(rundir.mean_sem([cell(r, "bulk_shear_rate_ratio") for r in rs]))
        cells.append(rundir.mean_sem([cell(r, "mu_top") - cell(r, "mu_bottom") if cell(r, "mu_top") is not None
                               and cell(r, "mu_bottom") is not None else None for r in rs]))
        for key in ("psi", "psi_e", "psi_full", "psi_zero"):
            cells.append(rundir.mean_sem([cell(r, "D") / (cell(r, "dv") ** 2 * cell(r, key))
                                   if cell(r, "D") and cell(r, "dv") and cell(r, key) else None
                                   for r in rs]))
        print(f"| {j:g} | " + " | ".join(pm(m, e) for m, e in cells) + " |")
    print()


if __name__ == "__main__":
    main()
