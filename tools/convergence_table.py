#!/usr/bin/python3
"""Is a numerical setting converged for what a sweep reports? A markdown table from a sweep's
sweep.csv (a sweep folder, or the store results/<name>/ that `sheardiff sweep ... --collect`
writes) whose points vary one setting (the axis, e.g. integrator.max_displacement) over several
seeds.

Per value of the axis: the mean over seeds of phi, mu, dv, Psi, D and the largest overlap (in a
simple-shear sweep, whose phi is imposed: the shear viscosity eta_s / eta, the particle pressure
P / (eta gammadot), mu = shear stress / P, dv, Psi, D and the largest overlap), each
+- the standard error of that mean, the cost (steps and run seconds per strain), and each
quantity's difference from the reference value of the axis (default: the smallest) in two units.
The standard error is the larger of the seeds' scatter (s / sqrt(n)) and what the runs' own error
bars give for the mean (rms of `<q>_err` over sqrt(n)): with two to four seeds the scatter alone
is itself uncertain by 35-70 % and can be small by chance. Units of the difference:
  * z   = difference / combined standard error: |z| > 2 is a resolved bias;
  * r   = difference / the reference's standard error: the accuracy criterion of
          docs/performance.md is |r| <= 1/2 (within half the statistical error). With a few
          seeds this r is itself noisy (its own error is ~ sqrt(2) / 1 in these units), so the
          table reports it and z, and the verdict needs both.

    /usr/bin/python3 tools/convergence_table.py DIR [--axis KEY] [--reference VALUE]
    /usr/bin/python3 tools/convergence_table.py DIR --reference-from REF_DIR --reference VALUE \
        [--reference-axis KEY] [--axis KEY] [--only KEY=VALUE ...]

With --reference-from, the reference is the points of another sweep (same protocol and seeds)
whose --reference-axis (default: its one axis besides run.seed) equals VALUE, e.g. the md = 3e-4 d
points of a step-size sweep against a sweep of a new step policy. --axis and --reference-axis
may also name a summary column the sweep holds fixed (e.g. J of a sweep over seeds only), to set
one store against another at the same J:

    /usr/bin/python3 tools/convergence_table.py results/sweep_3d_j01 --axis J \
        --reference-from results/sweep_3d_j01_none --reference-axis J --reference 0.1

An --only KEY that REF_DIR also has as an axis filters REF_DIR's points too (one ktilde of a
sweep over several).

With --widen Q=FACTOR the runs' own error bars of Q are multiplied by FACTOR, in every group and in
the reference (so the --first-order estimates move with them), before the larger of them and the
scatter is taken: the factor by which the seeds scatter beyond one run's bars
(`tools/results_table.py --error-check`), so that a comparison resting on one or two runs is not
judged against bars the seeds' scatter shows too small.

With --first-order (an axis of integrator.max_displacement), each other step h also estimates
the reference step h0's own bias, if the error is first order in the step (q(h) = q(0) + c h,
docs/performance.md "Matched trajectory error"): q(h0) - q(0) = (q(h) - q(h0)) h0 / (h - h0),
+- the combined standard error times |h0 / (h - h0)|, and r = that bias over the reference's
standard error. h0 is the reference's integrator.max_displacement, read from its points'
config.toml when the reference comes from another sweep. From a step three times coarser the
bias is half the shift. With two or more other steps, a last row fits the straight line
q(h) = q(0) + c h through every step's mean (the reference's included), weighted by their
standard errors, and gives its c h0 +- its standard error, r, and the line's chi2 (one degree of
freedom for three steps: a chi2 well above it says the error is not first order over those
steps). The steps' points are separate runs, so the fit has no shared reference to correct for.
"""
import argparse
import math
import sys

import rundir

STEP = "integrator.max_displacement"
QUANTITIES = [("phi", "phi"), ("mu", "mu"), ("dv", "dv / (gammadot d)"),
              ("psi", "Psi gammadot"), ("D", "D / (gammadot d^2)"),
              ("max_overlap", "largest overlap / d")]
# Simple shear imposes phi; its summary gives the stresses (units of docs/units.md, gammadot = J).
SIMPLE_SHEAR_QUANTITIES = [("viscosity", "eta_s / eta"),
                           ("pressure_viscosity", "P / (eta gammadot)"),
                           ("mu", "mu")] + QUANTITIES[2:]


