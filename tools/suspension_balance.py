#!/usr/bin/python3
"""Continuum models of pressure-driven channel flow of a suspension (issue 15, item 4).

Two steady, fully developed, one-dimensional models of a monolayer of discs (radius a) pumped
through a channel of width H at bulk areal fraction phi_b and fixed mean suspension velocity
<u>, from

  Nott, P. R. & Brady, J. F. 1994, "Pressure-driven flow of suspensions: simulation and
  theory", J. Fluid Mech. 275, 157-199, section 6 (the seed paper), and
  Phillips, R. J., Armstrong, R. C., Brown, R. A., Graham, A. L. & Abbott, J. R. 1992,
  "A constitutive equation for concentrated suspensions that accounts for shear-induced
  particle migration", Phys. Fluids A 4, 30-40.

docs/channel.md gives the equations, the choices and the comparison with the seed's Table 1.

Variables and scales (those of the seed's simulations)
------------------------------------------------------
s = y/H - 1/2: centreline s = 0, walls s = +-1/2 (solved on the half channel 0 <= s <= 1/2);
u scaled by <u> (the mean of u over the channel is 1); T = <u'.u'>_p scaled by <u>^2 (a/H)^2;
g = G H^2 / (eta <u>) the dimensionless pressure gradient (pure fluid: g = 12). Table-1
quantities: u_c = u(0), phi_c = phi(0), u_p = width average of the particle velocity (= 1 in
both models: no phase slip), Q_p = mean(phi u)/phi_b (seed section 5), dp_ratio = g/12.

Suspension-balance model (seed section 6.2: eqs 50, 54-56, 59, 60, constants of 6.2)
------------------------------------------------------------------------------------
  x-momentum, no phase slip (60):   d/ds( eta_s(phi) du/ds ) = -g
  y-momentum (59) with (50):        p(phi) T^(1/2) = P, a constant
  fluctuation energy (56):          eps^2 d/ds( kappa dT/ds ) + eta_p (du/ds)^2 - alpha T = 0
  mass:                             mean of phi over the channel = phi_b
  centre:   du/ds = dT/ds = 0;      walls: u = 0, T = 0;      mean u = 1 (fixes g)
  eta_s = (1 - phi/phi_m)^-1.82 (seed eq. 23), eta_p = eta_s - 1 (CHOICE), p = phi^1.5/(1 -
  phi/phi_m), alpha = k_alpha eta_p/phi, kappa = k_kappa eta_p, k_alpha = 0.19, k_kappa = 0.17,
  phi_m = 0.83 (seed 6.2). phi and u depend on the constants only through eps^2 k_kappa/k_alpha;
  T scales as 1/k_alpha.
CHOICE of length scale: eps = a/H with s scaled by the full width H (length_scale="H"), which
is what the dimensional balance (dissipation eta alpha T/a^2, flux -eta kappa grad T) gives.
The seed's printed conditions (wall at y = 1, int_0^1 phi dy = phi_b) suggest the half-width
instead, which with eps = a/H would make conduction 4x weaker; length_scale="half" computes
that reading. With "H" the model gives phi_c = 0.741 for case J, the case the seed fitted
k_alpha and k_kappa to (simulation: 0.74); with "half" the core jams (0.827).

Numerics: T = 0 at the wall forces phi = phi_m there, where eta_s, kappa and alpha diverge.
With x = 1 - phi/phi_m, T = P^2 x^2/phi^3 (from p T^(1/2) = P) and z = x^(2 - 1.82), the
conduction flux is eps^2 P^2 D(z) dz/ds with D = k_kappa (1 - x^1.82)(2/phi^3 + 3 phi_m x /
phi^4)/0.18, finite at the wall, and every term of the energy balance is regular in z. The
balance is discretised by finite volumes (second order) on a mesh stretched towards the wall,
with z = 0 at the wall node and zero flux at the centre; the unknowns z_i and ln P solve the
energy balances and the mass constraint (trapezoid rule) by Newton's method (sparse Jacobian:
tridiagonal block by finite differences, bordered by the ln P column and the mass row). The
energy balance is homogeneous in (T, g^2), so it is solved for g = 1 and rescaled: u and g
follow from eta_s du/ds = -g s by quadrature. Newton starts at H/a = 2 from a uniform
suspension with a thin wall layer and is continued in H/a (then in phi_b) to the case asked
for; this picks the branch whose concentration falls from the centre outwards (the local
balance p(phi) T^(1/2) = P has two roots; solve_bvp started elsewhere finds the same case-J
solution). domain="full" solves the whole channel without imposing symmetry (a check).

Diffusive-flux model (Phillips et al. 1992; seed section 6.1, eqs 20-25)
--------------------------------------------------------------------------
Zero net particle flux with a shear stress linear in s gives
    s phi (1 - phi/phi_m)^(1.82 (1 - K_eta/K_c)) = const,     K_c/K_eta = 0.66;
with the seed's (and Phillips et al.'s) rounding 1.82 (1 - K_eta/K_c) = -1 this is
    phi = phi_m / (1 + C r),  r = 2 s,   phi_b = (phi_m / C) ln(1 + C)
(the seed prints "phi_m log(1 + C)": the 1/C is lost in the text; without it the mean would
exceed phi_m). phi = phi_m at the centreline with slope -2 C phi_m in s: the cusp. u follows
from eta_s du/ds = -g s. exact_exponent=True uses the unrounded exponent 1.82 (1 - 1/0.66)
= -0.938. The model has no H/a.

Usage
-----
    /usr/bin/python3 tools/suspension_balance.py                    # model vs seed Table 1
    /usr/bin/python3 tools/suspension_balance.py --length-scale half
    /usr/bin/python3 tools/suspension_balance.py --plot J --out j.png
    /usr/bin/python3 tools/suspension_balance.py --solve 0.35 25    # any phi_b, H/a

From other tools (profiles as numpy arrays against y/H in [0, 1]):
    from suspension_balance import draw_model
    draw_model(axes3, 0.4, 18.32, sim=dict(y=y, phi=phi, u=u, T=T))
"""
import argparse
import math
import sys

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.sparse.linalg import spsolve

