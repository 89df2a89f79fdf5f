#!/usr/bin/python3
"""The seed's Table 1 and figures 2, 4, 7, 8, 10 from channel runs (Nott & Brady 1994).

Reads RUN_DIR/summary.json and the history in RUN_DIR/channel.h5 of `channel` runs
(src/observe/channel.cpp writes both; runs written before channel.h5 existed keep the history in
summary.json, which is read as well) and

- groups the runs by case: bulk areal fraction, H/a, coupling and number of discs. Seeds of one
  case are averaged; the error is the standard error of the seed scatter, std(ddof=1)/sqrt(n),
  and is shown only with 2 or more seeds;
- matches each case to the seed's Table 1 row with the same phi_b and H/a (within 0.01). B1-B5
  share these; the disc count then picks B5 (twice the cell), and otherwise B3 (tau = 1000, the
  seed's reference);
- prints, per case, "seed / ours (+- err) / SBM" for u_c, phi_c, u_p (the width average of the
  particle velocity), Q_p and the pressure-gradient ratio. SBM is the suspension-balance model
  of tools/suspension_balance.py. It also prints the steady time and the run length (seed /
  ours);
- prints the migration time: the time for the mean distance of the discs from the centreline to
  cover 1 - 1/e of its change, from the first history row to the steady mean. It is measured from
  the midpoint of the first sample interval, which is the time that row's average stands for,
  so an exponential approach gives its time constant. The fit t = k (H/a)^3 across cases, and
  the exponent of a power law where the cases have more than one H/a (over all cases, and per
  family of one phi_b and coupling, with errors from the seeds' scatter), test the seed's
  t_steady ~ (H/a)^3 a/<u> (its section 2);
- prints the asymmetry of the steady phi profile, phi(y/H) against phi(1 - y/H). This is the rms
  of the antisymmetric part, next to what the seed scatter alone would give;
- with --figures OUT_DIR, writes traces.png (centre distance and pressure-gradient ratio against
  time, one line per run: seed figure 2), profiles.png (phi, u and T against y/H, one colour per
  case: seed figures 4, 7, 8, 10; for a single case with both continuum models) and
  symmetry.png.

Usage
-----
    /usr/bin/python3 tools/channel_table.py runs/channel_B3_s1 runs/channel_B3_s2 runs/channel_J
    /usr/bin/python3 tools/channel_table.py runs/channel_* --markdown --figures figs/
    /usr/bin/python3 tools/channel_table.py RUN ... --no-model      # skip the SBM column

Exit status 1 (and nothing printed on stdout) if a directory has no summary.json, or holds a run
of another scene.
"""
import argparse
import json
import math
import os
import sys
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rundir  # noqa: E402  (tools/rundir.py: what every tool reads of a run)
import suspension_balance as sb  # noqa: E402

# Table columns: (label, our summary key (None: the width-average u_p of load_run), Table 1 /
# Profile field).
QUANTITIES = [("u_c", "channel_u_c", "u_c"), ("phi_c", "channel_phi_c", "phi_c"),
              ("u_p", None, "u_p"), ("Q_p", "channel_Q_p", "Q_p"),
              ("dp ratio", "channel_dp_ratio", "dp_ratio")]
PROFILES = ("phi", "u_p", "u_f", "T_time", "T_instant")
MATCH_TOL = 0.01
E_FRACTION = 1.0 - math.exp(-1.0)


class RunError(Exception):
    """A directory that is not a finished channel run."""


def _num(x):
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) else math.nan


