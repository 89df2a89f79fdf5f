#!/usr/bin/python3
"""Markdown tables of a finished sweep for docs/results.md: per group (ktilde, N, ...) the
measured points (J, phi, mu, D, dv, Psi, steps per strain, wall time) and the fitted laws side
by side with the seed's Table 1 and eq. (3.3).

    /usr/bin/python3 tools/results_table.py SWEEP_DIR
"""
import csv
import json
import pathlib
import sys


def fmt(x, p=3):
    return "-" if x is None else f"{x:.{p}g}"


def law(f, seed=None):
    if "error" in f:
        return f"not fitted ({f['error']})"
    s = f"{f['a']:.3g} +- {f['a_stderr']:.1g}, {f['b']:+.3f} +- {f['b_stderr']:.3f}"
    return s


def main():
    out = pathlib.Path(sys.argv[1])
    fits = json.loads((out / "fits.json").read_text())
    rows = list(csv.DictReader(open(out / "sweep.csv")))
    seed = fits["seed_table1"]
    total_wall = sum(float(r["wall_seconds"]) for r in rows if r.get("wall_seconds"))
    print(f"{fits['finished']} of {fits['points']} points finished; "
          f"summed run wall time {total_wall / 3600:.2f} h.\n")
    for g in fits["groups"]:
        axes = ", ".join(f"{k} = {v}" for k, v in g["axes"].items()) or "all points"
        print(f"#### {axes}\n")
        print("| J | phi | mu | D / (gammadot d^2) | dv / (gammadot d) | Psi gammadot | steps per strain | wall s |")
        print("|---|---|---|---|---|---|---|---|")
        by_j = {}
        for r in rows:
            if r["status"] != "done":
                continue
            if all(str(r.get("axis." + k, "")) in (str(v), f"{v}") or
                   (r.get("axis." + k) and float(r["axis." + k]) == float(v))
                   for k, v in g["axes"].items()):
                by_j.setdefault(float(r["J"]), r)
        for row in sorted(g["rows"], key=lambda r: r["J"]):
            r = by_j.get(row["J"], {})
            print(f"| {row['J']:g} | {fmt(row['phi'], 4)} | {fmt(row['mu'])} | {fmt(row['D'])} | "
                  f"{fmt(row['dv'])} | {fmt(row['psi'])} | "
                  f"{fmt(float(r['steps_per_strain']), 4) if r.get('steps_per_strain') else '-'} | "
                  f"{fmt(float(r['wall_seconds']), 4) if r.get('wall_seconds') else '-'} |")
        f = g["fits"]
        print("\n| law | sheardiff: a, b (+- standard errors) | seed Table 1: a, b |")
        print("|---|---|---|")
        for key, name in (("D_vs_J", "D/(gammadot d^2) = a J^b"),
                          ("dv_vs_J", "dv/(gammadot d) = a J^b"),
                          ("psi_vs_J", "Psi gammadot = a J^b"),
                          ("D_vs_phic_minus_phi", "D/(gammadot d^2) = a (phi_c - phi)^b"),
                          ("dv_vs_phic_minus_phi", "dv/(gammadot d) = a (phi_c - phi)^b"),
                          ("psi_vs_phic_minus_phi", "Psi gammadot = a (phi_c - phi)^b")):
            s = seed[key]
            print(f"| {name} | {law(f[key])} | {s['a']} +- {s['a_stderr']}, {s['b']} +- {s['b_stderr']} |")
        p = f["phi_of_J"]
        if "phi_c" in p:
            print(f"| phi = phi_c - a J^b | phi_c = {p['phi_c']:.4f} +- {p['phi_c_stderr']:.4f}, "
                  f"a = {p['a']:.3g} +- {p['a_stderr']:.2g}, b = {p['b']:.3f} +- {p['b_stderr']:.3f} "
                  f"| phi_c = 0.81, a = 0.64, b = 0.5 |")
        m = f["mu_of_J"]
        if "mu_c" in m:
            print(f"| mu = mu_c + a J^b | mu_c = {m['mu_c']:.3f} +- {m['mu_c_stderr']:.3f}, "
                  f"a = {m['a']:.3g} +- {m['a_stderr']:.2g}, b = {m['b']:.3f} +- {m['b_stderr']:.3f} | - |")
        print()


if __name__ == "__main__":
    main()
