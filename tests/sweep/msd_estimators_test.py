#!/usr/bin/python3
"""tools/msd_estimators.py on a synthetic store with a known answer: a point whose every-origin
D is 0.05 and whose multiple-tau MSDs are straight lines of slope 2 x 0.051 (every particle) and
2 x 0.0612 (the bulk) over its fit window [8, 15], curving away outside it (which a fit over the
wrong lags would pick up): ratios 1.020 and 1.200. A point without analysis.h5 is passed over and
a store with none is refused; a point without a bulk MSD has dashes there. Usage: msd_estimators_test.py REPO WORK"""
import json
import pathlib
import shutil
import subprocess
import sys

import h5py
import numpy as np

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
shutil.rmtree(work, ignore_errors=True)
store = work / "store"
point = store / "points" / "J=0.01_seed=1"
point.mkdir(parents=True)
(point / "summary.json").write_text(json.dumps(
    {"J": 0.01, "D": 0.05, "D_bulk": 0.0612, "msd_window": [8.0, 15.0]}))
lag = np.geomspace(0.01, 30.0, 60)
lag = np.sort(np.concatenate([lag, [8.0, 15.0]]))
bend = np.where((lag < 8.0) | (lag > 15.0), 0.3 * (lag - 11.5) ** 2, 0.0)
with h5py.File(point / "analysis.h5", "w") as f:
    f["msd/lag"] = lag
    f["msd/msd"] = 2 * 0.051 * lag + 0.2 + bend
    f["msd/msd_bulk"] = 2 * 0.0612 * lag + 0.1 + bend
# A run of discs without walls (simple shear): no bulk MSD, its cells a dash.
lone = store / "points" / "J=0.03_seed=1"
lone.mkdir()
(lone / "summary.json").write_text(json.dumps({"J": 0.03, "D": 0.02, "msd_window": [8.0, 15.0]}))
with h5py.File(lone / "analysis.h5", "w") as f:
    f["msd/lag"] = lag
    f["msd/msd"] = 2 * 0.02 * lag
bare = store / "points" / "J=0.02_seed=1"
bare.mkdir()
(bare / "summary.json").write_text(json.dumps({"J": 0.02, "D": 0.04, "msd_window": [8.0, 15.0]}))
tool = [sys.executable, str(repo / "tools/msd_estimators.py")]
out = subprocess.run(tool + [str(store)], capture_output=True, text=True, check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("| J=0.01_seed=1 |"))
cells = [c.strip() for c in line.strip("|").split("|")]
assert cells[1:] == ["0.05", "0.051", "1.020", "0.0612", "1.200"], cells
assert "J=0.02" not in out, out
line = next(l for l in out.splitlines() if l.startswith("| J=0.03_seed=1 |"))
assert [c.strip() for c in line.strip("|").split("|")][1:] == ["0.02", "0.02", "1.000", "-", "-"]
assert "over 2 points: mean 1.010, range 1.000-1.020" in out, out
shutil.rmtree(point)
shutil.rmtree(lone)
r = subprocess.run(tool + [str(store)], capture_output=True, text=True)
assert r.returncode != 0 and "no finished point with an analysis.h5" in r.stderr, r
print("msd_estimators: the two estimators' D over the run's window as expected")
