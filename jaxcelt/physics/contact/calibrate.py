"""Calibration of the approximate contact laws against the integral law, and their error maps.

The integral law (eqs. 7-9) and every approximant are homogeneous of degree zero in
(v_s, omega_s) (without smoothing), so the slip-spin space is sampled on the unit circle
omega_s = sin(alpha), |v_s| = cos(alpha), alpha in [-pi/2, pi/2] (alpha = 0: pure sliding,
+-pi/2: pure spin), times the slip direction beta (v_sx, v_sy = |v_s| (cos beta, sin beta)),
times rolling states (d_c, d_s) = (k_r cos gamma, k_r b_r sin gamma) (the range of eq. 10)
and d = 0. Both sides are linear in (d_c, d_s), so the integral law is evaluated three times
per slip sample.

`calibrate` fits (b_Ts, b_Ms, m_Ts, m_Ms) and optionally (S0, S2, S3) of `GeneralisedPade`
or `Pade` by Levenberg-Marquardt (optimistix) on the residuals of (T_sx, T_sy, M_s): the
method by which the paper's constants were obtained from the integral model [24]. The
approximants are evaluated with eps = 1e-14 (the smoothing of eq. 15 off).
"""

from __future__ import annotations

from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from jaxcelt._types import Array
from jaxcelt.physics.contact.integral import HertzProfile, IntegralLaw, patch_integrals, profile_moments
from jaxcelt.physics.contact.laws import (
    AbstractContactLaw,
    ContactKinematics,
    Coulomb,
    CoulombSpin,
    GeneralisedPade,
    Pade,
    pade_friction,
)
from jaxcelt.physics.params import CeltParams

__all__ = [
    "SlipSamples",
    "slip_samples",
    "integral_reference",
    "approximant_values",
    "calibrate",
    "Calibration",
    "error_map",
]

FIT_NAMES = ("b_Ts", "b_Ms", "m_Ts", "m_Ms")
S_NAMES = ("S0", "S2", "S3")


class SlipSamples(NamedTuple):
    """Flat arrays (n,) of non-dimensional kinematics (MODEL.md section 6) and rolling state."""

    vsx: Array
    vsy: Array
    omega_s: Array
    d_c: Array
    d_s: Array


def slip_samples(
    n_alpha: int = 21, n_beta: int = 16, n_gamma: int = 4, k_r: float = 0.4345, b_r: float = 1.196
) -> SlipSamples:
    """Grid over (alpha, beta) x rolling states {0} + n_gamma directions (module docstring)."""
    alpha = np.linspace(-np.pi / 2, np.pi / 2, n_alpha)
    beta = np.linspace(0, 2 * np.pi, n_beta, endpoint=False) + np.pi / n_beta / 2
    gamma = np.linspace(0, 2 * np.pi, n_gamma, endpoint=False) + 0.3
    dc = np.concatenate([[0.0], k_r * np.cos(gamma)])
    ds = np.concatenate([[0.0], k_r * b_r * np.sin(gamma)])
    A, Bt, D = np.meshgrid(alpha, beta, np.arange(len(dc)), indexing="ij")
    v = np.cos(A)
    return SlipSamples(*(jnp.asarray(a.reshape(-1)) for a in (v * np.cos(Bt), v * np.sin(Bt), np.sin(A), dc[D], ds[D])))


def integral_reference(s: SlipSamples, b: float, law: IntegralLaw | None = None) -> Array:
    """(n, 3) exact (T_sx, T_sy, M_s) at the samples (eq. 8, no smoothing), using linearity in d."""
    law = law or IntegralLaw(n_angle=32, n_radial=16)

    def one(vx, vy, w, dc, ds):
        f = lambda a, c: jnp.stack(
            patch_integrals(vx, vy, w, b, a, c, profile=law.profile, n_angle=law.n_angle, n_radial=law.n_radial)
        )
        f0 = f(0.0, 0.0)
        return f0 + dc * (f(1.0, 0.0) - f0) + ds * (f(0.0, 1.0) - f0)

    return jax.jit(jax.vmap(one))(*s)


def approximant_values(law: AbstractContactLaw, s: SlipSamples, p: CeltParams) -> Array:
    """(n, 3) (T_sx, T_sy, M_s) of a law's ``friction`` at the samples (eps taken from p)."""

    def one(vx, vy, w, dc, ds):
        kin = ContactKinematics(vx, vy, w, vx, vy)
        return jnp.stack(law.friction(kin, dc, ds, p))

    return jax.vmap(one)(*s)


class Calibration(NamedTuple):
    """Fit result: ``values`` (fitted constants by name), RMS/max error of the fit over the
    samples (all three components pooled) and per component, and the same for the start."""

    law: str
    values: dict
    rms: float
    max_err: float
    rms_by_component: tuple
    rms_start: float
    max_err_start: float
    steps: int


def _with(p: CeltParams, **kw) -> CeltParams:
    names = tuple(kw)
    return eqx.tree_at(
        lambda q: tuple(getattr(q, k) for k in names), p, tuple(jnp.asarray(v, dtype=float) for v in kw.values())
    )


