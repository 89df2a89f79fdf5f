#!/usr/bin/python3
"""tools/sweep_cost.py on a synthetic store with a known answer: two seeds of one point with
10,000 and 12,000 steps per strain and 1.5 and 2.5 factorisations per step (means 11,000 and 2.0)
cost at least 11,000 x 2.0 x 2 ms = 44 CPU s per strain, 44 x 36 / 3600 = 0.44 h per point of
36 strains; a second point filtered out by --only must not enter; a summary without the solver's
counters is skipped; a folder without points and a bad --only are refused.
Usage: sweep_cost_test.py REPO WORK"""
import json
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
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
print("sweep_cost: ok")
