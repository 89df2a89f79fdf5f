#!/usr/bin/python3
"""tools/results_table.py on a synthetic store with a known answer: one J-sweep group whose
J = 1e-3 row lies 0.01 above the seed's phi law and at 1.5x its D law, 1x its dv and Psi laws;
the per-J table must read those (+0.0100, 1.50, 1.00); a store of spheres has its phi law set
against Boyer et al.'s; and a store without J fits (channel cases over seeds) must be refused
with a reason. Usage: results_table_test.py REPO WORK"""
import csv
import json
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
work.mkdir(parents=True, exist_ok=True)
J = 1e-3
row = {"J": J, "runs": 3, "phi": 0.81 - 0.64 * J ** 0.5 + 0.01, "phi_sem": 0.001,
       "D": 1.5 * 0.024 * J ** -0.26, "D_sem": 0.003, "dv": 0.258 * J ** -0.25, "dv_sem": 0.01,
       "psi": 0.35 * J ** 0.24, "psi_sem": 0.001, "mu": 0.3, "mu_sem": 0.001}
law = {"a": 1.0, "a_stderr": 0.1, "b": -0.25, "b_stderr": 0.01}
names = ["D_vs_J", "dv_vs_J", "psi_vs_J", "D_vs_phic_minus_phi", "dv_vs_phic_minus_phi",
         "psi_vs_phic_minus_phi"]
fits = {"points": 3, "finished": 3, "seed_table1": {n: law for n in names},
        "groups": [{"axes": {}, "rows": [row],
                    "fits": dict({n: law for n in names},
                                 phi_of_J={"error": "too few"}, mu_of_J={"error": "too few"})}]}
(work / "fits.json").write_text(json.dumps(fits))
# Runs on exact laws (two seeds at +-2 %): the exponents over every part of the range are the
# laws' own, with phi = 0.81 - 0.64 J^(1/2).
with open(work / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=["point", "status", "J", "D", "dv", "psi", "phi",
                                      "steps_per_strain", "ms_per_step", "strain",
                                      "wall_seconds"])
    w.writeheader()
    for j in (1e-4, 1e-3, 1e-2, 3e-2, 1e-1):
        for s, x in ((1, 1.02), (2, 0.98)):
            w.writerow({"point": f"J={j:g}_seed={s}", "status": "done", "J": j,
                        "D": x * 0.024 * j ** -0.26, "dv": x * 0.258 * j ** -0.25,
                        "psi": x * 0.35 * j ** 0.24, "phi": 0.81 - 0.64 * j ** 0.5,
                        "steps_per_strain": 7000, "ms_per_step": 7.0, "strain": 33.0,
                        "wall_seconds": 3600.0})