def load_run(path):
    """The summary of a channel run, with the scalar width-average particle velocity under
    "u_p_mean" and the steady profiles under "profiles" (numpy arrays, nan for empty bins)."""
    f = str(rundir.Run(path).file("summary"))
    if not os.path.isfile(f):
        raise RunError(f"{path}: no summary.json (not a run directory, or the run has not finished)")
    try:
        with open(f) as fh:
            s = json.load(fh)
    except (OSError, ValueError) as e:
        raise RunError(f"{f}: unreadable ({e})")
    if not isinstance(s, dict) or "channel_H_over_a" not in s or "channel_phi_bulk" not in s:
        scene = s.get("scene", "?") if isinstance(s, dict) else "?"
        raise RunError(f"{f}: not a channel run (scene {scene!r}, no channel_H_over_a)")
    s["path"] = path
    if "channel_history" not in s:
        s["channel_history"] = load_history(path)
    # The scalar is channel_u_p_mean; an older writer overwrote the profile channel_u_p with it.
    u_p = s.get("channel_u_p")
    s["u_p_mean"] = _num(s.get("channel_u_p_mean", u_p if not isinstance(u_p, list) else None))
    s["profiles"] = {k: steady_profile(s, k) for k in PROFILES}
    return s


HISTORY_SERIES = ("time", "pressure_gradient_ratio", "centre_distance", "u_p_mean")


def load_history(path):
    """RUN_DIR/channel.h5's /channel_history as the dict of lists that summary.json once held
    (profile rows as lists, nan for an empty bin); {} if the run has no such file."""
    f = rundir.Run(path).file("channel")
    if not f.is_file():
        return {}
    try:
        with rundir.open_h5(f) as h5:
            g = h5["channel_history"]
            return {k: np.asarray(g[k], float).tolist() for k in HISTORY_SERIES + PROFILES}
    except (OSError, KeyError) as e:
        raise RunError(f"{f}: unreadable ({e})")


def steady_profile(s, key):
    """The steady profile `key`; if the summary holds no list for it, the mean of the history
    rows in the averaging window (equal-weight intervals: a fallback, not the exact average)."""
    v = s.get("channel_" + key)
    if isinstance(v, list):
        return np.array([math.nan if x is None else x for x in v], float)
    h = s.get("channel_history", {})
    rows, t = h.get(key), h.get("time")
    n = len(s.get("channel_y", []))
    if not rows or not t:
        return np.full(n, math.nan)
    start = np.concatenate([[0.0], t[:-1]])
    keep = start >= _num(s.get("channel_average_from", 0.0)) - 1e-9
    a = np.array([[math.nan if x is None else x for x in r] for r in rows], float)[keep]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(a, axis=0) if len(a) else np.full(n, math.nan)


def migration_time(time, centre, steady_centre):
    """Time for the centre distance to cover 1 - 1/e of its change from the first row to
    steady_centre, from the first interval's midpoint (rows are interval averages: for equal
    intervals an exponential stays an exponential of the midpoints, same time constant). Linear
    interpolation between rows; None if the change is nil or the level is never reached."""
    t = np.asarray(time, float)
    c = np.asarray(centre, float)
    if t.size < 2 or not math.isfinite(steady_centre) or steady_centre == c[0]:
        return None
    mid = 0.5 * (t + np.concatenate([[0.0], t[:-1]]))
    f = (c - c[0]) / (steady_centre - c[0])
    k = int(np.argmax(f >= E_FRACTION))
    if f[k] < E_FRACTION:
        return None
    tk = mid[k - 1] + (E_FRACTION - f[k - 1]) / (f[k] - f[k - 1]) * (mid[k] - mid[k - 1])
    return float(tk - mid[0])


def mean_err(values):
    """(mean, standard error from the scatter (None below 2 values), n) of the finite values."""
    v = np.array([x for x in values if x is not None and math.isfinite(x)], float)
    if v.size == 0:
        return math.nan, None, 0
    return float(v.mean()), (float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else None), v.size


