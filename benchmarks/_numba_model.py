"""The one hand-written port of the wobblestone right-hand side (MODEL.md sections 3-8) and an
adaptive Dormand-Prince 5(4) ensemble integrator -- the CPU baselines of ``bench_sweep.py``,
``peers.py`` and the independent reference of ``reference.py``.

Written independently of the JAX code from MODEL.md (same equations, same default readings);
checked against `jaxcelt.vector_field` by `check_against_jax` (tests/test_benchmarks_smoke.py).
Parameter vector layout: see `pack`. K, E, G, H and B^-1 are precomputed (as a hand-written
code would), so one RHS here is the irreducible arithmetic.

Three ways to call the same source: `rhs` (numba, allocation-free, for numba loops and CVODE),
`numba_rhs(p)` (an ``f(t, y)`` for scipy), `python_rhs(p)` (the same Python source run by the
interpreter, no compilation: the "plain Python/NumPy RHS" peer).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from scipy.special import ellipe, ellipk

from jaxcelt.integrate.solve import HEADING_GAP  # one rule for both sides of the benchmark

# indices into the packed parameter vector
(A1, A2, A3, M, K1, K2, K3, GRAV, AH, BB, MU, KR, BR, S0, S2, S3, BTS, BMS, MTS, MMS, EPS, EPSR, QPI, WPI, KAPPA, VSIGN,
 DEX, KE, EE, GE, HE) = range(31)  # fmt: skip
NP = 31


def pack(p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(P (31,), B (3,3), Binv (3,3)) from a scalar `jaxcelt.CeltParams`."""
    d = {k: float(np.asarray(v)) for k, v in p.as_dict().items()}
    e2 = 1 - d["b"] ** 2
    K, E = ellipk(e2), ellipe(e2)
    G = (K - E) / e2
    P = np.array([d["a1"], d["a2"], d["a3"], d["m"], d["k1"], d["k2"], d["k3"], d["g"], d["a_hat"], d["b"], d["mu"],
                  d["k_r"], d["b_r"], d["S0"], d["S2"], d["S3"], d["b_Ts"], d["b_Ms"], d["m_Ts"], d["m_Ms"], d["eps"],
                  d["eps_R"], d["q_pi"], d["omega_pi"], d["kappa"], d["v_pi_sign"], d["derivative_exact"], K, E, G, K - G])  # fmt: skip
    B = np.array([[d["B1"], -d["B12"], -d["B13"]], [-d["B12"], d["B2"], -d["B23"]], [-d["B13"], -d["B23"], d["B3"]]])
    return P, B, np.linalg.inv(B)