def quantity(r, q):
    """Quantity q of one finished point, or None; simple shear's derived stresses from its summary."""
    if q == "mu" and r.get("mu") in (None, "") and r.get("shear_stress") and r.get("pressure"):
        return float(r["shear_stress"]) / float(r["pressure"])
    if q == "pressure_viscosity":
        return float(r["pressure"]) / float(r["J"]) if r.get("pressure") and r.get("J") else None
    return None if r.get(rundir.key(q)) in (None, "") else float(r[q])


def g(x, p=3):
    return "-" if x is None else f"{x:.{p}g}"


def finished_rows(folder):
    """The finished points of a sweep folder or store (its sweep.csv), and its axes."""
    store = rundir.Store(folder)
    if not (store.path / rundir.SWEEP_CSV).is_file():
        sys.exit(f"{folder}: no sweep.csv (run `sheardiff sweep SWEEP.toml --out DIR "
                 "--collect` first)")
    rows = store.rows(done=True)
    if not rows:
        sys.exit(f"{folder}: no finished points yet")
    return rows, [k[len("axis."):] for k in rows[0]
                  if k.startswith("axis.") and k != "axis.run.seed"]


def stationary(rows, folder):
    """The points whose window passed the stationarity test."""
    kept = [r for r in rows if rundir.is_stationary(r)]
    if not kept:
        sys.exit(f"{folder}: no finished point with a stationary window")
    return kept


def the_axis(given, axes):
    """The axis a table is about: the one named, else the sweep's one axis besides run.seed."""
    return given or (axes[0] if len(axes) == 1 else None)


def setting(r, key):
    """A point's value of KEY: its axis column, else (a setting its sweep holds fixed, e.g. J of a
    sweep over seeds only) its summary column of that name."""
    v = r.get(f"axis.{key}")
    return float(v if v not in (None, "") else r[key])


def has(rows, key):
    """Whether the points have KEY as an axis or a summary column."""
    return f"axis.{key}" in rows[0] or rows[0].get(key) not in (None, "")