def match_table1(phi_b, h_over_a, n_mobile=None):
    """(name, row) of the seed's Table 1 for this phi_b and H/a, or (None, None)."""
    hits = [c for c, r in sb.TABLE1.items()
            if abs(r["phi_b"] - phi_b) <= MATCH_TOL and abs(r["h_over_a"] - h_over_a) <= MATCH_TOL]
    # The seed's N counts one row of wall discs too; our N is the mobile discs alone.
    same_cell = [c for c in hits if sb.TABLE1[c]["N"] - sb.TABLE1[c]["N_w"] == n_mobile]
    hits = same_cell or hits
    if not hits:
        return None, None
    name = "B3" if "B3" in hits else hits[0]
    return name, sb.TABLE1[name]


def group_cases(runs):
    """Runs grouped by (phi_b, H/a, coupling, N), each group a dict with its statistics."""
    groups = {}
    for s in runs:
        key = (round(_num(s["channel_phi_bulk"]), 4), round(_num(s["channel_H_over_a"]), 4),
               s.get("channel_coupling", "?"), s.get("N"))
        groups.setdefault(key, []).append(s)
    cases = []
    for (phi_b, ha, coupling, n), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        seeds = [r.get("seed") for r in rs]
        if len(set(seeds)) < len(seeds):
            print(f"channel_table.py: warning: case phi_b {phi_b}, H/a {ha} has repeated seeds {seeds}: "
                  "they are not independent samples", file=sys.stderr)
        name, row = match_table1(phi_b, ha, n)
        label = (name or f"phi{phi_b:g}_H{ha:g}") + ("" if coupling == "two_way" else f" ({coupling})")
        c = dict(label=label, name=name, row=row, phi_b=phi_b, h_over_a=ha, coupling=coupling,
                 runs=rs, seeds=seeds)
        c["stats"] = {q: mean_err([_num(r.get(key)) if key else r["u_p_mean"] for r in rs])
                      for q, key, _ in QUANTITIES}
        steady = [_num(r.get("channel_steady_time")) for r in rs if r.get("channel_steady")]
        c["steady"] = mean_err(steady)
        c["n_steady"] = len(steady)
        c["run_length"] = mean_err([_num(r.get("strain")) for r in rs])
        c["migration"] = [migration_time(r["channel_history"]["time"], r["channel_history"]["centre_distance"],
                                         _num(r.get("channel_centre_distance")))
                          if r.get("channel_history", {}).get("time") else None for r in rs]
        c["t_e"] = mean_err(c["migration"])
        cases.append(c)
    labels = [c["label"] for c in cases]
    for c in cases:   # same phi_b and H/a, another cell: the disc count tells them apart
        if labels.count(c["label"]) > 1:
            c["label"] += f" N={c['runs'][0].get('N')}"
    return cases


def model_for(case):
    """The suspension-balance Profile of the case, or None where the model has no solution."""
    try:
        return sb.suspension_balance(case["phi_b"], case["h_over_a"])
    except (ValueError, RuntimeError) as e:
        print(f"channel_table.py: no SBM solution for {case['label']}: {e}", file=sys.stderr)
        return None


def _fmt(x, digits=3):
    return "-" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def _ours(stat, digits=3):
    m, e, _ = stat
    return _fmt(m, digits) + ("" if e is None else f" +- {_fmt(e, digits)}")


def table_rows(cases, models):
    head = ["case", "phi_b", "H/a", "seeds"] + [f"{q} seed / ours / SBM" for q, _, _ in QUANTITIES] + \
           ["steady time", "run length seed / ours"]
    rows = [head]
    for c in cases:
        row, m = c["row"], models.get(c["label"])
        cells = [c["label"], f"{c['phi_b']:.2f}", f"{c['h_over_a']:.2f}", str(len(c["runs"]))]
        for q, _, field in QUANTITIES:
            seed = _fmt(row[field], 3 if field == "u_p" else 2) if row else "-"
            cells.append(f"{seed} / {_ours(c['stats'][q])} / {_fmt(getattr(m, field)) if m else '-'}")
        n = len(c["runs"])
        if c["n_steady"] == 0:
            steady = "not steady"
        else:
            steady = _ours(c["steady"], 0) + ("" if c["n_steady"] == n else f" ({c['n_steady']}/{n} steady)")
        cells += [steady, f"{row['t_run'] if row else '-'} / {_ours(c['run_length'], 0)}"]
        rows.append(cells)
    return rows