@nb.njit(inline="always")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@nb.njit(fastmath=False, cache=True, error_model="numpy")  # x/0 -> inf/nan as in JAX, no exception
def rhs(t, y, P, B, Bi, out):
    v0, v1, v2, w0, w1, w2, n0, n1, n2, psi = y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7], y[8], y[12]
    # contact geometry (eqs. 3-4)
    Aa0, Aa1, Aa2 = P[A1] ** 2, P[A2] ** 2, P[A3] ** 2
    An0, An1, An2 = Aa0 * n0, Aa1 * n1, Aa2 * n2
    s = math.sqrt(n0 * An0 + n1 * An1 + n2 * An2)
    r0, r1, r2 = -An0 / s, -An1 / s, -An2 / s
    rho0, rho1, rho2 = r0 - P[K1], r1 - P[K2], r2 - P[K3]
    nd0, nd1, nd2 = _cross(w0, w1, w2, n0, n1, n2)
    nd0, nd1, nd2 = -nd0, -nd1, -nd2
    Ad0, Ad1, Ad2 = Aa0 * nd0, Aa1 * nd1, Aa2 * nd2
    nAd = n0 * Ad0 + n1 * Ad1 + n2 * Ad2
    s3 = s * s * s
    rd0, rd1, rd2 = -Ad0 / s + nAd * An0 / s3, -Ad1 / s + nAd * An1 / s3, -Ad2 / s + nAd * An2 / s3
    # horizontal frame (eq. 6, section 4)
    q = math.sqrt(1.0 - n1 * n1)
    u0, u1, u2 = (-n1 * n0) / q, (1.0 - n1 * n1) / q, (-n1 * n2) / q
    ww0, ww1, ww2 = _cross(u0, u1, u2, n0, n1, n2)
    c, sn = math.cos(psi), math.sin(psi)
    E10, E11, E12 = c * ww0 - sn * u0, c * ww1 - sn * u1, c * ww2 - sn * u2
    E20, E21, E22 = sn * ww0 + c * u0, sn * ww1 + c * u1, sn * ww2 + c * u2
    # patch frame (section 5)
    qx = math.sqrt(1.0 - n0 * n0)
    ex0, ex1, ex2 = (1.0 - n0 * n0) / qx, (-n0 * n1) / qx, (-n0 * n2) / qx
    ey0, ey1, ey2 = _cross(n0, n1, n2, ex0, ex1, ex2)
    # velocities (eqs. 2, 16, 17)
    wr0, wr1, wr2 = _cross(w0, w1, w2, rho0, rho1, rho2)
    vA0, vA1, vA2 = v0 + wr0, v1 + wr1, v2 + wr2
    vp = P[VSIGN] * P[QPI] * P[WPI] * math.sin(P[WPI] * t)
    ah = P[AH]
    vs0, vs1, vs2 = (vA0 - vp * E10) / ah, (vA1 - vp * E11) / ah, (vA2 - vp * E12) / ah
    vr0, vr1, vr2 = vs0 + rd0 / ah, vs1 + rd1 / ah, vs2 + rd2 / ah
    vsx = vs0 * ex0 + vs1 * ex1 + vs2 * ex2
    vsy = vs0 * ey0 + vs1 * ey1 + vs2 * ey2
    om = w0 * n0 + w1 * n1 + w2 * n2
    vrx = vr0 * ex0 + vr1 * ex1 + vr2 * ex2
    vry = vr0 * ey0 + vr1 * ey1 + vr2 * ey2
    # rolling distortion (eqs. 10, 15)
    b = P[BB]
    DR = math.sqrt(vrx * vrx + vry * vry / (b * P[BR]) ** 2 + P[EPSR])
    dc = P[KR] * vrx / DR
    ds = P[KR] * vry / (b * DR)
    # friction approximant (eqs. 13-15)
    V2 = vsx * vsx + vsy * vsy + P[EPS]
    aw = abs(om)
    mT, mM = P[MTS], P[MMS]
    awT = aw ** (3 * mT) if aw > 0 else 0.0
    awM = aw ** (3 * mM) if aw > 0 else 0.0
    DT = (V2 ** (1.5 * mT) + P[BTS] ** mT * awT) ** (1 / mT)
    DM = (P[BMS] ** mM * awM + V2 ** (1.5 * mM)) ** (1 / mM)
    G, H, E = P[GE], P[HE], P[EE]
    pi = math.pi
    fac = P[BTS] * (1 - P[DEX]) + P[DEX]
    bts = P[BTS]
    numx = V2 * vsx + om * (bts * (4 * G * P[S0] * vsx * om - 4 * G * P[S2] * b * ds * om * om)
                            - fac * pi * P[S3] * b * ds * vsy * vsy - pi * P[S3] * dc * vsx * vsy)  # fmt: skip
    numy = V2 * vsy + om * (bts * (4 * H * P[S0] * vsy * om + 4 * H * P[S2] * dc * om * om)
                            + fac * pi * P[S3] * dc * vsx * vsx + pi * b * P[S3] * ds * vsx * vsy)  # fmt: skip
    numm = 4 * P[BMS] * E * P[S2] * om**3 + pi * P[S3] * (
        (vsx * vsx + b * b * vsy * vsy) * om + V2 * (dc * vsy - b * ds * vsx)
    )
    Tx, Ty, Ms = numx / DT, numy / DT, numm / DM
    mu = P[MU]
    t0_, t1_, t2_ = -mu * (Tx * ex0 + Ty * ey0), -mu * (Tx * ex1 + Ty * ey1), -mu * (Tx * ex2 + Ty * ey2)
    ms0, ms1, ms2 = -mu * ah * Ms * n0, -mu * ah * Ms * n1, -mu * ah * Ms * n2
    f = ah * pi * P[S3]
    mr0, mr1, mr2 = f * (b * ds * ex0 - dc * ey0), f * (b * ds * ex1 - dc * ey1), f * (b * ds * ex2 - dc * ey2)
    # normal force (section 8)
    rxn0, rxn1, rxn2 = _cross(rho0, rho1, rho2, n0, n1, n2)
    Bw0 = B[0, 0] * w0 + B[0, 1] * w1 + B[0, 2] * w2
    Bw1 = B[1, 0] * w0 + B[1, 1] * w1 + B[1, 2] * w2
    Bw2 = B[2, 0] * w0 + B[2, 1] * w1 + B[2, 2] * w2
    g0, g1, g2 = _cross(w0, w1, w2, Bw0, Bw1, Bw2)
    h0 = Bi[0, 0] * g0 + Bi[0, 1] * g1 + Bi[0, 2] * g2
    h1 = Bi[1, 0] * g0 + Bi[1, 1] * g1 + Bi[1, 2] * g2
    h2 = Bi[2, 0] * g0 + Bi[2, 1] * g1 + Bi[2, 2] * g2
    wn0, wn1, wn2 = _cross(w0, w1, w2, n0, n1, n2)
    wrd0, wrd1, wrd2 = _cross(w0, w1, w2, rd0, rd1, rd2)
    cc = vA0 * n0 + vA1 * n1 + vA2 * n2
    num = (P[GRAV] + wr0 * wn0 + wr1 * wn1 + wr2 * wn2 - (wrd0 * n0 + wrd1 * n1 + wrd2 * n2)
           + rxn0 * h0 + rxn1 * h1 + rxn2 * h2 - P[KAPPA] * cc)  # fmt: skip
    l0, l1, l2 = _cross(rho0, rho1, rho2, n0 + t0_, n1 + t1_, n2 + t2_)
    l0, l1, l2 = l0 + ms0 + mr0, l1 + ms1 + mr1, l2 + ms2 + mr2
    k0 = Bi[0, 0] * l0 + Bi[0, 1] * l1 + Bi[0, 2] * l2
    k1 = Bi[1, 0] * l0 + Bi[1, 1] * l1 + Bi[1, 2] * l2
    k2 = Bi[2, 0] * l0 + Bi[2, 1] * l1 + Bi[2, 2] * l2
    den = 1.0 / P[M] + rxn0 * k0 + rxn1 * k1 + rxn2 * k2
    N = num / den
    # Newton-Euler (eq. 1)
    F0, F1, F2 = N * (n0 + t0_), N * (n1 + t1_), N * (n2 + t2_)
    wv0, wv1, wv2 = _cross(w0, w1, w2, v0, v1, v2)
    out[0] = -wv0 - P[GRAV] * n0 + F0 / P[M]
    out[1] = -wv1 - P[GRAV] * n1 + F1 / P[M]
    out[2] = -wv2 - P[GRAV] * n2 + F2 / P[M]
    tq0, tq1, tq2 = _cross(rho0, rho1, rho2, F0, F1, F2)
    tq0, tq1, tq2 = tq0 + N * (ms0 + mr0) - g0, tq1 + N * (ms1 + mr1) - g1, tq2 + N * (ms2 + mr2) - g2
    out[3] = Bi[0, 0] * tq0 + Bi[0, 1] * tq1 + Bi[0, 2] * tq2
    out[4] = Bi[1, 0] * tq0 + Bi[1, 1] * tq1 + Bi[1, 2] * tq2
    out[5] = Bi[2, 0] * tq0 + Bi[2, 1] * tq1 + Bi[2, 2] * tq2
    out[6], out[7], out[8] = nd0, nd1, nd2
    out[9] = E10 * v0 + E11 * v1 + E12 * v2
    out[10] = E20 * v0 + E21 * v1 + E22 * v2
    out[11] = n0 * v0 + n1 * v1 + n2 * v2
    out[12] = (w0 * n0 + w2 * n2) / (1.0 - n1 * n1)