# ---- constants of the seed paper, section 6 ------------------------------------------------
PHI_M = 0.83         # maximum-packing areal fraction of a monolayer (seed 6.2)
KRIEGER_N = 1.82     # eta_s = (1 - phi/phi_m)^-n (seed eq. 23, after Phillips et al. 1992)
K_ALPHA = 0.19       # alpha = k_alpha eta_p / phi (seed 6.2)
K_KAPPA = 0.17       # kappa = k_kappa eta_p (seed 6.2)
KC_OVER_KETA = 0.66  # Phillips et al. (1992), quoted by the seed (6.1)

# ---- the seed's Table 1 ---------------------------------------------------------------------
# Columns as the seed lists them: bulk areal fraction phi_b, interior particles N, wall
# particles N_w, width H/a, range tau of the repulsive force (inf: no force, case B1), centreline
# velocity u_c/<u>, centreline areal fraction phi_c, mean particle velocity u_p/<u>, particle
# flux Q_p, pressure gradient over the pure-fluid one, run length (in a/<u>). Reconstructed
# from the paper's run-together text: "I35" there is B5 (102 particles, 18 wall particles; figure
# 11), and B1's "00" is infinity (the seed: B1 alone has no repulsive force).
TABLE1 = {
    "A":  dict(phi_b=0.40, N=32,  N_w=7,  h_over_a=14.02, tau=1000,     u_c=1.37, phi_c=0.71, u_p=0.954, Q_p=1.19, dp_ratio=2.44, t_run=2400),
    "B1": dict(phi_b=0.40, N=51,  N_w=9,  h_over_a=18.32, tau=math.inf, u_c=1.32, phi_c=0.64, u_p=0.980, Q_p=1.15, dp_ratio=2.37, t_run=4800),
    "B2": dict(phi_b=0.40, N=51,  N_w=9,  h_over_a=18.32, tau=100,      u_c=1.34, phi_c=0.71, u_p=0.975, Q_p=1.18, dp_ratio=2.13, t_run=4800),
    "B3": dict(phi_b=0.40, N=51,  N_w=9,  h_over_a=18.32, tau=1000,     u_c=1.34, phi_c=0.69, u_p=0.973, Q_p=1.18, dp_ratio=2.08, t_run=4800),
    "B4": dict(phi_b=0.40, N=51,  N_w=9,  h_over_a=18.32, tau=10000,    u_c=1.35, phi_c=0.70, u_p=0.974, Q_p=1.18, dp_ratio=2.05, t_run=4800),
    "B5": dict(phi_b=0.40, N=102, N_w=18, h_over_a=18.32, tau=1000,     u_c=1.35, phi_c=0.68, u_p=0.976, Q_p=1.17, dp_ratio=2.15, t_run=4800),
    "C":  dict(phi_b=0.40, N=61,  N_w=7,  h_over_a=30.29, tau=1000,     u_c=1.33, phi_c=0.78, u_p=0.988, Q_p=1.18, dp_ratio=2.04, t_run=12600),
    "D":  dict(phi_b=0.40, N=79,  N_w=7,  h_over_a=40.40, tau=1000,     u_c=1.30, phi_c=0.83, u_p=0.993, Q_p=1.17, dp_ratio=2.02, t_run=36000),
    "E":  dict(phi_b=0.30, N=26,  N_w=7,  h_over_a=14.02, tau=1000,     u_c=1.42, phi_c=0.67, u_p=0.943, Q_p=1.23, dp_ratio=1.89, t_run=2400),
    "F":  dict(phi_b=0.30, N=41,  N_w=9,  h_over_a=18.32, tau=1000,     u_c=1.37, phi_c=0.63, u_p=0.967, Q_p=1.24, dp_ratio=1.61, t_run=9600),
    "G":  dict(phi_b=0.30, N=48,  N_w=7,  h_over_a=30.29, tau=1000,     u_c=1.36, phi_c=0.72, u_p=0.974, Q_p=1.23, dp_ratio=1.62, t_run=29000),
    "H":  dict(phi_b=0.30, N=61,  N_w=7,  h_over_a=40.40, tau=1000,     u_c=1.35, phi_c=0.63, u_p=0.982, Q_p=1.18, dp_ratio=1.75, t_run=32000),
    "I":  dict(phi_b=0.15, N=25,  N_w=9,  h_over_a=18.32, tau=1000,     u_c=1.46, phi_c=0.45, u_p=0.801, Q_p=1.29, dp_ratio=1.32, t_run=7200),
    "J":  dict(phi_b=0.45, N=56,  N_w=9,  h_over_a=18.32, tau=1000,     u_c=1.32, phi_c=0.74, u_p=0.976, Q_p=1.17, dp_ratio=2.37, t_run=4800),
}
# The cases issue 15 names. B1, B2, B4, B5 differ from B3 only in the repulsion or the cell
# size, which neither continuum model sees: they get B3's model values.
ISSUE_CASES = ["A", "B3", "C", "D", "E", "F", "G", "H", "I", "J"]


