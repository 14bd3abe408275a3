"""The wobblestone on a vibrating base: the pure right-hand side, built from small stages.

Stages (each a pure function of one sample; batch with ``jax.vmap``), MODEL.md sections:

1. `contact_geometry`  -- contact point r(n) and its rate (eqs. 3-4; section 3)
2. `horizontal_frame`  -- global axes E1, E2 in body components from (n, psi) (eq. 6; section 4)
3. `patch_frame`       -- contact-patch axes e_x, e_y (Fig. 2; section 5)
4. `kinematics`        -- slip, spin and rolling velocities (eqs. 2, 16, 17; section 6)
5. contact law         -- loads per unit N (`jaxcelt.physics.contact.laws`; section 7)
6. `normal_force`      -- N from the differentiated constraint d/dt(v_A . n) = 0 (section 8)
7. `vector_field`      -- Newton-Euler, n_dot, r_C dot, psi dot (eqs. 1, 5, 6; section 8)

`CeltField` binds a contact law to `vector_field`, giving the ``f(t, y, params)`` that diffrax and the
orbit solvers integrate.

State y = (v[3], omega[3], n[3], r_C[3], psi), 13 numbers, SI units; v, omega, n in body
components, r_C in global components.
"""

from __future__ import annotations

from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp

from jaxcelt._math import cross3, matvec3, sincos
from jaxcelt._types import Array, Scalar, ScalarLike, State, Vec3
from jaxcelt.physics.contact.laws import AbstractContactLaw, ContactKinematics, ContactLoads
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.params import CeltParams

__all__ = [
    "Frame",
    "Geometry",
    "Kinematics",
    "contact_geometry",
    "horizontal_frame",
    "patch_frame",
    "kinematics",
    "contact_loads",
    "normal_force",
    "normal_force_parts",
    "vector_field",
    "vector_field_and_normal",
    "CeltField",
    "split_state",
    "field_time",
    "STATE_NAMES",
]

STATE_NAMES: tuple[str, ...] = (
    "v1", "v2", "v3", "omega1", "omega2", "omega3", "n1", "n2", "n3", "rC1", "rC2", "rC3", "psi",
)  # fmt: skip


def split_state(y: State) -> tuple[Vec3, Vec3, Vec3, Vec3, Scalar]:
    """(v, omega, n, r_C, psi) from the 13-vector."""
    return y[0:3], y[3:6], y[6:9], y[9:12], y[12]


class Geometry(NamedTuple):
    """Contact geometry (eqs. 3-4): r = O->A, rho = C->A, their rates, n_dot; body comps [m, m/s]."""

    r: Vec3
    rho: Vec3
    r_dot: Vec3
    n_dot: Vec3


def contact_geometry(n: Vec3, omega: Vec3, p: CeltParams) -> Geometry:
    """Contact point of the ellipsoid with the plane of normal n, and its body-frame rate.

    s = sqrt(n^T A n), r = -A n / s, with A = diag(a1^2, a2^2, a3^2) (eq. 4, MODEL.md A2);
    n_dot = -omega x n (eq. 1); r_dot = -(A n_dot)/s + (n^T A n_dot) A n / s^3 (n . r_dot = 0).
    """
    A = jnp.stack([p.a1, p.a2, p.a3]) ** 2
    An = A * n
    # one division, then products (a vectorised division costs as much as a dozen multiply-adds)
    inv_s = 1.0 / jnp.sqrt(jnp.dot(n, An))
    r = -An * inv_s
    n_dot = -cross3(omega, n)
    A_ndot = A * n_dot
    r_dot = (jnp.dot(n, A_ndot) * (inv_s * inv_s) * An - A_ndot) * inv_s
    return Geometry(r=r, rho=r - jnp.stack([p.k1, p.k2, p.k3]), r_dot=r_dot, n_dot=n_dot)


class Frame(NamedTuple):
    """Global horizontal axes E1, E2 (E3 = n) in body components; R = [E1; E2; n] maps body->global."""

    E1: Vec3
    E2: Vec3

    def to_global(self, x: Vec3, n: Vec3) -> Vec3:
        # written out, not three jnp.dot: the products then fuse into the output kernel (the
        # pool's step ~8 % faster; `jaxcelt._math` says why other dot products stay jnp.dot)
        return matvec3(jnp.stack([self.E1, self.E2, n]), x)


def horizontal_frame(n: Vec3, psi: ScalarLike) -> Frame:
    """E1, E2 from n and the precession angle psi (Z-X-Y sequence; MODEL.md section 4).

    u = (e2 - n2 n)/sqrt(1 - n2^2), w = u x n, E1 = cos(psi) w - sin(psi) u,
    E2 = sin(psi) w + cos(psi) u. Singular only when body x2 is vertical (n2 = +-1).
    """
    e2 = jnp.array([0.0, 1.0, 0.0], dtype=n.dtype)
    u = (e2 - n[1] * n) / jnp.sqrt(1.0 - n[1] ** 2)
    w = cross3(u, n)
    s, c = sincos(psi)
    return Frame(E1=c * w - s * u, E2=s * w + c * u)


