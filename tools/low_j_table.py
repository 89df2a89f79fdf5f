#!/usr/bin/python3
"""Steady-state phi, mu and spin statistics of pressure_shear runs (docs/low_j.md).

usage: tools/low_j_table.py RUNDIR[:FROM_STRAIN] ...   (FROM_STRAIN defaults to 2)

Averages over the recorded frames with strain >= FROM_STRAIN (also over each half of that
window, a drift check): bulk phi, mu = (mu_top + mu_bottom)/2, the particle-averaged spread of
omega/gammadot and v_y/gammadot, and the mean omega/gammadot (the fluid's is -1/2; for spheres
omega is the spin about z, the axis of the flow's vorticity). Works on a
run stopped by a signal (no summary.json) as long as its trajectory is closed.
"""
import os
import sys

import rundir  # tools/rundir.py: what every tool reads of a run

import numpy as np


def statistics(d, lo=2.0):
    """The table's row of run directory d over the frames with strain >= lo, as a dict."""
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
    return {'name': os.path.basename(d.rstrip('/')), 'J': J, 'strain': s[-1], 'from': lo,
            'phi': (phi[sel].mean(), phi[a].mean(), phi[b].mean()),
            'mu': (mu[sel].mean(), mu[a].mean(), mu[b].mean()),
            'std_omega': w[sel].std(axis=1).mean(), 'std_vy': vy[sel].std(axis=1).mean(),
            'mean_omega': w[sel].mean(),
            'steps_per_strain': run.summary.get('steps_per_strain', float('nan'))}


def row(r):
    return (f"{r['name']:16s} J {r['J']:.0e} strain {r['strain']:5.1f} window [{r['from']:g},] "
            f"phi {r['phi'][0]:.4f} ({r['phi'][1]:.4f} {r['phi'][2]:.4f})  "
            f"mu {r['mu'][0]:.3f} ({r['mu'][1]:.3f} {r['mu'][2]:.3f})  "
            f"std(omega)/J {r['std_omega']:5.1f}  std(vy)/J {r['std_vy']:4.2f}  "
            f"<omega>/J {r['mean_omega']:+.2f}  steps/strain {r['steps_per_strain']:.0f}")


if __name__ == '__main__':
    for arg in sys.argv[1:]:
        d, lo = arg.rsplit(':', 1) if ':' in arg else (arg, '2')
        print(row(statistics(d, float(lo))))
