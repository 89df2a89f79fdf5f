#!/usr/bin/python3
"""tools/convergence_table.py on a synthetic sweep.csv with a known answer: three values of a
setting, four seeds each; the coarsest carries a bias of exactly 4 reference standard errors in
dv and none elsewhere, so its (z, r) cells must read r = +4.0 for dv and r = 0.0 for phi (equal
seed values); runs' own error bars larger than their scatter set the mean's error; an unknown
axis must be refused; and a reference taken from another sweep (--reference-from) must give
the same cells as the same points in one sweep, also when both are sweeps over seeds only, set
against each other at the J each holds fixed (--axis J --reference-axis J, and --only J=...); a
window that failed the stationarity test is named, and left out with --stationary-only; a
simple-shear sweep (phi imposed) must be read through its stresses, mu = shear stress / pressure.
Usage: convergence_table_test.py REPO WORK"""
import csv
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
work.mkdir(parents=True, exist_ok=True)
cols = ["point", "status", "axis.integrator.max_displacement", "axis.run.seed", "phi", "mu", "dv",
        "psi", "D", "max_overlap", "steps_per_strain", "wall_seconds", "strain"]
# reference dv over seeds: 3.0 +- (0.1, -0.1, 0.1, -0.1): mean 3.0, sem = 0.1/sqrt(4) * sqrt(4/3)
offsets = [0.1, -0.1, 0.1, -0.1]
sem = (sum(o * o for o in offsets) / 3 / 4) ** 0.5
rows = []
for md, bias in [(3e-4, 0.0), (1e-3, 0.0), (3e-3, 4 * sem)]:
    for s, o in enumerate(offsets, 1):
        rows.append({"point": f"md={md}_seed={s}", "status": "done",
                     "axis.integrator.max_displacement": md, "axis.run.seed": s, "phi": 0.8,
                     "mu": 0.28 + o / 10, "dv": 3.0 + o + bias, "psi": 0.02 + o / 100,
                     "D": 0.2 + o / 10, "max_overlap": 0.003, "steps_per_strain": 1e4 / md * 1e-3,
                     "wall_seconds": 100.0, "strain": 10.0})
with open(work / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols)
    w.writeheader()
    w.writerows(rows)
