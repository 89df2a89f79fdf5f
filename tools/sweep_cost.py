#!/usr/bin/python3
"""What a sweep costs, from finished points: per (scene, N, ktilde, J) the mean steps per strain and
exact factorisations per step of the stored summaries, and the floor those counts set on the CPU
time of a run with one exact sparse factorisation per solve: factorisations per strain x the time
of one factorisation (--ms-per-factorisation, measured with bench/bench_solver on the machine
at hand). Steps and factorisations are machine-independent; the floor leaves out everything else
a step does (solves, assembly, neighbour search, observers), so a real run costs more.

    /usr/bin/python3 tools/sweep_cost.py STORE_OR_SWEEP_DIR... [--strains 33]
        [--ms-per-factorisation 2.3] [--only N=1000]

Each directory is a results store or a sweep folder (its points/*/summary.json are read). One
table prices one kind of factorisation: points of discs and of spheres are not mixed (--only
dimension=2 or 3), and for spheres --ms-per-factorisation must be given (their factorisation
costs ~25-35 times the discs' at N = 1000: bench_solver's cholmod_spheres)."""
import argparse
import sys

import rundir


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--strains", type=float, default=33.0,
                    help="strains per point, transient included (the seed's protocol: 3 + 30)")
    ap.add_argument("--ms-per-factorisation", type=float,
                    help="CPU ms of one factorisation (bench_solver; discs: 2.3 at N = 1000 by default; "
                         "spheres: required)")
    ap.add_argument("--only", action="append", default=[], metavar="KEY=VALUE",
                    help="keep the summaries whose KEY (N, ktilde, J, scene, dimension) equals VALUE")
    a = ap.parse_args()
    if a.strains <= 0 or (a.ms_per_factorisation is not None and a.ms_per_factorisation <= 0):
        sys.exit("--strains and --ms-per-factorisation must be > 0")
    only = []
    for cond in a.only:
        key, eq, value = cond.partition("=")
        if not eq or key not in ("N", "ktilde", "J", "scene", "dimension"):
            sys.exit(f"--only {cond}: give KEY=VALUE with KEY one of N, ktilde, J, scene, dimension")
        if key != "scene":
            try:
                value = float(value)
            except ValueError:
                sys.exit(f"--only {cond}: {key} takes a number")
        only.append((key, value))
    groups = {}
    for d in a.dirs:
        points = rundir.Store(d).points()
        if not points:
            sys.exit(f"{d}: no points finished in points/*/ (give a results store or a sweep folder)")
        for s in (p.summary for p in points):
            if not s.get("steps") or "factorisations" not in s:
                continue  # a summary from before the solver's counters
            s = dict(s, dimension=s.get("dimension", 2))  # summaries of discs before the key
            if any(s.get(k) != v if k == "scene" else float(s.get(k, "nan")) != v
                   for k, v in only):
                continue
            key = (s["scene"], s["N"], s["ktilde"], s["J"])
            groups.setdefault(s["dimension"], {}).setdefault(key, []).append(s)
    if not groups:
        sys.exit("no summary with steps and factorisations matched")
    if len(groups) > 1:
        sys.exit("the points hold discs and spheres, whose factorisations cost different times: "
                 "price one kind per table (--only dimension=2 or --only dimension=3)")
    dimension, groups = next(iter(groups.items()))
    if a.ms_per_factorisation is None:
        if dimension == 3:
            sys.exit("spheres: give --ms-per-factorisation, measured on this machine (bench_solver's "
                     "cholmod_spheres; the discs' default of 2.3 ms is ~25-35 times too small)")
        a.ms_per_factorisation = 2.3
    print(f"{'spheres' if dimension == 3 else 'discs'}: floor = factorisations per strain x "
          f"{a.ms_per_factorisation:g} ms; per point: {a.strains:g} strains\n")
    print("| scene | N | ktilde | J | points | steps / strain | factorisations / step "
          "| floor CPU s / strain | floor CPU h / point |")
    print("|---|---|---|---|---|---|---|---|---|")
    total = 0.0
    for (scene, n, k, j), ss in sorted(groups.items()):
        steps = sum(s["steps_per_strain"] for s in ss) / len(ss)
        fact = sum(s["factorisations"] / s["steps"] for s in ss) / len(ss)
        floor = steps * fact * a.ms_per_factorisation / 1e3
        hours = floor * a.strains / 3600
        total += hours
        print(f"| {scene} | {n} | {k:g} | {j:g} | {len(ss)} | {steps:,.0f} | {fact:.2f} "
              f"| {floor:.1f} | {hours:.2f} |")
    print(f"\none point of each row: {total:.2f} CPU h of factorisations at least")


if __name__ == "__main__":
    main()
