"""Contact laws: friction force, spin torque and rolling resistance per unit normal force.

A contact law maps the non-dimensional contact kinematics of the elliptic patch
(slip v_s = (v_A - v_pi)/a_hat in patch axes, spin omega_s = omega . n, rolling velocity
v_r = v_s + r_dot/a_hat; MODEL.md section 6) to the loads per unit N (MODEL.md section 7):

    t   = -mu (T_sx e_x + T_sy e_y)             friction force / N, acting at A
    m_s = -mu a_hat M_s n                       spin (drilling) torque / N
    m_r = a_hat pi S3 (b d_s e_x - d_c e_y)     rolling-resistance torque / N   (eq. 11)

Every law is an `AbstractContactLaw` (equinox's abstract/final pattern); concrete laws
implement `friction` (the non-dimensional T_sx, T_sy, M_s) and inherit the rest. Laws are
chosen by object or by name through `get_contact_law` (unknown names are rejected).
Discrete options (rolling resistance on/off, quadrature order) are static fields.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
from collections.abc import Callable
from typing import NamedTuple

import equinox as eqx
import jax.numpy as jnp

from jaxcelt import _math
from jaxcelt._types import Array, Scalar, ScalarLike
from jaxcelt.physics.contact.elliptic import contact_integrals
from jaxcelt.physics.params import CeltParams

__all__ = [
    "AbstractContactLaw",
    "ContactKinematics",
    "ContactLoads",
    "GeneralisedPade",
    "Pade",
    "CoulombSpin",
    "Coulomb",
    "pade_friction",
    "safe_abs_pow",
]


class ContactKinematics(NamedTuple):
    """Non-dimensional contact kinematics in the patch frame (MODEL.md section 6), [1/s]."""

    vsx: Scalar
    vsy: Scalar
    omega_s: Scalar
    vrx: Scalar
    vry: Scalar


class ContactLoads(NamedTuple):
    """Loads per unit normal force, body components (MODEL.md section 7).

    ``t`` [-] friction force, ``m_s`` [m] spin torque, ``m_r`` [m] rolling-resistance torque;
    ``T_sx, T_sy, M_s, d_c, d_s`` are the non-dimensional intermediate quantities.
    """

    t: Array
    m_s: Array
    m_r: Array
    T_sx: Scalar
    T_sy: Scalar
    M_s: Scalar
    d_c: Scalar
    d_s: Scalar


def safe_abs_pow(x: Array, p: Array) -> Array:
    """|x|**p with finite gradients at x = 0 in both x and p (needs p > 1 for d/dx).

    ``jnp.abs(x)**p`` has d/dp = |x|^p log|x| = 0 * -inf = NaN at x = 0; masking the base
    (jax_md's ``safe_mask`` idea) keeps value and both gradients at their limits (0).
    """
    ax = jnp.abs(x)
    pos = ax > 0
    return jnp.where(pos, jnp.where(pos, ax, 1.0) ** p, 0.0)


def _safe_log_abs(x: Array, log: Callable[[Array], Array] = jnp.log) -> tuple[Array, Array]:
    """(log|x| where x != 0 else 0, x != 0): with `_exp_or_0`, |x|**p = exp(p log|x|) with
    the value and both gradients of `safe_abs_pow` at x = 0 (the masked base, as there)."""
    pos = jnp.abs(x) > 0
    return log(jnp.where(pos, jnp.abs(x), 1.0)), pos


def _denominator_log(vector_log: bool) -> Callable[[Array], Array]:
    """The Pade laws' logarithm: `jaxcelt._math.log` in their ``wide_batch`` form, else ``jnp.log``.

    The vectorised one without its special-value handling (``normal=True``): its arguments here are
    1 + b^m x^m >= 1 and |w| / V where w != 0. A subnormal |w| / V (where a backend keeps
    subnormals at all) would get a wrong logarithm, but (|w| / V)^(3m) is 0 in float64 either way; a
    non-finite state still gives non-finite loads, through the numerators."""
    return functools.partial(_math.log, normal=True) if vector_log else jnp.log


def _exp_or_0(a: Array, pos: Array) -> Array:
    return jnp.where(pos, jnp.exp(a), 0.0)


class AbstractContactLaw(eqx.Module):
    """Interface of a contact law. Subclasses implement `friction`.

    ``rolling_resistance`` (static) switches the rolling-resistance distortion d_c, d_s of the
    pressure (eqs. 10, 15) and the torque m_r (eq. 11) on or off.
    """

    rolling_resistance: eqx.AbstractVar[bool]

    def wide_batch(self) -> AbstractContactLaw:
        """The same law, computed the way that pays in wide vmapped batches on a CPU (the lane
        pool's wide pools use it); by default the law itself. Values agree to rounding."""
        return self

    @abc.abstractmethod
    def friction(
        self, kin: ContactKinematics, d_c: Scalar, d_s: Scalar, p: CeltParams
    ) -> tuple[Scalar, Scalar, Scalar]:
        """Non-dimensional (T_sx, T_sy, M_s) of eq. (8) or its approximant."""

    def rolling_distortion(self, kin: ContactKinematics, p: CeltParams) -> tuple[Scalar, Scalar]:
        """Pressure distortion (d_c, d_s), eqs. (10) and (15) with smoothing eps_R.

        D_R = sqrt(v_rx^2 + (b b_r)^-2 v_ry^2 + eps_R), d_c = k_r v_rx / D_R,
        d_s = k_r v_ry / (b D_R) (MODEL.md section 9 A8). Zero when rolling resistance is off.
        """
        if not self.rolling_resistance:
            z = jnp.zeros_like(kin.vrx)
            return z, z
        # one division per lane (1/D_R); the lane-constant ones are computed once in a sweep
        inv_D_R = 1.0 / jnp.sqrt(kin.vrx**2 + kin.vry**2 * (1.0 / (p.b * p.b_r)) ** 2 + p.eps_R)
        return (p.k_r * inv_D_R) * kin.vrx, (p.k_r / p.b) * inv_D_R * kin.vry

    def loads(self, kin: ContactKinematics, e_x: Array, e_y: Array, n: Array, p: CeltParams) -> ContactLoads:
        """Loads per unit N in body components (eqs. 7 and 11 with signs restored)."""
        d_c, d_s = self.rolling_distortion(kin, p)
        T_sx, T_sy, M_s = self.friction(kin, d_c, d_s, p)
        t = -p.mu * (T_sx * e_x + T_sy * e_y)
        m_s = -p.mu * p.a_hat * M_s * n
        if self.rolling_resistance:
            m_r = p.a_hat * jnp.pi * p.S3 * (p.b * d_s * e_x - d_c * e_y)
        else:
            m_r = jnp.zeros_like(e_x)
        return ContactLoads(t, m_s, m_r, T_sx, T_sy, M_s, d_c, d_s)


class GeneralisedPade(AbstractContactLaw):
    """The paper's generalised Pade approximant of the integral law (eqs. 13-15).

    With V = sqrt(v_sx^2 + v_sy^2 + eps) (eq. 15), omega_s signed in numerators and |omega_s|
    only in denominators (MODEL.md section 7):

        D_T = (V^(3 m_Ts) + b_Ts^m_Ts |w|^(3 m_Ts))^(1/m_Ts)
        D_M = (b_Ms^m_Ms |w|^(3 m_Ms) + V^(3 m_Ms))^(1/m_Ms)
        T_sx = {V^2 v_sx + w [b_Ts(4 G S0 v_sx w - b d_s (pi S3 v_sy^2 + 4 G S2 w^2)) - pi S3 d_c v_sx v_sy]} / D_T
        T_sy = {V^2 v_sy + w [b_Ts(4 H S0 v_sy w + d_c (pi S3 v_sx^2 + 4 H S2 w^2)) + pi b S3 d_s v_sx v_sy]} / D_T
        M_s  = {4 b_Ms E S2 w^3 + pi S3 [(v_sx^2 + b^2 v_sy^2) w + V^2 (d_c v_sy - b d_s v_sx)]} / D_M

    ``params.derivative_exact = 1`` moves b_Ts off the pi S3 terms (MODEL.md section 9 A13a).
    ``m_Ts = m_Ms = 1`` is the classical Pade approximant (see `Pade`).
    """

    rolling_resistance: bool = eqx.field(default=True, static=True)
    vector_log: bool = eqx.field(default=False, static=True)
    """float64 logarithms of the denominators by `jaxcelt._math.log` (vector arithmetic) instead of
    ``jnp.log`` (XLA's CPU backend: one scalar libm call per element); see `wide_batch`."""

    def wide_batch(self) -> GeneralisedPade:
        """With ``vector_log``: faster in wide batches on a CPU, but its inlined polynomial makes
        XLA's compilation of a many-stage program about a second longer (docs/internals/sweep-engine.md)."""
        return dataclasses.replace(self, vector_log=True)

    def friction(self, kin, d_c, d_s, p):
        return pade_friction(kin, d_c, d_s, p, p.m_Ts, p.m_Ms, log=_denominator_log(self.vector_log))


def pade_friction(
    kin: ContactKinematics,
    d_c: Scalar,
    d_s: Scalar,
    p: CeltParams,
    m_T: ScalarLike,
    m_M: ScalarLike,
    log: Callable[[Array], Array] = jnp.log,
) -> tuple[Scalar, Scalar, Scalar]:
    """Eq. (13) with exponents (m_T, m_M) given explicitly (the shared kernel of the Pade laws).

    Non-dimensional (T_sx, T_sy, M_s); inputs in 1/s (MODEL.md section 7). ``log``: the natural
    logarithm used for the denominators' powers (``jnp.log`` or `jaxcelt._math.log`).
    """
    vsx, vsy, w = kin.vsx, kin.vsy, kin.omega_s
    _, E, G, H = contact_integrals(p.b)
    V2 = vsx**2 + vsy**2 + p.eps
    b, pi = p.b, jnp.pi
    # D_T = (V^(3 m_T) + b_Ts^m_T |w|^(3 m_T))^(1/m_T) = V^3 (1 + b_Ts^m_T x^m_T)^(1/m_T) with
    # x = (|w| / V)^3, D_M likewise. Their reciprocals are computed as V^-3 exp(-log(1 + b^m x^m) / m)
    # with x^m = exp(3 m log(|w| / V)): 3 logs and 4 exps, and 1/V (a reciprocal square root) the only
    # division (XLA's CPU pow costs ~14 ns per element against ~2 / ~4.4 ns for exp / log, and a
    # vectorised division costs as much as a dozen multiply-adds; `jaxcelt._math`).
    inv_V = 1.0 / jnp.sqrt(V2)
    inv_V3 = inv_V * inv_V * inv_V
    lr, w_pos = _safe_log_abs(w * inv_V, log)
    inv_D_T = inv_V3 * jnp.exp(-log(1.0 + p.b_Ts**m_T * _exp_or_0(3 * m_T * lr, w_pos)) * (1.0 / m_T))
    inv_D_M = inv_V3 * jnp.exp(-log(1.0 + p.b_Ms**m_M * _exp_or_0(3 * m_M * lr, w_pos)) * (1.0 / m_M))
    # Printed grouping: b_Ts multiplies the pi S3 terms that sit inside its bracket.
    # The derivative-exact grouping takes them out; blend by the 0/1 switch so that the
    # reading stays a float leaf (vmappable over readings).
    de = p.derivative_exact
    fac = p.b_Ts * (1 - de) + de
    num_x = V2 * vsx + w * (
        p.b_Ts * (4 * G * p.S0 * vsx * w - 4 * G * p.S2 * b * d_s * w**2)
        - fac * pi * p.S3 * b * d_s * vsy**2
        - pi * p.S3 * d_c * vsx * vsy
    )
    num_y = V2 * vsy + w * (
        p.b_Ts * (4 * H * p.S0 * vsy * w + 4 * H * p.S2 * d_c * w**2)
        + fac * pi * p.S3 * d_c * vsx**2
        + pi * b * p.S3 * d_s * vsx * vsy
    )
    num_m = 4 * p.b_Ms * E * p.S2 * w**3 + pi * p.S3 * ((vsx**2 + b**2 * vsy**2) * w + V2 * (d_c * vsy - b * d_s * vsx))
    return num_x * inv_D_T, num_y * inv_D_T, num_m * inv_D_M


class Pade(AbstractContactLaw):
    """The Pade approximant of the earlier papers: eq. (13) with m_Ts = m_Ms = 1.

    D_T = V^3 + b_Ts |w|^3, D_M = b_Ms |w|^3 + V^3; numerators as in `GeneralisedPade`
    (including the ``derivative_exact`` reading switch). ``p.m_Ts, p.m_Ms`` are ignored.
    Satisfies the same exact value and slope limits as eq. (13) (MODEL.md section 7).
    """

    rolling_resistance: bool = eqx.field(default=True, static=True)
    vector_log: bool = eqx.field(default=False, static=True)
    """as `GeneralisedPade.vector_log`"""

    def wide_batch(self) -> Pade:
        """With ``vector_log`` (as `GeneralisedPade.wide_batch`)."""
        return dataclasses.replace(self, vector_log=True)

    def friction(self, kin, d_c, d_s, p):
        return pade_friction(kin, d_c, d_s, p, 1.0, 1.0, log=_denominator_log(self.vector_log))


class CoulombSpin(AbstractContactLaw):
    """Coulomb force and an uncoupled spin torque (no Contensou coupling).

    T = v_s / V with V = sqrt(v_sx^2 + v_sy^2 + eps) (eq. 15 smoothing), and
    M_s = 4 E S2 w / sqrt(w^2 + eps), the pure-spin value of the integral law (MODEL.md
    section 7) smoothed the same way. Force and torque do not influence each other, so a
    spinning stone slides as easily as a non-spinning one (the exact law says it slides more
    easily). Exact limits: pure sliding and pure spin; slopes at v_s = 0 are wrong (1/sqrt(eps)).
    With rolling resistance on, only the torque m_r (eq. 11) is added; d_c, d_s do not enter
    the friction.
    """

    rolling_resistance: bool = eqx.field(default=True, static=True)

    def friction(self, kin, d_c, d_s, p):
        _, E, _, _ = contact_integrals(p.b)
        V = jnp.sqrt(kin.vsx**2 + kin.vsy**2 + p.eps)
        M = 4 * E * p.S2 * kin.omega_s / jnp.sqrt(kin.omega_s**2 + p.eps)
        return kin.vsx / V, kin.vsy / V, M


class Coulomb(AbstractContactLaw):
    """Coulomb point contact: T = v_s / sqrt(|v_s|^2 + eps), no spin torque (M_s = 0).

    Exact only in the pure-sliding limit. Rolling resistance (eq. 11) optional as for all laws.
    """

    rolling_resistance: bool = eqx.field(default=True, static=True)

    def friction(self, kin, d_c, d_s, p):
        V = jnp.sqrt(kin.vsx**2 + kin.vsy**2 + p.eps)
        return kin.vsx / V, kin.vsy / V, jnp.zeros_like(kin.omega_s)
