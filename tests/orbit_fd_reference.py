"""Finite-difference Floquet multipliers of the wobblestone on the independent numpy/scipy model.

Shares no code with jaxcelt: the vector field is `reference_numpy.rhs`, the integrator scipy's
DOP853, and the monodromy central differences of the one-period map in 8 coordinates of the
contact manifold, (v_A . e1, v_A . e2, omega, psi, n . e1 / n . n0, n . e2 / n . n0), with states
rebuilt on the manifold by `reference_numpy.initial_state`. Multipliers do not depend on the chart.
"""

from __future__ import annotations

import numpy as np
import reference_numpy as ref
from scipy.integrate import solve_ivp


def _basis(n0):
    e1 = np.array([1.0, 0.0, 0.0]) - n0[0] * n0
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(n0, e1)


def _rho(n, p):
    return ref.contact_point(n, p) - np.array([p["k1"], p["k2"], p["k3"]])


def coords(y, n0, psi_ref, p):
    e1, e2 = _basis(n0)
    v, w, n = y[0:3], y[3:6], y[6:9]
    vA = v + np.cross(w, _rho(n, p))
    psi = psi_ref + np.remainder(y[12] - psi_ref + np.pi, 2 * np.pi) - np.pi
    return np.concatenate([[vA @ e1, vA @ e2], w, [psi], [n @ e1 / (n @ n0), n @ e2 / (n @ n0)]])


def state(z, n0, p):
    e1, e2 = _basis(n0)
    n = n0 + z[6] * e1 + z[7] * e2
    n /= np.linalg.norm(n)
    u = z[0] * e1 + z[1] * e2
    vA = u - (u @ n) / (n0 @ n) * n0
    return ref.initial_state(p, omega=z[2:5], n=n, psi=z[5], v_A=vA)


def one_period(y0, t0, T, p, rtol=1e-12, atol=1e-14):
    s = solve_ivp(lambda t, y: ref.rhs(t, y, p), (t0, t0 + T), y0, method="DOP853", rtol=rtol, atol=atol)
    assert s.success, s.message
    return s.y[:, -1]


def fd_monodromy(y, t0, T, p, h=1e-5):
    """(8 x 8 central-difference monodromy, periodicity defect of y in the 8 coordinates)."""
    n0 = y[6:9] / np.linalg.norm(y[6:9])
    z = coords(y, n0, y[12], p)
    defect = coords(one_period(state(z, n0, p), t0, T, p), n0, y[12], p) - z
    M = np.empty((8, 8))
    for j in range(8):
        dz = np.zeros(8)
        dz[j] = h
        zp = coords(one_period(state(z + dz, n0, p), t0, T, p), n0, y[12], p)
        zm = coords(one_period(state(z - dz, n0, p), t0, T, p), n0, y[12], p)
        M[:, j] = (zp - zm) / (2 * h)
    return M, defect
