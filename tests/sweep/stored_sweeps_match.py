#!/usr/bin/python3
"""ctest: every committed sweep store still matches its sweep file under the current code.

For each sweep file of the repository (configs/, configs/*/sweeps/, bench/) whose `results`
folder holds stored points, `sheardiff sweep FILE --collect` is run on a copy of configs/,
bench/ and results/ (collect rewrites a store's sweep.csv and fits.json; the repository is not
touched). It must not refuse (exit 0, or 3 for a sweep still in progress), and every point the
store holds (points/NAME/summary.json) that the sweep names must be counted as stored, not
"missing": a stored record that no longer parses, or that a changed default no longer matches,
would otherwise be run again or refused on the next machine that continues the sweep. (A default
of integrator.explicit_safety changed from 0.5 to 0.73 made every sweep refuse its results.)

    stored_sweeps_match.py SHEARDIFF_BIN REPO_DIR WORK_DIR
"""
import csv
import pathlib
import shutil
import subprocess
import sys
import tomllib

binary, repo, work = (pathlib.Path(a).resolve() for a in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
copy = work / "repo"
for part in ("configs", "bench", "results"):
    shutil.copytree(repo / part, copy / part)

failures, checked = [], 0
files = sorted(p for pattern in ("configs/*.toml", "configs/*/sweeps/*.toml", "bench/*.toml")
               for p in copy.glob(pattern))
for f in files:
    sweep = tomllib.loads(f.read_text()).get("sweep", {})
    if "results" not in sweep:
        continue
    store = (f.parent / sweep["results"]).resolve()
    stored = {p.parent.name for p in store.glob("points/*/summary.json")}
    if not stored:
        continue  # not run yet
    checked += 1
    name = str(f.relative_to(copy))
    out = work / "out" / name.replace("/", "_")
    p = subprocess.run([str(binary), "sweep", f.name, "--out", str(out), "--collect", "-q"],
                       cwd=f.parent, capture_output=True, text=True)
    if p.returncode not in (0, 3):
        failures.append(f"{name}: exit {p.returncode}: {p.stderr.strip()[-400:]}")
        continue
    rows = list(csv.DictReader(open(out / "sweep.csv")))
    lost = [r["point"] for r in rows if r["point"] in stored and r["status"] == "missing"]
    if lost:
        failures.append(f"{name}: stored points not recognised: {lost}")
    elif not any(r["point"] in stored for r in rows):
        failures.append(f"{name}: names none of the {len(stored)} points its store holds")

for m in failures:
    print("FAIL  " + m)
print(f"{checked} sweep files with stored results checked, {len(failures)} failed")
sys.exit(1 if failures or checked < 40 else 0)
