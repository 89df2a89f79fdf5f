#!/usr/bin/env python3
"""Fuzz run over random *valid* configurations (issue 6): small N, a few steps, every scene,
integrator and Cholesky, lubrication on/off, frictional or not, J in [1e-5, 1], ktilde in
[1e2, 1e6], phi_init in [0.3, 0.85], random walls, steady-state, analysis and output settings.

Each configuration is written to a file and run with `sheardiff run CONFIG --out DIR` under a
timeout. A run must end in one of two ways:
  ok        exit 0 and a readable DIR/summary.json with a finite strain and steps > 0;
  detected  exit 3 with an "error: ..." message (a numerical failure the code caught), or
            exit 4 with "error: run health: ..." (a run health check stopped it,
            docs/stability.md).
Anything else is a failure: a signal (crash, abort), a hang (timeout), exit 1, or exit 2 (a
generated configuration was rejected: the generator and the validator disagree). The
configuration of every failure is printed and, with --keep DIR, saved there.

Failures whose stderr matches a line of --known FILE (regular expressions, '#' comments) are
reported as "known" and do not fail the run unless --strict is given: they are bugs already
reported and waiting for a fix (remove the line when it is fixed).

    random_valid_configs.py --bin build/sheardiff [--count 30] [--seed 1] [--timeout 60]
"""
import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time


def loguniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def fmt(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v + '"'
    if isinstance(v, float):
        return repr(v)
    return str(v)


def random_config(rng):
    """One valid configuration as {section: {key: value}}."""
    c = {}
    scene = rng.choice(["simple_shear", "pressure_shear"])
    c["scene"] = {"type": scene}
    c["particles"] = {
        "N": rng.randint(20, 60),
        "mix": rng.choice(["area", "volume", "number"]),
        "size_ratio": rng.choice([1.0, 1.4, round(rng.uniform(1.0, 2.0), 3)]),
        "phi_init": round(rng.uniform(0.3, 0.85), 4),
        "aspect": round(loguniform(rng, 0.5, 2.0), 4),
    }
    j = loguniform(rng, 1e-5, 1.0)
    c["flow"] = {"J": j, "lz": rng.choice([1.0, round(rng.uniform(0.5, 2.0), 3)])}
    c["lubrication"] = {
        "enabled": rng.random() < 0.6,
        "delta": loguniform(rng, 1e-3, 0.1),
        "h_max": round(rng.uniform(0.05, 0.9), 3),
    }
    ktilde = loguniform(rng, 1e2, 1e6)
    c["contact"] = {
        "ktilde": ktilde,
        "kt_ratio": round(rng.uniform(0.0, 1.0), 3),
        "mu": rng.choice([0.0, 0.5]),
    }
    integ = rng.choice(["implicit", "euler", "heun"])
    c["integrator"] = {"type": integ}
    if rng.random() < 0.2:
        # A fixed step: for explicit springs well below the contact stability limit (~10/k);
        # for implicit springs a small strain per step.
        dt = (rng.uniform(0.1, 1.0) / ktilde if integ != "implicit"
              else loguniform(rng, 1e-5, 1e-3) / j)
        c["integrator"]["dt"] = min(dt, 1000.0)
    if rng.random() < 0.3:
        c["integrator"]["max_displacement"] = loguniform(rng, 1e-4, 0.1)
        c["integrator"]["max_gap_fraction"] = round(rng.uniform(0.05, 1.0), 3)
        c["integrator"]["max_overlap_change"] = loguniform(rng, 1e-4, 0.1)
        c["integrator"]["max_strain_step"] = loguniform(rng, 1e-4, 0.1)
        c["integrator"]["explicit_safety"] = round(rng.uniform(0.05, 1.0), 3)
    c["solver"] = {"cholesky": rng.choice(["cholmod", "eigen"])}
    c["neighbour"] = {"skin": round(rng.uniform(0.1, 1.0), 3)}
    strain = rng.choice([0.05, 0.2, 1.0, 5.0])
    frame = loguniform(rng, 1e-4, 0.02)
    c["run"] = {
        "strain": strain,
        "seed": rng.randint(0, 2**31),
        "max_steps": rng.randint(20, 50),
        "transient_strain": rng.choice([0.0, round(rng.uniform(0.0, 0.5) * strain, 4)]),
    }
    c["walls"] = {
        "free_fall_speed": loguniform(rng, 0.05, 5.0),
        "jitter": round(rng.uniform(0.0, 1.0), 3),
    }
    c["steady"] = {
        "window": loguniform(rng, 0.005, 1.0),
        "h_tolerance": loguniform(rng, 1e-3, 0.5),
        "mu_tolerance": loguniform(rng, 1e-2, 1.0),
        "measure_strain": rng.choice([0.0, loguniform(rng, 1e-3, 0.5)]),
    }
    c["observables"] = {
        "wall_exclusion": round(rng.uniform(0.0, 5.0), 3),
        "profile_bin": round(rng.uniform(0.2, 2.0), 3),
    }
    lo = rng.choice([0.0, loguniform(rng, 1e-3, 0.1)])
    c["analysis"] = {
        "diffusion": rng.random() < 0.7,
        "msd_window_lo": lo,
        "msd_window_hi": lo + loguniform(rng, 1e-3, 1.0),
        "reference_times": rng.randint(1, 200),
        "vacf_max_lag": loguniform(rng, 1e-3, 2.0),
    }
    c["output"] = {
        "frame_strain": frame,
        "velocities": rng.random() < 0.7,
        "trajectory": rng.random() < 0.8,
    }
    widen_cell(c)
    return c


def widen_cell(c):
    """Raises particles.N until the periodic cell is valid (validate_run_inputs: every periodic
    edge above twice the neighbour cut-off of the largest pair); draws nothing from the random
    stream, so the other cases stay as they were."""
    p = c["particles"]
    ratio = p["size_ratio"]
    lub = c["lubrication"]
    reach = 1.0 + 0.5 * lub["h_max"] if lub["enabled"] else 1.0
    cutoff = 2.0 * 0.5 * max(1.0, ratio) * reach + c["neighbour"]["skin"]
    small_per_large = {"area": ratio**2, "volume": ratio**3, "number": 1.0}[p["mix"]]
    while True:
        n_large = math.floor(p["N"] / (1.0 + small_per_large) + 0.5)
        area = math.pi * 0.25 * ((p["N"] - n_large) + n_large * ratio**2)
        lx = math.sqrt(area / p["phi_init"] / p["aspect"])
        edge = lx if c["scene"]["type"] == "pressure_shear" else min(lx, p["aspect"] * lx)
        if edge > 2.0 * cutoff * 1.001:
            return
        p["N"] += 5


def to_toml(c):
    out = []
    for sec, kv in c.items():
        out.append(f"[{sec}]")
        out += [f"{k} = {fmt(v)}" for k, v in kv.items()]
        out.append("")
    return "\n".join(out)


def load_known(path):
    if not path:
        return []
    pats = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                pats.append(re.compile(line))
    return pats


def summary_ok(out_dir):
    try:
        with open(os.path.join(out_dir, "summary.json")) as f:
            js = json.load(f)
    except (OSError, ValueError) as e:
        return f"summary.json missing or unreadable: {e}"
    strain, steps = js.get("strain"), js.get("steps")
    if not isinstance(strain, (int, float)) or not math.isfinite(strain):
        return f"summary.json: strain = {strain!r}"
    if not isinstance(steps, int) or steps <= 0:
        return f"summary.json: steps = {steps!r}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True, help="the sheardiff executable")
    ap.add_argument("--count", type=int, default=30)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per run")
    ap.add_argument("--keep", help="folder to save the configuration of every failure in")
    ap.add_argument("--known", help="file of regular expressions of known failures")
    ap.add_argument("--strict", action="store_true", help="known failures fail too")
    a = ap.parse_args()

    known = load_known(a.known)
    rng = random.Random(a.seed)
    work = tempfile.mkdtemp(prefix="sheardiff_fuzz_")
    counts = {"ok": 0, "detected": 0, "known": 0, "FAIL": 0}
    failures = []
    t_start = time.monotonic()
    env = dict(os.environ, OMP_THREAD_LIMIT=os.environ.get("OMP_THREAD_LIMIT", "1"))
    try:
        for k in range(a.count):
            c = random_config(rng)
            text = to_toml(c)
            cfg = os.path.join(work, f"case{k:04d}.toml")
            out = os.path.join(work, f"out{k:04d}")
            with open(cfg, "w") as f:
                f.write(text)
            t0 = time.monotonic()
            try:
                p = subprocess.run([a.bin, "run", cfg, "--out", out], capture_output=True,
                                   text=True, errors="replace", timeout=a.timeout, env=env)
                rc, err = p.returncode, p.stderr
            except subprocess.TimeoutExpired as e:
                rc = None
                err = (e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes)
                       else e.stderr or "")
            dt = time.monotonic() - t0
            what = ""
            if rc == 0:
                problem = summary_ok(out)
                verdict, what = ("ok", "") if problem is None else ("FAIL", problem)
            elif (rc == 3 and "error:" in err) or (rc == 4 and "run health:" in err):
                verdict, what = "detected", next((l for l in err.splitlines() if l.startswith("error:")), err.strip())
            else:
                verdict = "FAIL"
                what = ("hang: no exit within the timeout" if rc is None
                        else f"killed by signal {-rc}" if rc < 0
                        else f"exit {rc}" + (" (SIGABRT)" if rc == 134 else ""))
                tail = err.strip().splitlines()[-3:]
                if tail:
                    what += ": " + " | ".join(tail)
                if any(pat.search(err) for pat in known):
                    verdict = "known"
            counts[verdict] += 1
            key = (f"{c['scene']['type']:14s} {c['integrator']['type']:8s} "
                   f"N={c['particles']['N']:<3d} J={c['flow']['J']:.1e} "
                   f"k={c['contact']['ktilde']:.1e} mu={c['contact']['mu']} "
                   f"lub={'on ' if c['lubrication']['enabled'] else 'off'} "
                   f"phi0={c['particles']['phi_init']:.2f}")
            print(f"[{k:3d}] {verdict:8s} {dt:6.2f}s {key} {what}", flush=True)
            if verdict in ("FAIL", "known"):
                failures.append((k, verdict, what, text))
                if a.keep:
                    os.makedirs(a.keep, exist_ok=True)
                    shutil.copy(cfg, os.path.join(a.keep, f"{verdict.lower()}_seed{a.seed}_case{k:04d}.toml"))
            shutil.rmtree(out, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    for k, verdict, what, text in failures:
        print(f"\n--- case {k} ({verdict}): {what}\n{text}")
    total = time.monotonic() - t_start
    print(f"\n{a.count} random valid configs (seed {a.seed}) in {total:.1f} s: "
          f"{counts['ok']} ok, {counts['detected']} detected numerical failures (exit 3 or 4), "
          f"{counts['known']} known bugs, {counts['FAIL']} failures")
    bad = counts["FAIL"] + (counts["known"] if a.strict else 0)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
