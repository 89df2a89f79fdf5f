#!/usr/bin/python3
"""The shear stress of the pressure cell's bulk against the walls' mu, and both against Boyer,
Guazzelli & Pouliquen (2011), from the stored points' summaries (profiles included).

The one-body Stokes drag acts against the imposed flow gammadot (y - y_b) (docs/model.md
section 3), so wherever the particles' mean velocity u_x(y) departs from it the drag adds a force
density f_x(y) = n(y) 3 pi eta d (gammadot (y - y_b) - u_x(y)) along x, and the shear stress is
not the same at every height: x momentum balance of the slab between the bottom wall and y gives

    sigma_xy(y) = mu_bottom P - int_0^y f_x dy'     (and from the top: mu_top P + int_y^H f_x dy').

For each point this prints, averaged over the bulk band (the profile bins at least
`observables.wall_exclusion` from both wall lines, as phi):

  * sigma_xy / P of the pair forces (profile_shear_stress, docs/model.md section 9);
  * where the points measured it (profile_shear_stress_lubrication), the part of the first that the
    lubrication forces make, the rest being the contacts'; for spheres, a second table sets the
    two parts beside the contact and hydrodynamic terms of Boyer et al.'s fit (for orientation);
  * mu plus the drag between the walls and each height of the band: the equation above, with
    n(y) 3 pi eta d from each bin's volume fraction (the species mixed as `particles.mix` says, in
    every bin alike) and u_x(y) the bin's mean over the particles centred in it (a bin without
    centres takes its nearest such bin's); the mean of the two walls' values.

--points adds, per point:
  * the part of that drag between the wall lines and the band's edges (the rest lies between the
    band's edge and each height within it);
  * the drag over the whole gap, which the walls' difference mu_bottom - mu_top must equal;
  * the slip at the walls: the mean, weighted by phi over the bins between each wall line and the
    band, of how far the particles' u_x runs ahead of the imposed flow at the fixed wall and
    behind it at the moving one, averaged over the two walls (NaN if no bin lies there). The
    drag next to the walls is about c J phi_w wall_exclusion times it, c the drag per unit volume
    fraction and phi_w those bins' mean volume fraction;
  * for spheres, the spacing of the walls' spheres, lx / floor(lx) in d
    (src/scene/pressure_shear_3d.cpp lays each wall as a square lattice of spheres of diameter d
    filling lx x lz): the gaps between them widen the further it lies above 1.

The two are independent measurements of one stress: the first from the pair forces, the second
from the wall forces and the velocity profile. Per J: the mean over the stationary points (+- the
standard error of the seeds' scatter), with Boyer et al.'s mu(J) and that fit less its J term (the
suspending fluid's own stress eta gammadot, which no force of this model carries) for spheres.

    /usr/bin/python3 tools/wall_stress.py STORE [STORE ...]     # e.g. results/sweep_3d_j01 results/sweep_3d
    /usr/bin/python3 tools/wall_stress.py --points STORE ...    # one row per point as well
    /usr/bin/python3 tools/wall_stress.py --include-not-stationary ...   # the failed windows too
"""
import argparse
import dataclasses
import math
import pathlib
import sys

import rundir
from results_table import BOYER_LAWS, boyer_contact_term, boyer_hydrodynamic_term, fmt, pm


def drag_coefficient(cfg):
    """n 3 pi eta d per unit volume fraction (eta = 1, in P / (gammadot d) per d): the drag
    density on particles moving at 1 relative to the fluid, over phi. The species' numbers are
    in the ratio `particles.mix` sets (src/setup/random_packing.cpp): small to large 1 by number,
    size_ratio^2 by area, size_ratio^3 by volume."""
    p = cfg.get("particles", {})
    spheres = cfg.get("scene", {}).get("dimension", 2) == 3
    ratio = p.get("size_ratio", 1.4)
    radii = (0.5, 0.5 * ratio)

    def measure(a):
        return 4.0 / 3.0 * math.pi * a ** 3 if spheres else math.pi * a * a

    small_per_large = {"number": 1.0, "area": ratio ** 2, "volume": ratio ** 3}[p.get("mix", "volume")]
    numbers = (small_per_large, 1.0)
    # Each species' share of the volume fraction, and its drag per unit of it.
    shares = [n * measure(a) for n, a in zip(numbers, radii)]
    lz = 1.0 if spheres else cfg.get("flow", {}).get("lz", 1.0)
    return sum(w / sum(shares) / measure(a) * 3.0 * math.pi * 2.0 * a
               for w, a in zip(shares, radii)) / lz


