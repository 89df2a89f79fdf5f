#!/usr/bin/env python3
"""Stress-test grid (issue 6): the built binary over discs and spheres x J x ktilde x start x
integrator x dt mode, small N and short strain, pressure-imposed plane shear (the scene with a
wall pressure check).

Each point ends in one of these categories:
  survived  exit 0 and every sanity check below holds;
  rejected  exit 2: the configuration was refused up front (e.g. a fixed explicit dt above the
            spring stability limit);
  detected  exit 4 (a run health check stopped the run) or 3 (a numerical failure caught);
  capped    killed at the per-point time cap (exit 143 after a checkpoint): unfinished, not
            wrong (the full grid reports them; the CI subset has none);
  SILENT    exit 0 but wrong: a contact overlap above health.max_overlap, a wall pressure error
            above --pressure-tol, a force-balance residual above --residual-tol, the strain or
            step count not reached, or a NaN/Inf in summary.json or trajectory.h5;
  CRASH     any other exit (signal, 1, ...).
SILENT and CRASH must not happen: the script exits 1 if any point falls in them, except
SILENT points matching a line of --known FILE (regular expressions over "particles=P
integrator=I dt=D problem=TEXT"): bugs already reported and waiting for a fix, shown as "known".

  stress_grid.py --bin build/sheardiff [--grid ci|full] [--cap 60] [--markdown FILE]
"""
import argparse
import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

STRAIN = 0.05
MAX_STEPS = 3000
# Per dimension: the number of particles and the dense and dilute starts. Discs: 60, area
# fractions 0.80 and 0.45. Spheres: 64 (a cell just wider than two neighbour cut-offs), volume
# fractions 0.55 (the densest random start the scene builds: random addition, then compression
# with overlap relaxation) and 0.30.
CELLS = {2: {"N": 60, "key": "phi_init", "dense": 0.80, "dilute": 0.45},
         3: {"N": 64, "key": "phi_init_spheres", "dense": 0.55, "dilute": 0.30}}
STARTS = ("dense", "dilute")
NAMES = {2: "discs", 3: "spheres"}


def points(grid):
    js = [1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0]
    ks = [1e2, 1e3, 1e4, 1e5, 1e6]
    full = list(itertools.product(CELLS, js, ks, STARTS, ["implicit", "heun"],
                                  ["adaptive", "fixed"]))
    if grid == "full":
        return full
    # CI: the corners of the grid, each integrator and dt mode at least once in each dimension
    # (< 30 s in all).
    return [
        (2, 1e-4, 1e2, "dense", "implicit", "adaptive"),
        (2, 1e-1, 1e6, "dense", "implicit", "adaptive"),
        (2, 1.0, 1e3, "dilute", "implicit", "fixed"),
        (2, 1e-5, 1e4, "dense", "implicit", "fixed"),
        (2, 1e-2, 1e2, "dense", "heun", "adaptive"),
        (2, 1.0, 1e4, "dilute", "heun", "adaptive"),
        (2, 1e-2, 1e2, "dense", "heun", "fixed"),
        (2, 1e-3, 1e6, "dense", "heun", "fixed"),
        (3, 1e-5, 1e4, "dense", "implicit", "adaptive"),
        (3, 1e-1, 1e6, "dense", "implicit", "adaptive"),
        (3, 1.0, 1e3, "dilute", "implicit", "fixed"),
        (3, 1e-2, 1e2, "dense", "heun", "adaptive"),
        (3, 1e-3, 1e6, "dense", "heun", "fixed"),
    ]


def config_text(dim, j, k, start, integ, mode):
    # A fixed dt is a strain step of 1e-3: fine for implicit springs, above the stability
    # limit of explicit ones at large ktilde (then the config must be rejected).
    dt = 1e-3 / j if mode == "fixed" else 0.0
    cell = CELLS[dim]
    return f"""[scene]
type = "pressure_shear"
dimension = {dim}
[particles]
N = {cell["N"]}
{cell["key"]} = {cell[start]}
[flow]
J = {j!r}
[contact]
ktilde = {k!r}
[integrator]
type = "{integ}"
dt = {dt!r}
[run]
strain = {STRAIN}
max_steps = {MAX_STEPS}
[steady]
window = 0.02
[analysis]
diffusion = false
[output]
frame_strain = 0.01
checkpoint_strain = 0.0
"""


def nonfinite_in_h5(path):
    try:
        import h5py
        import numpy as np
    except ImportError:
        return None
    bad = []
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and obj.size:
                if not np.all(np.isfinite(obj[()])):
                    bad.append(name)
        f.visititems(visit)
    return bad


def nonfinite_in_json(x, path=""):
    if isinstance(x, float) and not math.isfinite(x):
        return [path]
    if isinstance(x, dict):
        return sum((nonfinite_in_json(v, f"{path}.{k}") for k, v in x.items()), [])
    if isinstance(x, list):
        return sum((nonfinite_in_json(v, f"{path}[{i}]") for i, v in enumerate(x)), [])
    return []