tool = [sys.executable, str(repo / "tools/convergence_table.py"), str(work)]
out = subprocess.run(tool, capture_output=True, text=True, check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("| 0.003 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[4].endswith(", +4.0)"), f"dv cell {cells[4]!r}: want r = +4.0"
assert "(" not in cells[2], f"phi cell {cells[2]!r}: equal seeds have no error, no ratio"
line = next(l for l in out.splitlines() if l.startswith("| 0.001 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[4].endswith("(+0.0, +0.0)"), f"dv cell {cells[4]!r}: want no bias"
# --first-order against md = 1e-3: the 3e-3 row's dv shift of 4 reference errors says the
# reference is 4 x 1e-3 / (3e-3 - 1e-3) = 2 of its errors from q(0) (r = +2.0); the unbiased
# 3e-4 row says 0; phi (equal everywhere) has no error, so no estimate.
out = subprocess.run(tool + ["--reference", "1e-3", "--first-order"], capture_output=True,
                     text=True, check=True).stdout
est = out[out.index("own bias"):].splitlines()
row = [c.strip() for c in next(l for l in est if l.startswith("| 0.003 |")).strip("|").split("|")]
assert row[3].endswith("(r +2.0)") and row[1] == "-", row
row = [c.strip() for c in next(l for l in est if l.startswith("| 0.0003 |")).strip("|").split("|")]
assert row[3].endswith("(r +0.0)"), row
assert not any(l.startswith("| 0.001 |") for l in est), "the reference's own row has no estimate"
# The line through the three steps (equal errors; h = 0.3, 1, 3 in units of 1e-3, dv = 0, 0, 4 in
# reference errors): slope 6.2667 / 3.9267 = 1.596 errors per 1e-3, so the reference's bias is
# r = +1.6, +- 1 / sqrt(3.9267) = 0.50 errors, and chi2 = 0.67 about the line.
row = [c.strip() for c in next(l for l in est if l.startswith("| all steps, a line |"))
       .strip("|").split("|")]
assert row[3].endswith("(chi2 0.67, r +1.6)") and row[1] == "-", row
bias, err = (float(x) for x in row[3].split(" (")[0].split(" +- "))
assert abs(err / bias - 0.505 / 1.596) < 0.02, row
# Its reference step from another sweep's points' config.toml (a sweep over seeds at md = 1e-3).
seeds_md = work / "seeds_md"
(seeds_md / "points").mkdir(parents=True, exist_ok=True)
with open(seeds_md / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols[:2] + ["axis.run.seed", "J"] + cols[4:])
    w.writeheader()
    for r in rows:
        if r["axis.integrator.max_displacement"] == 1e-3:
            ref_row = {k: v for k, v in r.items() if k != "axis.integrator.max_displacement"}
            ref_row.update(point=f"seed={r['axis.run.seed']}", J=0.01)
            w.writerow(ref_row)
            d = seeds_md / "points" / ref_row["point"]
            d.mkdir(exist_ok=True)
            (d / "config.toml").write_text("[integrator]\nmax_displacement = 0.001\n")
out = subprocess.run(tool + ["--only", "integrator.max_displacement=3e-3", "--reference-from",
                             str(seeds_md), "--reference-axis", "J", "--reference", "0.01",
                             "--first-order"], capture_output=True, text=True, check=True).stdout
est = out[out.index("h0 = 0.001 d"):].splitlines()
row = [c.strip() for c in next(l for l in est if l.startswith("| 0.003 |")).strip("|").split("|")]
assert row[3].endswith("(r +2.0)"), row
bad = subprocess.run(tool + ["--axis", "run.seed", "--first-order"], capture_output=True, text=True)
assert bad.returncode != 0 and "--first-order needs" in bad.stderr, bad.stderr
# Runs whose own error bars exceed their scatter: the mean's error is rms(psi_err) / sqrt(n).
cols.append("psi_err")
for r in rows:
    r["psi_err"] = 1.0
with open(work / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols)
    w.writeheader()
    w.writerows(rows)
out = subprocess.run(tool, capture_output=True, text=True, check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("| 0.0003 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[5].endswith("+- 0.5"), f"psi cell {cells[5]!r}: want the runs' own error 1/sqrt(4)"
# --widen psi=1.5: those own bars count 1.5 times, 0.75 for the mean, in the reference and in the
# other groups alike; D has no own bars and keeps its scatter. --widen D=2 leaves psi's 0.5. A
# factor below 1 and a name that is not a column are refused.
out = subprocess.run(tool + ["--widen", "psi=1.5"], capture_output=True, text=True,
                     check=True).stdout
for md in ("0.0003", "0.003"):
    line = next(l for l in out.splitlines() if l.startswith(f"| {md} |"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    want = "+- 0.75" if md == "0.0003" else "+- 0.75 (+0.0, +0.0)"
    assert cells[5].endswith(want), f"psi cell {cells[5]!r} at md = {md}: want 1.5 / sqrt(4)"
assert "The runs' own bars of psi are widened 1.5 times." in out, out
out = subprocess.run(tool + ["--widen", "D=2"], capture_output=True, text=True,
                     check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("| 0.0003 |"))
assert [c.strip() for c in line.strip("|").split("|")][5].endswith("+- 0.5"), line
for wrong in ("psi=0.5", "Psi=1.5"):
    bad = subprocess.run(tool + ["--widen", wrong], capture_output=True, text=True)
    assert bad.returncode != 0 and f"--widen {wrong}" in bad.stderr, bad.stderr
bad = subprocess.run(tool + ["--axis", "flow.J"], capture_output=True, text=True)
assert bad.returncode != 0 and "--axis" in bad.stderr, bad.stderr
# The md = 3e-4 points as the reference of another sweep (a new setting, same seeds): its biased
# value must read r = +4.0 in dv against them, as above, and the reference gets its own row.
other = work / "other"
other.mkdir(exist_ok=True)
cols2 = [c if c != "axis.integrator.max_displacement" else "axis.integrator.max_entry_overlap"
         for c in cols]
new_rows = []
for r in rows:
    if r["axis.integrator.max_displacement"] == 3e-3:
        q = {k if k != "axis.integrator.max_displacement" else "axis.integrator.max_entry_overlap":
             v for k, v in r.items()}
        q["axis.integrator.max_entry_overlap"] = 3e-4
        new_rows.append(q)
with open(other / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols2)
    w.writeheader()
    w.writerows(new_rows)
out = subprocess.run([sys.executable, str(repo / "tools/convergence_table.py"), str(other),
                      "--reference-from", str(work), "--reference", "3e-4"],
                     capture_output=True, text=True, check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("| 0.0003 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[4].endswith(", +4.0)"), f"dv cell {cells[4]!r}: want r = +4.0 against the other sweep"
assert any(l.startswith("| reference | 4 |") for l in out.splitlines()), out
bad = subprocess.run([sys.executable, str(repo / "tools/convergence_table.py"), str(other),
                      "--reference-from", str(work), "--reference", "5e-4"],
                     capture_output=True, text=True)
assert bad.returncode != 0 and "--reference 0.0005" in bad.stderr, bad.stderr
# --only keeps one value of the axis.
out = subprocess.run(tool + ["--only", "integrator.max_displacement=1e-3"], capture_output=True,
                     text=True, check=True).stdout
assert [l[:9] for l in out.splitlines() if l.startswith("| 0.")] == ["| 0.001 |"], out
bad = subprocess.run(tool + ["--only", "flow.J=1e-3"], capture_output=True, text=True)
assert bad.returncode != 0 and "--only flow.J=1e-3" in bad.stderr, bad.stderr
bad = subprocess.run(tool + ["--only", "integrator.max_displacement=abc"], capture_output=True,
                     text=True)
assert bad.returncode != 0 and "a number" in bad.stderr, bad.stderr
# --only on an axis both sweeps vary (ktilde) keeps that value in the reference too: a
# reference sweep over two ktilde whose other ktilde is far off must not enter the reference.
for folder, names, data in [(work / "ref_k", cols, rows), (work / "new_k", cols2, new_rows)]:
    folder.mkdir(exist_ok=True)
    out_rows = []
    for k in (1e3, 1e5):
        for r in data:
            q = dict(r)
            q["axis.contact.ktilde"] = k
            if k == 1e5:
                q["dv"] = float(q["dv"]) + 100.0
            out_rows.append(q)
    with open(folder / "sweep.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=names + ["axis.contact.ktilde"])
        w.writeheader()
        w.writerows(out_rows)
out = subprocess.run([sys.executable, str(repo / "tools/convergence_table.py"), str(work / "new_k"),
                      "--axis", "integrator.max_entry_overlap", "--reference-from",
                      str(work / "ref_k"), "--reference-axis", "integrator.max_displacement",
                      "--reference", "3e-4", "--only", "contact.ktilde=1e3"],
                     capture_output=True, text=True, check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("| 0.0003 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[4].endswith(", +4.0)"), f"dv cell {cells[4]!r}: the other ktilde entered the reference"
assert any(l.startswith("| reference | 4 |") for l in out.splitlines()), out
# A simple-shear sweep imposes phi: its table reads the viscosity, P / (eta gammadot) and
# mu = shear stress / P from the summary's stresses. Shear stress 1.5 and 1.5 + 4 sem in the
# coarsest setting at P = 3: mu must read r = +4.0 there and 0.5 in the reference.
ss_dir = work / "simple_shear"
ss_dir.mkdir(exist_ok=True)
ss_cols = [c for c in cols if c not in ("phi", "mu")] + ["scene", "J", "shear_stress", "pressure",
                                                          "viscosity"]
ss_rows = []
for r in rows:
    q = {k: v for k, v in r.items() if k in ss_cols}
    shift = 3 * (float(r["dv"]) - 3.0) / 10  # dv's offsets and bias, scaled to mu at P = 3
    q.update(scene="simple_shear", J=1e-2, pressure=3.0, shear_stress=1.5 + shift,
             viscosity=(1.5 + shift) / 1e-2)
    ss_rows.append(q)
with open(ss_dir / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=ss_cols)
    w.writeheader()
    w.writerows(ss_rows)
out = subprocess.run([sys.executable, str(repo / "tools/convergence_table.py"), str(ss_dir)],
                     capture_output=True, text=True, check=True).stdout
header = next(l for l in out.splitlines() if l.startswith("| integrator"))
assert "eta_s / eta | P / (eta gammadot) | mu |" in header and "phi" not in header, header
cells = [c.strip() for c in next(l for l in out.splitlines()
                                 if l.startswith("| 0.003 |")).strip("|").split("|")]
assert cells[3].startswith("300 +- 0"), f"P / (eta gammadot) cell {cells[3]!r}: want 3 / 1e-2"
assert cells[4].endswith(", +4.0)"), f"mu cell {cells[4]!r}: want r = +4.0"
ref_cells = [c.strip() for c in next(l for l in out.splitlines()
                                     if l.startswith("| 0.0003 |")).strip("|").split("|")]
assert ref_cells[4].startswith("0.5 +- "), f"mu cell {ref_cells[4]!r}: want 1.5 / 3"
# Two sweeps over seeds only, each at a fixed J (the sliding laws' comparison of the 3D sweep at
# J = 0.1): --axis J and --reference-axis J name the summary column; the biased one reads r = +4.0.
for name, data in [("seeds_ref", [r for r in rows if r["axis.integrator.max_displacement"] == 3e-4]),
                   ("seeds_new", [r for r in rows if r["axis.integrator.max_displacement"] == 3e-3])]:
    (work / name).mkdir(exist_ok=True)
    names = [c for c in cols if c != "axis.integrator.max_displacement"] + ["J"]
    with open(work / name / "sweep.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=names, extrasaction="ignore")
        w.writeheader()
        w.writerows([dict(r, J=0.1) for r in data])
out = subprocess.run([sys.executable, str(repo / "tools/convergence_table.py"), str(work / "seeds_new"),
                      "--axis", "J", "--reference-from", str(work / "seeds_ref"),
                      "--reference-axis", "J", "--reference", "0.1"],
                     capture_output=True, text=True, check=True).stdout
cells = [c.strip() for c in next(l for l in out.splitlines()
                                 if l.startswith("| 0.1 |")).strip("|").split("|")]
assert cells[4].endswith(", +4.0)"), f"dv cell {cells[4]!r}: want r = +4.0 at the same J"
bad = subprocess.run([sys.executable, str(repo / "tools/convergence_table.py"), str(work / "seeds_new"),
                      "--axis", "J", "--reference-from", str(work / "seeds_ref"),
                      "--reference-axis", "J", "--reference", "0.05"], capture_output=True, text=True)
assert bad.returncode != 0 and "--reference 0.05" in bad.stderr, bad.stderr
# --only takes a summary column held fixed as --axis does: J = 0.1 keeps every point, J = 0.05
# none (refused, not an empty table).
seeds_tool = [sys.executable, str(repo / "tools/convergence_table.py"), str(work / "seeds_new"),
              "--axis", "J", "--reference-from", str(work / "seeds_ref"), "--reference-axis", "J",
              "--reference", "0.1"]
out = subprocess.run(seeds_tool + ["--only", "J=0.1"], capture_output=True, text=True,
                     check=True).stdout
assert next(l for l in out.splitlines() if l.startswith("| 0.1 |")).startswith("| 0.1 | 4 |"), out
bad = subprocess.run(seeds_tool + ["--only", "J=0.05"], capture_output=True, text=True)
assert bad.returncode != 0 and "no finished point has J = 0.05" in bad.stderr, bad.stderr
# A window that failed the stationarity test counts by default and is named; --stationary-only
# leaves it out: a fifth seed far off in dv, flagged, moves the mean only without the flag.
flagged_dir = work / "seeds_flagged"
flagged_dir.mkdir(exist_ok=True)
data = [r for r in rows if r["axis.integrator.max_displacement"] == 3e-3]
flagged_row = dict(data[0], point="md=0.003_seed=5", status="done, not stationary", dv=103.0)
names = [c for c in cols if c != "axis.integrator.max_displacement"] + ["J"]
with open(flagged_dir / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=names, extrasaction="ignore")
    w.writeheader()
    w.writerows([dict(r, J=0.1) for r in data + [flagged_row]])
flagged_tool = [sys.executable, str(repo / "tools/convergence_table.py"), str(flagged_dir), "--axis",
                "J", "--reference-from", str(work / "seeds_ref"), "--reference-axis", "J",
                "--reference", "0.1"]
out = subprocess.run(flagged_tool, capture_output=True, text=True, check=True).stdout
assert "md=0.003_seed=5 (done, not stationary)" in out, out
assert next(l for l in out.splitlines() if l.startswith("| 0.1 |")).startswith("| 0.1 | 5 |"), out
out = subprocess.run(flagged_tool + ["--stationary-only"], capture_output=True, text=True,
                     check=True).stdout
assert "seed=5" not in out, out
cells = [c.strip() for c in next(l for l in out.splitlines()
                                 if l.startswith("| 0.1 |")).strip("|").split("|")]
assert cells[1] == "4" and cells[4].endswith(", +4.0)"), f"without the flagged seed: {cells}"
print("convergence_table: ok")
