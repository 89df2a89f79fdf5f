#!/usr/bin/python3
"""Steady-state phi, mu and spin statistics of pressure_shear runs (docs/low_j.md).

usage: tools/low_j_table.py RUNDIR[:FROM_STRAIN] ...   (FROM_STRAIN defaults to 2)

Averages over the recorded frames with strain >= FROM_STRAIN (also over each half of that
window, a drift check): bulk phi, mu = (mu_top + mu_bottom)/2, the particle-averaged spread of
omega/gammadot and v_y/gammadot, and the mean omega/gammadot (the fluid's is -1/2; for spheres
omega is the spin about z, the axis of the flow's vorticity). Works on a
run stopped by a signal (no summary.json) as long as its trajectory is closed.
"""
import os, sys

import rundir  # tools/rundir.py: what every tool reads of a run

import numpy as np

for arg in sys.argv[1:]:
    d, lo = (arg.rsplit(':', 1) + ['2'])[:2] if ':' in arg else (arg, '2')
    lo = float(lo)
    run = rundir.Run(d)
    with run.open('trajectory') as f:
        o = f['observables']
        s = o['strain/value'][:]
        t = o['strain/time'][:]
        sel = s >= lo
        J = s[-1] / t[-1]
        phi = o['phi/value'][:]
        mu = 0.5 * (o['mu_top/value'][:] + o['mu_bottom/value'][:])
        p = f['particles/suspension']
        mobile = p['motion'][:] == 0
        w = p['angular_velocity/value'][:][:, mobile] / J
        if w.ndim == 3:  # spheres: the spin about z, the axis of the imposed flow's vorticity
            w = w[:, :, 2]
        vy = p['velocity/value'][:][:, mobile, 1] / J
    idx = np.where(sel)[0]
    a, b = idx[: len(idx) // 2], idx[len(idx) // 2:]
    sps = run.summary.get('steps_per_strain', float('nan'))
    print(f'{os.path.basename(d.rstrip("/")):16s} J {J:.0e} strain {s[-1]:5.1f} window [{lo:g},] '
          f'phi {phi[sel].mean():.4f} ({phi[a].mean():.4f} {phi[b].mean():.4f})  '
          f'mu {mu[sel].mean():.3f} ({mu[a].mean():.3f} {mu[b].mean():.3f})  '
          f'std(omega)/J {w[sel].std(axis=1).mean():5.1f}  std(vy)/J {vy[sel].std(axis=1).mean():4.2f}  '
          f'<omega>/J {w[sel].mean():+.2f}  steps/strain {sps:.0f}')