def judge(out, args):
    """Problems of a run that exited 0 (empty = survived) and its numbers."""
    with open(os.path.join(out, "summary.json")) as f:
        s = json.loads(f.read().replace("NaN", "null").replace("Infinity", "null"))
    problems = []
    health = s.get("health", {})
    ov = max(s.get("max_overlap") or 0.0, health.get("max_overlap") or 0.0)
    res = health.get("max_residual")
    perr = s.get("pressure_max_relative_error")
    if ov > health.get("max_overlap_limit", 0.1):
        problems.append(f"overlap {ov:.3g}")
    if res is None or res > args.residual_tol:
        problems.append(f"residual {res}")
    if perr is None or perr > args.pressure_tol:
        problems.append(f"pressure error {perr}")
    if not (s.get("strain", 0) >= STRAIN * (1 - 1e-9) or s.get("steps") == MAX_STEPS):
        problems.append(f"ended at strain {s.get('strain')} after {s.get('steps')} steps")
    with open(os.path.join(out, "summary.json")) as f:
        raw = f.read()
    if "NaN" in raw or "Infinity" in raw:
        problems.append("NaN in summary.json")
    problems += [f"non-finite {p}" for p in nonfinite_in_json(s)]
    traj = os.path.join(out, "trajectory.h5")
    if os.path.exists(traj):
        bad = nonfinite_in_h5(traj)
        if bad:
            problems.append("non-finite in trajectory: " + ", ".join(bad[:3]))
    return problems, {"overlap": ov, "residual": res, "perr": perr, "strain": s.get("strain"),
                      "steps": s.get("steps")}


def run_point(args, work, p):
    dim, j, k, start, integ, mode = p
    name = f"{NAMES[dim]}_J{j:g}_k{k:g}_{start}_{integ}_{mode}"
    cfg = os.path.join(work, name + ".toml")
    out = os.path.join(work, name)
    with open(cfg, "w") as f:
        f.write(config_text(dim, j, k, start, integ, mode))
    t0 = time.monotonic()
    proc = subprocess.Popen([args.bin, "run", cfg, "--out", out], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        _, err = proc.communicate(timeout=args.cap)
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        proc.terminate()  # SIGTERM: the run writes a checkpoint and exits 143
        try:
            _, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            _, err = proc.communicate()
        rc = "cap"
    secs = time.monotonic() - t0
    nums = {}
    what = ""
    first_error = next((l for l in err.splitlines() if l.startswith("error:")), err.strip()[:200])
    if rc == 0:
        problems, nums = judge(out, args)
        cat = "survived" if not problems else "SILENT"
        what = "; ".join(problems)
    elif rc == 2:
        cat, what = "rejected", first_error
    elif rc in (3, 4):
        cat, what = "detected", first_error
    elif rc == "cap":
        cat, what = "capped", f"time cap {args.cap:g} s"
    else:
        cat, what = "CRASH", f"exit {rc}: {first_error}"
    shutil.rmtree(out, ignore_errors=True)
    return {"particles": NAMES[dim], "J": j, "ktilde": k, "start": start, "integrator": integ, "dt": mode, "category": cat,
            "what": what, "seconds": secs, **nums}


def fmt_num(x):
    return "-" if x is None else f"{x:.2g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True)
    ap.add_argument("--grid", choices=["ci", "full"], default="ci")
    ap.add_argument("--cap", type=float, default=60.0, help="seconds per point")
    ap.add_argument("--pressure-tol", type=float, default=1e-6)
    ap.add_argument("--residual-tol", type=float, default=1e-6)
    ap.add_argument("--known", help="file of regular expressions of known SILENT points")
    ap.add_argument("--markdown", help="write the table here")
    ap.add_argument("--json", help="write the raw results here")
    args = ap.parse_args()
    known = []
    if args.known:
        with open(args.known) as f:
            known = [re.compile(l.strip()) for l in f if l.strip() and not l.startswith("#")]
    work = tempfile.mkdtemp(prefix="sheardiff_stress_")
    results = []
    try:
        pts = points(args.grid)
        for i, p in enumerate(pts):
            r = run_point(args, work, p)
            key = (f"particles={r['particles']} integrator={r['integrator']} dt={r['dt']} "
                   f"problem={r['what']}")
            if r["category"] == "SILENT" and any(k.search(key) for k in known):
                r["category"] = "known"
            results.append(r)
            print(f"[{i + 1}/{len(pts)}] {r['category']:9s} {r['seconds']:6.1f}s "
                  f"{r['particles']:7s} J={r['J']:g} "
                  f"k={r['ktilde']:g} {r['start']:6s} {r['integrator']:8s} {r['dt']:8s} "
                  f"overlap={fmt_num(r.get('overlap'))} res={fmt_num(r.get('residual'))} "
                  f"perr={fmt_num(r.get('perr'))} {r['what'][:160]}", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    counts = {}
    for r in results:
        counts[r["category"]] = counts.get(r["category"], 0) + 1
    print("\n" + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write("| particles | J | ktilde | start | integrator | dt | result | "
                    "max overlap (d) | residual | wall pressure error | steps | s | detail |\n"
                    "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
            for r in results:
                detail = r["what"].replace("|", "/")
                if len(detail) > 140:
                    detail = detail[:140] + "..."
                f.write(f"| {r['particles']} | {r['J']:g} | {r['ktilde']:g} | {r['start']} | {r['integrator']} | "
                        f"{r['dt']} | {r['category']} | {fmt_num(r.get('overlap'))} | "
                        f"{fmt_num(r.get('residual'))} | {fmt_num(r.get('perr'))} | "
                        f"{r.get('steps', '-')} | {r['seconds']:.1f} | {detail} |\n")
    bad = counts.get("SILENT", 0) + counts.get("CRASH", 0)
    if args.grid == "ci":
        bad += counts.get("capped", 0)  # the CI subset is chosen to finish well inside its cap
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
