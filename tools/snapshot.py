#!/usr/bin/python3
"""Render one frame of a sheardiff H5MD trajectory to PNG.

Walls are black; mobile particles are coloured by their height at the first frame (as in the
seed paper's figure 1a-b), so mixing across the gap shows as mixed colours.

    /usr/bin/python3 tools/snapshot.py RUN_DIR [--frame -1] [--out RUN_DIR/snapshot.png]
"""
import argparse
import pathlib

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PatchCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path, help="run directory (holds trajectory.h5) or an .h5 file")
    ap.add_argument("--frame", type=int, default=-1, help="frame index (default: last)")
    ap.add_argument("--out", type=pathlib.Path, help="PNG file (default: RUN/snapshot.png)")
    args = ap.parse_args()
    path = args.run / "trajectory.h5" if args.run.is_dir() else args.run
    out = args.out or path.parent / "snapshot.png"
    with h5py.File(path, "r") as f:
        g = f["particles/suspension"]
        pos = g["position/value"]
        n_frames = pos.shape[0]
        if n_frames == 0:
            raise SystemExit(f"{path}: no frames")
        k = args.frame % n_frames
        x = pos[k]
        x0 = pos[0]
        diam = g["diameter"][()]
        motion = g["motion"][()] if "motion" in g else np.zeros(len(diam), int)
        lx, ly = g["box/edges/value"][k]
        strain = f["observables/strain/value"][k] if "observables/strain" in f else float("nan")
    mobile = motion == 0
    colour_key = x0[:, 1]
    lo, hi = colour_key[mobile].min(), colour_key[mobile].max()
    cmap = plt.get_cmap("coolwarm")
    fig, ax = plt.subplots(figsize=(6, 6 * max(0.3, (x[:, 1].max() - x[:, 1].min() + 2) / lx)))
    patches, colours = [], []
    for i in range(len(diam)):
        for shift in (-lx, 0.0, lx):  # periodic in x: draw the images that cross the edges
            cx = x[i, 0] % lx + shift
            if cx + diam[i] / 2 < 0 or cx - diam[i] / 2 > lx:
                continue
            patches.append(Circle((cx, x[i, 1]), diam[i] / 2))
            colours.append("black" if not mobile[i] else cmap((colour_key[i] - lo) / max(hi - lo, 1e-12)))
    ax.add_collection(PatchCollection(patches, facecolors=colours, edgecolors="none"))
    ax.set_xlim(0, lx)
    ax.set_ylim(x[:, 1].min() - 1, x[:, 1].max() + 1)
    ax.set_aspect("equal")
    ax.set_xlabel("x / d")
    ax.set_ylabel("y / d")
    ax.set_title(f"{path.parent.name}: frame {k}, strain {strain:.3g}")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()
