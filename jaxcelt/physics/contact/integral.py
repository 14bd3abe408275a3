"""The exact integral Coulomb-Contensou law over the elliptic patch (eqs. 7-9, 11), by quadrature.

Over the unit ellipse F = {x^2 + y^2/b^2 <= 1} (lengths in units of the major semi-axis a_hat)
with pressure sigma = b^-1 sigma0(rho) (1 + d_c x + b^-1 d_s y), rho = sqrt(x^2 + y^2/b^2)
(eq. 9), and local slip u = (v_sx - w y, v_sy + w x) (w = omega_s):

    T_sx = int_F sigma u_x/|u|,   T_sy = int_F sigma u_y/|u|,   M_s = int_F sigma (x u_y - y u_x)/|u|

(eq. 8; MODEL.md section 7). The integrand is discontinuous at the instantaneous centre of
sliding (ICS), x_c = -v_sy/w, y_c = v_sx/w, where u = 0; around it u/|u| depends on the
polar angle only. The quadrature therefore works in the scaled coordinates (x, eta = y/b),
where F is the unit disk, in polar coordinates centred at c = the ICS when it lies in the
patch (else its radial projection onto the rim). Every ray from c leaves the disk at
R(phi) = -c.d + sqrt((c.d)^2 + 1 - |c|^2), so the grid covers F exactly. Angles are split at
the two tangent directions of c (where R changes fast when c is near the rim) and at
phi = +-pi/2 (where u/|u| turns fast on a thin ellipse), each arc with Gauss-Legendre nodes;
radially r = R (1 - s^2)^2 with Gauss-Legendre in s, which makes the Hertz edge
sqrt(1 - rho^2) smooth in s and clusters nodes at the ICS. Convergence is spectral
(see `tests/test_integral_law.py` and ``docs/contact``).

Everything is static except the kinematics and the parameters: the law is a hashable
`equinox.Module`, usable as ``contact_law=`` in `jaxcelt.simulate`, under vmap and grad.
"""

from __future__ import annotations

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._types import Array, Scalar, ScalarLike
from jaxcelt.physics.contact.laws import AbstractContactLaw, ContactKinematics, ContactLoads
from jaxcelt.physics.params import CeltParams

__all__ = [
    "AbstractPressureProfile",
    "HertzProfile",
    "UniformProfile",
    "CustomProfile",
    "IntegralLaw",
    "patch_integrals",
    "profile_moments",
    "HERTZ_S",
]

HERTZ_S = {"S0": 3 / 8, "S1": 1 / (2 * np.pi), "S2": 3 / 32, "S3": 1 / (5 * np.pi)}
"""Moments S_i = int_0^1 sigma0 rho^i d rho of the Hertz profile (MODEL.md section 7)."""


def _safe_sqrt(x: Array) -> Array:
    # sqrt with zero value and zero gradient for x <= 0 (Hertz edge, tangent rays).
    pos = x > 0
    return jnp.where(pos, jnp.sqrt(jnp.where(pos, x, 1.0)), 0.0)


class AbstractPressureProfile(eqx.Module):
    """Radial pressure profile sigma0(rho) on the unit disk, normalised 2 pi S1 = 1 (eq. 9)."""

    def __call__(self, rho: Array) -> Array:
        """sigma0 at scaled radius rho in [0, 1] (any shape), normalised."""
        return self.raw(rho) / self.norm()

    def raw(self, rho: Array) -> Array:
        raise NotImplementedError

    def norm(self) -> float:
        """2 pi int_0^1 raw(rho) rho d rho (1 for a normalised profile)."""
        with jax.ensure_compile_time_eval():  # a constant, also while an outer jit traces
            return float(2 * np.pi * _moment(self.raw, 1))


def _moment(fn: Callable, i: int, n: int = 64) -> Array:
    # rho = 1 - t^2 puts a sqrt edge singularity of fn at t = 0 into a smooth integrand.
    t, w = np.polynomial.legendre.leggauss(n)
    t, w = 0.5 * (t + 1), 0.5 * w
    rho = 1 - t**2
    return jnp.sum(w * 2 * t * fn(jnp.asarray(rho)) * rho**i)


def profile_moments(profile: AbstractPressureProfile) -> dict[str, Array]:
    """S0..S3 of a profile (eq. 9): S_i = int_0^1 sigma0(rho) rho^i d rho (dimensionless)."""
    return {f"S{i}": _moment(profile, i) for i in range(4)}


