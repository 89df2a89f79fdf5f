#!/usr/bin/python3
"""tools/stationarity_check.py store --markdown on two synthetic stores with a known answer: a
stationary point, a drifting one (its reason kept) and an old point without a verdict, which is
named below the table, not given a row. Usage: stationarity_check_test.py REPO WORK"""
import json
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
signals = {"net_drag_y": 0.01, "net_drag_y_err": 0.02, "mu_top_minus_bottom": -0.005,
           "mu_top_minus_bottom_err": 0.01, "H_change": 0.2, "H_change_err": 0.04,
           "bulk_normal_load": 1.01, "bulk_normal_load_err": 0.01}
points = {"a": {"J=0.02_seed=1": dict(signals, J=0.02, phi=0.5012, stationary=True),
                "J=0.01_seed=1": dict(signals, J=0.01, phi=0.52, stationary=False,
                                      not_stationary="H_change")},
          "b": {"J=0.1_seed=1": {"J": 0.1, "phi": 0.43, "mu_top": 0.9, "mu_bottom": 0.91}}}
for store, runs in points.items():
    for name, summary in runs.items():
        d = work / store / "points" / name
        d.mkdir(parents=True, exist_ok=True)
        (d / "summary.json").write_text(json.dumps(summary))
out = subprocess.run([sys.executable, str(repo / "tools/stationarity_check.py"), "store",
                      "--markdown", str(work / "a"), str(work / "b")],
                     capture_output=True, text=True, check=True).stdout
lines = out.splitlines()
rows = [l for l in lines if l.startswith("| a |") or l.startswith("| b |")]
assert len(rows) == 2, out
# Sorted by J within a store: the drifting J = 0.01 first.
assert rows[0] == ("| a | J=0.01_seed=1 | 0.5200 | +0.010 +- 0.020 | -0.005 +- 0.010 "
                   "| +0.200 +- 0.040 | +1.010 +- 0.010 | drifting: H_change |"), rows[0]
assert rows[1].startswith("| a | J=0.02_seed=1 | 0.5012 |") and rows[1].endswith(
    "| stationary |"), rows[1]
assert lines[-1].startswith("No stationarity verdict recorded") and "b/points" not in lines[-1] \
    and lines[-1].rstrip(".").endswith("b/J=0.1_seed=1"), lines[-1]
print("stationarity_check: --markdown rows, order and the points without a verdict as expected")

# blocks: a run's window_blocks printed block by block, with the line through H's block means
# (here H rises 0.05 d a block of 2 strains: 0.025 d per strain, 0.2 d over the 8-strain
# window, exactly, so with no scatter about the line); a null H_change and a run without a
# verdict print as such, not as an error; a run without window_blocks and an unfinished one
# are named as such.
blocked = work / "blocked"
blocked.mkdir(parents=True, exist_ok=True)
(blocked / "summary.json").write_text(json.dumps(dict(signals, stationary=True, window_blocks={
    "strain": [11.0, 13.0, 15.0, 17.0], "H": [20.0, 20.05, 20.1, 20.15], "phi": None,
    "mu": [0.5, 0.51, 0.49, 0.5], "mu_top_minus_bottom": [0.0, 0.01, -0.01, 0.0],
    "net_drag_y": [0.0, 0.0, 0.0, 0.0], "bulk_normal_load": [1.0, 1.01, 0.99, 1.0]})))
noverdict = work / "noverdict"
noverdict.mkdir(parents=True, exist_ok=True)
(noverdict / "summary.json").write_text(json.dumps({"H_change": None, "window_blocks": {
    "strain": [1.0, 3.0, 5.0, 7.0], "H": [20.0, 20.0, 20.0, 20.0], "phi": [0.5, None, 0.5, 0.5],
    "mu": None, "mu_top_minus_bottom": None, "net_drag_y": None, "bulk_normal_load": None}}))
unfinished = work / "unfinished"
unfinished.mkdir(parents=True, exist_ok=True)
out = subprocess.run([sys.executable, str(repo / "tools/stationarity_check.py"), "blocks",
                      str(blocked), str(work / "a/points/J=0.02_seed=1"), str(noverdict),
                      str(unfinished)],
                     capture_output=True, text=True, check=True).stdout
lines = out.splitlines()
assert lines[0].startswith(f"{blocked}: 4 blocks, verdict stationary"), out
assert lines[2] == "  11.00 | 20.0000 | - | 0.5000 | 0.0000 | 0.0000 | 1.0000", out
assert "line through H's block means: +0.2000 +- 0.0000 d over the window" in out, out
# phi is null: no line for it.
assert "line through phi's" not in out.split("\n\n")[0], out
assert f"{work / 'a/points/J=0.02_seed=1'}: no window_blocks" in out, out
assert f"{unfinished}: no summary.json" in out, out
assert f"{noverdict}: 4 blocks, verdict no verdict" in out and "H_change - +- - d" in out, out
assert "   3.00 | 20.0000 | - | - | - | - | -" in out, out
print("stationarity_check: blocks prints the window block by block and its line")