# ---- constitutive functions (seed 6.1, 6.2) ---------------------------------------------------
def eta_s(phi, phi_m=PHI_M, n=KRIEGER_N):
    """Relative suspension viscosity (1 - phi/phi_m)^-n (seed eq. 23)."""
    return (1.0 - np.asarray(phi, float) / phi_m) ** (-n)


def eta_p(phi, phi_m=PHI_M, n=KRIEGER_N):
    """Particle-phase viscosity eta_s - 1 (our choice: the seed only says it follows from eta_s)."""
    return eta_s(phi, phi_m, n) - 1.0


def pressure_fn(phi, phi_m=PHI_M):
    """Particle-pressure function p = phi^(3/2) / (1 - phi/phi_m) (seed 6.2)."""
    phi = np.asarray(phi, float)
    return phi ** 1.5 / (1.0 - phi / phi_m)


def alpha_fn(phi, k_alpha=K_ALPHA, phi_m=PHI_M, n=KRIEGER_N):
    """Dissipation function alpha = k_alpha eta_p / phi (seed 6.2)."""
    return k_alpha * eta_p(phi, phi_m, n) / np.asarray(phi, float)


def kappa_fn(phi, k_kappa=K_KAPPA, phi_m=PHI_M, n=KRIEGER_N):
    """Conductivity kappa = k_kappa eta_p (seed 6.2)."""
    return k_kappa * eta_p(phi, phi_m, n)


def _trapz(f, x):
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))


# ---- a solved profile ------------------------------------------------------------------------
class Profile:
    """A model solution on the half channel, s = y/H - 1/2 in [0, 1/2] (s = 0: the centreline).

    Arrays s, phi, u, T (T is None for the diffusive-flux model); g = G H^2/(eta <u>); the
    Table-1 quantities u_c, phi_c, u_p, Q_p, dp_ratio; mean_phi (trapezoid rule); info (solver
    details). full() gives the profiles across the channel against y/H in [0, 1]; at(y) samples
    them at y/H."""

    def __init__(self, s, phi, u, T, g, phi_b, model, info=None):
        self.s, self.phi, self.u, self.T, self.g = s, phi, u, T, g
        self.phi_b, self.model, self.info = phi_b, model, dict(info or {})
        self.u_c = float(u[0])
        self.phi_c = float(phi[0])
        self.u_p = 2.0 * _trapz(u, s)                 # width average of u_p = u (no slip)
        self.Q_p = 2.0 * _trapz(phi * u, s) / phi_b
        self.dp_ratio = g / 12.0
        self.mean_phi = 2.0 * _trapz(phi, s)

    def full(self):
        """(y/H, phi, u, T) from one wall (y/H = 0) to the other (y/H = 1)."""
        y = np.concatenate([0.5 - self.s[::-1], 0.5 + self.s[1:]])

        def mirror(f):
            return None if f is None else np.concatenate([f[::-1], f[1:]])
        return y, mirror(self.phi), mirror(self.u), mirror(self.T)

    def at(self, y_over_h):
        """phi, u, T (T None for diffusive flux) at the given y/H values in [0, 1]."""
        s = np.abs(np.asarray(y_over_h, float) - 0.5)
        T = None if self.T is None else np.interp(s, self.s, self.T)
        return np.interp(s, self.s, self.phi), np.interp(s, self.s, self.u), T