# Dormand-Prince 5(4) tableau
_C = np.array([0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1])
_A = np.zeros((7, 7))
_A[1, :1] = [1 / 5]
_A[2, :2] = [3 / 40, 9 / 40]
_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_A[6, :6] = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_B5 = _A[6].copy()
_E = _B5 - np.array([5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])


@nb.njit(cache=True, error_model="numpy")
def _dopri_lane(y0, t0, ts, P, B, Bi, rtol, atol, max_steps, out_ys, C, A, B5, E, stop_invalid=False):
    """Integrate one lane, stepping exactly onto each ts[j]; returns (steps, rhs_evals, status).

    ``stop_invalid``: end the lane (status 2) at the first accepted step whose end state has
    N <= 0 (lift-off) or n3 <= 0, as ``jaxcelt``'s ``stop_on_invalid`` does. Integrated on, a lane past
    validity ends (status 4) where the stone lies on its side, 1 - n2^2 < ``HEADING_GAP``, as jaxcelt's
    lanes do. N comes free from
    the FSAL derivative: the normal projection of m (v_dot + w x v) = -m g n + N (n + t) with
    t . n = 0 gives N = m ((v_dot + w x v) . n + g).
    """
    n = 13
    y = y0.copy()
    K = np.empty((7, n))
    yt = np.empty(n)
    t = t0
    rhs(t, y, P, B, Bi, K[0])
    evals = 1
    # initial step: Hairer's heuristic (cheap version)
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = atol + rtol * abs(y[i])
        d0 += (y[i] / sc) ** 2
        d1 += (K[0, i] / sc) ** 2
    d0, d1 = math.sqrt(d0 / n), math.sqrt(d1 / n)
    h = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    j = 0
    steps = 0
    past = False  # the lane has left the model's validity (N <= 0 or n3 <= 0 at an accepted step)
    while j < ts.shape[0]:
        if steps >= max_steps:
            return steps, evals, 1
        tn = ts[j]
        hit = t + h >= tn
        hh = tn - t if hit else h
        for s in range(1, 7):
            for i in range(n):
                acc = y[i]
                for r in range(s):
                    acc += hh * A[s, r] * K[r, i]
                yt[i] = acc
            rhs(t + C[s] * hh, yt, P, B, Bi, K[s])
        evals += 6
        err = 0.0
        for i in range(n):
            e = 0.0
            for r in range(7):
                e += hh * E[r] * K[r, i]
            sc = atol + rtol * max(abs(y[i]), abs(yt[i]))
            err += (e / sc) ** 2
        err = math.sqrt(err / n)
        steps += 1
        if err != err:
            return steps, evals, 3  # NaN/inf state (an invalid lane integrated on into a singularity)
        if err <= 1.0:
            t = tn if hit else t + hh
            for i in range(n):
                y[i] = yt[i]
                K[0, i] = K[6, i]  # FSAL
            if hit:
                out_ys[j] = y
                j += 1
            c0, c1, c2 = _cross(y[3], y[4], y[5], y[0], y[1], y[2])
            N = P[M] * ((K[0, 0] + c0) * y[6] + (K[0, 1] + c1) * y[7] + (K[0, 2] + c2) * y[8] + P[GRAV])
            if N <= 0.0 or y[8] <= 0.0:
                if stop_invalid:
                    return steps, evals, 2
                past = True
            if past and 1.0 - y[7] * y[7] < HEADING_GAP:
                return steps, evals, 4  # on its side past validity (jaxcelt.integrate.solve.HEADING_GAP)
        fac = 10.0 if err == 0 else min(10.0, max(0.2, 0.9 * err ** (-1 / 5)))
        h = hh * fac
        if err > 1.0 and h < 10.0 * (np.nextafter(t, np.inf) - t):
            return steps, evals, 3  # step size collapsed (scipy's rule, as jaxcelt.integrate.solve.MIN_STEP_ULPS)
    return steps, evals, 0