def calibrate(
    law: str = "generalised_pade",
    *,
    b: float = 0.1813,
    profile=None,
    fit_S: bool = False,
    start: CeltParams | None = None,
    samples: SlipSamples | None = None,
    reference: Array | None = None,
    max_steps: int = 200,
) -> Calibration:
    """Least-squares fit of an approximant's constants to the integral law for sigma0 and b.

    Args:
        law: ``"generalised_pade"`` (fits b_Ts, b_Ms, m_Ts, m_Ms) or ``"pade"`` (b_Ts, b_Ms).
        b: axis ratio of the patch.
        profile: sigma0 (default Hertz); the S_i start from its moments (MODEL.md A10).
        fit_S: also fit S0, S2, S3 (the paper fitted them; with the profile's own S_i the
            approximants satisfy the exact limits of MODEL.md section 7).
        start: parameters to start from (default the paper's constants with the profile's S_i).
    """
    profile = profile or HertzProfile()
    if law not in ("generalised_pade", "pade"):
        raise ValueError(f"calibrate: law must be 'generalised_pade' or 'pade', got {law!r}")
    S = {k: float(v) for k, v in profile_moments(profile).items() if k != "S1"}
    p0 = start if start is not None else CeltParams.paper(b=b, **S)
    p0 = _with(p0, eps=1e-14, b=b)
    s = samples if samples is not None else slip_samples()
    ref = (
        reference
        if reference is not None
        else integral_reference(s, b, IntegralLaw(profile=profile, n_angle=32, n_radial=16))
    )
    names = list(FIT_NAMES if law == "generalised_pade" else FIT_NAMES[:2]) + (list(S_NAMES) if fit_S else [])
    theta0 = jnp.log(jnp.asarray([float(getattr(p0, k)) for k in names]))
    exps = (lambda q: (q.m_Ts, q.m_Ms)) if law == "generalised_pade" else (lambda q: (1.0, 1.0))

    def residual(theta, _):
        q = _with(p0, **dict(zip(names, jnp.exp(theta))))
        mT, mM = exps(q)

        def one(vx, vy, w, dc, ds):
            kin = ContactKinematics(vx, vy, w, vx, vy)
            return jnp.stack(pade_friction(kin, dc, ds, q, mT, mM))

        return (jax.vmap(one)(*s) - ref).reshape(-1)

    r0 = residual(theta0, None)
    sol = optx.least_squares(
        residual, optx.LevenbergMarquardt(rtol=1e-10, atol=1e-12), theta0, max_steps=max_steps, throw=False
    )
    r = residual(sol.value, None).reshape(-1, 3)
    return Calibration(
        law=law,
        values={k: float(v) for k, v in zip(names, np.exp(np.asarray(sol.value)))} | ({} if fit_S else S),
        rms=float(jnp.sqrt(jnp.mean(r**2))),
        max_err=float(jnp.max(jnp.abs(r))),
        rms_by_component=tuple(float(x) for x in jnp.sqrt(jnp.mean(r**2, axis=0))),
        rms_start=float(jnp.sqrt(jnp.mean(r0**2))),
        max_err_start=float(jnp.max(jnp.abs(r0))),
        steps=int(sol.stats["num_steps"]),
    )


def error_map(
    law: AbstractContactLaw,
    p: CeltParams,
    *,
    n_alpha: int = 61,
    n_beta: int = 48,
    d: tuple[float, float] = (0.0, 0.0),
    reference_law: IntegralLaw | None = None,
) -> dict:
    """Error of a law against the integral law over the slip-spin plane at a rolling state.

    Returns a dict with ``alpha`` (n_alpha,), ``beta`` (n_beta,), ``exact`` and ``approx``
    (n_alpha, n_beta, 3) and ``err`` = |approx - exact| (Euclidean over T_sx, T_sy, M_s), for
    the axis ratio ``p.b``; the law is evaluated with ``p`` (set eps small for the bare law).
    """
    alpha = np.linspace(-np.pi / 2, np.pi / 2, n_alpha)
    beta = np.linspace(0, 2 * np.pi, n_beta)
    A, Bt = np.meshgrid(alpha, beta, indexing="ij")
    v = np.cos(A)
    shape = A.shape
    s = SlipSamples(
        *(
            jnp.asarray(x.reshape(-1))
            for x in (v * np.cos(Bt), v * np.sin(Bt), np.sin(A), np.full(A.size, d[0]), np.full(A.size, d[1]))
        )
    )
    ref_law = reference_law or IntegralLaw(n_angle=32, n_radial=16)
    exact = integral_reference(s, float(p.b), ref_law).reshape(*shape, 3)
    approx = approximant_values(law, s, p).reshape(*shape, 3)
    return {
        "alpha": alpha,
        "beta": beta,
        "exact": np.asarray(exact),
        "approx": np.asarray(approx),
        "err": np.linalg.norm(np.asarray(approx - exact), axis=-1),
    }


APPROXIMANTS = {
    "generalised_pade": GeneralisedPade,
    "pade": Pade,
    "coulomb_spin": CoulombSpin,
    "coulomb": Coulomb,
}
