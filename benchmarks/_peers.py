"""Independent NumPy/numba port of the wobblestone right-hand side (MODEL.md sections 3-8,
generalised Pade law eq. 13, printed b_Ts grouping with the derivative-exact switch) and a
hand-written adaptive Dormand-Prince 5(4) ensemble integrator in numba.

Used by the reference protocol (scipy DOP853 on an RHS that shares no code with jaxcelt) and by
the peer benchmarks. Written here because ``benchmarks/_numba_model.py`` did not exist when this
work started; `numba_rhs` is checked against `jaxcelt.vector_field` in `check_against_jax`.

The same Python source is the "numpy RHS" (run by the interpreter, 3-vectors as small arrays)
and, compiled with ``numba.njit``, the "numba RHS".
"""

from __future__ import annotations

import math

import numpy as np

try:
    import numba

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    HAVE_NUMBA = False

from jaxcelt.params import PARAM_NAMES

_P_INDEX = {name: i for i, name in enumerate(PARAM_NAMES)}


def pack_params(p) -> np.ndarray:
    """Params -> flat float64 array: PARAM_NAMES order, then E, G, H of the contact ellipse."""
    from jaxcelt import contact_integrals

    vals = [float(np.asarray(getattr(p, k))) for k in PARAM_NAMES]
    _, E, G, H = contact_integrals(p.b)
    return np.array(vals + [float(E), float(G), float(H)], dtype=np.float64)


def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _solve3(M, x, out):
    # Cramer's rule for the 3x3 inertia tensor
    det = (
        M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
        - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
        + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0])
    )
    out[0] = (
        x[0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
        - M[0, 1] * (x[1] * M[2, 2] - M[1, 2] * x[2])
        + M[0, 2] * (x[1] * M[2, 1] - M[1, 1] * x[2])
    ) / det
    out[1] = (
        M[0, 0] * (x[1] * M[2, 2] - M[1, 2] * x[2])
        - x[0] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
        + M[0, 2] * (M[1, 0] * x[2] - x[1] * M[2, 0])
    ) / det
    out[2] = (
        M[0, 0] * (M[1, 1] * x[2] - x[1] * M[2, 1])
        - M[0, 1] * (M[1, 0] * x[2] - x[1] * M[2, 0])
        + x[0] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0])
    ) / det


