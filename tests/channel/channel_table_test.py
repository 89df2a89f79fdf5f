#!/usr/bin/python3
"""ctest channel_table: tools/channel_table.py on synthetic channel summaries with known numbers.

The summaries are written into a temporary directory in the format of src/observe/channel.cpp:
two seeds of case B3, case J alone, a case of no Table 1 row, a B3-sized run with the old
format (the scalar written over the channel_u_p profile), and a run of another scene. Each
check says what it compares and why its tolerance is what it is. Run as
    /usr/bin/python3 tests/channel/channel_table_test.py [-k NAME]
Exit 0 if every check passes, 1 otherwise (each failure printed with its numbers).
"""
import json
import math
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
TOOL = ROOT / "tools" / "channel_table.py"
sys.path.insert(0, str(ROOT / "tools"))
import channel_table as ct  # noqa: E402
import suspension_balance as sb  # noqa: E402
from testrun import run_tests

DT = 20.0        # sample interval, a/<u>
ROUND = 1e-12    # relative round-off of the few arithmetic operations behind a mean or an error


def check(cond, msg):
    if not cond:
        raise AssertionError(msg)


def history_centre(tau, t_end, c_inf=4.0, amp=2.0):
    """Interval averages of c(t) = c_inf + amp exp(-t/tau) over [k DT, (k+1) DT], as the observer
    writes them (time = the end of each interval)."""
    t = np.arange(DT, t_end + 0.5 * DT, DT)
    c = c_inf + amp * tau / DT * (np.exp(-(t - DT) / tau) - np.exp(-t / tau))
    return t, c


def summary(phi_b, ha, seed, n, tau, asym, scalars, scene="channel", old_format=False):
    """A channel summary: bins of a/2 as the observer makes them, a symmetric phi profile plus
    asym (2y - 1), a centre-distance history relaxing with time constant tau."""
    bins = max(1, round(2 * ha))
    y = (np.arange(bins) + 0.5) / bins
    phi = phi_b * (1 + 0.5 * np.cos(2 * np.pi * (y - 0.5))) + asym * (2 * y - 1)
    u = list(6 * y * (1 - y))
    T_t, T_i = [0.1] * bins, [0.05] * bins
    u[0] = T_t[0] = T_i[0] = None     # an empty bin (no disc) is written as null
    t_end = 20 * tau
    t, c = history_centre(tau, t_end)
    rows = lambda p: [list(p)] * t.size  # noqa: E731
    s = dict(scene=scene, seed=seed, N=n, strain=t_end, steps=1000, wall_seconds=1.0,
             channel_H_over_a=ha, channel_phi_bulk=phi_b, channel_mean_velocity=1.0,
             channel_coupling="two_way", channel_pressure_gradient_poiseuille=12 / (0.5 * ha) ** 2,
             channel_y=list(y), channel_phi=list(phi), channel_u_p=u, channel_u_f=u,
             channel_T_time=T_t, channel_T_instant=T_i,
             channel_steady=True, channel_steady_time=5 * tau, channel_average_from=5 * tau,
             channel_centre_distance=4.0,
             channel_history=dict(time=list(t), pressure_gradient_ratio=[2.0] * t.size,
                                  centre_distance=list(c), u_p_mean=[1.0] * t.size,
                                  phi=rows(phi), u_p=rows(u), u_f=rows(u), T_time=rows(T_t),
                                  T_instant=rows(T_i)))
    s["channel_u_p" if old_format else "channel_u_p_mean"] = scalars.pop("u_p")
    s.update({f"channel_{k}": v for k, v in scalars.items()})
    if scene != "channel":
        s = {k: v for k, v in s.items() if not k.startswith("channel_")}
    return s


def write(tmp, name, s):
    d = pathlib.Path(tmp) / name
    d.mkdir()
    (d / "summary.json").write_text(json.dumps(s))
    return str(d)


B3 = dict(phi_b=0.4, ha=18.32, n=42)
J = dict(phi_b=0.45, ha=18.32, n=47)
S1 = dict(u_c=1.30, phi_c=0.70, u_p=0.97, Q_p=1.15, dp_ratio=2.10)
S2 = dict(u_c=1.36, phi_c=0.66, u_p=0.99, Q_p=1.19, dp_ratio=2.20)
TAU = {1: 390.0, 2: 430.0}   # not multiples of DT: the crossing falls between rows
TAU_MEAN = 410.0
ASYM = {1: 0.01, 2: 0.03}