def velocity_from_viscosity(s, eta):
    """u and g for d/ds(eta du/ds) = -g on s in [0, 1/2] with du/ds(0) = 0, u(1/2) = 0 and the
    mean of u equal to 1, for the viscosity eta given on the grid s (trapezoid rule; eta may be
    inf where the suspension is jammed). Constant eta: u = 1.5 (1 - 4 s^2), g = 12 eta."""
    s = np.asarray(s, float)
    with np.errstate(divide="ignore"):
        dv = -s / np.asarray(eta, float)             # v = u/g
    v = np.concatenate([[0.0], np.cumsum(0.5 * (dv[1:] + dv[:-1]) * np.diff(s))])
    v -= v[-1]
    g = (s[-1] - s[0]) / _trapz(v, s)
    return g * v, g


# ---- diffusive-flux model ---------------------------------------------------------------------
def diffusive_flux(phi_b, npts=4001, phi_m=PHI_M, n=KRIEGER_N, kc_over_keta=KC_OVER_KETA,
                   exact_exponent=False):
    """Phillips et al. (1992) steady channel profile (seed 6.1) on s in [0, 1/2].

    Default: the seed's closed form phi = phi_m/(1 + C r), r = 2 s, with
    phi_b = (phi_m/C) ln(1 + C). exact_exponent=True: s phi (1 - phi/phi_m)^e = const with
    e = n (1 - 1/kc_over_keta), the constant fixed by the mean. info holds C (or the constant)
    and the exponent."""
    if not 0.0 < phi_b < phi_m:
        raise ValueError(f"phi_b must lie in (0, {phi_m}), got {phi_b}")
    s = np.linspace(0.0, 0.5, npts)
    r = 2.0 * s
    if not exact_exponent:
        C = brentq(lambda C: phi_m * math.log1p(C) / C - phi_b, 1e-12, 1e15, xtol=1e-300, rtol=1e-15)
        phi = phi_m / (1.0 + C * r)
        info = dict(C=C, exponent=-1.0)
    else:
        e = n * (1.0 - 1.0 / kc_over_keta)
        if e >= 0:
            raise ValueError("the exact-exponent profile needs K_eta/K_c > 1")

        def profile(c):
            # phi (1 - phi/phi_m)^e = c/r has one root in (0, phi_m) for e < 0
            out = np.full(r.size, phi_m)
            for i in range(1, r.size):
                out[i] = brentq(lambda f: f * (1.0 - f / phi_m) ** e - c / r[i], 0.0,
                                phi_m * (1.0 - 1e-15), xtol=1e-15)
            return out
        c = brentq(lambda c: 2.0 * _trapz(profile(c), s) - phi_b, 1e-12, 1e3, xtol=1e-15)
        phi = profile(c)
        info = dict(c=c, exponent=e)
    x = np.maximum(1.0 - phi / phi_m, 0.0)
    with np.errstate(divide="ignore"):
        eta = np.where(x > 0, x ** (-n), np.inf)
    u, g = velocity_from_viscosity(s, eta)
    return Profile(s, phi, u, None, g, phi_b, "diffusive_flux", info)