def _rhs(t, y, P, dy):
    a1, a2, a3, m = P[0], P[1], P[2], P[3]
    B1, B2, B3, B12, B13, B23 = P[4], P[5], P[6], P[7], P[8], P[9]
    k = P[10:13]
    g, a_hat, b, mu, k_r, b_r = P[13], P[14], P[15], P[16], P[17], P[18]
    S0, S2, S3, b_Ts, b_Ms, m_T, m_M = P[19], P[20], P[21], P[22], P[23], P[24], P[25]
    eps, eps_R, q_pi, om_pi, kappa, sgn, de = P[26], P[27], P[28], P[29], P[30], P[31], P[32]
    E, G, H = P[33], P[34], P[35]
    v = y[0:3]
    w = y[3:6]
    n = y[6:9]
    psi = y[12]
    A = np.empty(3)
    A[0], A[1], A[2] = a1 * a1, a2 * a2, a3 * a3
    An = A * n
    s = math.sqrt(_dot(n, An))
    ndot = np.empty(3)
    _cross(w, n, ndot)
    ndot = -ndot
    Andot = A * ndot
    rdot = -Andot / s + _dot(n, Andot) * An / s**3
    rho = -An / s - k
    # global horizontal frame (eq. 6) and patch frame
    u = -n[1] * n
    u[1] += 1.0
    u = u / math.sqrt(1.0 - n[1] ** 2)
    ww = np.empty(3)
    _cross(u, n, ww)
    c, si = math.cos(psi), math.sin(psi)
    E1 = c * ww - si * u
    E2 = si * ww + c * u
    ex = -n[0] * n
    ex[0] += 1.0
    ex = ex / math.sqrt(1.0 - n[0] ** 2)
    ey = np.empty(3)
    _cross(n, ex, ey)
    # kinematics
    tmp = np.empty(3)
    _cross(w, rho, tmp)
    vA = v + tmp
    vs = (vA - sgn * q_pi * om_pi * math.sin(om_pi * t) * E1) / a_hat
    vr = vs + rdot / a_hat
    vsx, vsy, ws = _dot(vs, ex), _dot(vs, ey), _dot(w, n)
    vrx, vry = _dot(vr, ex), _dot(vr, ey)
    # rolling-resistance distortion (eqs. 10, 15)
    DR = math.sqrt(vrx**2 + vry**2 / (b * b_r) ** 2 + eps_R)
    dc = k_r * vrx / DR
    ds = k_r * vry / (b * DR)
    # generalised Pade friction (eq. 13)
    V2 = vsx**2 + vsy**2 + eps
    aw = abs(ws)
    DT = (V2 ** (1.5 * m_T) + b_Ts**m_T * aw ** (3 * m_T)) ** (1 / m_T)
    DM = (b_Ms**m_M * aw ** (3 * m_M) + V2 ** (1.5 * m_M)) ** (1 / m_M)
    fac = b_Ts * (1 - de) + de
    pi = math.pi
    nx = V2 * vsx + ws * (
        b_Ts * (4 * G * S0 * vsx * ws - 4 * G * S2 * b * ds * ws**2)
        - fac * pi * S3 * b * ds * vsy**2
        - pi * S3 * dc * vsx * vsy
    )
    ny = V2 * vsy + ws * (
        b_Ts * (4 * H * S0 * vsy * ws + 4 * H * S2 * dc * ws**2)
        + fac * pi * S3 * dc * vsx**2
        + pi * b * S3 * ds * vsx * vsy
    )
    nm = 4 * b_Ms * E * S2 * ws**3 + pi * S3 * ((vsx**2 + b**2 * vsy**2) * ws + V2 * (dc * vsy - b * ds * vsx))
    Tsx, Tsy, Ms = nx / DT, ny / DT, nm / DM
    tt = -mu * (Tsx * ex + Tsy * ey)
    ms = -mu * a_hat * Ms * n
    mr = a_hat * pi * S3 * (b * ds * ex - dc * ey)
    # normal force from the differentiated constraint (section 8)
    Bm = np.empty((3, 3))
    Bm[0, 0], Bm[0, 1], Bm[0, 2] = B1, -B12, -B13
    Bm[1, 0], Bm[1, 1], Bm[1, 2] = -B12, B2, -B23
    Bm[2, 0], Bm[2, 1], Bm[2, 2] = -B13, -B23, B3
    rxn = np.empty(3)
    _cross(rho, n, rxn)
    Bw = np.array([_dot(Bm[0], w), _dot(Bm[1], w), _dot(Bm[2], w)])
    wxBw = np.empty(3)
    _cross(w, Bw, wxBw)
    sol = np.empty(3)
    _solve3(Bm, wxBw, sol)
    wxr = np.empty(3)
    wxn = np.empty(3)
    wxrd = np.empty(3)
    _cross(w, rho, wxr)
    _cross(w, n, wxn)
    _cross(w, rdot, wxrd)
    num = g + _dot(wxr, wxn) - _dot(wxrd, n) + _dot(rxn, sol) - kappa * _dot(vA, n)
    lev = np.empty(3)
    _cross(rho, n + tt, lev)
    lev = lev + ms + mr
    _solve3(Bm, lev, sol)
    den = 1.0 / m + _dot(rxn, sol)
    N = num / den
    F = N * (n + tt)
    wxv = np.empty(3)
    _cross(w, v, wxv)
    dy[0:3] = -wxv - g * n + F / m
    tq = np.empty(3)
    _cross(rho, F, tq)
    tq = tq + N * (ms + mr) - wxBw
    _solve3(Bm, tq, sol)
    dy[3:6] = sol
    dy[6:9] = ndot
    dy[9] = _dot(E1, v)
    dy[10] = _dot(E2, v)
    dy[11] = _dot(n, v)
    dy[12] = (w[0] * n[0] + w[2] * n[2]) / (1.0 - n[1] ** 2)


def numpy_rhs(p):
    """f(t, y) -> dy/dt in plain Python/NumPy (the 'numpy RHS' of the peer table)."""
    P = pack_params(p)

    def f(t, y):
        dy = np.empty(13)
        _rhs(t, np.asarray(y, dtype=np.float64), P, dy)
        return dy

    return f


if HAVE_NUMBA:
    _cross_nb = numba.njit(cache=True)(_cross)
    _dot_nb = numba.njit(cache=True)(_dot)
    _solve3_nb = numba.njit(cache=True)(_solve3)
    # rebind helpers inside the compiled RHS (numba resolves globals at compile time)
    _g = dict(_rhs.__globals__)
    _g.update(_cross=_cross_nb, _dot=_dot_nb, _solve3=_solve3_nb)
    import types

    _rhs_nb_py = types.FunctionType(_rhs.__code__, _g, "_rhs_nb")
    rhs_nb = numba.njit(cache=False, fastmath=False)(_rhs_nb_py)