class HertzProfile(AbstractPressureProfile):
    """Hertz: sigma0 = 3/(2 pi) sqrt(1 - rho^2); S0..S3 = 3/8, 1/(2 pi), 3/32, 1/(5 pi)."""

    def raw(self, rho):
        return 3 / (2 * np.pi) * _safe_sqrt(1 - rho**2)

    def norm(self):
        return 1.0


class UniformProfile(AbstractPressureProfile):
    """Uniform pressure sigma0 = 1/pi; S_i = 1/(pi (i + 1))."""

    def raw(self, rho):
        return jnp.full_like(rho, 1 / np.pi)

    def norm(self):
        return 1.0


class CustomProfile(AbstractPressureProfile):
    """User-supplied sigma0: a jnp-traceable callable ``fn(rho) -> >= 0`` on [0, 1].

    Normalised automatically to 2 pi S1 = 1. The callable is a static field (it must be
    hashable, e.g. a module-level function), so the law stays a jit-static object.
    """

    fn: Callable = eqx.field(static=True)

    def raw(self, rho):
        return self.fn(rho)


def _gl(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return x, w


def patch_integrals(
    vsx: ScalarLike,
    vsy: ScalarLike,
    omega_s: ScalarLike,
    b: ScalarLike,
    d_c: ScalarLike = 0.0,
    d_s: ScalarLike = 0.0,
    *,
    profile: AbstractPressureProfile | None = None,
    eps: ScalarLike = 0.0,
    n_angle: int = 32,
    n_radial: int = 16,
) -> tuple[Scalar, Scalar, Scalar]:
    """(T_sx, T_sy, M_s) of the integral law (eq. 8) for one sample, by polar quadrature at the ICS.

    Args:
        vsx, vsy, omega_s: slip and spin, non-dimensional by a_hat [1/s].
        b: axis ratio of the patch (0, 1].
        d_c, d_s: rolling-resistance distortion of the pressure (eq. 9-10).
        profile: sigma0 (default Hertz).
        eps: smoothing [1/s^2]: |u| -> sqrt(|u|^2 + eps) (0 = the exact law, as eq. 15 does for V).
        n_angle: Gauss nodes per angular arc (4 arcs); n_radial: nodes per ray.

    Returns non-dimensional scalars. Differentiable everywhere except exactly at
    v_s = 0 = omega_s with eps = 0 (where the law itself is undefined).
    """
    profile = HertzProfile() if profile is None else profile
    vsx, vsy, w, b = (jnp.asarray(a, dtype=float) for a in (vsx, vsy, omega_s, b))
    # ICS in scaled coordinates: P / w with P = (-v_sy, v_sx / b); clamp into the unit disk.
    Px, Py = -vsy, vsx / b
    P2 = Px**2 + Py**2
    Pn = _safe_sqrt(P2)
    aw = jnp.abs(w)
    den = jnp.maximum(w * w, Pn * aw)
    # At v_s = 0 = omega_s the centre is arbitrary: take 0 with a double where, so that
    # gradients stay finite there (den -> 0).
    ok = den > 1e-150
    den = jnp.where(ok, den, 1.0)
    cx = jnp.where(ok, Px * w / den, 0.0)
    cy = jnp.where(ok, Py * w / den, 0.0)
    c2 = jnp.minimum(cx**2 + cy**2, 1.0)
    # Angular breakpoints: tangent directions of c (phi_c +- pi/2) and the eta axis (+-pi/2).
    is0 = c2 == 0
    phi_c = jnp.arctan2(jnp.where(is0, 0.0, cy), jnp.where(is0, 1.0, cx))
    brk = jnp.mod(jnp.stack([phi_c + np.pi / 2, phi_c - np.pi / 2, np.pi / 2, -np.pi / 2]), 2 * np.pi)
    brk = jnp.sort(brk)
    lo = brk
    hi = jnp.concatenate([brk[1:], brk[:1] + 2 * np.pi])
    ta, wa = _gl(n_angle)
    half = 0.5 * (hi - lo)
    phi = (0.5 * (hi + lo))[:, None] + half[:, None] * ta[None, :]  # (4, n_angle)
    wphi = half[:, None] * wa[None, :]
    phi, wphi = phi.reshape(-1), wphi.reshape(-1)
    dx, dy = jnp.cos(phi), jnp.sin(phi)
    cd = cx * dx + cy * dy
    R = -cd + _safe_sqrt(cd**2 + 1.0 - c2)  # (n_phi,)
    # Radial map r = R (1 - s^2)^2, s in (0, 1): dr = 4 R s (1 - s^2) ds.
    ts, ws = _gl(n_radial)
    s = 0.5 * (ts + 1)
    ws = 0.5 * ws
    g = (1 - s**2) ** 2
    jac = 4 * s * (1 - s**2)
    r = R[:, None] * g[None, :]  # (n_phi, n_s)
    x = cx + r * dx[:, None]
    eta = cy + r * dy[:, None]
    y = b * eta
    rho = _safe_sqrt(x**2 + eta**2)
    ux = vsx - w * y
    uy = vsy + w * x
    nu2 = ux**2 + uy**2 + eps
    inv = jnp.where(nu2 > 0, 1 / _safe_sqrt(jnp.where(nu2 > 0, nu2, 1.0)), 0.0)
    sig = profile(jnp.minimum(rho, 1.0)) * (1 + d_c * x + d_s * eta)
    # dx dy = b dx d eta and sigma = b^-1 sigma0 (...): the b's cancel; polar area r dr dphi.
    wt = wphi[:, None] * (ws * jac)[None, :] * R[:, None] * r * sig * inv
    Tx = jnp.sum(wt * ux)
    Ty = jnp.sum(wt * uy)
    M = jnp.sum(wt * (x * uy - y * ux))
    return Tx, Ty, M


class IntegralLaw(AbstractContactLaw):
    """The exact integral law (eqs. 7-9, 11) by quadrature: the reference for every approximant.

    Static fields: ``profile`` (sigma0; default Hertz), ``n_angle`` and ``n_radial``
    (quadrature size; 4 * n_angle * n_radial nodes), ``smoothing`` (True: |u| ->
    sqrt(|u|^2 + p.eps), the analogue of eq. 15, needed for time integration through sticking;
    False: the exact law), ``rolling_resistance``.

    The S_i of the rolling-resistance torque (eq. 11) are the profile's moments, not
    ``p.S0..S3`` (which the paper fitted; MODEL.md section 9 A10). ``p.b`` is the axis ratio.
    """

    profile: AbstractPressureProfile = eqx.field(default_factory=HertzProfile, static=True)
    n_angle: int = eqx.field(default=24, static=True)
    n_radial: int = eqx.field(default=12, static=True)
    smoothing: bool = eqx.field(default=True, static=True)
    rolling_resistance: bool = eqx.field(default=True, static=True)

    def __check_init__(self):
        if self.n_angle < 2 or self.n_radial < 2:
            raise ValueError(f"IntegralLaw: n_angle, n_radial must be >= 2, got {self.n_angle}, {self.n_radial}")

    def friction(self, kin: ContactKinematics, d_c, d_s, p: CeltParams):
        return patch_integrals(
            kin.vsx,
            kin.vsy,
            kin.omega_s,
            p.b,
            d_c,
            d_s,
            profile=self.profile,
            eps=p.eps if self.smoothing else 0.0,
            n_angle=self.n_angle,
            n_radial=self.n_radial,
        )

    def loads(self, kin, e_x, e_y, n, p) -> ContactLoads:
        """As the base class, with S3 of eq. (11) taken from the profile."""
        S3 = profile_moments(self.profile)["S3"]
        return super().loads(kin, e_x, e_y, n, eqx.tree_at(lambda q: q.S3, p, jnp.asarray(S3, dtype=float)))


def integral_law_batch(law: IntegralLaw, vsx, vsy, omega_s, b, d_c=0.0, d_s=0.0, eps=0.0):
    """vmapped `patch_integrals` over broadcast 1-D inputs (convenience for maps and fits)."""
    args = jnp.broadcast_arrays(*(jnp.asarray(a, dtype=float) for a in (vsx, vsy, omega_s, d_c, d_s)))
    f = lambda a, b_, c, d, e: patch_integrals(
        a, b_, c, b, d, e, profile=law.profile, eps=eps, n_angle=law.n_angle, n_radial=law.n_radial
    )
    shape = args[0].shape
    out = jax.vmap(f)(*(a.reshape(-1) for a in args))
    return tuple(o.reshape(shape) for o in out)