# ---- suspension-balance model -------------------------------------------------------------------
class _Discretisation:
    """Finite-volume form of the suspension-balance energy equation and mass constraint."""

    def __init__(self, phi_b, eps2, npts, domain, phi_m, n, k_alpha, k_kappa, stretch):
        self.phi_b, self.eps2, self.domain = phi_b, eps2, domain
        self.phi_m, self.n, self.ka, self.kk = phi_m, n, k_alpha, k_kappa
        self.gam = 2.0 - n
        xi = np.linspace(0.0, 1.0, npts + 1)
        w = 1.0 - np.sinh(stretch * (1.0 - xi)) / math.sinh(stretch) if stretch > 0 else xi
        sh = 0.5 * w                                     # 0 .. 1/2, fine at the wall
        self.s = sh if domain == "half" else np.concatenate([-sh[::-1], sh[1:]])
        self.h = np.diff(self.s)
        self.V = np.zeros_like(self.s)
        self.V[:-1] += 0.5 * self.h
        self.V[1:] += 0.5 * self.h
        self.free = np.ones(self.s.size, bool)
        self.free[-1] = False                            # z = 0 at the wall
        if domain == "full":
            self.free[0] = False
        self.nz = int(self.free.sum())
        self.npar = 1 if domain == "half" else 2         # ln P (and the stress offset c)
        self.L = self.s[-1] - self.s[0]

    def fields(self, z):
        x = np.clip(z, 0.0, 1.0) ** (1.0 / self.gam)
        return x, self.phi_m * (1.0 - x)

    def unpack(self, U):
        z = np.zeros(self.s.size)
        z[self.free] = U[:self.nz]
        c = U[self.nz + 1] if self.domain == "full" else 0.0
        return z, U[self.nz], c

    def residual(self, U):
        s, n = self.s, self.n
        z, lnP, c = self.unpack(U)
        P2 = math.exp(2.0 * lnP)
        x, phi = self.fields(z)
        xf, phif = self.fields(0.5 * (z[1:] + z[:-1]))
        D = self.kk * (1.0 - xf ** n) * (2.0 / phif ** 3 + 3.0 * self.phi_m * xf / phif ** 4) / self.gam
        q = self.eps2 * P2 * D * np.diff(z) / self.h            # conduction flux at faces
        div = np.zeros_like(s)
        div[:-1] += q
        div[1:] -= q
        diss = self.ka * P2 * (np.clip(z, 0, 1) - x ** 2) / phi ** 4   # alpha T, regular at phi_m
        prod = (1.0 - x ** n) * x ** n * (s - c) ** 2                  # eta_p (dv/ds)^2, g = 1
        out = [(div - self.V * (diss - prod))[self.free], [np.dot(self.V, phi) - self.phi_b * self.L]]
        if self.domain == "full":
            dv = (c - s) * x ** n
            out.append([np.sum(0.5 * (dv[1:] + dv[:-1]) * self.h)])   # u(-1/2) = u(1/2) = 0
        return np.concatenate(out)

    def jacobian(self, U, R0):
        m, nz = U.size, self.nz
        rows, cols, vals = [], [], []
        for colour in range(3):                                  # tridiagonal energy block
            idx = np.arange(colour, nz, 3)
            step = 1e-7 * np.maximum(1e-3, np.abs(U[idx]))
            dU = np.zeros(m)
            dU[idx] = step
            dR = self.residual(U + dU) - R0
            for o in (-1, 0, 1):
                i = idx + o
                ok = (i >= 0) & (i < nz)
                rows.append(i[ok]); cols.append(idx[ok]); vals.append(dR[i[ok]] / step[ok])
        for k in range(self.npar):                               # ln P, c: full columns
            step = 1e-7 * max(1.0, abs(U[nz + k]))
            dU = np.zeros(m)
            dU[nz + k] = step
            rows.append(np.arange(m)); cols.append(np.full(m, nz + k))
            vals.append((self.residual(U + dU) - R0) / step)
        z, _, c = self.unpack(U)
        x, _ = self.fields(z)
        zc = np.maximum(z, 1e-300)
        dxdz = np.where(z > 0, zc ** (1.0 / self.gam - 1.0) / self.gam, 0.0)
        rows.append(np.full(nz, nz)); cols.append(np.arange(nz))
        vals.append((-self.phi_m * self.V * dxdz)[self.free])   # mass row (exact)
        if self.domain == "full":
            dv = self.V * (c - self.s) * self.n * np.maximum(x, 1e-300) ** (self.n - 1.0) * dxdz
            rows.append(np.full(nz, nz + 1)); cols.append(np.arange(nz)); vals.append(dv[self.free])
        return sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(m, m))

    def newton(self, U, maxit=40):
        """Damped Newton; returns (U, iterations) or raises RuntimeError."""
        for it in range(maxit):
            R = self.residual(U)
            r0 = np.linalg.norm(R)
            if not np.isfinite(r0):
                raise RuntimeError("non-finite residual")
            if r0 < 1e-14:
                return U, it
            dU = spsolve(self.jacobian(U, R), -R)
            if not np.all(np.isfinite(dU)):
                raise RuntimeError("singular Newton system")
            lam = 1.0
            while True:
                Un = U + lam * dU
                Un[:self.nz] = np.clip(Un[:self.nz], 0.0, 1.0 - 1e-12)
                rn = np.linalg.norm(self.residual(Un))
                if np.isfinite(rn) and rn < (1.0 - 1e-4 * lam) * r0:
                    break
                lam *= 0.5
                if lam < 1e-4:
                    if r0 < 1e-10:      # at round-off: no descent left
                        return U, it
                    raise RuntimeError(f"line search failed at |R| = {r0:.3g}")
            U = Un
            if lam == 1.0 and np.max(np.abs(dU)) < 1e-10:
                return U, it + 1
        raise RuntimeError(f"Newton did not converge in {maxit} iterations (|R| = {rn:.3g})")

    def start(self):
        """Uniform suspension at phi_b with a thin wall layer; P from the local balance."""
        s = self.s
        xb = 1.0 - self.phi_b / self.phi_m
        z = xb ** self.gam * np.tanh((0.5 - np.abs(s)) / min(2.0 * math.sqrt(self.eps2), 0.02))
        T = self.phi_b * (0.25 * xb ** self.n) ** 2 / self.ka
        P = pressure_fn(self.phi_b, self.phi_m) * math.sqrt(T)
        return np.concatenate([z[self.free], [math.log(P)], [0.0] * (self.npar - 1)])

    def transfer(self, other, U_other):
        """Unknowns of another discretisation's solution, interpolated onto this mesh."""
        z_o, lnP, c = other.unpack(U_other)
        if other.domain == "half" and self.domain == "full":
            z = np.interp(np.abs(self.s), other.s, z_o)
        else:
            z = np.interp(self.s, other.s, z_o)
        return np.concatenate([z[self.free], [lnP], [c] * (self.npar - 1)])

    def profile(self, U, length_scale, ha):
        z, lnP, c = self.unpack(U)
        x, phi = self.fields(z)
        if self.domain == "half":
            with np.errstate(divide="ignore"):
                u, g = velocity_from_viscosity(self.s, np.where(x > 0, x ** (-self.n), np.inf))
        else:                       # shear stress g (c - s): the offset c found by the solve
            dv = (c - self.s) * x ** self.n
            v = np.concatenate([[0.0], np.cumsum(0.5 * (dv[1:] + dv[:-1]) * self.h)])
            v -= v[-1]
            g = self.L / np.dot(self.V, v)
            u = g * v
        T = g ** 2 * math.exp(2.0 * lnP) * x ** 2 / phi ** 3
        info = dict(P=g * math.exp(lnP), c=c, eps2=self.eps2, npts=self.s.size, length_scale=length_scale,
                    h_over_a=ha, residual=float(np.linalg.norm(self.residual(U))), domain=self.domain)
        if self.domain == "full":
            info["full"] = (self.s.copy(), phi, u, T)
            k = self.s >= 0
            return Profile(self.s[k], phi[k], u[k], T[k], g, self.phi_b, "suspension_balance", info)
        return Profile(self.s, phi, u, T, g, self.phi_b, "suspension_balance", info)


