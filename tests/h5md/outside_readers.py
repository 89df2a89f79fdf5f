#!/usr/bin/python3
"""ctest: sheardiff's trajectories read by code other than sheardiff's own.

Runs a small simple-shear and a small pressure-cell run (contact network on), then
1. the independent H5MD 1.1 checker (tests/h5md/h5md_check.py, units required) must pass on
   both, and must fail on a copy whose box/edges step is a copy rather than a hard link;
2. position + image . edges continuous in time over many Lees-Edwards crossings (the convention
   of LAMMPS and GSD), in the H5MD file and in its GSD export (issue 34: the image used to be
   the one nearest the unwrapped position, which jumped by Lx once the shift gained since a
   crossing passed Lx/2);
3. a trajectory read while its run writes it (HDF5 single-writer/multiple-reader mode);
4. the GSD export (tools/h5md_to_gsd.py) read back with the gsd package: the box of every frame
   must be the H5MD one (Lx, Ly, tilt = xy Ly), and the minimum-image overlaps found under that
   box must be the simulation's (largest overlap at most the run's health limit, every pair of
   /connectivity/contacts within contact distance), while the same positions under the box
   without its tilt show the false overlaps across the y edges that the tilt removes;
5. the LAMMPS dump export (tools/h5md_to_lammps.py) read by MDAnalysis: positions, velocities and
   box as h5py reads them, the unwrapped positions continuous;
6. storage: per-frame series shuffled and deflated, no unwrapped_position where it is
   position + image . edges;
7. a run of spheres (scene.dimension = 3): the H5MD checker passes on its 3D layout, and its GSD
   export is a 3D box (Lx, Ly, Lz) with every sphere inside it and position + image . box
   continuous in time over its x crossings; MDAnalysis reads its LAMMPS dump export as in 5,
   z and its image counts included; snapshot.py's sections by planes z = Z hold the spheres'
   volume (Delesse's rule);
8. centre_of_mass_drift.py's drag of the recorded velocities equals the walls' load difference
   (net_drag_y) frame by frame, for discs and for spheres;
9. low_j_table.py's mean spin is the particles' spin about z read from the file, near the mean
   flow's -gammadot/2 for discs and for spheres.

    outside_readers.py --bin build/sheardiff --root . --work DIR
"""
import argparse
import pathlib
import shutil
import subprocess
import sys

import h5py
import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from h5md_check import check_file  # noqa: E402

SIMPLE = """[scene]
type = "simple_shear"
[particles]
N = 100
phi_init = 0.78
[flow]
J = 1e-2
[run]
strain = 0.5
seed = 3
transient_strain = 0.1
[analysis]
diffusion = false
[output]
frame_strain = 0.05
contacts = true
author = "Outside Reader Test"
"""
PRESSURE = """[scene]
type = "pressure_shear"
[particles]
N = 80
phi_init = 0.6
[flow]
J = 1e-2
[run]
strain = 3.0
seed = 2
[analysis]
diffusion = false
[steady]
window = 0.3
measure_strain = 0.6
[output]
frame_strain = 0.05
contacts = true
"""
LONG = """[scene]
type = "simple_shear"
[particles]
N = 100
phi_init = 0.78
[flow]
J = 1e-2
[run]
strain = 6.0
seed = 3
transient_strain = 0.1
[analysis]
diffusion = false
[output]
frame_strain = 0.01
"""
GENUINE = 0.1  # d: health.max_overlap, the largest overlap a run may have
failures = []


SPHERES = """[scene]
type = "pressure_shear"
dimension = 3
[particles]
N = 64
[flow]
J = 3e-2
[contact]
ktilde = 1e3
[run]
strain = 1.5
seed = 5
[analysis]
diffusion = false
[output]
frame_strain = 0.02
"""