def render(rows, markdown):
    if markdown:
        out = ["| " + " | ".join(rows[0]) + " |", "|" + " --- |" * len(rows[0])]
        return "\n".join(out + ["| " + " | ".join(r) + " |" for r in rows[1:]])
    w = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return "\n".join("  ".join(x.ljust(w[i]) for i, x in enumerate(r)).rstrip() for r in rows)


def cubic_fit(cases):
    """t_e = k (H/a)^3 by least squares through the origin; the ratio per case; and the
    exponent of a power law t_e = A (H/a)^p where the cases span more than one H/a."""
    pts = [(c["h_over_a"], c["t_e"][0]) for c in cases if math.isfinite(c["t_e"][0])]
    if not pts:
        return None
    x = np.array([h ** 3 for h, _ in pts])
    t = np.array([v for _, v in pts])
    out = dict(slope=float(np.dot(x, t) / np.dot(x, x)), ratios=(t / x).tolist(), exponent=None)
    if len({h for h, _ in pts}) > 1 and np.all(t > 0):
        out["exponent"] = float(np.polyfit(np.log([h for h, _ in pts]), np.log(t), 1)[0])
    return out


def family_exponents(cases):
    """The exponent p of t_e = A (H/a)^p within each family of cases sharing phi_b and coupling
    (the seed's (H/a)^3 is a statement at fixed phi_b): {(phi_b, coupling): (p, err, widths)}
    for families spanning two or more H/a. err propagates the cases' seed-scatter errors through
    the weighted fit of ln t_e on ln(H/a) (None unless every case has one)."""
    fams = {}
    for c in cases:
        m, e, _ = c["t_e"]
        if math.isfinite(m) and m > 0:
            fams.setdefault((c["phi_b"], c["coupling"]), []).append((c["h_over_a"], m, e))
    out = {}
    for key, pts in sorted(fams.items()):
        if len({h for h, _, _ in pts}) < 2:
            continue
        x = np.log([h for h, _, _ in pts])
        y = np.log([m for _, m, _ in pts])
        if all(e is not None and e > 0 for _, _, e in pts):
            w = np.array([(m / e) ** 2 for _, m, e in pts])  # 1 / var(ln t_e)
            xb = np.dot(w, x) / w.sum()
            sxx = np.dot(w, (x - xb) ** 2)
            p = float(np.dot(w, (x - xb) * (y - np.dot(w, y) / w.sum())) / sxx)
            out[key] = (p, float(1.0 / math.sqrt(sxx)), sorted({h for h, _, _ in pts}))
        else:
            out[key] = (float(np.polyfit(x, y, 1)[0]), None, sorted({h for h, _, _ in pts}))
    return out


def migration_text(cases, markdown):
    rows = [["case", "H/a", "(H/a)^3", "t_e (a/<u>)", "t_e / (H/a)^3", "steady time / (H/a)^3"]]
    for c in cases:
        x = c["h_over_a"] ** 3
        m, e, _ = c["t_e"]
        rows.append([c["label"], f"{c['h_over_a']:.2f}", f"{x:.0f}", _ours(c["t_e"], 0),
                     _fmt(m / x, 4) + ("" if e is None else f" +- {_fmt(e / x, 4)}"),
                     _fmt(c["steady"][0] / x, 4) if c["n_steady"] else "not steady"])
    fit = cubic_fit(cases)
    tail = ("no case reaches 1 - 1/e of its migration" if fit is None else
            f"fit t_e = k (H/a)^3 through the origin: k = {fit['slope']:.4g}" +
            ("" if fit["exponent"] is None else f"; power law t_e ~ (H/a)^p: p = {fit['exponent']:.2f}"
             " (seed: 3)"))
    for (phi_b, coupling), (p, e, hs) in family_exponents(cases).items():
        tail += (f"\nphi_b {phi_b:g} ({coupling}), H/a = {', '.join(f'{h:g}' for h in hs)}: "
                 f"t_e ~ (H/a)^p, p = {p:.2f}" + ("" if e is None else f" +- {e:.2f}") + " (seed: 3)")
    return render(rows, markdown) + "\n\n" + tail