def _continue(make, U, a, b, log=True):
    """March the parameter from a to b (geometrically if log), re-solving with Newton from the
    previous solution; adaptive steps. make(p) -> _Discretisation."""
    d = make(a)
    frac, done = 0.25, 0.0
    while done < 1.0:
        t = min(1.0, done + frac)
        p = a * (b / a) ** t if log else a + (b - a) * t
        dn = make(p)
        try:
            Un, it = dn.newton(U)
        except RuntimeError:
            frac *= 0.5
            if frac < 1e-4:
                raise RuntimeError(f"continuation stalled at {p:.6g} (from {a:.6g} to {b:.6g})")
            continue
        d, U, done = dn, Un, t
        if it <= 5:
            frac = min(2.0 * frac, 0.5)
    return d, U


def suspension_balance(phi_b, h_over_a, npts=800, length_scale="H", k_alpha=K_ALPHA,
                       k_kappa=K_KAPPA, phi_m=PHI_M, n=KRIEGER_N, domain="half", stretch=4.0,
                       asym_guess=0.0):
    """Nott & Brady's suspension-balance model (seed 6.2) at bulk areal fraction phi_b and
    width h_over_a = H/a; returns a Profile on s in [0, 1/2] (T in <u>^2 (a/H)^2).

    npts: mesh intervals on the half channel (stretched towards the wall by `stretch`).
    length_scale: "H" (eps = a/H, s scaled by the full width; default) or "half" (the literal
    reading, eps = a/H with the coordinate scaled by H/2: conduction 4x weaker).
    domain: "half" (symmetry imposed at s = 0) or "full" (whole channel, wall conditions only;
    started from the half solution tilted by asym_guess; info["full"] = (s, phi, u, T))."""
    if not 0.0 < phi_b < phi_m:
        raise ValueError(f"phi_b must lie in (0, {phi_m}), got {phi_b}")
    if not h_over_a > 0:
        raise ValueError(f"H/a must be positive, got {h_over_a}")
    if not 1.0 <= n < 2.0:
        raise ValueError("the wall variable z = x^(2 - n) needs 1 <= n < 2")
    if length_scale not in ("H", "half"):
        raise ValueError("length_scale must be 'H' or 'half'")
    ha_eff = h_over_a if length_scale == "H" else 2.0 * h_over_a   # eps^2 = 1/ha_eff^2

    def make(phi, ha, npts_, dom="half"):
        return _Discretisation(phi, 1.0 / ha ** 2, npts_, dom, phi_m, n, k_alpha, k_kappa, stretch)

    def march(mesh):
        # H/a from 2 at an anchor fraction, then phi_b, each step a Newton solve
        anchor = min(max(phi_b, 0.15), 0.45)
        ha0 = min(2.0, ha_eff)
        d = make(anchor, ha0, mesh)
        U, _ = d.newton(d.start())
        if ha_eff != ha0:
            d, U = _continue(lambda ha: make(anchor, ha, mesh), U, ha0, ha_eff)
        if phi_b != anchor:
            d, U = _continue(lambda ph: make(ph, ha_eff, mesh), U, anchor, phi_b)
        return d, U

    # continuation on a coarse mesh, then Newton on the fine one; if that fails (thin wall
    # layers of dilute cases are not resolved on the coarse mesh), continuation on the fine one
    coarse = min(npts, 400)
    d, U = march(coarse)
    if coarse != npts:
        fine = make(phi_b, ha_eff, npts)
        try:
            U, _ = fine.newton(fine.transfer(d, U))
            d = fine
        except RuntimeError:
            d, U = march(npts)
    if domain == "full":
        full = make(phi_b, ha_eff, npts, "full")
        Uf = full.transfer(d, U)
        # tilt the start: x (i.e. 1 - phi/phi_m) scaled by 1 + asym_guess s, and a shear-stress
        # offset c = asym_guess/20 (the centre of stress moved off the centreline)
        x = Uf[:full.nz] ** (1.0 / full.gam) * (1.0 + asym_guess * full.s[full.free])
        Uf[:full.nz] = np.clip(x, 0.0, 0.99) ** full.gam
        Uf[-1] = asym_guess / 20.0
        Uf, _ = full.newton(Uf, maxit=80)
        d, U = full, Uf
    elif domain != "half":
        raise ValueError("domain must be 'half' or 'full'")
    return d.profile(U, length_scale, h_over_a)