@nb.njit(parallel=True, cache=True)
def dopri_ensemble(Y0, TS, PP, B, Bi, rtol, atol, max_steps, stop_invalid=False):
    """All lanes (prange over lanes): Y0 (L, 13), TS (L, S), PP (L, NP) -> (ys (L, S, 13), steps, evals, status)."""
    L, S = TS.shape
    ys = np.full((L, S, 13), np.inf)
    steps = np.zeros(L, np.int64)
    evals = np.zeros(L, np.int64)
    status = np.zeros(L, np.int64)
    for k in nb.prange(L):
        s, e, st = _dopri_lane(
            Y0[k], 0.0, TS[k], PP[k], B, Bi, rtol, atol, max_steps, ys[k], _C, _A, _B5, _E, stop_invalid
        )
        steps[k], evals[k], status[k] = s, e, st
    return ys, steps, evals, status


@nb.njit(cache=True)
def rhs_loop(y, P, B, Bi, n):
    """n RHS evaluations (per-RHS cost measurement)."""
    out = np.empty(13)
    acc = 0.0
    for i in range(n):
        rhs(0.1 + i * 1e-9, y, P, B, Bi, out)
        acc += out[3]
    return acc


# --------------------------------------------------------------------------------------------
# f(t, y) wrappers for scipy, and the agreement check against jaxcelt


