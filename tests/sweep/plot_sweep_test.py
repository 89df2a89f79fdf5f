#!/usr/bin/python3
"""tools/plot_sweep.py on the committed spheres' store with the discs' beside them (--discs):
the figure is written and the discs' every J is drawn; a --discs folder without fits.json is
refused before anything is drawn, naming the option. Usage: plot_sweep_test.py REPO WORK"""
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
work.mkdir(parents=True, exist_ok=True)
tool = repo / "tools/plot_sweep.py"
out = work / "sweep_3d.png"
out.unlink(missing_ok=True)
run = subprocess.run([sys.executable, str(tool), str(repo / "results/spheres_n1000"), "--out",
                      str(out), "--discs", str(repo / "results/table1_n1000")],
                     capture_output=True, text=True)
assert run.returncode == 0, run.stderr
# results/table1_n1000 holds seven J (1e-4 to 0.1), one group.
assert "--discs: 7 J of" in run.stdout, run.stdout
assert out.stat().st_size > 50_000, out.stat().st_size
bad = subprocess.run([sys.executable, str(tool), str(repo / "results/spheres_n1000"), "--out",
                      str(work / "never.png"), "--discs", str(work)],
                     capture_output=True, text=True)
assert bad.returncode != 0 and "--discs" in bad.stderr and "no fits.json" in bad.stderr, bad
assert not (work / "never.png").exists()
print("plot_sweep: the spheres' figure with the discs beside them; a --discs without fits.json refused")