# ---- comparison with the seed's Table 1 -------------------------------------------------------
def table_rows(cases=ISSUE_CASES, length_scale="H", npts=800):
    """(case, paper row, suspension-balance Profile, diffusive-flux Profile) per case."""
    out, cache = [], {}
    for c in cases:
        r = TABLE1[c]
        key = (r["phi_b"], r["h_over_a"])
        if key not in cache:
            cache[key] = suspension_balance(r["phi_b"], r["h_over_a"], npts=npts, length_scale=length_scale)
        out.append((c, r, cache[key], diffusive_flux(r["phi_b"])))
    return out


def format_table(rows):
    """Markdown table: per quantity the seed's value, the suspension-balance model (SBM) and
    the diffusive-flux model (DF)."""
    head = ("| case | phi_b | H/a | run length | u_c seed / SBM / DF | phi_c seed / SBM / DF | "
            "u_p seed / models | Q_p seed / SBM / DF | dp ratio seed / SBM / DF |")
    lines = [head, "|" + " --- |" * 9]
    for c, r, m, d in rows:
        lines.append(
            f"| {c} | {r['phi_b']:.2f} | {r['h_over_a']:.2f} | {r['t_run']} | "
            f"{r['u_c']:.2f} / {m.u_c:.3f} / {d.u_c:.3f} | {r['phi_c']:.2f} / {m.phi_c:.3f} / {d.phi_c:.3f} | "
            f"{r['u_p']:.3f} / {m.u_p:.3f} | {r['Q_p']:.2f} / {m.Q_p:.3f} / {d.Q_p:.3f} | "
            f"{r['dp_ratio']:.2f} / {m.dp_ratio:.3f} / {d.dp_ratio:.3f} |")
    return "\n".join(lines)