# blocks --sliding 3: the line through every 3 consecutive blocks of H (2-strain blocks, so a
# 6-strain span each). H flat, then rising 0.3 d a block, the last 0.01 d above the line:
#   blocks 1-3 flat: change 0, no scatter, not beyond;
#   blocks 2-4 (20, 20, 20.3): slope 0.6 / 8 a strain, change 0.45; residuals (0.05, -0.1, 0.05),
#     so the slope's error sqrt(0.015 / 8) and the change's 6 times it, 0.260 (z 1.7);
#   blocks 3-5 on a line: beyond; blocks 4-6 (20.3, 20.6, 20.91): change 0.915 +- 0.00866.
wander = work / "wander"
wander.mkdir(parents=True, exist_ok=True)
(wander / "summary.json").write_text(json.dumps(dict(signals, stationary=True, window_blocks={
    "strain": [1.0, 3.0, 5.0, 7.0, 9.0, 11.0], "H": [20.0, 20.0, 20.0, 20.3, 20.6, 20.91],
    "phi": None, "mu": None, "mu_top_minus_bottom": None, "net_drag_y": None,
    "bulk_normal_load": None})))
out = subprocess.run([sys.executable, str(repo / "tools/stationarity_check.py"), "blocks",
                      str(wander), "--sliding", "3"], capture_output=True, text=True,
                     check=True).stdout
assert "lines through H's block means over every 3 consecutive blocks:" in out, out
assert "  strains    2.0 -    8.0: +0.450 +- 0.260 d (z +1.7)" in out, out
assert "  strains    6.0 -   12.0: +0.915 +- 0.009 d (z +105.7)" in out, out
assert "  2 of 4 beyond 3 standard errors" in out, out
bad = subprocess.run([sys.executable, str(repo / "tools/stationarity_check.py"), "blocks",
                      str(wander), "--sliding", "2"], capture_output=True, text=True)
assert bad.returncode != 0 and "--sliding must be >= 3" in bad.stderr, bad.stderr
print("stationarity_check: blocks --sliding prints each shorter window's line and counts them")

# blocks --blocking: mu's 12 block means alternate in pairs (1, 1, -1, -1, ...). Their lag-1
# autocorrelation is 1/12 (eleven products +-1 summing to 1, over 12); the sem of single blocks
# is sqrt(12/11)/sqrt(12), of pairs (1, -1, ...) sqrt(6/5)/sqrt(6), a ratio of 1.48; the fours'
# means are all 0, a ratio of 0. A signal with a null block reads "-".
paired = work / "paired"
paired.mkdir(parents=True, exist_ok=True)
(paired / "summary.json").write_text(json.dumps(dict(signals, stationary=True, window_blocks={
    "strain": [1.0 + 2 * k for k in range(12)], "H": [20.0] * 11 + [None], "phi": None,
    "mu": [1.0, 1.0, -1.0, -1.0] * 3, "mu_top_minus_bottom": None, "net_drag_y": None,
    "bulk_normal_load": None})))
out = subprocess.run([sys.executable, str(repo / "tools/stationarity_check.py"), "blocks",
                      str(paired), "--blocking"], capture_output=True, text=True,
                     check=True).stdout
assert "mu | +0.08 | 1.48 | 0.00" in out, out
assert "H | - | - | -" in out, out
# Pooled over two runs of different lengths: a second run of 4 blocks whose mu alternates (1, -1,
# 1, -1) has lag-1 -3/4; with the first's +1/12 the mean is -1/3 = -0.33 and its standard error
# over the two 0.42; independent blocks give -(1/12 + 1/4) / 2 = -0.17 on average (-1/n per run,
# not -1 over the mean n, which would be -0.12). H pools nothing: one run has it.
flip = work / "flip"
flip.mkdir(parents=True, exist_ok=True)
(flip / "summary.json").write_text(json.dumps(dict(signals, stationary=True, window_blocks={
    "strain": [1.0 + 2 * k for k in range(4)], "H": None, "phi": None,
    "mu": [1.0, -1.0, 1.0, -1.0], "mu_top_minus_bottom": None, "net_drag_y": None,
    "bulk_normal_load": None})))
out = subprocess.run([sys.executable, str(repo / "tools/stationarity_check.py"), "blocks",
                      str(paired), str(flip), "--blocking"], capture_output=True, text=True,
                     check=True).stdout
pooled = out[out.index("lag-1 autocorrelation pooled over the runs (2):"):]
assert "mu | 2 | -0.33 +- 0.42 | -0.17" in pooled and "\nH |" not in pooled, out
print("stationarity_check: blocks --blocking reads the blocks' correlation, one run and pooled")
