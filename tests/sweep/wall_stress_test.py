#!/usr/bin/python3
"""tools/wall_stress.py on synthetic points with a known answer. The particles lag the imposed
flow by eps (y - H/2) at a uniform volume fraction phi, so the drag density is
f = c J phi eps (y - H/2), c the mixture's 3 pi d per unit volume fraction, and x momentum
balance gives sigma_xy(y) = mu - c J phi eps (y^2 / 2 - H y / 2) from either wall; the tool's
"mu + drag to the bulk" must be that stress's mean over the bulk band's bin centres. The pair
stress column must read the profile's band mean; a point whose window failed the stationarity
test is left out; discs and spheres together are refused. Usage: wall_stress_test.py REPO WORK"""
import json
import math
import pathlib
import subprocess
import sys

repo, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
J, phi, eps, H, b, mu, e = 0.05, 0.5, 0.02, 16.0, 0.5, 0.7, 3.0
ys = [(k + 0.5) * b for k in range(int(H / b) + 4)]  # bins run past the top wall, as a run's do


def write_point(store, name, dimension, mix, stationary=True, sxy_band=0.9):
    d = store / "points" / name
    d.mkdir(parents=True, exist_ok=True)
    (d / "config.toml").write_text(
        f'[scene]\ntype = "pressure_shear"\ndimension = {dimension}\n'
        f'[particles]\nmix = "{mix}"\nsize_ratio = 1.4\n[flow]\nlz = 1.0\n'
        f'[observables]\nwall_exclusion = {e}\n')
    inside = [y <= H for y in ys]
    summary = {
        "J": J, "H": H, "mu": mu, "mu_top": mu, "mu_bottom": mu, "dimension": dimension,
        "stationary": stationary, "profile_bin": b, "profile_y": ys,
        "profile_phi": [phi if i else 0.0 for i in inside],
        "profile_u_x": [y * (1 - eps) + eps * H / 2 if i else 0.0 for y, i in zip(ys, inside)],
        # the band's bins read sxy_band, the walls' another value the band mean must not see
        "profile_shear_stress": [sxy_band if e <= y <= H - e else 0.3 for y in ys],
    }
    (d / "summary.json").write_text(json.dumps(summary))


def expected(c):
    band = [y for y in ys if e <= y <= H - e]
    return sum(mu - c * J * phi * eps * (y * y / 2 - H * y / 2) for y in band) / len(band)


def row_cells(out, first):
    rows = [line for line in out.splitlines() if line.startswith(f"| {first} |")]
    assert len(rows) == 1, out
    return [c.strip() for c in rows[0].strip("|").split("|")]


def run(*stores):
    return subprocess.run([sys.executable, str(repo / "tools/wall_stress.py"), *map(str, stores)],
                          capture_output=True, text=True)


# Spheres, equal volumes of d and 1.4 d: number per volume (phi / 2) / (pi a^3 4 / 3) each.
spheres = work / "spheres"
write_point(spheres, "seed=1", 3, "volume")
write_point(spheres, "seed=2", 3, "volume", stationary=False, sxy_band=5.0)
c3 = sum(0.5 / (4 / 3 * math.pi * a ** 3) * 3 * math.pi * 2 * a for a in (0.5, 0.7))
r = run(spheres)
assert r.returncode == 0, r.stderr
cells = row_cells(r.stdout, "0.05")
assert cells[1] == "1", f"the drifting point must not count: {cells}"
assert abs(float(cells[3]) - 0.9) < 1e-9, cells
assert abs(float(cells[4]) - expected(c3)) < 1.5e-3, (cells, expected(c3))
assert expected(c3) - mu > 0.1, "the drag term must be large enough to test"
boyer = 0.32 + 0.38 / (1 + 0.005 / J) + J + 2.5 * 0.585 * J ** 0.5
assert abs(float(cells[8]) - 0.9 / (boyer - J)) < 1e-3, cells

# Discs mixed by number in a monolayer of thickness l_z = 1: area fractions a^2 / (sum a^2).
discs = work / "discs"
write_point(discs, "seed=1", 2, "number")
c2 = sum(a * a / (0.25 + 0.49) / (math.pi * a * a) * 3 * math.pi * 2 * a for a in (0.5, 0.7))
r = run(discs)
assert r.returncode == 0, r.stderr
cells = row_cells(r.stdout, "0.05")
assert len(cells) == 5, f"discs have no Boyer columns: {cells}"
assert abs(float(cells[4]) - expected(c2)) < 1.5e-3, (cells, expected(c2))

r = run(spheres, discs)
assert r.returncode != 0 and "mix discs and spheres" in r.stderr, (r.returncode, r.stderr)
print("wall_stress: ok")