# ---- drawing ---------------------------------------------------------------------------------
def draw_model(axes, phi_b, h_over_a, sim=None, length_scale="H", label_sim="simulation",
               diffusive=True, parabola=True):
    """Draw the models for (phi_b, H/a) on three matplotlib axes (phi, u/<u>, T against y/H in
    [0, 1]), over simulated profiles if given: sim = dict(y=..., phi=..., u=..., T=...) of numpy
    arrays against y/H (any key may be missing or None). Returns (SBM Profile, DF Profile)."""
    sbm = suspension_balance(phi_b, h_over_a, length_scale=length_scale)
    df = diffusive_flux(phi_b) if diffusive else None
    sim = sim or {}
    for ax, key in zip(axes, ("phi", "u", "T")):
        if sim.get("y") is not None and sim.get(key) is not None:
            ax.plot(sim["y"], sim[key], "o", ms=3, color="0.4", label=label_sim)
    y, phi, u, T = sbm.full()
    axes[0].plot(y, phi, "C0-", label="suspension balance")
    axes[1].plot(y, u, "C0-", label="suspension balance")
    axes[2].plot(y, T, "C0-", label="suspension balance")
    if df is not None:
        yd, phid, ud, _ = df.full()
        axes[0].plot(yd, phid, "C3--", label="diffusive flux")
        axes[1].plot(yd, ud, "C3--", label="diffusive flux")
    if parabola:
        yy = np.linspace(0, 1, 201)
        axes[1].plot(yy, 6.0 * yy * (1.0 - yy), "k-", lw=2.5, alpha=0.4, label="Newtonian parabola")
    for ax, name in zip(axes, (r"$\phi$", r"$u/\langle u\rangle$", r"$T/(\langle u\rangle^2 (a/H)^2)$")):
        ax.set_xlabel("y/H")
        ax.set_ylabel(name)
        ax.set_xlim(0, 1)
    axes[0].axhline(phi_b, color="0.7", lw=0.8)
    return sbm, df


def plot_case(case, out, length_scale="H"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    r = TABLE1[case]
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    draw_model(axes, r["phi_b"], r["h_over_a"], length_scale=length_scale)
    axes[0].plot([0.5], [r["phi_c"]], "k*", ms=10, label="seed Table 1 (centre)")
    axes[1].plot([0.5], [r["u_c"]], "k*", ms=10, label="seed Table 1 (centre)")
    axes[0].legend(fontsize=7)
    axes[1].legend(fontsize=7)
    fig.suptitle(f"case {case}: phi_b = {r['phi_b']}, H/a = {r['h_over_a']} "
                 f"(length scale {length_scale})")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default=",".join(ISSUE_CASES),
                    help="comma-separated Table 1 cases (default: %(default)s; 'all' for all 14)")
    ap.add_argument("--length-scale", choices=("H", "half"), default="H",
                    help="reading of the seed's eps (see module docstring)")
    ap.add_argument("--npts", type=int, default=800, help="mesh intervals on the half channel")
    ap.add_argument("--plot", metavar="CASE", help="draw phi, u, T of one Table 1 case")
    ap.add_argument("--out", default="channel_model.png", help="image file for --plot")
    ap.add_argument("--solve", nargs=2, type=float, metavar=("PHI_B", "H_OVER_A"),
                    help="solve one (phi_b, H/a) and print its numbers")
    a = ap.parse_args(argv)
    if a.plot:
        if a.plot not in TABLE1:
            ap.error(f"unknown case {a.plot}; known: {', '.join(TABLE1)}")
        plot_case(a.plot, a.out, a.length_scale)
        return 0
    if a.solve:
        try:
            m = suspension_balance(a.solve[0], a.solve[1], npts=a.npts, length_scale=a.length_scale)
            d = diffusive_flux(a.solve[0])
        except (ValueError, RuntimeError) as e:
            print(f"suspension_balance.py: {e}", file=sys.stderr)
            return 1
        for name, p in (("suspension balance", m), ("diffusive flux", d)):
            print(f"{name}: u_c {p.u_c:.4f}  phi_c {p.phi_c:.4f}  u_p {p.u_p:.4f}  Q_p {p.Q_p:.4f}  "
                  f"dp ratio {p.dp_ratio:.4f}" + (f"  T_c {p.T[0]:.4g}" if p.T is not None else ""))
        return 0
    cases = list(TABLE1) if a.cases == "all" else [c.strip() for c in a.cases.split(",") if c.strip()]
    bad = [c for c in cases if c not in TABLE1]
    if bad:
        ap.error(f"unknown case(s) {', '.join(bad)}; known: {', '.join(TABLE1)}")
    print(format_table(table_rows(cases, a.length_scale, a.npts)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
