#!/usr/bin/python3
"""Export a sheardiff trajectory (H5MD) to a LAMMPS text dump, the format MDAnalysis, OVITO and
VMD read with the box as LAMMPS defines it (docs/trajectory.md, "LAMMPS dump export").

    /usr/bin/python3 tools/h5md_to_lammps.py RUN_DIR_or_H5 [--out RUN/trajectory.lammpstrj[.gz]]
                                             [--every K]

    import MDAnalysis as mda
    u = mda.Universe("RUN/trajectory.lammpstrj", format="LAMMPSDUMP")
    u = mda.Universe("RUN/trajectory.lammpstrj", format="LAMMPSDUMP",
                     lammps_coordinate_convention="unwrapped")  # continuous positions

Per frame: ITEM: TIMESTEP (the run's step), the atoms' count, a triclinic box whose tilt xy is
the frame's Lees-Edwards shift (the reduced tilt of the trajectory's edges), and per atom
`id type x y z xu yu zu ix iy iz vx vy vz diameter`: positions, images and velocities exactly as
the trajectory holds them (their shortest exact decimal text), and the unwrapped position
xu = x + ix Lx + iy xy, yu = y + iy Ly, zu = z + iz Lz, continuous in time (docs/trajectory.md,
"Positions, image and unwrapped positions").
MDAnalysis reads x y z by default and xu yu zu with lammps_coordinate_convention="unwrapped";
its own unwrap_images=True ignores the tilt (MDAnalysis 2.4 adds image x box length), so use the
xu columns in a sheared box. The box is the trajectory's: its lower corner
at the origin (MDAnalysis measures positions from that corner, so what it reads equals what
h5py reads), the edges Lx, Ly (and Lz for spheres) and the tilt xy of the frame. A run of spheres
(scene.dimension = 3) is periodic in z with its own Lz; for discs the third dimension is padding,
as in LAMMPS's own 2D dumps: z = 0, iz = 0 and a z extent of one diameter, [0, 1]. Types: 1 small, 2 large,
3 fixed_wall, 4 floating_wall, 5 driven_wall. The pressure cell is not periodic in y: its y
boundary is LAMMPS's fixed one (`pp ff pp`), and, as in the trajectory, its y edge is the
packing's height H, from which the wall particles stick out. Lengths are in d and velocities in
P d / eta, as stored (divide by J for gammadot d; the channel: by channel.mean_velocity for <u>;
docs/units.md), as
LAMMPS's `units lj` leaves them: the file states no unit (MDAnalysis will call them Angstrom and
Angstrom/ps).
"""
import argparse
import gzip
import pathlib
import sys

import rundir  # tools/rundir.py: what every tool reads of a run

import numpy as np

TYPES = ["small", "large", "fixed_wall", "floating_wall", "driven_wall"]


def type_ids(species, motion):
    """LAMMPS type (from 1) of each particle: its species when mobile, else its wall kind."""
    return np.where(motion == 0, species, motion + 1).astype(int) + 1


def write_frame(out, t, k, types):
    pos, img = t["position"][k], t["image"][k]
    n, dim = pos.shape
    e = t["edges"][k]
    lx, xy, ly = float(e[0, 0]), float(e[1, 0]), float(e[1, 1])
    lz = float(e[2, 2]) if dim == 3 else 1.0
    # LAMMPS stores a tilted box by the bounds of its bounding box (the dump command's rule).
    out.write(f"ITEM: TIMESTEP\n{int(t['step'][k])}\nITEM: NUMBER OF ATOMS\n{n}\n")
    out.write(f"ITEM: BOX BOUNDS xy xz yz pp {'pp' if t['periodic_y'] else 'ff'} pp\n")
    out.write(f"{min(0.0, xy)!r} {lx + max(0.0, xy)!r} {xy!r}\n0.0 {ly!r} 0.0\n0.0 {lz!r} 0.0\n")
    out.write("ITEM: ATOMS id type x y z xu yu zu ix iy iz vx vy vz diameter\n")
    vel = t["velocity"][k] if t["velocity"] is not None else np.zeros((n, dim))
    # LAMMPS's unwrapped position: the image's box vectors added, the tilt included.
    xu = pos[:, 0] + img[:, 0] * lx + img[:, 1] * xy
    yu = pos[:, 1] + img[:, 1] * ly
    text = lambda values: [repr(float(v)) for v in values]  # noqa: E731
    if dim == 3:
        z, zu, iz, vz = text(pos[:, 2]), text(pos[:, 2] + img[:, 2] * lz), img[:, 2], text(vel[:, 2])
    else:
        z, zu, iz, vz = ["0.0"] * n, ["0.0"] * n, [0] * n, ["0.0"] * n
    columns = [range(1, n + 1), types, text(pos[:, 0]), text(pos[:, 1]), z, text(xu), text(yu), zu,
               img[:, 0], img[:, 1], iz, text(vel[:, 0]), text(vel[:, 1]), vz, text(t["diameter"])]
    out.write("\n".join(" ".join(str(c) for c in row) for row in zip(*columns)) + "\n")


def export(h5_path, out_path, every=1):
    t = rundir.read_trajectory(h5_path)
    if t["position"].shape[2] not in (2, 3):
        raise SystemExit(f"h5md_to_lammps: {h5_path} has positions of {t['position'].shape[2]} components")
    types = type_ids(t["species"], t["motion"])
    frames = range(0, t["position"].shape[0], every)
    opener = gzip.open if str(out_path).endswith(".gz") else open
    tmp = pathlib.Path(str(out_path) + ".tmp")
    with opener(tmp, "wt") as out:
        for k in frames:
            write_frame(out, t, k, types)
    tmp.replace(out_path)  # whole or absent
    return len(frames)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path, help="run directory (holds trajectory.h5) or an .h5 file")
    ap.add_argument("--out", type=pathlib.Path,
                    help="dump file, gzipped if it ends in .gz (default: trajectory.lammpstrj beside the trajectory)")
    ap.add_argument("--every", type=int, default=1, help="write every K-th frame (default 1)")
    args = ap.parse_args()
    if args.every < 1:
        sys.exit(f"h5md_to_lammps: --every must be at least 1, not {args.every}")
    path = args.run / rundir.FILES["trajectory"] if args.run.is_dir() else args.run
    if not path.is_file():
        sys.exit(f"h5md_to_lammps: no trajectory at {path}")
    out = args.out or path.with_suffix(".lammpstrj")
    frames = export(path, out, args.every)
    print(f"{out}: {frames} frames")


if __name__ == "__main__":
    main()
