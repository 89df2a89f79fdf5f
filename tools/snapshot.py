#!/usr/bin/python3
"""Render one frame of a sheardiff H5MD trajectory to PNG.

Walls are black; mobile particles are coloured by their height at the first frame (as in the
seed paper's figure 1a-b, with a colour bar), so mixing across the gap shows as mixed colours.
Discs crossing a periodic edge are drawn on both sides: across x, and across the Lees-Edwards
y edges shifted by the frame's tilt (box/edges). The title gives the run's J, phi and N.

A run of spheres (scene.dimension = 3) is drawn as its section by the plane z = Z (the middle of
the box unless --z is given): each sphere that the plane cuts, periodic images in z included, as
the circle of the cut, radius sqrt(a^2 - (z - Z)^2); the walls' frozen spheres, which a plane
may pass between, are drawn whole behind them in grey (their projection on the x-y plane).
Averaged over the plane's position, the sections' area fraction is the volume fraction.

    /usr/bin/python3 tools/snapshot.py RUN_DIR [--frame -1] [--z Z] [--out RUN_DIR/snapshot.png]
"""
import argparse
import pathlib
import sys

import rundir  # tools/rundir.py: what every tool reads of a run

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PatchCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
import numpy as np  # noqa: E402


def read_frame(path, frame):
    with rundir.open_h5(path) as f:
        groups = list(f["particles"])
        g = f["particles"]["suspension" if "suspension" in groups else groups[0]]
        pos = g["position/value"]
        n_frames = pos.shape[0]
        if n_frames == 0:
            sys.exit(f"snapshot: {path} holds no frames yet")
        k = frame % n_frames
        edges = g["box/edges/value"][k]
        if edges.ndim == 1:  # a cuboid box (files before the triclinic layout)
            edges = np.diag(edges)
        boundary = [b.decode() if isinstance(b, bytes) else str(b) for b in g["box"].attrs["boundary"]]
        obs = f.get("observables", {})
        frame_obs = {name: obs[name]["value"][k] for name in ("strain", "phi")
                     if name in obs and "value" in obs[name]}
        diam = g["diameter"][()]
        return dict(k=k, x=pos[k], x0=pos[0], diam=diam,
                    motion=g["motion"][()] if "motion" in g else np.zeros(len(diam), int),
                    lx=edges[0, 0], tilt=edges[1, 0], ly=edges[1, 1],
                    lz=edges[2, 2] if edges.shape[0] == 3 else None,
                    periodic_y=boundary[1] == "periodic", obs=frame_obs)


def section(z, diam, lz, z0):
    """The plane z = z0 through spheres at heights z in a box periodic in z with edge lz: the
    index of each sphere it cuts (an image in z counts) and the radius of the cut."""
    a = 0.5 * diam
    dz = (z - z0) % lz  # in [0, lz): the images below and above are dz - lz and dz
    index, radius = [], []
    for shift in (-lz, 0.0, lz):  # a sphere wider than the box could be cut twice
        d = dz + shift
        cut = np.abs(d) < a
        index.append(np.flatnonzero(cut))
        radius.append(np.sqrt(a[cut] ** 2 - d[cut] ** 2))
    return np.concatenate(index), np.concatenate(radius)


def drawn_spheres(z, diam, mobile, lz, z0):
    """What a section of spheres draws: the index of each circle and its radius, the walls' whole
    spheres first (drawn behind), then the mobile spheres' cuts by the plane z = z0."""
    cut, radius = section(z, diam, lz, z0)
    cut, radius = cut[mobile[cut]], radius[mobile[cut]]
    walls = np.flatnonzero(~mobile)
    return np.concatenate([walls, cut]), np.concatenate([0.5 * diam[walls], radius])