@dataclasses.dataclass
class PointStress:
    """One finished point's stresses over P (velocities over gammadot, lengths in d)."""
    J: float
    mu: float  # the walls'
    bulk: float  # the bulk band's pair sigma_xy
    walls_plus_drag: float  # mu + the drag between the walls and each height of the band
    dimension: int
    gap_drag: float  # the drag over the whole gap
    walls_difference: float  # mu_bottom - mu_top
    lubrication: float | None  # the lubrication part of bulk, where measured
    next_to_walls: float  # the part of walls_plus_drag - mu between the wall lines and the band
    wall_slip: float  # NaN where no bin lies between a wall line and the band


def point_stresses(run):
    """The PointStress of one finished point, or None without profiles."""
    s, cfg = run.summary, run.config
    need = ("profile_y", "profile_phi", "profile_u_x", "profile_shear_stress", "profile_bin",
            "profile_T")
    if any(s.get(k) is None for k in need) or s.get("mu") is None:
        return None
    J, H, b = s["J"], s["H"], s["profile_bin"]
    e = cfg.get("observables", {}).get("wall_exclusion", 3.0)
    c = drag_coefficient(cfg)
    y, phi, ux, sxy, _, temp = (s[k] for k in need)
    inside = [k for k in range(len(y)) if 0.0 <= y[k] <= H]
    # A bin no particle is centred in reads u_x = T = 0 exactly, though the caps of its
    # neighbours' particles give it a volume fraction (the bins at the walls): those particles
    # move with the nearest bin that has centres.
    centred = [k for k in inside if ux[k] != 0.0 or temp[k] != 0.0]
    if not centred:
        return None

    def slip(k):
        nearest = k if k in centred else min(centred, key=lambda m: abs(m - k))
        return y[nearest] - ux[nearest]

    # Drag density on the particles of each bin (u_x and y in d, velocities over gammadot).
    f = {k: c * J * phi[k] * slip(k) for k in inside}
    below, from_bottom = 0.0, {}
    for k in inside:
        from_bottom[k] = s["mu_bottom"] - (below + 0.5 * b * f[k])
        below += b * f[k]
    above, from_top = 0.0, {}
    for k in reversed(inside):
        from_top[k] = s["mu_top"] + above + 0.5 * b * f[k]
        above += b * f[k]
    band = [k for k in inside if e <= y[k] <= H - e]
    if not band:
        return None
    mean = lambda v: sum(v) / len(v)  # noqa: E731
    walls_plus_drag = 0.5 * (mean([from_bottom[k] for k in band]) + mean([from_top[k] for k in band]))
    lub = s.get("profile_shear_stress_lubrication")
    under = [k for k in inside if y[k] < e]
    over = [k for k in inside if y[k] > H - e]
    # What the drag adds to the stress between each wall line and the band's edge; the rest of
    # walls_plus_drag - mu is the drag between the band's edge and each height within it.
    next_to_walls = 0.5 * (-sum(b * f[k] for k in under) + sum(b * f[k] for k in over))

    def weighted_slip(bins, sign):
        weight = sum(phi[k] for k in bins)
        return sign * sum(phi[k] * slip(k) for k in bins) / weight if weight > 0 else math.nan

    # slip(k) = y - u_x: ahead of the imposed flow at the fixed wall is -slip, behind it at the
    # moving wall +slip; both positive where the profile flattens towards the walls.
    wall_slip = 0.5 * (weighted_slip(under, -1.0) + weighted_slip(over, 1.0))
    return PointStress(J, s["mu"], mean([sxy[k] for k in band]), walls_plus_drag,
                       s.get("dimension", 2), below, s["mu_bottom"] - s["mu_top"],
                       mean([lub[k] for k in band]) if lub else None, next_to_walls, wall_slip)


def wall_spacing(summary):
    """The centre distance of neighbouring wall spheres in d: each wall is floor(lx) spheres a
    side on a square lattice filling lx x lz (src/scene/pressure_shear_3d.cpp, add_wall)."""
    return summary["lx"] / max(1, math.floor(summary["lx"]))


def boyer_less_fluid(J):
    return BOYER_LAWS["mu"](J) - J