def expect(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def min_image_overlaps(pos, diam, lx, ly, xy_len, periodic_y=True):
    """Pairs (i, j, overlap) overlapping under the box with edge vectors (lx, 0), (xy_len, ly)."""
    d = pos[None, :, :] - pos[:, None, :]
    if periodic_y:
        ny = np.round(d[..., 1] / ly)
        d[..., 0] -= ny * xy_len
        d[..., 1] -= ny * ly
    d[..., 0] -= lx * np.round(d[..., 0] / lx)
    r = np.hypot(d[..., 0], d[..., 1])
    s = 0.5 * (diam[:, None] + diam[None, :])
    ov = s - r
    i, j = np.nonzero(np.triu(ov > 0, 1))
    return i, j, ov[i, j], r, s


def run(binary, work, name, text):
    cfg = work / f"{name}.toml"
    cfg.write_text(text)
    out = work / name
    p = subprocess.run([binary, "run", str(cfg), "--out", str(out)], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{name}: sheardiff run failed ({p.returncode}):\n{p.stderr}")
    return out / "trajectory.h5"


def check_conformance(traj, work):
    errors = check_file(traj, require_units=True)
    for e in errors:
        print("      " + e)
    expect(not errors, f"{traj.parent.name}: independent H5MD 1.1 checker, units required")
    broken = work / f"{traj.parent.name}_unlinked.h5"
    shutil.copy(traj, broken)
    with h5py.File(broken, "r+") as f:
        e = f["particles/suspension/box/edges"]
        step = e["step"][()]
        del e["step"]
        e["step"] = step
    errors = check_file(broken, require_units=True)
    expect(any("hard link" in x for x in errors), f"{traj.parent.name}: the checker catches an unlinked step")


def check_gsd(root, traj, periodic_y):
    import gsd.hoomd

    name = traj.parent.name
    out = traj.with_suffix(".gsd")
    subprocess.run([sys.executable, str(root / "tools" / "h5md_to_gsd.py"), str(traj), "--out", str(out)],
                   check=True, capture_output=True)
    with h5py.File(traj, "r") as f:
        g = f["particles/suspension"]
        edges = g["box/edges/value"][()]
        diam = g["diameter"][()]
        pairs = f["connectivity/contacts/value"][()]
        normal = f["connectivity/contacts/normal_force"][()]
        max_overlap = f["observables/max_overlap/value"][()]
    listed = normal[pairs[:, :, 0] >= 0]
    expect(listed.size > 0 and bool(np.all(listed > 0)),
           f"{name}: every listed contact has a normal force > 0 ({listed.size} entries, smallest "
           f"{listed.min(initial=np.inf):.3g}; a pair the last move opened used to be listed with 0)")
    try:
        traj_gsd = gsd.hoomd.open(name=str(out), mode="r")
    except ValueError:
        traj_gsd = gsd.hoomd.open(name=str(out), mode="rb")
    box_ok, worst, worst_free, false_pairs, pair_gap = True, 0.0, 0.0, 0, 0.0
    with traj_gsd as t:
        expect(len(t) == len(edges), f"{name}: GSD holds all {len(edges)} frames")
        for k, fr in enumerate(t):
            lx, ly, lz, xy = (float(x) for x in fr.configuration.box[:4])
            if periodic_y:
                box_ok &= bool(np.isclose(lx, edges[k, 0, 0]) and np.isclose(ly, edges[k, 1, 1])
                               and np.isclose(xy * ly, edges[k, 1, 0], atol=1e-5) and lz == 0)
            else:
                box_ok &= bool(np.isclose(lx, edges[k, 0, 0]) and xy == 0 and lz == 0)
            box_ok &= fr.configuration.dimensions == 2
            pos = fr.particles.position[:, :2].astype(np.float64)
            i, j, ov, r, s = min_image_overlaps(pos, diam, lx, ly, xy * ly)
            # The discs of one rough wall overlap by construction and are no contacts.
            wall = np.isin(fr.particles.typeid, [fr.particles.types.index("fixed_wall"),
                                                 fr.particles.types.index("floating_wall")])
            ov = ov[~(wall[i] & wall[j])]
            worst = max(worst, ov.max(initial=0.0))
            expect_max = max_overlap[k]
            if ov.size and ov.max() > expect_max + 1e-3:
                print(f"      frame {k}: overlap {ov.max():.4f} d above the run's max_overlap {expect_max:.4f} d")
                box_ok = False
            used = pairs[k][pairs[k, :, 0] >= 0]
            if used.size:
                pair_gap = max(pair_gap, float(np.max(r[used[:, 0], used[:, 1]] - s[used[:, 0], used[:, 1]])))
            if periodic_y:
                _, _, ov0, _, _ = min_image_overlaps(pos, diam, lx, ly, 0.0)
                false_pairs = max(false_pairs, int(np.sum(ov0 > GENUINE)))
                worst_free = max(worst_free, ov0.max(initial=0.0))
    expect(box_ok, f"{name}: gsd reads the H5MD box (Lx, Ly, xy Ly = tilt) and the run's overlaps in every frame")
    print(f"      largest overlap under the GSD box: {worst:.4f} d (run's max_overlap {max_overlap.max():.4f} d)")
    expect(worst <= GENUINE, f"{name}: no overlap above {GENUINE} d under the GSD box")
    expect(pair_gap <= 1e-2, f"{name}: every /connectivity/contacts pair touches under the box (widest gap {pair_gap:.2e} d)")
    if periodic_y:
        print(f"      without the tilt: {false_pairs} pairs overlapping by more than {GENUINE} d, up to {worst_free:.2f} d")
        expect(false_pairs > 0, f"{name}: the box without its tilt shows false overlaps (the check has teeth)")


def check_continuity(root, traj):
    """position + image . edges moves by less than a tenth of the cell per frame, equals the
    unwrapped position in y, and stays so through the GSD export; the nearest-image convention
    on the same frames jumps (the check has teeth)."""
    with h5py.File(traj, "r") as f:
        g = f["particles/suspension"]
        pos = g["position/value"][()]
        img = g["image/value"][()].astype(np.float64)
        edges = g["box/edges/value"][()]
        unw = g["unwrapped_position/value"][()]
    x = pos + img[:, :, :1] * edges[:, None, 0, :] + img[:, :, 1:] * edges[:, None, 1, :]
    lx, ly = edges[0, 0, 0], edges[0, 1, 1]
    step = np.abs(np.diff(x, axis=0))
    crossings = int(np.sum(np.abs(np.diff(img[:, :, 1], axis=0))))
    print(f"      {len(x)} frames, {crossings} crossings of the y edge, largest move per frame "
          f"{step.max():.3f} d")
    expect(crossings > 50, f"{traj.parent.name}: the run crosses the Lees-Edwards edge often ({crossings})")
    expect(step.max() < 0.1 * lx, f"{traj.parent.name}: position + image . edges is continuous")
    expect(np.abs(x[:, :, 1] - unw[:, :, 1]).max() < 1e-9 * ly,
           f"{traj.parent.name}: position + image . edges equals the unwrapped position in y")
    # The nearest image of the unwrapped position, the convention this replaced.
    tilt = edges[:, None, 1, 0]
    iy = np.round((unw[:, :, 1] - pos[:, :, 1]) / ly)
    ix = np.round((unw[:, :, 0] - pos[:, :, 0] - iy * tilt) / lx)
    jumps = int(np.sum(np.abs(np.diff(pos[:, :, 0] + ix * lx + iy * tilt, axis=0)) > 0.5 * lx))
    print(f"      the nearest-image convention on the same frames: {jumps} jumps of about Lx")
    expect(jumps > 0, f"{traj.parent.name}: the nearest-image convention jumps here (the check has teeth)")
    try:
        import gsd.hoomd
    except ImportError:
        return
    out = traj.with_suffix(".gsd")
    subprocess.run([sys.executable, str(root / "tools" / "h5md_to_gsd.py"), str(traj), "--out", str(out)],
                   check=True, capture_output=True)
    try:
        t = gsd.hoomd.open(name=str(out), mode="r")
    except ValueError:
        t = gsd.hoomd.open(name=str(out), mode="rb")
    with t:
        xs = []
        for fr in t:
            lx_, ly_, _, xy = (float(v) for v in fr.configuration.box[:4])
            r = fr.particles.position[:, :2].astype(np.float64)
            im = fr.particles.image[:, :2].astype(np.float64)
            xs.append(r + im[:, :1] * np.array([lx_, 0.0]) + im[:, 1:] * np.array([xy * ly_, ly_]))
    gstep = np.abs(np.diff(np.array(xs), axis=0)).max()
    expect(gstep < 0.1 * lx, f"{traj.parent.name}: the GSD export's position + image . box is continuous "
                             f"(largest move per frame {gstep:.3f} d)")


def check_storage(simple, pressure):
    """Per-frame series compressed (shuffle + deflate), and nothing stored that the same file
    already holds: without Lees-Edwards the unwrapped position is position + image . edges, so
    the pressure cell stores no copy (simple shear keeps its own: its x differs, docs/trajectory.md)."""
    for traj, lees_edwards in ((simple, True), (pressure, False)):
        with h5py.File(traj, "r") as f:
            g = f["particles/suspension"]
            for name in ("position", "velocity", "image"):
                ds = g[name]["value"]
                expect(ds.compression == "gzip" and ds.shuffle,
                       f"{traj.parent.name}: {name} is shuffled and deflated "
                       f"({ds.compression}, shuffle {ds.shuffle})")
            expect(("unwrapped_position" in g) == lees_edwards,
                   f"{traj.parent.name}: unwrapped_position stored only under Lees-Edwards")


def check_mdanalysis(root, traj, periodic_y):
    """MDAnalysis (Debian's python3-mdanalysis) reads the LAMMPS dump export
    (tools/h5md_to_lammps.py): every frame's positions equal h5py's (to float32, MDAnalysis's
    precision), its box vectors the H5MD edges (tilt included), its velocities h5py's, and with
    lammps_coordinate_convention="unwrapped" the positions equal position + image . edges and
    are continuous over the run's Lees-Edwards crossings. Discs have z = 0; spheres their own z,
    and a z edge of the H5MD Lz."""
    import warnings

    warnings.simplefilter("ignore")  # MDAnalysis guesses masses, Python 3.11 deprecations
    import MDAnalysis as mda

    out = traj.with_suffix(".lammpstrj.gz")
    subprocess.run([sys.executable, str(root / "tools" / "h5md_to_lammps.py"), str(traj), "--out", str(out)],
                   check=True, capture_output=True)
    with h5py.File(traj, "r") as f:
        g = f["particles/suspension"]
        pos, vel = g["position/value"][()], g["velocity/value"][()]
        img, edges = g["image/value"][()].astype(np.float64), g["box/edges/value"][()]
    dim = pos.shape[2]
    unw = pos + np.einsum("fnk,fkc->fnc", img, edges)
    name = traj.parent.name
    for convention, want in (("auto", pos), ("unwrapped", unw)):
        u = mda.Universe(str(out), format="LAMMPSDUMP", lammps_coordinate_convention=convention)
        expect(len(u.trajectory) == len(pos), f"{name}: MDAnalysis reads {len(pos)} frames ({len(u.trajectory)})")
        worst_pos = worst_box = worst_vel = 0.0
        for k, ts in enumerate(u.trajectory):
            worst_pos = max(worst_pos, np.abs(ts.positions[:, :dim] - want[k].astype(np.float32)).max(),
                            np.abs(ts.positions[:, dim:]).max(initial=0.0))
            worst_vel = max(worst_vel, np.abs(ts.velocities[:, :dim] - vel[k].astype(np.float32)).max(),
                            np.abs(ts.velocities[:, dim:]).max(initial=0.0))
            box = ts.triclinic_dimensions
            # The pressure cell's y edge is the packing's height, not the box's: x (and z) only.
            compared = [0, 1] if periodic_y else [0]
            if dim == 3:
                worst_box = max(worst_box, np.abs(box[2] - edges[k, 2]).max(), np.abs(box[:2, 2]).max())
            worst_box = max(worst_box, np.abs(box[np.ix_(compared, [0, 1])] - edges[k][np.ix_(compared, [0, 1])]).max())
        expect(worst_pos == 0.0, f"{name} ({convention}): MDAnalysis's positions are h5py's as float32 "
                                 f"(largest difference {worst_pos:.3g})")
        expect(worst_vel == 0.0, f"{name}: MDAnalysis's velocities are h5py's as float32 ({worst_vel:.3g})")
        # The box goes through lengths and angles in float32 in MDAnalysis.
        expect(worst_box < 1e-6 * edges[:, 0, 0].max(),
               f"{name}: MDAnalysis's box vectors are the H5MD edges (largest difference {worst_box:.3g})")
    moves = np.abs(np.diff(unw, axis=0)).max()
    expect(moves < 0.1 * edges[0, 0, 0], f"{name}: the unwrapped positions MDAnalysis reads are continuous "
                                         f"(largest move per frame {moves:.3f} d)")


def check_plot_run_numbers(root, run_dir):
    """plot_run.py shows a finished pressure-cell run's own means and error bars (issue 34: it
    recomputed them from a later window, with the spread of correlated frames as the error)."""
    import json
    summary = json.loads((run_dir / "summary.json").read_text())
    if not summary.get("steady"):
        expect(False, f"{run_dir.name}: the test run reaches steady state")
        return
    p = subprocess.run([sys.executable, str(root / "tools" / "plot_run.py"), str(run_dir), "--print",
                        "--out", str(run_dir / "numbers.png")], capture_output=True, text=True)
    shown = {}
    for line in p.stdout.splitlines():
        if ": " in line and " +- " in line:
            name, rest = line.split(": ", 1)
            shown[name] = [float(x) for x in rest.split(" (")[0].split(" +- ")]
    for name, key in (("phi", "phi"), ("mu", "mu"), ("H / d", "H")):
        got = shown.get(name)
        want = [summary[key], summary.get(key + "_err", float("nan"))]
        if not np.isfinite(want[1]):
            expect(False, f"{run_dir.name}: the test run's window has error bars ({key}_err)")
        same = got is not None and all(np.isclose(a, b, rtol=1e-9, equal_nan=True) for a, b in zip(got, want))
        expect(same, f"plot_run.py shows {run_dir.name}'s own {key} and {key}_err ({got} against {want})")


def check_plot_tools(root, work, runs):
    """The plot tools draw both runs (no analysis.h5 in either) and end with one line, not a
    traceback, when their input is missing."""
    for tool, png in (("plot_run.py", "timeseries.png"), ("snapshot.py", "snapshot.png")):
        for run_dir in runs:
            p = subprocess.run([sys.executable, str(root / "tools" / tool), str(run_dir)],
                               capture_output=True, text=True)
            expect(p.returncode == 0 and (run_dir / png).is_file(),
                   f"{tool} draws {run_dir.name}/{png}" + (f": {p.stderr.strip()}" if p.returncode else ""))
        if tool == "plot_run.py":
            check_plot_run_numbers(root, runs[-1])
        p = subprocess.run([sys.executable, str(root / "tools" / tool), str(work / "missing")],
                           capture_output=True, text=True)
        lines = p.stderr.strip().splitlines()
        expect(p.returncode != 0 and len(lines) == 1 and "Traceback" not in p.stderr,
               f"{tool} on a missing run: one line ({lines[:1]})")


def check_live_reading(binary, root, work):
    """A trajectory is read while its run writes it: in HDF5's single-writer/multiple-reader mode
    (h5py with swmr=True, as tools/rundir.py opens files) the frames grow between two reads, the
    last frame of the first read was whole (the second read finds it unchanged), and snapshot.py
    draws the running run, which then stops cleanly on SIGTERM."""
    import os
    import signal
    import time

    cfg = work / "live.toml"
    cfg.write_text(PRESSURE.replace("strain = 3.0", "strain = 400.0").replace("measure_strain = 0.6",
                                                                              "measure_strain = 390.0"))
    out = work / "live"
    proc = subprocess.Popen([binary, "run", str(cfg), "--out", str(out), "-q"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    traj = out / "trajectory.h5"
    counts, seen = [], []
    try:
        deadline = time.time() + 120
        while time.time() < deadline and len(counts) < 2 and proc.poll() is None:
            time.sleep(2.5)
            if not traj.is_file():
                continue
            try:
                with h5py.File(traj, "r", libver="latest", swmr=True) as f:
                    pos = f["particles/suspension/position/value"]
                    frames = pos.shape[0]
                    if frames == 0:
                        continue
                    last = pos[frames - 1]
                    # The frame read last time, read again now: it was whole when first read.
                    again = pos[counts[0] - 1] if counts else None
            except OSError as e:
                expect(False, f"live trajectory opens in SWMR mode ({e})")
                break
            expect(bool(np.all(np.isfinite(last)) and np.any(last != 0.0)),
                   f"live frame {frames - 1}: finite positions, not the fill value")
            if again is not None:
                expect(np.array_equal(again, seen[0]),
                       f"live frame {counts[0] - 1} read again later is the same")
            counts.append(frames)
            seen.append(last)
        expect(proc.poll() is None, "the run is still running while it is read")
        expect(len(counts) == 2 and counts[1] > counts[0],
               f"frames grow between two reads of the running run ({counts})")
        p = subprocess.run([sys.executable, str(root / "tools" / "snapshot.py"), str(out)],
                           capture_output=True, text=True)
        expect(p.returncode == 0, f"snapshot.py draws the running run ({p.stderr.strip()})")
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGTERM)
        proc.wait()
    expect(proc.returncode == 128 + signal.SIGTERM, f"the run stopped by SIGTERM (exit {proc.returncode})")


def check_gsd_spheres(root, traj):
    import gsd.hoomd

    out = traj.with_suffix(".gsd")
    subprocess.run([sys.executable, str(root / "tools" / "h5md_to_gsd.py"), str(traj), "--out", str(out)],
                   check=True, capture_output=True)
    with h5py.File(traj, "r") as f:
        edges = f["particles/suspension/box/edges/value"][()]
    try:
        traj_gsd = gsd.hoomd.open(name=str(out), mode="r")
    except ValueError:
        traj_gsd = gsd.hoomd.open(name=str(out), mode="rb")
    box_ok, inside, jump, crossings, prev = True, True, 0.0, 0, None
    with traj_gsd as t:
        expect(len(t) == len(edges), f"spheres: GSD holds all {len(edges)} frames")
        for k, fr in enumerate(t):
            lx, ly, lz, xy = (float(x) for x in fr.configuration.box[:4])
            box_ok &= bool(fr.configuration.dimensions == 3 and np.isclose(lx, edges[k, 0, 0])
                           and np.isclose(lz, edges[k, 2, 2]) and xy == 0)
            r = fr.particles.position.astype(np.float64)
            im = fr.particles.image.astype(np.int64)
            inside &= bool(np.all(np.abs(r[:, 0]) <= 0.5 * lx + 1e-4) and np.all(np.abs(r[:, 2]) <= 0.5 * lz + 1e-4))
            u = r + im[:, [0]] * np.array([lx, 0, 0]) + im[:, [1]] * np.array([xy * ly, ly, 0]) \
                + im[:, [2]] * np.array([0, 0, lz])
            if prev is not None:
                jump = max(jump, float(np.abs(u - prev).max()))
            crossings = max(crossings, int(np.abs(im[:, 0]).sum()))
            prev = u
    expect(box_ok, "spheres: every GSD frame is a 3D box with the H5MD Lx and Lz")
    expect(inside, "spheres: every sphere lies inside the GSD box in x and z")
    expect(crossings > 0 and jump < 0.25 * float(edges[0, 0, 0]),
           f"spheres: position + image . box continuous ({crossings} x image counts, largest step "
           f"between frames {jump:.3g} d)")


def check_snapshot_spheres(root, traj):
    """snapshot.py draws a run of spheres as its section by a plane z = Z. Delesse's rule checks
    the sections: over planes spread evenly across the box, the mean area of the cut circles is
    the spheres' volume over Lz (exactly, for the integral; 400 planes put the midpoint rule
    within ~1e-5 here), which fails if an image across the z edge is missed (spheres within a of
    the edge lose their cut) or a cut has the sphere's radius (x 1.5)."""
    sys.path.insert(0, str(root / "tools"))
    import snapshot

    with h5py.File(traj, "r") as f:
        g = f["particles/suspension"]
        z, diam = g["position/value"][-1][:, 2], g["diameter"][()]
        lz = float(g["box/edges/value"][-1][2, 2])
    planes = (np.arange(400) + 0.5) * lz / 400
    area = np.mean([np.sum(np.pi * snapshot.section(z, diam, lz, z0)[1] ** 2) for z0 in planes])
    volume = np.sum(np.pi * diam ** 3 / 6) / lz
    expect(abs(area / volume - 1) < 1e-3, f"spheres: snapshot.py's sections hold the spheres' volume "
                                          f"(mean section area over Lz's, relative {area / volume - 1:.2g})")
    # The plane through a mobile sphere's centre draws it whole, every wall sphere whole, and no
    # mobile sphere the plane misses (the cut is taken in z, among the mobile spheres only).
    with h5py.File(traj, "r") as f:
        motion = f["particles/suspension/motion"][()]
    mobile = motion == 0
    k = int(np.flatnonzero(mobile)[0])
    index, radius = snapshot.drawn_spheres(z, diam, mobile, lz, z[k])
    cuts = {int(i): r for i, r in zip(index, radius) if mobile[i]}
    walls = [int(i) for i in index if not mobile[i]]
    dz = np.abs((z - z[k] + 0.5 * lz) % lz - 0.5 * lz)
    expect(cuts.get(k) == 0.5 * diam[k] and sorted(walls) == list(np.flatnonzero(~mobile))
           and set(cuts) == set(np.flatnonzero(mobile & (dz < 0.5 * diam)).tolist()),
           f"spheres: snapshot.py draws the walls whole and the mobile spheres the plane cuts "
           f"({len(walls)} walls, {len(cuts)} cuts)")
    out = traj.parent / "snapshot.png"
    out.unlink(missing_ok=True)
    p = subprocess.run([sys.executable, str(root / "tools" / "snapshot.py"), str(traj.parent), "--z", "0"],
                       capture_output=True, text=True)
    expect(p.returncode == 0 and out.exists() and out.stat().st_size > 0,
           f"spheres: snapshot.py draws a section ({p.stderr.strip()})")
    p = subprocess.run([sys.executable, str(root / "tools" / "snapshot.py"), str(traj.parent), "--z", str(2 * lz)],
                       capture_output=True, text=True)
    expect(p.returncode != 0 and "--z must lie in" in p.stderr,
           f"spheres: snapshot.py refuses a section outside the box ({p.stderr.strip()})")


def check_drift(root, traj):
    """tools/centre_of_mass_drift.py: the Stokes drag of the recorded velocities over the walls'
    area (Lx lz for discs, Lx Lz for spheres) is, frame by frame, what the walls' load
    difference (net_drag_y) balances: equal to round-off."""
    sys.path.insert(0, str(root / "tools"))
    import centre_of_mass_drift

    # Every third frame: the printed means must come from the same frames on both sides.
    r = centre_of_mass_drift.drift(traj.parent, every=3)
    gap = np.abs(r["implied_by_frame"] - r["drag_by_frame"]).max()
    scale = np.abs(r["drag_by_frame"]).max()
    expect(scale > 0 and gap < 1e-9 * scale and abs(r["implied_drag"] - r["drag"]) < 1e-9 * scale,
           f"{traj.parent.name}: centre_of_mass_drift.py's implied drag is net_drag_y in every frame "
           f"and in their means (largest difference {gap:.2g} P of {scale:.2g})")


def check_spin_table(root, traj):
    """tools/low_j_table.py's <omega>/gammadot is the mean spin about z (the axis of the imposed
    flow's vorticity) of the mobile particles, read here from the file on its own. Sheared
    particles spin with half the local vorticity, -gammadot/2 where the local shear rate is the
    imposed one; wall slip and layering in these small cells move the local rate by up to ~30 %,
    hence the band. A mean over the three axes of spheres (the tool's error before) gives about
    a third of it and falls outside."""
    sys.path.insert(0, str(root / "tools"))
    import low_j_table

    r = low_j_table.statistics(str(traj.parent), 0.5)
    with h5py.File(traj, "r") as f:
        s = f["observables/strain/value"][:]
        rate = s[-1] / f["observables/strain/time"][-1]
        p = f["particles/suspension"]
        w = p["angular_velocity/value"][:][:, p["motion"][:] == 0]
    spin = (w[..., 2] if w.ndim == 3 else w)[s >= 0.5].mean() / rate
    expect(abs(r["mean_omega"] - spin) < 1e-12 and -0.65 < spin < -0.35,
           f"{traj.parent.name}: low_j_table.py's mean spin {r['mean_omega']:+.3f} gammadot is the "
           f"file's spin about z ({spin:+.3f}), near -1/2")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--root", required=True, type=pathlib.Path)
    ap.add_argument("--work", required=True, type=pathlib.Path)
    args = ap.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True)
    simple = run(args.bin, args.work, "simple_shear", SIMPLE)
    pressure = run(args.bin, args.work, "pressure_cell", PRESSURE)
    for traj in (simple, pressure):
        check_conformance(traj, args.work)
    with h5py.File(simple, "r") as f:
        author = f["h5md/author"].attrs["name"]
        expect((author.decode() if isinstance(author, bytes) else author) == "Outside Reader Test",
               "output.author reaches /h5md/author")
    with h5py.File(pressure, "r") as f:
        expect("profiles" not in f["observables"],
               "pressure cell: the profiles are in summary.json, not in the trajectory")
    check_storage(simple, pressure)
    try:
        import gsd.hoomd  # noqa: F401
    except ImportError:
        expect(False, "the gsd package (python3-gsd, tools/setup.sh) is installed")
    else:
        check_gsd(args.root, simple, True)
        check_gsd(args.root, pressure, False)
    spheres = run(args.bin, args.work, "spheres", SPHERES)
    check_conformance(spheres, args.work)
    if "gsd" in sys.modules:
        check_gsd_spheres(args.root, spheres)
    check_snapshot_spheres(args.root, spheres)
    for traj in (pressure, spheres):
        check_drift(args.root, traj)
        check_spin_table(args.root, traj)
    long = run(args.bin, args.work, "simple_shear_long", LONG)
    check_continuity(args.root, long)
    try:
        import MDAnalysis  # noqa: F401
    except ImportError:
        expect(False, "MDAnalysis (python3-mdanalysis, tools/setup.sh) is installed")
    else:
        check_mdanalysis(args.root, long, True)
        check_mdanalysis(args.root, pressure, False)
        check_mdanalysis(args.root, spheres, False)
    check_plot_tools(args.root, args.work, (simple.parent, pressure.parent))
    check_live_reading(args.bin, args.root, args.work)
    print(f"{len(failures)} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