def with_value(rows, key, wanted):
    """The rows whose KEY (axis or summary column) equals wanted."""
    return [r for r in rows if setting(r, key) == wanted]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--axis", help="the setting that varies (default: the one axis that is not "
                    "run.seed)")
    ap.add_argument("--reference", type=float, help="the converged value of the axis (default: "
                    "the smallest)")
    ap.add_argument("--reference-from", metavar="REF_DIR", help="take the reference points "
                    "from this sweep folder or store instead of DIR")
    ap.add_argument("--reference-axis", help="REF_DIR's axis that --reference names (default: "
                    "its one axis that is not run.seed)")
    ap.add_argument("--stationary-only", action="store_true",
                    help="leave out the points whose measured window failed the stationarity "
                    "test (status 'done, not stationary' and the like); by default they count "
                    "and the table names them")
    ap.add_argument("--first-order", action="store_true",
                    help="with --axis integrator.max_displacement: the reference step's own bias "
                    "estimated from each other step, if the error is first order in the step")
    ap.add_argument("--widen", action="append", default=[], metavar="Q=FACTOR",
                    help="multiply the runs' own error bars of quantity Q (a column of the "
                    "table: phi, mu, dv, psi, D, ...) by FACTOR, in every group and the "
                    "reference's, before the larger of them and the seeds' scatter is taken "
                    "(repeatable): the R of `results_table.py --error-check`, where the seeds "
                    "scatter beyond one run's bars")
    ap.add_argument("--only", action="append", default=[], metavar="KEY=VALUE",
                    help="keep only the points whose axis KEY (or summary column KEY) has this "
                    "value (repeatable), e.g. one J of a sweep over several J against that J's "
                    "reference")
    a = ap.parse_args()
    widen = {}
    known = sorted({k for k, _ in QUANTITIES + SIMPLE_SHEAR_QUANTITIES})
    for w in a.widen:
        q, eq, factor = w.partition("=")
        try:
            widen[q] = float(factor)
        except ValueError:
            widen[q] = math.nan
        if not eq or q not in known or not widen[q] >= 1.0 or not math.isfinite(widen[q]):
            sys.exit(f"--widen {w}: give Q=FACTOR with Q one of {known} and a "
                     f"FACTOR >= 1, e.g. phi=1.57")
    rows, axes = finished_rows(a.dir)
    if a.stationary_only:
        rows = stationary(rows, a.dir)
    only = []
    for cond in a.only:
        key, eq, value = cond.partition("=")
        try:
            wanted = float(value)
        except ValueError:
            wanted = None
        if not eq or wanted is None or not has(rows, key):
            sys.exit(f"--only {cond}: give KEY=VALUE, a number for an axis KEY, one of "
                     f"{axes + ['run.seed']}, or a summary column held fixed (e.g. J)")
        rows = with_value(rows, key, wanted)
        if not rows:
            sys.exit(f"--only {cond}: no finished point has {key} = {value}")
        only.append((cond, key, wanted))
    axis = the_axis(a.axis, axes)
    if axis is None or not has(rows, axis):
        sys.exit(f"{a.dir}: give --axis, one of {axes} or a summary column held fixed (e.g. J)")
    groups = {}
    for r in rows:
        groups.setdefault(setting(r, axis), []).append(r)
    if a.reference_from:
        if a.reference is None:
            sys.exit("--reference-from needs --reference VALUE (of --reference-axis)")
        ref_rows, ref_axes = finished_rows(a.reference_from)
        if a.stationary_only:
            ref_rows = stationary(ref_rows, a.reference_from)
        ref_axis = the_axis(a.reference_axis, ref_axes)
        if ref_axis is None or not has(ref_rows, ref_axis):
            sys.exit(f"{a.reference_from}: give --reference-axis, one of {ref_axes} or a summary "
                     "column held fixed (e.g. J)")
        ref_value = a.reference
        # An --only axis that REF_DIR also varies (e.g. ktilde) selects its reference points too.
        for cond, key, wanted in only:
            if f"axis.{key}" in ref_rows[0]:
                ref_rows = with_value(ref_rows, key, wanted)
                if not ref_rows:
                    sys.exit(f"--only {cond}: no finished point of {a.reference_from} has it")
        ref_group = with_value(ref_rows, ref_axis, ref_value)
        if not ref_group:
            sys.exit(f"--reference {ref_value}: no finished point of {a.reference_from} has "
                     f"{ref_axis} = {ref_value}")
        ref_label = f"reference: {ref_axis} = {ref_value:g} of {a.reference_from}"
    else:
        ref_value = a.reference if a.reference is not None else min(groups)
        if ref_value not in groups:
            sys.exit(f"--reference {ref_value}: no finished point has {axis} = {ref_value}")
        ref_group = groups[ref_value]
        ref_label = f"reference {ref_value:g}"

    quantities = (SIMPLE_SHEAR_QUANTITIES if rows[0].get("scene") == "simple_shear"
                  else QUANTITIES)

    def stats(rs, q):
        m, e = rundir.mean_sem(quantity(r, q) for r in rs)
        errs = [float(r[q + "_err"]) for r in rs if r.get(q + "_err") not in (None, "")]
        if m is not None and errs and len(errs) == len(rs):
            own = math.sqrt(sum(x * x for x in errs) / len(errs)) / math.sqrt(len(errs))
            own *= widen.get(q, 1.0)
            e = own if e is None else max(e, own)
        return m, e

    ref = {q: stats(ref_group, q) for q, _ in quantities}
    print(f"{sum(len(v) for v in groups.values())} finished points; axis {axis}, {ref_label}. "
          f"Cells: mean over seeds +- standard error of the mean (the larger of the "
          f"seeds' scatter and the runs' own error bars); "
          f"(z, r) = difference from the reference in combined standard errors and in the "
          f"reference's standard error."
          + "".join(f" The runs' own bars of {q} are widened {f:g} times." for q, f in
                    widen.items()))
    flagged = sorted({r["point"] + " (" + r["status"] + ")"
                      for rs in groups.values() for r in rs if not rundir.is_stationary(r)})
    if a.reference_from:
        flagged += [f"{r['point']} of {a.reference_from} ({r['status']})" for r in ref_group
                    if not rundir.is_stationary(r)]
    print(("Counted although their window failed the stationarity test (--stationary-only "
           "leaves them out): " + ", ".join(flagged) + ".\n") if flagged else "")
    print("| " + axis + " | seeds | " + " | ".join(h for _, h in quantities)
          + " | steps / strain | run s / strain |")
    print("|---" * (len(quantities) + 4) + "|")
    table = [(f"{v:g}", rs, not a.reference_from and v == ref_value)
             for v, rs in sorted(groups.items(), reverse=True)]
    if a.reference_from:
        table.append(("reference", ref_group, True))
    for label, rs, is_ref in table:
        cells = []
        for q, _ in quantities:
            m, e = stats(rs, q)
            cell = g(m, 4) + (f" +- {e:.2g}" if e is not None else "")
            rm, re = ref[q]
            if not is_ref and m is not None and rm is not None and re:
                comb = math.hypot(e or 0.0, re)
                cell += f" ({(m - rm) / comb:+.1f}, {(m - rm) / re:+.1f})"
            cells.append(cell)
        steps, _ = stats(rs, "steps_per_strain")
        secs = rundir.mean_sem([float(r["wall_seconds"]) / float(r["strain"]) for r in rs
                         if r.get("wall_seconds") and r.get("strain")])[0]
        print(f"| {label} | {len(rs)} | " + " | ".join(cells) + f" | {g(steps)} | {g(secs)} |")
    if a.first_order:
        first_order(a, axis, ref_value, ref_group, groups, quantities, stats, ref)


