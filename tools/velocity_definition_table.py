#!/usr/bin/python3
"""dv and Psi for each velocity definition against the seed's laws, from a results store.

Reads STORE/points/*/summary.json of runs made with analysis.velocity_intervals (for example
results/velocity_definition_n250, from configs/sweep_velocity_definition_n250.toml) and prints a
Markdown table: per J, dv and Psi from the instantaneous velocities and from displacements over
each interval, as ratios to the seed's laws dv = 0.26 J^(-1/4) and Psi = 0.35 J^(1/4) (with the
run's jackknife errors), and D / (dv^2 Psi) per definition. Then, per definition, whether both
ratios are within 2 sigma of 1 at every J. The seed's laws are the discs'; a store of spheres
is set against them too, as the 2D reference, and the table's heading says so.

    tools/velocity_definition_table.py results/velocity_definition_n250 [--out FILE]
"""
import argparse
import pathlib
import sys

import rundir


def seed_dv(j):
    return 0.26 * j ** -0.25


def seed_psi(j):
    return 0.35 * j ** 0.25


def load(store):
    rows = []
    for run in rundir.Store(store).points():
        s = run.summary
        if "velocity_intervals" not in s or "dv" not in s:
            continue
        defs = [("instantaneous", s["dv"], s.get("dv_err"), s["psi"], s.get("psi_err"))]
        for k, delta in enumerate(s["velocity_intervals"]):
            defs.append((f"Delta = {delta:g}", s["dv_intervals"][k], s["dv_intervals_err"][k],
                         s["psi_intervals"][k], s["psi_intervals_err"][k]))
        rows.append({"J": s["J"], "D": s["D"], "stationary": s.get("stationary"),
                     "point": run.path.name, "defs": defs, "dimension": s.get("dimension", 2)})
    return sorted(rows, key=lambda r: r["J"])


def ratio(x, err, law):
    r = x / law
    return r, (err / law if err is not None else float("nan"))


def table(rows):
    # The k-th interval is rounded to each run's sample grid, so its value differs between J:
    # definitions are matched by position, and the header gives each interval's range over J.
    count = min(len(r["defs"]) for r in rows)
    names = ["instantaneous"]
    for k in range(1, count):
        deltas = sorted({float(r["defs"][k][0].split("=")[1]) for r in rows})
        span = f"{deltas[0]:.3g}" if len(deltas) == 1 else f"{deltas[0]:.3g}-{deltas[-1]:.3g}"
        names.append(f"Delta = {span}")
    out = ["| J | stationary | D | " + " | ".join(
        f"{n}: dv/seed, Psi/seed, D/(dv^2 Psi)" for n in names) + " |",
        "|---|---|---|" + "---|" * len(names)]
    within = [True] * count
    for r in rows:
        cells = []
        for k, (_, dv, dv_err, psi, psi_err) in enumerate(r["defs"][:count]):
            a, ae = ratio(dv, dv_err, seed_dv(r["J"]))
            b, be = ratio(psi, psi_err, seed_psi(r["J"]))
            cells.append(f"{a:.2f} +- {ae:.2f}, {b:.2f} +- {be:.2f}, {r['D'] / (dv * dv * psi):.2f}")
            if not (abs(a - 1) <= 2 * ae and abs(b - 1) <= 2 * be):
                within[k] = False
        out.append(f"| {r['J']:g} | {r['stationary']} | {r['D']:.4g} | " + " | ".join(cells) + " |")
    out.append("")
    for k, n in enumerate(names):
        out.append(f"- {n}: dv and Psi both within 2 sigma of the seed's laws at every J: "
                   f"{'yes' if within[k] else 'no'}")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("store")
    ap.add_argument("--out", help="also write the table to this file")
    a = ap.parse_args()
    rows = load(a.store)
    if not rows:
        sys.exit(f"{a.store}: no point with analysis.velocity_intervals")
    text = table(rows)
    if any(r["dimension"] == 3 for r in rows):
        text = "Spheres against the seed's laws of discs (the 2D reference):\n\n" + text
    sys.stdout.write(text)
    if a.out:
        pathlib.Path(a.out).write_text(text)


if __name__ == "__main__":
    main()
