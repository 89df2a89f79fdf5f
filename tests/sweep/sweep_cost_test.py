#!/usr/bin/python3
"""tools/sweep_cost.py on a synthetic store with a known answer: two seeds of one point with
10,000 and 12,000 steps per strain and 1.5 and 2.5 factorisations per step (means 11,000 and 2.0)
cost at least 11,000 x 2.0 x 2 ms = 44 CPU s per strain, 44 x 36 / 3600 = 0.44 h per point of
36 strains; a second point filtered out by --only must not enter; a summary without the solver's
counters is skipped; a folder without points and a bad --only are refused; a point of spheres
is not priced with the discs' (one kind per table, and its factorisation's time given).
Usage: sweep_cost_test.py REPO WORK"""
import json
import pathlib
import shutil
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
shutil.rmtree(work, ignore_errors=True)  # a rerun starts from the synthetic store alone
store = work / "store"
points = [("J=0.0001_seed=1", 1e-4, 10000.0, 1.5), ("J=0.0001_seed=2", 1e-4, 12000.0, 2.5),
          ("J=0.01_seed=1", 1e-2, 3000.0, 1.0)]
for name, j, steps_per_strain, fact in points:
    d = store / "points" / name
    d.mkdir(parents=True, exist_ok=True)
    steps = int(steps_per_strain * 10)
    json.dump({"scene": "pressure_shear", "N": 1000, "ktilde": 1e4, "J": j, "steps": steps,
               "steps_per_strain": steps_per_strain, "factorisations": int(fact * steps)},
              open(d / "summary.json", "w"))
old = store / "points" / "J=0.001_seed=1"  # no factorisations counter: skipped
old.mkdir(parents=True, exist_ok=True)
json.dump({"scene": "pressure_shear", "N": 1000, "ktilde": 1e4, "J": 1e-3, "steps": 5,
           "steps_per_strain": 5.0}, open(old / "summary.json", "w"))
tool = [sys.executable, str(repo / "tools/sweep_cost.py"), str(store), "--strains", "36",
        "--ms-per-factorisation", "2"]
out = subprocess.run(tool + ["--only", "J=1e-4"], capture_output=True, text=True,
                     check=True).stdout
rows = [l for l in out.splitlines() if l.startswith("| pressure_shear")]
assert len(rows) == 1, out
cells = [c.strip() for c in rows[0].strip("|").split("|")]
assert cells[4:] == ["2", "11,000", "2.00", "44.0", "0.44"], cells
assert "0.44 CPU h" in out, out
out = subprocess.run(tool, capture_output=True, text=True, check=True).stdout
assert len([l for l in out.splitlines() if l.startswith("| pressure_shear")]) == 2, out
out = subprocess.run(tool + ["--only", "scene=simple_shear"], capture_output=True, text=True)
assert out.returncode != 0 and "no summary" in out.stderr, out.stderr
for bad_args in (["--only", "seed=1"], ["--only", "J=abc"], ["--strains", "0"]):
    bad = subprocess.run(tool + bad_args, capture_output=True, text=True)
    assert bad.returncode != 0 and bad_args[0] in bad.stderr, bad.stderr
bad = subprocess.run([sys.executable, str(repo / "tools/sweep_cost.py"), str(work / "none")],
                     capture_output=True, text=True)
assert bad.returncode != 0 and "no points" in bad.stderr, bad.stderr
# Spheres: a point of them beside the discs' is refused unless one kind is chosen, and alone
# they are priced only at a time given for their factorisation (the discs' default is not).
d = store / "points" / "spheres_J=0.01_seed=1"
d.mkdir(parents=True, exist_ok=True)
json.dump({"scene": "pressure_shear", "dimension": 3, "N": 1000, "ktilde": 1e4, "J": 1e-2,
           "steps": 30000, "steps_per_strain": 3000.0, "factorisations": 30000}, open(d / "summary.json", "w"))
mixed = subprocess.run(tool, capture_output=True, text=True)
assert mixed.returncode != 0 and "--only dimension=" in mixed.stderr, mixed.stderr
out = subprocess.run(tool + ["--only", "dimension=2"], capture_output=True, text=True, check=True).stdout
assert len([l for l in out.splitlines() if l.startswith("| pressure_shear")]) == 2, out
spheres = [sys.executable, str(repo / "tools/sweep_cost.py"), str(store), "--only", "dimension=3"]
bad = subprocess.run(spheres, capture_output=True, text=True)
assert bad.returncode != 0 and "--ms-per-factorisation" in bad.stderr, bad.stderr
out = subprocess.run(spheres + ["--ms-per-factorisation", "60", "--strains", "36"], capture_output=True,
                     text=True, check=True).stdout
rows = [l for l in out.splitlines() if l.startswith("| pressure_shear")]
assert len(rows) == 1 and out.startswith("spheres"), out
cells = [c.strip() for c in rows[0].strip("|").split("|")]
assert cells[4:] == ["1", "3,000", "1.00", "180.0", "1.80"], cells  # 3000 x 60 ms; x 36 / 3600
print("sweep_cost: ok")