def title_of(run_dir, fr):
    run = rundir.Run(run_dir)
    cfg, summary = run.config, run.summary
    j = cfg.get("flow", {}).get("J", summary.get("J"))
    mobile = fr["motion"] == 0
    if "phi" in summary:  # the run's: fixed, or the steady mean of a pressure cell
        phi = summary["phi"]
    elif "phi" in fr["obs"]:  # an unfinished pressure cell: the bulk area fraction of this frame
        phi = fr["obs"]["phi"]
    elif fr["lz"] is not None:
        phi = np.sum(np.pi * fr["diam"][mobile] ** 3 / 6) / (fr["lx"] * fr["ly"] * fr["lz"])
    else:
        phi = np.sum(np.pi * fr["diam"][mobile] ** 2 / 4) / (fr["lx"] * fr["ly"])
    strain = fr["obs"].get("strain", float("nan"))
    j_text = f"J = {j:g}, " if j is not None else ""
    return (f"{run_dir.name}: {j_text}$\\phi$ = {phi:.3f}, N = {int(mobile.sum())}\n"
            f"frame {fr['k']}, strain {strain:.3g}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path, help="run directory (holds trajectory.h5) or an .h5 file")
    ap.add_argument("--frame", type=int, default=-1, help="frame index (default: last)")
    ap.add_argument("--z", type=float, help="spheres: the height of the section, in d (default: Lz / 2)")
    ap.add_argument("--out", type=pathlib.Path, help="PNG file (default: RUN/snapshot.png)")
    args = ap.parse_args()
    path = args.run / "trajectory.h5" if args.run.is_dir() else args.run
    if not path.is_file():
        sys.exit(f"snapshot: no trajectory at {path}")
    out = args.out or path.parent / "snapshot.png"
    try:
        fr = read_frame(path, args.frame)
    except (OSError, KeyError) as e:
        sys.exit(f"snapshot: {path}: not a readable sheardiff trajectory ({type(e).__name__}: {e})")
    x, x0, diam, lx, ly, tilt = fr["x"].copy(), fr["x0"], fr["diam"], fr["lx"], fr["ly"], fr["tilt"]
    mobile = fr["motion"] == 0
    radius = 0.5 * diam
    title = title_of(path.parent, fr)
    if fr["lz"] is not None:  # spheres: their section by the plane z = z0
        if args.z is not None and not 0 <= args.z <= fr["lz"]:
            sys.exit(f"snapshot: --z must lie in [0, {fr['lz']:g}] (the box's z edge), not {args.z:g}")
        z0 = 0.5 * fr["lz"] if args.z is None else args.z
        order, radius = drawn_spheres(x[:, 2], diam, mobile, fr["lz"], z0)
        x, x0, mobile = x[order], x0[order], mobile[order]
        title += f", section z = {z0:.3g} d"
    elif args.z is not None:
        sys.exit("snapshot: --z is for runs of spheres (this trajectory holds discs)")
    if fr["periodic_y"]:  # into the primary cell [0, lx) x [0, ly), through the sheared edge
        ny = np.floor(x[:, 1] / ly)
        x[:, 1] -= ny * ly
        x[:, 0] -= ny * tilt
    x[:, 0] %= lx
    colour_key = x0[:, 1]
    lo, hi = (colour_key[mobile].min(), colour_key[mobile].max()) if mobile.any() else (0.0, 1.0)
    cmap = plt.get_cmap("coolwarm")
    norm = matplotlib.colors.Normalize(vmin=lo, vmax=max(hi, lo + 1e-12))
    ylo, yhi = (0.0, ly) if fr["periodic_y"] else (x[:, 1].min() - 1, x[:, 1].max() + 1)
    fig, ax = plt.subplots(figsize=(6.8, 6 * max(0.3, (yhi - ylo) / lx)))
    y_images = (-1, 0, 1) if fr["periodic_y"] else (0,)
    patches, colours = [], []
    wall_colour = "0.75" if fr["lz"] is not None else "black"  # spheres' walls lie behind their cuts
    for i in range(len(radius)):
        a = radius[i]
        colour = wall_colour if not mobile[i] else cmap(norm(colour_key[i]))
        for ky in y_images:
            cy = x[i, 1] + ky * ly
            if fr["periodic_y"] and (cy + a < 0 or cy - a > ly):
                continue
            base = (x[i, 0] + ky * tilt) % lx  # the image across a y edge is shifted by the tilt
            for kx in (-1, 0, 1):
                cx = base + kx * lx
                if cx + a < 0 or cx - a > lx:
                    continue
                patches.append(Circle((cx, cy), a))
                colours.append(colour)
    ax.add_collection(PatchCollection(patches, facecolors=colours, edgecolors="none"))
    ax.set_xlim(0, lx)
    ax.set_ylim(ylo, yhi)
    ax.set_aspect("equal")
    ax.set_xlabel("x / d")
    ax.set_ylabel("y / d")
    ax.set_title(title, fontsize=10)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.8)
    bar.set_label("height at the first frame, y / d")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()
