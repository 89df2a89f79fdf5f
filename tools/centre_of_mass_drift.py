#!/usr/bin/python3
"""The discs' diameter-weighted centre of mass in a pressure-cell run: its drift from the
unwrapped positions (least-squares slope over the last three quarters of the frames, in d per
strain) and the mean diameter-weighted y velocity of the recorded velocities (in gammadot d), and
the net y drag that velocity implies, 3 pi eta sum(d_i) <v_y> / (P Lx), against the run's
net_drag_y observable. A stationary cell has all three at zero (docs/results.md, J = 0.1).

    /usr/bin/python3 tools/centre_of_mass_drift.py RUN_DIR [--every K]
"""
import argparse
import pathlib

import rundir  # tools/rundir.py: what every tool reads of a run

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=pathlib.Path)
    ap.add_argument("--every", type=int, default=5, help="use every K-th frame (default 5)")
    a = ap.parse_args()
    with rundir.Run(a.run).open("trajectory") as f:
        g = f["particles/suspension"]
        mobile = g["motion"][()] == 0
        d = g["diameter"][()][mobile]
        strain = f["observables/strain/value"][()]
        vel = g["velocity/value"]
        frames = range(0, min(vel.shape[0], len(strain)), a.every)
        pos = rundir.unwrapped_positions(g, list(frames))
        gammadot = strain[-1] / f["observables/strain/time"][-1]
        vy = np.array([(d * vel[k][mobile, 1]).sum() / d.sum() for k in frames])
        yc = np.array([(d * pos[j][mobile, 1]).sum() / d.sum() for j in range(len(frames))])
        t = np.array([strain[k] for k in frames])
        lx = float(f["particles/suspension/box/edges/value"][-1][0][0])
        drag = f["observables/net_drag_y/value"][()]
    keep = slice(len(t) // 4, None)
    slope = np.polyfit(t[keep], yc[keep], 1)[0]
    v = vy[keep].mean()
    print(f"{a.run}: strain {t[keep][0]:.1f}-{t[-1]:.1f}")
    print(f"  centre of mass (diameter-weighted) from positions: {slope:+.4f} d per strain")
    print(f"  from the recorded velocities:                      {v / gammadot:+.4f} gammadot d")
    print(f"  net y drag they imply, 3 pi sum(d) <v_y> / Lx:      {-3 * np.pi * d.sum() * v / lx:+.3f} P")
    print(f"  net_drag_y observable (same frames):               {drag[len(drag) // 4:].mean():+.3f} P")


if __name__ == "__main__":
    main()
