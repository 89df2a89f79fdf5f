#!/usr/bin/python3
"""tools/wall_stress.py on synthetic points with a known answer. The particles lag the imposed
flow by eps (y - y0) at a uniform volume fraction phi, y0 below mid-gap, so the drag density is
f = c J phi eps (y - y0), c the mixture's 3 pi d per unit volume fraction, and the walls differ by
the drag over the whole gap. The bin under the top wall holds caps of particles but no centre
(u_x = T = 0 there, as a run writes it): its particles move as the nearest bin's. x momentum
balance then gives the stress at every y below it in closed form, from either wall; the tool's
"mu + drag to the bulk" must be its mean over the bulk band's bin centres, and the slip at the
walls the phi-weighted mean of the profile's departure in the bins next to them. The pair stress column
and its lubrication part must read the profiles' band means; a point whose window failed the stationarity test is left out;
discs and spheres together are refused. Usage: wall_stress_test.py REPO WORK"""
import json
import math
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
J, phi, eps, H, b, mu_top, e, y0 = 0.05, 0.5, 0.02, 16.0, 0.5, 0.7, 3.0, 6.0
phi_edge = 0.3  # the volume fraction of the bin under the top wall, which has no centre
ys = [(k + 0.5) * b for k in range(int(H / b) + 4)]  # bins run past the top wall, as a run's do
edge = int(H / b) - 1  # the last bin below the top wall's line


def phi_at(k):
    """phi in the band and above it; rising from 0.2 phi to phi over the bins below e, so that
    the slip's weighting by phi shows; phi_edge in the edge bin; 0 past the top wall."""
    if k > edge:
        return 0.0
    if k == edge:
        return phi_edge
    return phi * (0.2 + 0.8 * ys[k] / e) if ys[k] < e else phi


def drag(c):
    """Per bin below H: the drag density the synthetic profile holds."""
    return [c * J * phi_at(k) * eps * (ys[min(k, edge - 1)] - y0) for k in range(edge + 1)]


def write_point(store, name, dimension, mix, c, lz=1.0, stationary=True, sxy_band=0.9,
                lubrication_band=None):
    d = store / "points" / name
    d.mkdir(parents=True, exist_ok=True)
    (d / "config.toml").write_text(
        f'[scene]\ntype = "pressure_shear"\ndimension = {dimension}\n'
        f'[particles]\nmix = "{mix}"\nsize_ratio = 1.4\n[flow]\nlz = {lz}\n'
        f'[observables]\nwall_exclusion = {e}\n')
    mu_bottom = mu_top + sum(drag(c)) * b  # x momentum of the whole cell
    centred = [k < edge for k in range(len(ys))]
    summary = {
        "J": J, "H": H, "lx": 9.86, "mu": 0.5 * (mu_top + mu_bottom), "mu_top": mu_top, "mu_bottom": mu_bottom,
        "dimension": dimension, "stationary": stationary, "profile_bin": b, "profile_y": ys,
        "profile_phi": [phi_at(k) for k in range(len(ys))],
        "profile_u_x": [y - eps * (y - y0) if i else 0.0 for y, i in zip(ys, centred)],
        "profile_T": [0.01 if i else 0.0 for i in centred],
        # the band's bins read sxy_band, the walls' another value the band mean must not see
        "profile_shear_stress": [sxy_band if e <= y <= H - e else 0.3 for y in ys],
    }
    if lubrication_band is not None:
        summary["profile_shear_stress_lubrication"] = [lubrication_band if e <= y <= H - e else 0.1
                                                       for y in ys]
    (d / "summary.json").write_text(json.dumps(summary))


def expected(c):
    """The stress at each band centre y from the top wall: mu_top + the drag above y, in closed
    form (the linear drag below the edge bin, integrated exactly) plus the edge bin's."""
    f = drag(c)
    band = [y for y in ys if e <= y <= H - e]
    below_edge = H - b
    def integral(y):  # of c J phi eps (y' - y0) from y to the edge bin's lower side
        return c * J * phi * eps * ((below_edge ** 2 - y ** 2) / 2 - y0 * (below_edge - y))
    return sum(mu_top + integral(y) + f[edge] * b for y in band) / len(band)


def row_cells(out, first):
    rows = [line for line in out.splitlines() if line.startswith(f"| {first} |")]
    assert len(rows) == 1, out
    return [c.strip() for c in rows[0].strip("|").split("|")]


def run(*stores):
    return subprocess.run([sys.executable, str(repo / "tools/wall_stress.py"), *map(str, stores)],
                          capture_output=True, text=True)


# Spheres, equal volumes of d and 1.4 d: number per volume (phi / 2) / (pi a^3 4 / 3) each.
c3 = sum(0.5 / (4 / 3 * math.pi * a ** 3) * 3 * math.pi * 2 * a for a in (0.5, 0.7))
spheres = work / "spheres"
write_point(spheres, "seed=1", 3, "volume", c3, lubrication_band=0.4)
write_point(spheres, "seed=2", 3, "volume", c3, stationary=False, sxy_band=5.0)
r = run(spheres)
assert r.returncode == 0, r.stderr
# Spheres print two tables: the stresses, then their split against Boyer et al.'s terms.
cells = row_cells(r.stdout.split("\n\n")[0], "0.05")
assert cells[1] == "1", f"the drifting point must not count: {cells}"
assert abs(float(cells[3]) - 0.9) < 1e-9, cells
assert abs(float(cells[4]) - expected(c3)) < 1.5e-3, (cells, expected(c3))
assert abs(expected(c3) - mu_top) > 0.1, "the drag term must be large enough to test"
boyer = 0.32 + 0.38 / (1 + 0.005 / J) + J + 2.5 * 0.585 * J ** 0.5
assert cells[5] == "0.4 (1)", f"the band's lubrication part, from the one point: {cells}"
assert abs(float(cells[9]) - 0.9 / (boyer - J)) < 1e-3, cells
# The split table (the second): the contacts' part is the band's pair stress less its
# lubrication part, each beside its term of the fit at J = 0.05 (0.32 + 0.38 / 1.1 and
# 2.5 x 0.585 x 0.05^1/2).
contact_term, hydro_term = 0.665455, 0.327025
cells = row_cells(r.stdout.split("\n\n")[1], "0.05")
assert cells[1] == "1" and abs(float(cells[2]) - 0.5) < 1e-9, cells
assert abs(float(cells[3]) - contact_term) < 1e-3, cells
assert abs(float(cells[4]) - 0.5 / contact_term) < 1e-3, cells
assert abs(float(cells[5]) - 0.4) < 1e-9 and abs(float(cells[7]) - 0.4 / hydro_term) < 1e-3, cells

