#!/usr/bin/python3
"""The mobile particles' diameter-weighted centre of mass in a pressure-cell run: its drift from
the unwrapped positions (least-squares slope over the last three quarters of the frames, in d per
strain) and the mean diameter-weighted y velocity of the recorded velocities (in gammadot d), and
the net y drag that velocity implies, 3 pi eta sum(d_i) <v_y> / (P Lx lz) (spheres: / (P Lx Lz)),
against the run's net_drag_y observable on the same frames, which it equals frame by frame. A stationary cell has all three at zero (docs/results.md, J = 0.1).

    /usr/bin/python3 tools/centre_of_mass_drift.py RUN_DIR [--every K]
"""
import argparse
import pathlib

import rundir  # tools/rundir.py: what every tool reads of a run

import numpy as np


def drift(run_dir, every=5):
    """The three estimates over the last three quarters of every K-th frame: the centre of mass's
    slope (d per strain), the mean recorded y velocity (gammadot d), the net y drag it implies and
    the net_drag_y observable on the same frames (P)."""
    run = rundir.Run(run_dir)
    with run.open("trajectory") as f:
        g = f["particles/suspension"]
        mobile = g["motion"][()] == 0
        d = g["diameter"][()][mobile]
        strain = f["observables/strain/value"][()]
        vel = g["velocity/value"]
        frames = list(range(0, min(vel.shape[0], len(strain)), every))
        pos = rundir.unwrapped_positions(g, frames)
        gammadot = strain[-1] / f["observables/strain/time"][-1]
        vy = np.array([(d * vel[k][mobile, 1]).sum() / d.sum() for k in frames])
        yc = np.array([(d * pos[j][mobile, 1]).sum() / d.sum() for j in range(len(frames))])
        t = strain[frames]
        edges = g["box/edges/value"][()][frames]
        drag = f["observables/net_drag_y/value"][()][frames]
    # The load is carried over Lx Lz for spheres and over Lx lz for the monolayer of discs.
    depth = edges[:, 2, 2] if edges.shape[1] == 3 else np.full(len(frames), run.config.get("flow", {}).get("lz", 1.0))
    # Each frame's Stokes drag on the mobile particles, 3 pi eta d v_y (v in P d / eta, the
    # stored unit), over the wall area: what the walls' load difference must balance.
    implied = -3 * np.pi * d.sum() * vy / (edges[:, 0, 0] * depth)
    keep = slice(len(t) // 4, None)
    return dict(strain=(float(t[keep][0]), float(t[-1])), slope=float(np.polyfit(t[keep], yc[keep], 1)[0]),
                velocity=float(vy[keep].mean() / gammadot), implied_drag=float(implied[keep].mean()),
                drag=float(drag[keep].mean()), implied_by_frame=implied, drag_by_frame=drag,
                spheres=edges.shape[1] == 3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=pathlib.Path)
    ap.add_argument("--every", type=int, default=5, help="use every K-th frame (default 5)")
    a = ap.parse_args()
    r = drift(a.run, a.every)
    area = "(Lx Lz)" if r["spheres"] else "(Lx lz)"
    print(f"{a.run}: strain {r['strain'][0]:.1f}-{r['strain'][1]:.1f}")
    print(f"  centre of mass (diameter-weighted) from positions: {r['slope']:+.4f} d per strain")
    print(f"  from the recorded velocities:                      {r['velocity']:+.4f} gammadot d")
    print(f"  net y drag they imply, 3 pi sum(d) <v_y> / {area}: {r['implied_drag']:+.3f} P")
    print(f"  net_drag_y observable (same frames):               {r['drag']:+.3f} P")


if __name__ == "__main__":
    main()