def asymmetry(runs):
    """Per run: rms over bin pairs of the antisymmetric part (phi(y) - phi(1 - y))/2, and the
    offset of the phi centroid from the centreline in H (positive: towards the top wall)."""
    out = []
    for r in runs:
        p, y = r["profiles"]["phi"], np.asarray(r["channel_y"], float)
        half = p.size // 2
        d = 0.5 * (p[:half] - p[::-1][:half])
        d = d[np.isfinite(d)]
        ok = np.isfinite(p)
        out.append((float(np.sqrt(np.mean(d ** 2))) if d.size else math.nan,
                    float(np.sum(p[ok] * (y[ok] - 0.5)) / np.sum(p[ok])) if ok.any() else math.nan))
    return out


def case_profile(case, key):
    """Seed mean and standard error (nan below 2 seeds) of a steady profile, per bin."""
    a = np.array([r["profiles"][key] for r in case["runs"]], float)
    n = np.sum(np.isfinite(a), axis=0)
    with warnings.catch_warnings():   # empty bins and single seeds: nan, as meant
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(a, axis=0)
        err = np.where(n > 1, np.nanstd(a, axis=0, ddof=1) / np.sqrt(np.maximum(n, 1)), math.nan)
    return mean, err


def symmetry_text(cases, markdown):
    rows = [["case", "seeds", "rms (phi(y) - phi(1-y))/2", "centroid offset (H)", "seed scatter / sqrt 2",
             "rms / expected"]]
    for c in cases:
        asym = asymmetry(c["runs"])
        rms, off = mean_err([a for a, _ in asym]), mean_err([o for _, o in asym])
        # The antisymmetric part of independent bin noise of std sigma has rms sigma/sqrt 2.
        noise = math.nan
        if len(c["runs"]) > 1:
            a = np.array([r["profiles"]["phi"] for r in c["runs"]], float)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                noise = float(np.sqrt(np.nanmean(np.nanstd(a, axis=0, ddof=1) ** 2) / 2.0))
        rows.append([c["label"], str(len(c["runs"])), _ours(rms, 4), _ours(off, 4), _fmt(noise, 4),
                     _fmt(rms[0] / noise, 2) if noise > 0 else "-"])
    return render(rows, markdown)


# ---- figures -------------------------------------------------------------------------------------
COLOURS = ["C2", "C1", "C4", "C5", "C6", "C8", "C9", "C7"]   # C0 and C3 are the models' colours