def make_runs(tmp):
    r = {}
    for sd, sc in ((1, S1), (2, S2)):
        r[f"b3_{sd}"] = write(tmp, f"b3_{sd}", summary(**B3, seed=sd, tau=TAU[sd], asym=ASYM[sd], scalars=dict(sc)))
    # time constants as (H/a)^3: J's equal to B3's seed mean, the odd case's scaled to H/a = 25
    r["j"] = write(tmp, "j", summary(**J, seed=1, tau=TAU_MEAN, asym=0.0, scalars=dict(S1)))
    r["odd"] = write(tmp, "odd", summary(0.35, 25.0, 1, 69, TAU_MEAN * (25 / 18.32) ** 3, 0.0, dict(S1)))
    r["old"] = write(tmp, "old", summary(0.4, 18.32, 3, 84, 400.0, 0.0, dict(S1), old_format=True))
    r["shear"] = write(tmp, "shear", summary(0.4, 18.32, 1, 42, 400.0, 0.0, dict(S1), scene="simple_shear"))
    return r


def run_cli(*args):
    return subprocess.run([sys.executable, str(TOOL), *args], capture_output=True, text=True, timeout=300)


# ---------------------------------------------------------------------------------------------
def test_seed_mean_and_error():
    """Two seeds of B3: each column is the mean of the two, and its error the standard error
    from the scatter, std(ddof=1)/sqrt(2) = |x1 - x2|/2 (the n-1 formula: with ddof=0 it would
    be |x1 - x2|/(2 sqrt 2)). A few float operations: 1e-12 relative. A single seed has no
    error."""
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        cases = ct.group_cases([ct.load_run(r["b3_1"]), ct.load_run(r["b3_2"]), ct.load_run(r["j"])])
        check([c["label"] for c in cases] == ["B3", "J"], f"labels {[c['label'] for c in cases]}")
        b3, j = cases
        for q, key in (("u_c", "u_c"), ("phi_c", "phi_c"), ("u_p", "u_p"), ("Q_p", "Q_p"), ("dp ratio", "dp_ratio")):
            m, e, n = b3["stats"][q]
            m_ref, e_ref = 0.5 * (S1[key] + S2[key]), 0.5 * abs(S1[key] - S2[key])
            check(n == 2 and abs(m - m_ref) <= ROUND * m_ref and abs(e - e_ref) <= ROUND * m_ref,
                  f"B3 {q}: {m} +- {e} (n {n}), expected {m_ref} +- {e_ref}")
            check(j["stats"][q][1] is None and j["stats"][q][0] == S1[key], f"J {q}: {j['stats'][q]}")
        m, e, n = ct.mean_err([1.0, 2.0, 4.0, None, math.nan])
        check(n == 3 and abs(e - math.sqrt(7 / 3) / math.sqrt(3)) < 1e-15, f"mean_err: {m} {e} {n}")


def test_case_matching():
    """Table 1 rows by phi_b and H/a within 0.01 (the seed prints phi_b to 2 digits and H/a to
    4 figures): 0.409 still matches, 0.411 does not. B1-B5 share phi_b and H/a: 42 mobile discs
    (the seed's 51 minus its 9 wall discs) give B3, 84 give B5, any other count B3 (the seed's
    reference, tau = 1000). Seeds are grouped apart from another disc count or coupling."""
    check(ct.match_table1(0.4, 18.32, 42)[0] == "B3", "B3")
    check(ct.match_table1(0.4, 18.32, 84)[0] == "B5", "B5 by its disc count")
    check(ct.match_table1(0.4, 18.32, None)[0] == "B3", "B3 by default")
    check(ct.match_table1(0.409, 18.329, 42)[0] == "B3", "within 0.01")
    check(ct.match_table1(0.411, 18.32, 42)[0] is None, "phi_b off by 0.011 matched")
    check(ct.match_table1(0.3, 40.4)[0] == "H" and ct.match_table1(0.45, 18.32)[0] == "J", "H, J")
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        cases = ct.group_cases([ct.load_run(r[k]) for k in ("b3_1", "old", "odd", "b3_2")])
        got = {c["label"]: len(c["runs"]) for c in cases}
        check(got == {"B3": 2, "B5": 1, "phi0.35_H25": 1}, f"groups {got}")