def numba_rhs(p):
    """f(t, y) -> dy/dt, compiled with numba (the 'numba RHS')."""
    if not HAVE_NUMBA:
        raise ImportError("numba is not installed")
    P = pack_params(p)
    dy0 = np.empty(13)
    rhs_nb(0.0, np.zeros(13) + np.array([0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.0]), P, dy0)

    def f(t, y):
        dy = np.empty(13)
        rhs_nb(float(t), np.ascontiguousarray(y, dtype=np.float64), P, dy)
        return dy

    return f


def check_against_jax(p, n_samples: int = 20, seed: int = 0) -> float:
    """Max relative difference between this port and `jaxcelt.vector_field` at random states."""
    import jaxcelt as jc

    rng = np.random.default_rng(seed)
    f = numba_rhs(p) if HAVE_NUMBA else numpy_rhs(p)
    worst = 0.0
    for _ in range(n_samples):
        n = rng.normal(size=3) * np.array([0.2, 0.2, 0.0]) + np.array([0, 0, 1.0])
        n /= np.linalg.norm(n)
        y = np.asarray(
            jc.initial_state(
                p, omega=rng.normal(size=3) * 3, n=n, psi=rng.uniform(0, 6), v_A=np.cross(n, rng.normal(size=3)) * 0.1
            )
        )
        t = rng.uniform(0, 2)
        a = f(t, y)
        b = np.asarray(jc.vector_field(t, y, p))
        worst = max(worst, float(np.max(np.abs(a - b)) / (np.max(np.abs(b)) + 1e-300)))
    return worst


# --------------------------------------------------------------------------------------------
# hand-written adaptive Dormand-Prince 5(4) ensemble in numba

_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_A = np.zeros((7, 7))
_A[1, 0] = 1 / 5
_A[2, :2] = [3 / 40, 9 / 40]
_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_A[6, :6] = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_B5 = _A[6].copy()
_B4 = np.array([5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])
_BE = _B5 - _B4


if HAVE_NUMBA:

    @numba.njit(cache=False)
    def _dopri5_lane(y0, P, ts, rtol, atol, max_steps, out):
        """One trajectory: adaptive DP5(4) (FSAL, PI controller), stepping exactly onto ts."""
        y = y0.copy()
        k = np.empty((7, 13))
        t = ts[0]
        out[0] = y
        rhs_nb(t, y, P, k[0])
        # initial step: crude Hairer-style guess
        d0 = np.sqrt(np.mean((y / (atol + rtol * np.abs(y))) ** 2))
        d1 = np.sqrt(np.mean((k[0] / (atol + rtol * np.abs(y))) ** 2))
        h = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
        steps = 0
        rejected = 0
        err_prev = 1.0
        ytmp = np.empty(13)
        for i in range(1, ts.shape[0]):
            tend = ts[i]
            while t < tend:
                if steps >= max_steps:
                    return steps, rejected, 1
                hh = min(h, tend - t)
                for s in range(1, 7):
                    ytmp[:] = y
                    for j in range(s):
                        if _A[s, j] != 0.0:
                            ytmp += hh * _A[s, j] * k[j]
                    rhs_nb(t + _C[s] * hh, ytmp, P, k[s])
                # ytmp now holds the 5th-order solution (row 6 of A = B5)
                err = 0.0
                for c in range(13):
                    e = 0.0
                    for j in range(7):
                        e += _BE[j] * k[j, c]
                    sc = atol + rtol * max(abs(y[c]), abs(ytmp[c]))
                    err += (hh * e / sc) ** 2
                err = math.sqrt(err / 13)
                steps += 1
                if err <= 1.0 or hh < 1e-14:
                    t = t + hh if hh < tend - t else tend
                    y[:] = ytmp
                    k[0] = k[6]
                    fac = 0.9 * err ** (-0.7 / 5) * err_prev ** (0.4 / 5) if err > 0 else 10.0
                    err_prev = max(err, 1e-4)
                    h = hh * min(10.0, max(0.2, fac))
                else:
                    rejected += 1
                    h = hh * max(0.2, 0.9 * err ** (-1 / 5))
                if not np.isfinite(err):
                    return steps, rejected, 3
            out[i] = y
        return steps, rejected, 0

    @numba.njit(parallel=True, cache=False)
    def dopri5_ensemble(Y0, PP, ts, rtol, atol, max_steps, out, stats):
        """Lanes in parallel (numba prange over CPU threads). Y0 (L,13), PP (L,36)."""
        for i in numba.prange(Y0.shape[0]):
            s, r, st = _dopri5_lane(Y0[i], PP[i], ts, rtol, atol, max_steps, out[i])
            stats[i, 0] = s
            stats[i, 1] = r
            stats[i, 2] = st
