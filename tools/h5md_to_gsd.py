#!/usr/bin/python3
"""Export a sheardiff trajectory (H5MD) to GSD, the HOOMD-blue format that freud, OVITO, the
gsd package and HOOMD itself read (docs/trajectory.md, "GSD export").

    /usr/bin/python3 tools/h5md_to_gsd.py RUN_DIR_or_H5 [--out RUN/trajectory.gsd]

Per frame: a 2D box (dimensions 2, Lz = 0; a run of spheres: dimensions 3 with its Lz) with the
Lees-Edwards shift as the tilt factor
xy = tilt / Ly, positions wrapped into HOOMD's centred box with matching `image` counts (the
unwrapped position is position + image . box vectors, shifted by the constant (-Lx/2, -Ly/2)),
diameters, velocities, and types small / large / fixed_wall / floating_wall / driven_wall. The pressure cell
has no periodicity in y: its GSD box (periodic in every direction in HOOMD) is made taller
than the packing by two diameters, so that no contact crosses it. Scalar observables go to
the frame log as sheardiff/<name>. Units stay the project's (docs/units.md): GSD has none.
"""
import argparse
import pathlib
import sys

import rundir  # tools/rundir.py: what every tool reads of a run

import numpy as np

TYPES = ["small", "large", "fixed_wall", "floating_wall", "driven_wall"]


def open_gsd(path):
    import gsd.hoomd

    for mode in ("w", "wb"):  # gsd >= 2.8 / older
        try:
            return gsd.hoomd.open(name=str(path), mode=mode)
        except ValueError:
            continue
    raise SystemExit(f"{path}: this gsd package opens no file for writing")


def new_frame():
    import gsd.hoomd

    return (getattr(gsd.hoomd, "Frame", None) or gsd.hoomd.Snapshot)()


def export(h5_path, out):
    t = rundir.read_trajectory(h5_path)
    pos, edges, image, vel, diam = t["position"], t["edges"], t["image"], t["velocity"], t["diameter"]
    species, motion, steps, obs, periodic_y = t["species"], t["motion"], t["step"], t["observables"], t["periodic_y"]
    n_frames, n, dim = pos.shape
    typeid = np.where(motion == 0, species, motion + 1).astype(np.uint32)
    dmax = float(diam.max())
    if not periodic_y:
        lo, hi = pos[:, :, 1].min(), pos[:, :, 1].max()
        y_centre, ly_pad = 0.5 * (lo + hi), (hi - lo) + 2 * dmax
    with open_gsd(out) as traj:
        for k in range(n_frames):
            lx, tilt, ly = edges[k, 0, 0], edges[k, 1, 0], edges[k, 1, 1]
            lz = edges[k, 2, 2] if dim == 3 else 0.0
            r = pos[k].astype(np.float64).copy()
            img = image[k].astype(np.int64).copy()
            if dim == 3:  # z: centred and wrapped as x below, independent of the tilt
                r[:, 2] -= 0.5 * lz
                iz = np.floor(r[:, 2] / lz + 0.5)
                r[:, 2] -= iz * lz
                img[:, 2] += iz.astype(np.int64)
            if periodic_y:
                r[:, :2] -= (0.5 * lx, 0.5 * ly)
                iy = np.floor(r[:, 1] / ly + 0.5)
                r[:, 1] -= iy * ly
                r[:, 0] -= iy * tilt
                img[:, 1] += iy.astype(np.int64)
            else:
                ly, tilt = ly_pad, 0.0
                r[:, :2] -= (0.5 * lx, y_centre)
                img[:, 1] = 0
            xy = tilt / ly
            ix = np.floor((r[:, 0] - xy * r[:, 1]) / lx + 0.5)
            r[:, 0] -= ix * lx
            img[:, 0] += ix.astype(np.int64)
            fr = new_frame()
            fr.configuration.step = int(steps[k])
            fr.configuration.dimensions = dim
            fr.configuration.box = [lx, ly, lz, xy, 0.0, 0.0]
            fr.particles.N = n
            fr.particles.types = TYPES
            fr.particles.typeid = typeid
            pad = [] if dim == 3 else [np.zeros(n)]
            fr.particles.position = np.column_stack([r, *pad]).astype(np.float32)
            fr.particles.image = np.column_stack([img, *[p.astype(np.int64) for p in pad]]).astype(np.int32)
            fr.particles.diameter = diam.astype(np.float32)
            if vel is not None:
                fr.particles.velocity = np.column_stack([vel[k], *pad]).astype(np.float32)
            fr.log = {f"sheardiff/{key}": np.array([v[k]]) for key, v in obs.items() if len(v) > k}
            traj.append(fr)
    return n_frames


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path, help="run directory (holds trajectory.h5) or an .h5 file")
    ap.add_argument("--out", type=pathlib.Path, help="GSD file (default: beside the trajectory)")
    args = ap.parse_args()
    path = args.run / "trajectory.h5" if args.run.is_dir() else args.run
    if not path.is_file():
        sys.exit(f"h5md_to_gsd: no trajectory at {path}")
    try:
        import gsd.hoomd  # noqa: F401
    except ImportError:
        sys.exit("h5md_to_gsd: the gsd package is missing (Debian: apt-get install python3-gsd)")
    out = args.out or path.with_suffix(".gsd")
    frames = export(path, out)
    print(f"{out}: {frames} frames")


if __name__ == "__main__":
    main()