def test_old_format_u_p():
    """A summary whose channel_u_p is the scalar (the profile overwritten): the scalar is the
    width-average particle velocity, and the profile is rebuilt from the history rows in the
    averaging window (all rows equal here: the mean of some 300 equal rows differs from them by
    the summation round-off, a few hundred ulps: 1e-12)."""
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        old, new = ct.load_run(r["old"]), ct.load_run(r["b3_1"])
        check(old["u_p_mean"] == S1["u_p"] and new["u_p_mean"] == S1["u_p"], "scalar u_p")
        check(np.allclose(old["profiles"]["u_p"], new["profiles"]["u_p"], rtol=0, atol=1e-12, equal_nan=True),
              "profile from the history")
        check(math.isnan(new["profiles"]["u_p"][0]) and math.isnan(new["profiles"]["T_time"][0]),
              "null bin not nan")


def test_migration_time():
    """An exponential approach c = c_inf + A exp(-t/tau), written as interval averages over
    DT: for equal intervals the averages are an exponential of the interval midpoints with the
    same tau, so the 1 - 1/e crossing measured from the first midpoint is tau itself. Linear
    interpolation of the concave rise 1 - exp(-t/tau) finds it late, by at most
    DT^2/(8 tau) exp(2 DT/tau) (the chord's deficit over its slope; 0.134 at tau = 410, where
    the crossing falls half-way between rows and the error is 0.122): the check is
    0 <= t_e - tau <= that bound. Measured from t = 0 instead, t_e would be late by DT/2 = 10.
    Two seeds (tau 390 and 430): mean within the larger bound (0.142) of 410, standard error
    within half the bound of |430 - 390|/2 = 20. The fit: cases whose tau scale as (H/a)^3 give
    the slope 410/18.32^3 and the ratios within the relative bound DT^2/(8 tau^2) exp(2 DT/tau)
    <= 3.7e-4, and a power-law exponent of 3 within 2.5e-3 (two such errors over the log ratio
    ln(25/18.32) = 0.31)."""
    def bound(tau):
        return DT ** 2 / (8 * tau) * math.exp(2 * DT / tau)
    for tau in (410.0, 400.0, 1000.0 / 3.0):
        t, c = history_centre(tau, 20 * tau)
        te = ct.migration_time(t, c, 4.0)
        check(0.0 <= te - tau <= bound(tau), f"t_e {te} for tau {tau} (bound {bound(tau):.3f})")
    check(ct.migration_time(t, c, c[0]) is None, "no change: no time")
    check(ct.migration_time(t[:3], c[:3], 4.0) is None, "level not reached: no time")
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        cases = ct.group_cases([ct.load_run(r[k]) for k in ("b3_1", "b3_2", "odd")])
        b3 = next(c for c in cases if c["label"] == "B3")
        m, e, n = b3["t_e"]
        check(n == 2 and 0 <= m - TAU_MEAN <= bound(390.0) and abs(e - 20.0) <= 0.5 * bound(390.0),
              f"B3 t_e {m} +- {e}")
        fit = ct.cubic_fit(cases)
        k = TAU_MEAN / 18.32 ** 3
        check(abs(fit["slope"] / k - 1) <= 3.7e-4, f"slope {fit['slope']} vs {k}")
        check(abs(fit["exponent"] - 3) <= 2.5e-3, f"exponent {fit['exponent']}")
        check(all(abs(x / k - 1) <= 3.7e-4 for x in fit["ratios"]), f"ratios {fit['ratios']}")
    # Families: within each (phi_b, coupling) the weighted log fit of ln t_e on ln(H/a). Closed
    # forms: t_e = k_f h^3 exactly in two families gives p = 3 in each to round-off (a fit across
    # families would mix their prefactors); with relative errors r on every case the slope error
    # is r / sqrt(sum (x - xbar)^2) for equal weights; a family of one width gives nothing.
    def case(phi_b, h, t, e=None):
        return dict(phi_b=phi_b, coupling="two_way", h_over_a=h, t_e=(t, e, 2 if e else 1))
    hs = (14.02, 18.32, 30.29, 40.4)
    cs = [case(0.4, h, 0.02 * h ** 3, 0.1 * 0.02 * h ** 3) for h in hs] + \
         [case(0.3, h, 0.07 * h ** 3) for h in hs[:2]] + [case(0.15, 18.32, 1000.0)]
    fam = ct.family_exponents(cs)
    x = np.log(hs)
    check(set(fam) == {(0.4, "two_way"), (0.3, "two_way")}, f"families {sorted(fam)}")
    p4, e4, _ = fam[(0.4, "two_way")]
    check(abs(p4 - 3) < 1e-12 and abs(e4 - 0.1 / math.sqrt(((x - x.mean()) ** 2).sum())) < 1e-12,
          f"phi 0.4: p {p4} +- {e4}")
    p3, e3, _ = fam[(0.3, "two_way")]
    check(abs(p3 - 3) < 1e-12 and e3 is None, f"phi 0.3: p {p3} +- {e3}")