def print_split(by_j):
    """Spheres: the bulk's sigma_xy split into the contacts' and the lubrication's parts, each
    beside the term of Boyer et al.'s fit that stands for it. For orientation only: their split is
    a fitting form, and their hydrodynamic term holds all the fluid's stress between particles
    (the one-body stresslet and the many-body far field too), of which lubrication is a part."""
    rows = {J: [x for _, x in pts if x.lubrication is not None] for J, pts in by_j.items()}
    rows = {J: r for J, r in rows.items() if r}
    if not rows:
        return
    print()
    print("| J | points | contact part / P | Boyer's contact term | ratio | lubrication part / P | "
          "Boyer's (5/2) phi_m J^1/2 | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for J in sorted(rows):
        (con, con_e), (lub, lub_e) = (rundir.mean_sem(c) for c in
                                      ([x.bulk - x.lubrication for x in rows[J]],
                                       [x.lubrication for x in rows[J]]))
        bc, bh = boyer_contact_term(J), boyer_hydrodynamic_term(J)
        print(f"| {J:g} | {len(rows[J])} | {pm(con, con_e)} | {bc:.3g} | {con / bc:.3f} | "
              f"{pm(lub, lub_e)} | {bh:.3g} | {lub / bh:.3f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stores", nargs="+", type=pathlib.Path)
    ap.add_argument("--points", action="store_true", help="print each point's row as well")
    ap.add_argument("--include-not-stationary", action="store_true",
                    help="count the points whose window failed the stationarity test too (as "
                         "`sheardiff fit --include-not-stationary`); their rows say so")
    args = ap.parse_args()
    by_j = {}
    for path in args.stores:
        if not (path / rundir.POINTS).is_dir():
            sys.exit(f"{path}: no points/ folder (a sweep folder or results/<name>)")
        for run in rundir.Store(path).points():
            if not run.summary.get("stationary") and not args.include_not_stationary:
                continue
            x = point_stresses(run)
            if x is None:
                continue
            by_j.setdefault(x.J, []).append((run.path, x))
    if not by_j:
        sys.exit("no stationary finished point with profiles in " + ", ".join(map(str, args.stores)))
    dims = {x.dimension for rows in by_j.values() for _, x in rows}
    if len(dims) > 1:
        sys.exit("the stores mix discs and spheres: tabulate each on its own")
    spheres = dims == {3}
    if args.points:
        # The drag over the whole gap is the walls' difference (x momentum of the whole cell):
        # the check that the profiles hold the drag.
        print("| point | J | mu (walls) | bulk sigma_xy / P | mu + drag to the bulk | of which next "
              "to the walls | drag over the gap / P | mu_bottom - mu_top | lubrication part of the "
              "bulk's / P | slip at the walls / (gammadot d) |"
              + (" walls' spacing / d |" if spheres else ""))
        print("|---|---|---|---|---|---|---|---|---|---|" + ("---|" if spheres else ""))
        for J in sorted(by_j):
            for path, x in by_j[J]:
                summary = rundir.Run(path).summary
                flag = "" if summary.get("stationary") else " (not stationary)"
                print(f"| {path.parent.parent.name}/{path.name}{flag} | {J:g} | {x.mu:.3f} | "
                      f"{x.bulk:.3f} | {x.walls_plus_drag:.3f} | {x.next_to_walls:+.3f} | "
                      f"{x.gap_drag:+.3f} | {x.walls_difference:+.3f} | {fmt(x.lubrication)} | "
                      f"{x.wall_slip:+.3f} |" + (f" {wall_spacing(summary):.3f} |" if spheres else ""))
        print()
    boyer = " Boyer | Boyer less J | bulk / Boyer | bulk / (Boyer less J) |" if spheres else ""
    print("| J | points | mu (walls) | bulk sigma_xy / P (pair forces) | mu + drag to the bulk | "
          "lubrication part of the bulk's (points) |" + boyer)
    print("|---|---|---|---|---|---|" + "---|" * (4 if spheres else 0))
    for J in sorted(by_j):
        cols = list(zip(*[(x.mu, x.bulk, x.walls_plus_drag) for _, x in by_j[J]]))
        (mu, mu_e), (bulk, bulk_e), (plus, plus_e) = (rundir.mean_sem(c) for c in cols)
        # Points run before the lubrication part was measured have none: the mean of those that do.
        lubs = [x.lubrication for _, x in by_j[J] if x.lubrication is not None]
        lub = pm(*rundir.mean_sem(lubs)) + f" ({len(lubs)})" if lubs else "-"
        row = (f"| {J:g} | {len(by_j[J])} | {pm(mu, mu_e)} | {pm(bulk, bulk_e)} | {pm(plus, plus_e)} "
               f"| {lub} |")
        if spheres:
            ref, less = BOYER_LAWS["mu"](J), boyer_less_fluid(J)
            row += f" {ref:.3g} | {less:.3g} | {bulk / ref:.3f} | {bulk / less:.3f} |"
        print(row)
    if spheres:
        print_split(by_j)


if __name__ == "__main__":
    main()