def patch_frame(n: Vec3) -> tuple[Vec3, Vec3]:
    """Contact-patch axes (Fig. 2; MODEL.md section 5, A6).

    e_x = (e1 - n1 n)/sqrt(1 - n1^2) (long body axis projected on the base), e_y = n x e_x.
    """
    e1 = jnp.array([1.0, 0.0, 0.0], dtype=n.dtype)
    e_x = (e1 - n[0] * n) / jnp.sqrt(1.0 - n[0] ** 2)
    return e_x, cross3(n, e_x)


def field_time(t: ScalarLike, omega_pi: ScalarLike, dtype, offset: ScalarLike = 0.0):
    """The time to evaluate the field at for t + ``offset``, in ``dtype`` (the state's).

    float64: t + offset, unchanged. Otherwise the same forcing phase one period from 0:
    (t - n 2 pi/omega_pi) + offset with n = floor(t omega_pi/2 pi), computed in float64 and rounded
    once. The field depends on t only through sin(omega_pi t) (`base_velocity`), so this is the same
    field, with the stage times resolved to float32's precision of a period rather than of t itself:
    at t = 120 s float32 times are 7.6 us apart, and stage times rounded that coarsely make the error
    estimate reject step after step until the step size collapses."""
    if jnp.dtype(dtype) == jnp.float64:
        return t + offset if not (isinstance(offset, float) and offset == 0.0) else t
    t64 = jnp.asarray(t, jnp.float64)
    period = (2 * jnp.pi) / jnp.asarray(omega_pi, jnp.float64)
    return ((t64 - jnp.floor(t64 / period) * period) + jnp.asarray(offset, jnp.float64)).astype(dtype)


def base_velocity(t: ScalarLike, frame: Frame, p: CeltParams) -> Vec3:
    """v_pi = s_pi q_pi omega_pi sin(omega_pi t) E1 in body components [m/s] (eq. 17, A12)."""
    return p.v_pi_sign * p.q_pi * p.omega_pi * sincos(p.omega_pi * t)[0] * frame.E1


class Kinematics(NamedTuple):
    """Everything the contact law and the balance laws need at one state."""

    v: Vec3
    omega: Vec3
    n: Vec3
    geom: Geometry
    frame: Frame
    e_x: Vec3
    e_y: Vec3
    v_A: Vec3
    """absolute velocity of the body point at A [m/s]"""
    contact: ContactKinematics
    """non-dimensional slip/spin/rolling [1/s]"""


def kinematics(t: ScalarLike, y: State, p: CeltParams) -> Kinematics:
    """Relative velocities at the contact (eqs. 2, 16; MODEL.md section 6).

    v_A = v + omega x rho; v_s = (v_A - v_pi)/a_hat; omega_s = omega . n;
    v_r = v_s + r_dot/a_hat; x/y components on the patch axes.
    """
    v, omega, n, _, psi = split_state(y)
    geom = contact_geometry(n, omega, p)
    frame = horizontal_frame(n, psi)
    e_x, e_y = patch_frame(n)
    v_A = v + cross3(omega, geom.rho)
    # v_s keeps its division: XLA's fusion pass does not copy a division into every kernel that
    # reads v_s, while products it copies, with all they are computed from (the frame's sine and
    # cosine among them): with v_s * (1/a_hat), XLA's optimised pool step has about a fifth more operations
    v_s = (v_A - base_velocity(t, frame, p)) / p.a_hat
    v_r = v_s + geom.r_dot * (1.0 / p.a_hat)
    ck = ContactKinematics(
        vsx=jnp.dot(v_s, e_x),
        vsy=jnp.dot(v_s, e_y),
        omega_s=jnp.dot(omega, n),
        vrx=jnp.dot(v_r, e_x),
        vry=jnp.dot(v_r, e_y),
    )
    return Kinematics(v, omega, n, geom, frame, e_x, e_y, v_A, ck)


def contact_loads(kin: Kinematics, p: CeltParams, law: AbstractContactLaw) -> ContactLoads:
    """Loads per unit N from the chosen contact law (MODEL.md section 7)."""
    return law.loads(kin.contact, kin.e_x, kin.e_y, kin.n, p)


def _B_inverse(p: CeltParams) -> Array:
    """B^-1 by the adjugate (closed-form 3x3 inverse): B is symmetric positive definite and well
    conditioned; unlike ``jnp.linalg.solve`` (a LAPACK call per lane) its products fuse under
    ``jax.vmap``, and in a sweep over other parameters it is computed once, not per lane."""
    B = p.B
    c0, c1, c2 = cross3(B[1], B[2]), cross3(B[2], B[0]), cross3(B[0], B[1])
    # B symmetric: rows of the adjugate are c0, c1, c2.
    return jnp.stack([c0, c1, c2]) * (1.0 / jnp.dot(B[0], c0))