def test_symmetry():
    """phi = symmetric + a (2y - 1): the rms of (phi(y) - phi(1 - y))/2 over the pairs of the
    lower half is |a| rms(2y - 1); for two seeds the seed
    scatter per bin is |a1 - a2| |2y - 1|/sqrt 2, so the noise level sigma/sqrt 2 is
    |a1 - a2|/2 rms(2y - 1) over the bins. Closed forms: 1e-12 relative."""
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        runs = [ct.load_run(r["b3_1"]), ct.load_run(r["b3_2"])]
        y = np.asarray(runs[0]["channel_y"])
        lower = 2 * y[:y.size // 2] - 1
        for run, a in zip(runs, (ASYM[1], ASYM[2])):
            rms, _ = ct.asymmetry([run])[0]
            ref = a * math.sqrt(np.mean(lower ** 2))
            check(abs(rms / ref - 1) < 1e-12, f"rms {rms} vs {ref}")
        text = ct.symmetry_text(ct.group_cases(runs), markdown=True)
        noise = 0.5 * abs(ASYM[1] - ASYM[2]) * math.sqrt(np.mean((2 * y - 1) ** 2))
        check(f"| {noise:.4f} |" in text, f"noise {noise:.4f} not in\n{text}")


def test_cli_table():
    """The printed table: B3's cells "seed / ours +- err / SBM" with the SBM value of
    suspension_balance for (0.4, 18.32) (3 decimals, as printed), the lone J without an error,
    the case of no Table 1 row with "-" for the seed, the steady time and the run lengths."""
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        p = run_cli(r["b3_1"], r["b3_2"], r["j"], r["odd"], "--markdown")
        check(p.returncode == 0, f"exit {p.returncode}: {p.stderr}")
        sbm = sb.suspension_balance(0.4, 18.32)
        row = next(line for line in p.stdout.splitlines() if line.startswith("| B3 |"))
        for cell in (f"1.34 / 1.330 +- 0.030 / {sbm.u_c:.3f}", f"0.69 / 0.680 +- 0.020 / {sbm.phi_c:.3f}",
                     "0.973 / 0.980 +- 0.010 / 1.000", f"2.08 / 2.150 +- 0.050 / {sbm.dp_ratio:.3f}",
                     "| 2050 +- 100 |", "| 4800 / 8200 +- 400 |", "| 2 |"):
            check(cell in row, f"{cell!r} not in {row}")
        row = next(line for line in p.stdout.splitlines() if line.startswith("| J |"))
        check("1.32 / 1.300 / " in row and "+-" not in row.split("|")[5], f"J row {row}")
        check(any(line.startswith("| phi0.35_H25 |") and "| - / 1.300 / " in line
                  for line in p.stdout.splitlines()), "unmatched case")
        check("k = " in p.stdout and "p = 3.00" in p.stdout, "migration fit not printed")
        p = run_cli(r["j"], "--no-model")
        check(p.returncode == 0 and "1.32 / 1.300 / -" in p.stdout and "not steady" not in p.stdout,
              f"--no-model: {p.stdout}{p.stderr}")


def test_figures():
    """--figures writes the three PNGs (each over 10 kB: a blank figure is smaller); the
    continuum models are drawn for a single case only (draw_model called once, not for two)."""
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        out = pathlib.Path(tmp) / "figs"
        p = run_cli(r["b3_1"], r["b3_2"], r["odd"], "--figures", str(out), "--no-model")
        check(p.returncode == 0, f"exit {p.returncode}: {p.stderr}")
        for f in ("traces.png", "profiles.png", "symmetry.png"):
            check((out / f).is_file() and (out / f).stat().st_size > 10000, f"{f} missing or blank")
        calls = []
        real = ct.sb.draw_model
        ct.sb.draw_model = lambda *a, **k: calls.append(a[1:3]) or real(*a, **k)
        try:
            ct.figures(ct.group_cases([ct.load_run(r["j"])]), str(out / "one"))
            ct.figures(ct.group_cases([ct.load_run(r["j"]), ct.load_run(r["odd"])]), str(out / "two"))
        finally:
            ct.sb.draw_model = real
        check(calls == [(0.45, 18.32)], f"draw_model calls {calls}")


def test_refusals():
    """A directory without summary.json, a summary of another scene and unreadable JSON: exit 1,
    the reason on stderr, nothing on stdout (no partial table)."""
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        empty = pathlib.Path(tmp) / "empty"
        empty.mkdir()
        bad = pathlib.Path(tmp) / "bad"
        bad.mkdir()
        (bad / "summary.json").write_text("{not json")
        for d, why in ((empty, "no summary.json"), (r["shear"], "not a channel run"), (bad, "unreadable")):
            p = run_cli(r["j"], str(d), "--no-model")
            check(p.returncode == 1 and why in p.stderr and p.stdout == "",
                  f"{d}: exit {p.returncode}, stderr {p.stderr!r}, stdout {p.stdout[:80]!r}")


def test_history_in_channel_h5():
    """A run of the old layout (history in summary.json) moved by tools/channel_history_to_h5.py:
    the summary loses the history and names channel.h5; load_run then gives the same history
    (float64 series exactly, profiles to float32's 1e-7 relative, empty bins still nan), the
    same steady profiles and the same migration time. A second pass leaves the pair alone."""
    import channel_history_to_h5 as mv
    with tempfile.TemporaryDirectory() as tmp:
        r = make_runs(tmp)
        before = ct.load_run(r["b3_1"])
        check(mv.main([r["b3_1"]]) == 0, "converter failed")
        s = json.loads((pathlib.Path(r["b3_1"]) / "summary.json").read_text())
        check("channel_history" not in s and s.get("channel_history_file") == "channel.h5",
              f"summary keys after the move: {sorted(s)[:5]}...")
        after = ct.load_run(r["b3_1"])
        hb, ha = before["channel_history"], after["channel_history"]
        for k in ct.HISTORY_SERIES:
            check(ha[k] == list(hb[k]), f"series {k} changed")
        for k in ct.PROFILES:
            a = np.array(ha[k], float)
            b = np.array([[math.nan if x is None else x for x in row] for row in hb[k]], float)
            check(a.shape == b.shape and np.array_equal(np.isnan(a), np.isnan(b))
                  and np.allclose(a, b, rtol=1e-7, atol=0, equal_nan=True), f"profile {k}")
        for k in ct.PROFILES:
            check(np.allclose(after["profiles"][k], before["profiles"][k], rtol=1e-7, equal_nan=True),
                  f"steady {k}")
        t_b = ct.migration_time(hb["time"], hb["centre_distance"], before["channel_centre_distance"])
        t_a = ct.migration_time(ha["time"], ha["centre_distance"], after["channel_centre_distance"])
        check(t_a == t_b, f"migration time {t_a} against {t_b}")
        h5 = (pathlib.Path(r["b3_1"]) / "channel.h5").read_bytes()
        check(mv.main([r["b3_1"]]) == 0 and (pathlib.Path(r["b3_1"]) / "channel.h5").read_bytes() == h5,
              "second pass touched the files")


def main():
    return run_tests(globals(), __doc__)


if __name__ == "__main__":
    sys.exit(main())