def figures(cases, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(out_dir, exist_ok=True)
    written = []
    colour = {c["label"]: COLOURS[i % len(COLOURS)] for i, c in enumerate(cases)}

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    styles = ["-", "--", ":", "-."]
    for c in cases:
        for i, r in enumerate(c["runs"]):
            h = r.get("channel_history", {})
            if not h.get("time"):
                continue
            kw = dict(color=colour[c["label"]], ls=styles[i % len(styles)], lw=1.2,
                      label=f"{c['label']} seed {r.get('seed')}")
            ax1.plot(h["time"], h["centre_distance"], **kw)
            ax2.plot(h["time"], h["pressure_gradient_ratio"], **kw)
            if r.get("channel_steady"):
                ax1.axvline(_num(r.get("channel_steady_time")), color=colour[c["label"]], lw=0.6, ls=":")
    ax1.set_ylabel("mean |y - y_centre| / d")
    ax2.set_ylabel("G / G_Poiseuille")
    ax2.set_xlabel("t <u>/a")
    ax1.legend(fontsize=7, ncol=2)
    ax1.set_title("migration (dotted verticals: detected steady state)")
    fig.tight_layout()
    written.append(_save(fig, out_dir, "traces.png"))

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    if len(cases) == 1:
        sb.draw_model(axes, cases[0]["phi_b"], cases[0]["h_over_a"], parabola=False)
    for c in cases:
        col, y = colour[c["label"]], np.asarray(c["runs"][0]["channel_y"], float)
        phi, phi_e = case_profile(c, "phi")
        axes[0].errorbar(y, phi, yerr=_bars(phi_e), fmt="o", ms=3, color=col, label=c["label"])
        up, up_e = case_profile(c, "u_p")
        axes[1].errorbar(y, up, yerr=_bars(up_e), fmt="o", ms=3, color=col, label=f"{c['label']} particles")
        axes[1].plot(y, case_profile(c, "u_f")[0], "-", color=col, lw=1, label=f"{c['label']} fluid")
        axes[2].plot(y, case_profile(c, "T_time")[0], "o-", ms=3, lw=0.8, color=col,
                     label=f"{c['label']} T about the time mean")
        axes[2].plot(y, case_profile(c, "T_instant")[0], "s--", ms=3, lw=0.8, mfc="none", color=col,
                     label=f"{c['label']} T about the instantaneous mean")
    s = np.linspace(0, 1, 201)
    axes[1].plot(s, 6 * s * (1 - s), "k-", lw=2, label="Poiseuille 6 s (1 - s)")
    for ax, name in zip(axes, (r"$\phi$", r"$u/\langle u\rangle$", r"$T/(\langle u\rangle^2 (a/H)^2)$")):
        ax.set_xlabel("y/H")
        ax.set_ylabel(name)
        ax.set_xlim(0, 1)
        ax.legend(fontsize=6)
    fig.tight_layout()
    written.append(_save(fig, out_dir, "profiles.png"))

    fig, ax = plt.subplots(figsize=(5, 5))
    for c in cases:
        phi, err = case_profile(c, "phi")
        half = phi.size // 2
        ax.errorbar(phi[:half], phi[::-1][:half], xerr=_bars(err[:half]), yerr=_bars(err[::-1][:half]), fmt="o", ms=3,
                    color=colour[c["label"]], label=c["label"])
    top = max(0.9, ax.get_xlim()[1], ax.get_ylim()[1])
    ax.plot([0, top], [0, top], "k-", lw=0.8)
    ax.set_xlabel(r"$\phi(y/H)$, lower half")
    ax.set_ylabel(r"$\phi(1 - y/H)$")
    ax.set_title("symmetry of the steady profile (bars: seed standard error)", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    written.append(_save(fig, out_dir, "symmetry.png"))
    plt.close("all")
    return written


def _bars(err):
    return None if not np.isfinite(err).any() else np.nan_to_num(err)


def _save(fig, out_dir, name):
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=120)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("runs", nargs="+", metavar="RUN_DIR")
    ap.add_argument("--markdown", action="store_true", help="markdown tables")
    ap.add_argument("--figures", metavar="OUT_DIR", help="write traces.png, profiles.png, symmetry.png")
    ap.add_argument("--no-model", action="store_true", help="leave out the suspension-balance column")
    a = ap.parse_args(argv)
    try:
        runs = [load_run(p) for p in a.runs]
    except RunError as e:
        print(f"channel_table.py: {e}", file=sys.stderr)
        return 1
    cases = group_cases(runs)
    models = {} if a.no_model else {c["label"]: model_for(c) for c in cases}
    print(render(table_rows(cases, models), a.markdown))
    print("\nMigration time t_e (centre distance at 1 - 1/e of its change; seed section 2: ~ (H/a)^3):\n")
    print(migration_text(cases, a.markdown))
    print("\nAsymmetry of the steady phi profile:\n")
    print(symmetry_text(cases, a.markdown))
    if a.figures:
        for p in figures(cases, a.figures):
            print(f"wrote {p}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