def reference_step(a, axis, ref_value, ref_group):
    """The reference points' integrator.max_displacement: the axis value, or their config's."""
    if not a.reference_from and axis == STEP:
        return ref_value
    folder = rundir.Store(a.reference_from or a.dir)
    steps = set()
    for r in ref_group:
        cfg = rundir.Run(folder.path / "points" / r["point"]).config
        if "max_displacement" not in cfg.get("integrator", {}):
            sys.exit(f"--first-order: {r['point']} of {folder.path} has no config.toml with "
                     f"integrator.max_displacement")
        steps.add(float(cfg["integrator"]["max_displacement"]))
    if len(steps) != 1:
        sys.exit(f"--first-order: the reference points ran with several steps {sorted(steps)}")
    return steps.pop()


def first_order(a, axis, ref_value, ref_group, groups, quantities, stats, ref):
    if axis != STEP:
        sys.exit(f"--first-order needs --axis {STEP}")
    h0 = reference_step(a, axis, ref_value, ref_group)
    print(f"\nThe reference step's own bias q(h0) - q(0), h0 = {h0:g} d, if the error is first "
          f"order in the step (+- its standard error; r = over the reference's):\n")
    print("| from h | " + " | ".join(hd for _, hd in quantities) + " |")
    print("|---" * (len(quantities) + 1) + "|")
    for h, rs in sorted(groups.items(), reverse=True):
        if h == h0 and not a.reference_from:
            continue
        if h == h0:
            sys.exit(f"--first-order: the rows at h = {h:g} ran with the reference's own step")
        factor = h0 / (h - h0)
        cells = []
        for q, _ in quantities:
            m, e = stats(rs, q)
            rm, re = ref[q]
            if m is None or rm is None or not re:
                cells.append("-")
                continue
            bias = (m - rm) * factor + 0.0  # + 0.0: no "-0" for an exact zero
            err = math.hypot(e or 0.0, re) * abs(factor)
            cells.append(f"{bias:+.2g} +- {err:.2g} (r {bias / re:+.1f})")
        print(f"| {h:g} | " + " | ".join(cells) + " |")
    steps = [h for h in groups if h != h0]
    if len(steps) < 2:
        return
    cells = []
    for q, _ in quantities:
        pts = [(h, *stats(groups[h], q)) for h in steps] + [(h0, *ref[q])]
        if any(m is None or not e for _, m, e in pts):
            cells.append("-")
            continue
        c, var_c, chi2 = weighted_line(pts)
        bias = c * h0 + 0.0
        cells.append(f"{bias:+.2g} +- {math.sqrt(var_c) * h0:.2g} (chi2 {chi2:.2g}, "
                     f"r {bias / ref[q][1]:+.1f})")
    print("| all steps, a line | " + " | ".join(cells) + " |")


def weighted_line(pts):
    """Slope, its variance and chi2 of the line through (h, mean, standard error) points."""
    w = [1.0 / (e * e) for _, _, e in pts]
    s, sx = sum(w), sum(wi * h for wi, (h, _, _) in zip(w, pts))
    sxx = sum(wi * h * h for wi, (h, _, _) in zip(w, pts))
    sy = sum(wi * m for wi, (_, m, _) in zip(w, pts))
    sxy = sum(wi * h * m for wi, (h, m, _) in zip(w, pts))
    det = s * sxx - sx * sx
    c = (s * sxy - sx * sy) / det
    q0 = (sxx * sy - sx * sxy) / det
    chi2 = sum(wi * (m - q0 - c * h) ** 2 for wi, (h, m, _) in zip(w, pts))
    return c, s / det, chi2

if __name__ == "__main__":
    main()