tool = [sys.executable, str(repo / "tools/results_table.py"), str(work)]
out = subprocess.run(tool, capture_output=True, text=True, check=True).stdout
start = out.index("Every J against")
line = next(l for l in out[start:].splitlines() if l.startswith("| 0.001 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[3] == "+0.0100", f"phi - seed's law {cells[3]!r}: want +0.0100"
assert cells[6].startswith("1.50"), f"D ratio {cells[6]!r}: want 1.50"
assert cells[9].startswith("1.00") and cells[12].startswith("1.00"), line
cost = next(l for l in out[out.index("Cost per run"):].splitlines() if l.startswith("| 0.001 |"))
assert "| 2 | 7000 | 7.0 | 33.0 | 1.00 |" in cost, cost
ranges = out[out.index("Exponents over parts"):].splitlines()
full = next(l for l in ranges if l.startswith("| 0.0001 - 0.1 |"))
cells = [c.strip() for c in full.strip("|").split("|")]
assert cells[2].startswith("-0.26 ") and cells[3].startswith("-0.25 "), full
assert cells[4].startswith("0.24 ") and "b = 0.5 " in cells[5], full
# --ranges prints that table alone, the same rows without the heading.
only = subprocess.run([sys.executable, str(repo / "tools/results_table.py"), "--ranges",
                       str(work)], capture_output=True, text=True, check=True).stdout
assert only.splitlines()[0].startswith("| J range |") and full in only.splitlines(), only
# Spheres (sweep.csv's dimension = 3): their phi law is set against Boyer et al.'s J -> 0 form,
# phi_m (1 - J^1/2) with phi_m = 0.585, not against the discs' phi_c = 0.81; phi_c = 0.590 +- 0.005
# is 1.0 standard error from it (19.7 combined errors from the discs' 0.81 +- 0.01).
spheres = work / "spheres"
spheres.mkdir(exist_ok=True)
sphere_fits = json.loads((work / "fits.json").read_text())
sphere_fits["groups"][0]["fits"]["phi_of_J"] = {"phi_c": 0.590, "phi_c_stderr": 0.005, "a": 0.5,
                                                "a_stderr": 0.01, "b": 0.5, "b_stderr": 0.01}
(spheres / "fits.json").write_text(json.dumps(sphere_fits))
with open(work / "sweep.csv") as src, open(spheres / "sweep.csv", "w", newline="") as dst:
    rows = list(csv.DictReader(src))
    w = csv.DictWriter(dst, fieldnames=list(rows[0]) + ["dimension"])
    w.writeheader()
    for r in rows:
        w.writerow(dict(r, dimension=3))
out = subprocess.run([sys.executable, str(repo / "tools/results_table.py"), "--laws", str(spheres)],
                     capture_output=True, text=True, check=True).stdout
phi_row = next(l for l in out.splitlines() if l.startswith("| phi = phi_c"))
assert "phi_m = 0.585" in phi_row and "phi_c: agrees (1.0 sigma)" in phi_row, phi_row
# A store of channel cases: no J fits, refused with the reason.
fits = {"points": 2, "finished": 2, "groups": []}
(work / "fits.json").write_text(json.dumps(fits))
r = subprocess.run(tool, capture_output=True, text=True)
assert r.returncode != 0 and "no J fits" in r.stderr, (r.returncode, r.stderr)
# --compare: a run 10 % above the reference in D with both error bars 0.003 (z = 0.01 /
# sqrt(2 x 0.003^2) = +2.4), the same phi.
for name, d in (("ref", 0.1), ("other", 0.11)):
    (work / name).mkdir(exist_ok=True)
    (work / name / "summary.json").write_text(json.dumps(
        {"phi": 0.8, "phi_err": 0.001, "D": d, "D_err": 0.003, "dv": 3.0, "dv_err": 0.01}))
out = subprocess.run([sys.executable, str(repo / "tools/results_table.py"), "--compare",
                      str(work / "ref"), str(work / "other")],
                     capture_output=True, text=True, check=True).stdout
other = next(l for l in out.splitlines() if l.startswith(f"| {work / 'other'} |"))
cells = [c.strip() for c in other.strip("|").split("|")]
assert cells[3] == "0.11 +- 0.003 (1.100, z +2.4)", cells[3]
assert cells[1] == "0.8 +- 0.001 (1.000, z +0.0)", cells[1]
assert cells[6] == "-", cells[6]
# --discs: discs with D = 0.1 J^-1/2 at J = 0.01 and 0.04 (errors 1 %), spheres at J = 0.02
# with half that D and at J = 0.04 with the same: the discs' D at 0.02 is the power law between
# their neighbours, exactly 0.1 x 0.02^-1/2, so the ratios are 0.500 and 1.000.
def store(path, rows):
    path.mkdir(exist_ok=True)
    (path / "fits.json").write_text(json.dumps(
        {"points": len(rows), "finished": len(rows), "groups": [{"axes": {}, "rows": rows}]}))
    (path / "sweep.csv").write_text("point,status\n")


def d_row(J, scale, runs):
    D = scale * 0.1 * J ** -0.5
    return {"J": J, "runs": runs, "D": D, "D_sem": 0.01 * D, "D_run_err": 0.005 * D}


store(work / "discs", [d_row(0.01, 1.0, 3), d_row(0.04, 1.0, 3)])
store(work / "spheres", [d_row(0.02, 0.5, 3), d_row(0.04, 1.0, 2)])
out = subprocess.run([sys.executable, str(repo / "tools/results_table.py"), "--discs",
                      str(work / "discs"), str(work / "spheres")],
                     capture_output=True, text=True, check=True).stdout
rows = {l.split("|")[1].strip(): [c.strip() for c in l.strip("|").split("|")]
        for l in out.splitlines() if l.startswith("| 0.0")}
assert rows["0.02"][3].startswith("0.707 +- "), rows["0.02"]
assert rows["0.02"][4] == "0.500 +- 0.006", rows["0.02"]
assert rows["0.02"][-1] == "between J = 0.01 and 0.04", rows["0.02"]
assert rows["0.04"][4].startswith("1.000 +- ") and rows["0.04"][-1] == "measured", rows["0.04"]
assert rows["0.02"][6] == "-", rows["0.02"]  # no dv in either store
# --error-check: at J = 0.01 three seeds of phi 0.80, 0.81, 0.82, each +- 0.005 (chi2 = 8, two
# degrees of freedom); at J = 0.02 two seeds of phi 0 and 1 with errors 1 and 2, whose chi2 about
# the inverse-variance mean is 1 / (1 + 4) = 0.2 (an unweighted mean would give 0.3125); a
# flagged window at J = 0.02 that would blow the chi2 up is left out. Without error_blocks the
# bars are exact, so right bars give chi2 with 2, 1 and (pooled) 3 degrees of freedom: R is
# sqrt(chi2 / median), the interval from the 84 and 16 % points, P the tail beyond 8.2. The tool
# draws these (40,000 draws), so its figures are held to the closed forms within 0.02-0.03.
from scipy import stats


def cells_of(text, name):
    line = next(l for l in text.splitlines() if l.startswith(f"| {name} |"))
    return [c.strip() for c in line.strip("|").split("|")]


def near(cell, want, tol):
    assert abs(float(cell) - want) <= tol, (cell, want)


# --steps: D = 0.1 J^-1/2 at J = 0.01 and 0.04, each +- 1 % (the seeds' scatter, larger than
# the runs' 0.5 %): -0.5 +- sqrt(2) x 0.01 / ln 4 = 0.0102. Then flat to J = 0.16, a single
# seed (no scatter) whose own bar is 3 %: +0.000 +- hypot(0.01, 0.03) / ln 4 = 0.0228. No dv or
# Psi in the store.
steps = work / "steps"
single = dict(d_row(0.04, 1.0, 1), J=0.16, D_sem=None)
single["D_run_err"] = 0.03 * single["D"]
store(steps, [d_row(0.01, 1.0, 3), d_row(0.04, 1.0, 3), single])
fits = json.loads((steps / "fits.json").read_text())
fits["seed_table1"] = {n: law for n in names}
(steps / "fits.json").write_text(json.dumps(fits))
out = subprocess.run([sys.executable, str(repo / "tools/results_table.py"), "--steps",
                      str(steps)], capture_output=True, text=True, check=True).stdout
assert cells_of(out, "0.01 - 0.04") == ["0.01 - 0.04", "-0.500 +- 0.010", "-", "-"], out
assert cells_of(out, "0.04 - 0.16") == ["0.04 - 0.16", "+0.000 +- 0.023", "-", "-"], out
check = work / "error_check"
check.mkdir(exist_ok=True)
(check / "fits.json").write_text(json.dumps({"points": 6, "finished": 6, "groups": []}))
with open(check / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=["point", "status", "J", "phi", "phi_err"])
    w.writeheader()
    for s_, x in enumerate((0.80, 0.81, 0.82), 1):
        w.writerow({"point": f"a/J=0.01_seed={s_}", "status": "done", "J": 0.01, "phi": x,
                    "phi_err": 0.005})
    for s_, (x, e) in enumerate(((0.0, 1.0), (1.0, 2.0)), 1):
        w.writerow({"point": f"b/J=0.02_seed={s_}", "status": "done", "J": 0.02, "phi": x,
                    "phi_err": e})
    w.writerow({"point": "b/J=0.02_seed=3", "status": "done, not stationary", "J": 0.02,
                "phi": 50.0, "phi_err": 0.001})
tool = [sys.executable, str(repo / "tools/results_table.py"), "--error-check", str(check)]
out = subprocess.run(tool, capture_output=True, text=True, check=True).stdout
cells = cells_of(out, "phi")
near(cells[1], (8 / stats.chi2.median(2)) ** 0.5, 0.03)    # 2.40
near(cells[2], (0.2 / stats.chi2.median(1)) ** 0.5, 0.02)  # 0.66
pooled = cells[3].replace("[", "").replace("]", "").replace(",", "").split()
near(pooled[0], (8.2 / stats.chi2.median(3)) ** 0.5, 0.02)      # 1.86
near(pooled[1], (8.2 / stats.chi2.ppf(0.84, 3)) ** 0.5, 0.02)   # 1.26
near(pooled[2], (8.2 / stats.chi2.ppf(0.16, 3)) ** 0.5, 0.03)   # 3.13
assert cells[4] == "3", cells
near(cells[5], stats.chi2.sf(8.2, 3), 0.004)                    # 0.042
assert "J = 0.02, 2 seeds" in out and "| mu |" not in out, out
# Within a J range: J = 0.02 alone.
out = subprocess.run(tool + ["0.015", "0.1"], capture_output=True, text=True, check=True).stdout
assert "J = 0.01" not in out and cells_of(out, "phi")[1] == cells[2], out
# Bars estimated from 4 blocks each: two seeds of phi 0 and 1, +- 0.5. Their chi2 is
# (x1 - x2)^2 / (s1^2 + s2^2) = 2, and with right bars it is Z^2 over (chi2 with 6 degrees of
# freedom) / 6, an F(1, 6) variable: heavier-tailed than chi2 with one degree of freedom, so P
# rises from 0.16 to 0.21 and R falls from 2.10 to 1.97.
with open(check / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=["point", "status", "J", "phi", "phi_err", "error_blocks"])
    w.writeheader()
    for s_, x in enumerate((0.0, 1.0), 1):
        w.writerow({"point": f"J=0.01_seed={s_}", "status": "done", "J": 0.01, "phi": x,
                    "phi_err": 0.5, "error_blocks": 4})
out = subprocess.run(tool, capture_output=True, text=True, check=True).stdout
cells = cells_of(out, "phi")
near(cells[1], (2 / stats.f.median(1, 6)) ** 0.5, 0.03)
near(cells[4], stats.f.sf(2, 1, 6), 0.01)
# --bulk: at J = 0.01 two seeds of D 0.04 and 0.06 with D_bulk 0.05 and 0.07 (means 0.05 and
# 0.06, each +- 0.01 from the seeds' scatter; ratios 1.25 and 7/6, mean 1.208 +- 0.042) and D
# bars 0.002 and 0.008 (scaled by the ratios 0.0025 and 0.00933: rms 0.00683 over sqrt(2) =
# 0.0048; unscaled 0.0041, the mean instead of the rms 0.0042, mean bar x mean ratio 0.0043,
# rms bar x ratio of the means 0.0049), at J = 0.02 one seed without a D bar and a flagged
# window that the fits did not use.
bulk = work / "bulk"
bulk.mkdir(exist_ok=True)
(bulk / "fits.json").write_text(json.dumps(
    {"points": 4, "finished": 4, "seed_table1": {n: law for n in names},
     "groups": [{"axes": {}, "rows": [row], "fits": {}}]}))
with open(bulk / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=["point", "status", "J", "D", "D_bulk", "D_err"])
    w.writeheader()
    for s_, (d, db, e) in enumerate(((0.04, 0.05, 0.002), (0.06, 0.07, 0.008)), 1):
        w.writerow({"point": f"J=0.01_seed={s_}", "status": "done", "J": 0.01, "D": d,
                    "D_bulk": db, "D_err": e})
    w.writerow({"point": "J=0.02_seed=1", "status": "done", "J": 0.02, "D": 0.03,
                "D_bulk": 0.036})
    w.writerow({"point": "J=0.02_seed=2", "status": "done, not stationary", "J": 0.02,
                "D": 9.0, "D_bulk": 1.0})
out = subprocess.run([sys.executable, str(repo / "tools/results_table.py"), "--bulk", str(bulk)],
                     capture_output=True, text=True, check=True).stdout
assert cells_of(out, "0.01") == ["0.01", "2", "0.05 +- 0.01", "0.06 +- 0.01", "1.21 +- 0.042",
                                 "0.0048"], out
assert cells_of(out, "0.02") == ["0.02", "1", "0.03", "0.036", "1.2", "-"], out
print("results_table: per-J ratios, cost table, refusal, --compare, --discs, --steps, "
      "--error-check and --bulk as expected")