class _NormalForceTerms(NamedTuple):
    num: Scalar
    den: Scalar
    Binv_gyro: Vec3
    """B^-1 (w x B w)"""
    Binv_lever: Vec3
    """B^-1 (rho x (n + t) + m_s + m_r): the angular acceleration per unit N"""


def _normal_force_terms(kin: Kinematics, loads: ContactLoads, p: CeltParams) -> _NormalForceTerms:
    w, n, rho = kin.omega, kin.n, kin.geom.rho
    Binv = _B_inverse(p)
    rxn = cross3(rho, n)
    c = jnp.dot(kin.v_A, n)
    Binv_gyro = matvec3(Binv, cross3(w, matvec3(p.B, w)))
    num = (
        p.g
        + jnp.dot(cross3(w, rho), cross3(w, n))
        - jnp.dot(cross3(w, kin.geom.r_dot), n)
        + jnp.dot(rxn, Binv_gyro)
        - p.kappa * c
    )
    Binv_lever = matvec3(Binv, cross3(rho, n + loads.t) + loads.m_s + loads.m_r)
    den = 1.0 / p.m + jnp.dot(rxn, Binv_lever)
    return _NormalForceTerms(num, den, Binv_gyro, Binv_lever)


def normal_force_parts(kin: Kinematics, loads: ContactLoads, p: CeltParams) -> tuple[Scalar, Scalar]:
    """Numerator and denominator of N (index reduction of eqs. 1-2; MODEL.md section 8).

    N = [g + (w x rho).(w x n) - (w x r_dot).n + (rho x n).B^-1(w x B w) - kappa c]
        / [1/m + (rho x n).B^-1(rho x (n + t) + m_s + m_r)],    c = v_A . n.
    Numerator in m/s^2, denominator in 1/kg. The denominator must stay > 0.
    """
    terms = _normal_force_terms(kin, loads, p)
    return terms.num, terms.den


def normal_force(
    t: ScalarLike, y: State, params: CeltParams, contact_law: AbstractContactLaw | str | None = None
) -> Scalar:
    """Normal reaction N [N] at state y and time t (MODEL.md section 8)."""
    law = get_contact_law(contact_law)
    kin = kinematics(t, y, params)
    num, den = normal_force_parts(kin, contact_loads(kin, params, law), params)
    return num / den


def vector_field(
    t: ScalarLike, y: State, params: CeltParams, contact_law: AbstractContactLaw | str | None = None
) -> State:
    """dy/dt of the wobblestone (eqs. 1, 5, 6 with N from the constraint), shape (13,).

    m (v_dot + w x v) = -m g n + N (n + t)
    B w_dot + w x (B w) = rho x N (n + t) + N (m_s + m_r)
    n_dot = -w x n;  r_C_dot = R v (global);  psi_dot = (w1 n1 + w3 n3)/(1 - n2^2)
    """
    return vector_field_and_normal(t, y, params, contact_law)[0]


class CeltField(eqx.Module):
    """`vector_field` with its contact law bound: ``CeltField(law)(t, y, params)``, diffrax's ``f(t, y, args)``.

    A module (pytree), so the law's own parameters are leaves of the term, not constants of a closure.
    """

    law: AbstractContactLaw

    def __call__(self, t: ScalarLike, y: State, args: CeltParams) -> State:
        return vector_field(t, y, args, self.law)


def vector_field_and_normal(
    t: ScalarLike, y: State, params: CeltParams, contact_law: AbstractContactLaw | str | None = None
) -> tuple[State, tuple[Scalar, Scalar]]:
    """`vector_field` and, from the same evaluation, (N [N], denominator of N [1/kg]).

    What the validity monitor needs, at no extra cost where a solver evaluates the field at a
    step's end anyway (FSAL Runge-Kutta methods; the sweep's lane pool).
    """
    return _vector_field_and_normal(t, y, params, get_contact_law(contact_law))


# One jit around the whole field: JAX traces it once per argument signature and reuses that
# trace wherever a program evaluates the field again (every Runge-Kutta stage; diffrax traces a
# step several times; the tangent field's jvp). XLA inlines the call, so compiled programs are
# unchanged -- only tracing is cheaper (about 0.3 s off the sweep pool's trace).
@jax.jit
def _vector_field_and_normal(t, y, p, law):
    kin = kinematics(t, y, p)
    loads = contact_loads(kin, p, law)
    terms = _normal_force_terms(kin, loads, p)
    N = terms.num / terms.den
    v, w, n = kin.v, kin.omega, kin.n
    v_dot = -cross3(w, v) - p.g * n + (N * (1.0 / p.m)) * (n + loads.t)
    # B w_dot = rho x N (n + t) + N (m_s + m_r) - w x B w, with both B^-1 products already at hand
    w_dot = N * terms.Binv_lever - terms.Binv_gyro
    rC_dot = kin.frame.to_global(v, n)
    psi_dot = (w[0] * n[0] + w[2] * n[2]) / (1.0 - n[1] ** 2)
    return jnp.concatenate([v_dot, w_dot, kin.geom.n_dot, rC_dot, psi_dot[None]]), (N, terms.den)