# Points with and without the split at one J: the split is each point's own difference, over
# the points that have one (a split of the means over all points would read 0.767 here).
mixed = work / "mixed"
write_point(mixed, "seed=1", 3, "volume", c3, lubrication_band=0.4)
write_point(mixed, "seed=2", 3, "volume", c3, sxy_band=1.5)
write_point(mixed, "seed=3", 3, "volume", c3, sxy_band=0.8, lubrication_band=0.2)
r = run(mixed)
assert r.returncode == 0, r.stderr
cells = row_cells(r.stdout.split("\n\n")[1], "0.05")
assert cells[1] == "2", cells
assert cells[2].startswith("0.55 +- 0.05") and cells[5].startswith("0.3 +- 0.1"), cells

# The check of --points: the drag over the whole gap is the walls' difference (the synthetic
# walls were set so), the mean of the two walls' estimates being blind to which wall is which.
r = subprocess.run([sys.executable, str(repo / "tools/wall_stress.py"), "--points", str(spheres)],
                   capture_output=True, text=True)
assert r.returncode == 0, r.stderr
cells = row_cells(r.stdout, "spheres/seed=1")
assert abs(float(cells[6]) - float(cells[7])) < 1.5e-3 and abs(float(cells[7])) > 0.1, cells
assert abs(float(cells[8]) - 0.4) < 1e-9, cells
# The slip at the walls: the particles run ahead of the imposed flow by eps (y0 - y) below y0 and
# fall behind it by eps (y - y0) above; over the bins below e and above H - e (the edge bin moving
# as the one below it), each weighted by its phi. Printed to 3 decimals, so within 6e-4: an
# unweighted mean (0.1292) or one without the edge bin (0.1243) is further off (0.1253).
under = [k for k in range(edge + 1) if ys[k] < e]
over = [k for k in range(edge + 1) if ys[k] > H - e]
ahead = sum(phi_at(k) * eps * (y0 - ys[k]) for k in under) / sum(phi_at(k) for k in under)
behind = sum(phi_at(k) * eps * (ys[min(k, edge - 1)] - y0) for k in over) / sum(
    phi_at(k) for k in over)
wall_slip = 0.5 * (ahead + behind)
assert abs(float(cells[9]) - wall_slip) < 6e-4 and wall_slip > 0.1, (cells, wall_slip)
# The drag between the wall lines and the band's edges: the drag density summed over those bins,
# against the flow at the bottom wall, with it at the top.
f = drag(c3)
next_to_walls = 0.5 * b * (-sum(f[k] for k in under) + sum(f[k] for k in over))
assert abs(float(cells[5]) - next_to_walls) < 6e-4 and next_to_walls > 0.01, (cells, next_to_walls)
# Spheres: 9 wall spheres a side fill lx = 9.86, 1.096 d apart.
assert cells[10] == "1.096", cells

# The drifting point counts when asked, and its row says it failed the test.
r = subprocess.run([sys.executable, str(repo / "tools/wall_stress.py"), "--points",
                    "--include-not-stationary", str(spheres)], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
assert len(row_cells(r.stdout, "spheres/seed=2 (not stationary)")) == 11, r.stdout
assert row_cells(r.stdout.split("\n\n")[1], "0.05")[1] == "2", r.stdout

# Discs mixed by volume (1.4^3 small discs to a large one) in a monolayer of thickness 1.5:
# the species' area fractions are their numbers times their areas.
shares = [1.4 ** 3 * 0.25, 0.49]
c2 = sum(w / sum(shares) / (math.pi * a * a) * 3 * math.pi * 2 * a
         for w, a in zip(shares, (0.5, 0.7))) / 1.5
discs = work / "discs"
write_point(discs, "seed=1", 2, "volume", c2, lz=1.5)
r = run(discs)
assert r.returncode == 0, r.stderr
cells = row_cells(r.stdout, "0.05")
assert len(cells) == 6 and cells[5] == "-", f"discs have no Boyer columns, these none measured: {cells}"
assert abs(float(cells[4]) - expected(c2)) < 1.5e-3, (cells, expected(c2))

r = subprocess.run([sys.executable, str(repo / "tools/wall_stress.py"), "--points", str(discs)],
                   capture_output=True, text=True)
assert r.returncode == 0, r.stderr
assert len(row_cells(r.stdout, "discs/seed=1")) == 10, f"discs' walls have no lattice: {r.stdout}"

r = run(spheres, discs)
assert r.returncode != 0 and "mix discs and spheres" in r.stderr, (r.returncode, r.stderr)
print("wall_stress: ok")