def _scipy_f(kernel, p):
    """``f(t, y) -> dy/dt`` over ``kernel(t, y, P, B, Bi, out)`` (a fresh array per call, as scipy expects)."""
    P, B, Bi = pack(p)

    def f(t, y):
        out = np.empty(13)
        kernel(float(t), np.ascontiguousarray(y, dtype=np.float64), P, B, Bi, out)
        return out

    return f


def numba_rhs(p):
    """``f(t, y) -> dy/dt`` over the compiled `rhs`."""
    return _scipy_f(rhs, p)


def _interpreted(fn, **globals_):
    import types

    g = dict(fn.py_func.__globals__)
    g.update(globals_)
    return types.FunctionType(fn.py_func.__code__, g, fn.py_func.__name__ + "_py")


_rhs_py = _interpreted(rhs, _cross=_cross.py_func)


def python_rhs(p):
    """``f(t, y) -> dy/dt``: the source of `rhs` run by the Python interpreter (nothing compiled)."""
    return _scipy_f(_rhs_py, p)


def ensemble(Y0, ts, p, rtol, atol, max_steps=10**7):
    """`dopri_ensemble` for one parameter set and common sample times ``ts`` (ts[0] = 0 = start time).

    Returns (ys (L, len(ts), 13) with ys[:, 0] = Y0, steps (L,), evals (L,), status (L,)).
    """
    P, B, Bi = pack(p)
    Y0 = np.ascontiguousarray(Y0, dtype=np.float64)
    L = Y0.shape[0]
    ts = np.asarray(ts, dtype=np.float64)
    if ts[0] != 0.0:
        raise ValueError(f"ts[0] must be 0 (the start time), got {ts[0]}")
    TS = np.ascontiguousarray(np.broadcast_to(ts[1:], (L, ts.size - 1)))
    PP = np.ascontiguousarray(np.broadcast_to(P, (L, NP)))
    ys, steps, evals, status = dopri_ensemble(Y0, TS, PP, B, Bi, rtol, atol, max_steps)
    return np.concatenate([Y0[:, None], ys], axis=1), steps, evals, status


def check_against_jax(p, n_samples: int = 20, seed: int = 0, interpreted: bool = False) -> float:
    """Max relative difference (max-abs over the 13 components / max |f_jax|) between this port and
    `jaxcelt.vector_field` at random tilted, spinning, sliding states and random times."""
    import jaxcelt as jc

    rng = np.random.default_rng(seed)
    f = python_rhs(p) if interpreted else numba_rhs(p)
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
