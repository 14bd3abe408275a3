"""Rolling without slip: the classical nonholonomic rattleback (Kane & Levinson 1982; Garcia &
Hubbard 1988) with the geometry of the main model (MODEL.md sections 3-4).

The contact point does not slip on the base: v_A = v + omega x rho = v_pi (eq. 2 strengthened
to all three components; v_pi of eq. 17, zero on a fixed table). v is then no longer a state:
differentiating the constraint in the body frame (d E1/dt = -omega x E1) gives

    v_dot = f' E1 - omega x v_pi - omega_dot x rho - omega x r_dot,    v_pi = f(t) E1,

and eliminating the contact force F = m (v_dot + omega x v + g n) from the Euler equation
B omega_dot + omega x B omega = rho x F gives the reduced equations

    M(n) omega_dot = m rho x (f' E1 - omega x (omega x rho) - omega x r_dot + g n) - omega x B omega,
    M(n) = B + m (|rho|^2 I - rho rho^T),
    n_dot = -omega x n,   r_C_dot = R v (global),   psi_dot = (w1 n1 + w3 n3)/(1 - n2^2)   (eq. 6)

with rho(n), r_dot(n, omega) from eqs. (3)-(4). Reduced state z = (omega, n, r_C, psi), 10
numbers. Without a moving base the energy 1/2 m |v|^2 + 1/2 omega^T B omega - m g rho . n is
conserved: there is no dissipation (no friction work, no rolling resistance). No contact law
enters; the friction the contact must supply, |F_t|/N, is reported so that one can check
whether rolling without slip is admissible for a given mu.
"""

from __future__ import annotations

from typing import NamedTuple

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._diffrax_adapter import diffeqsolve
from jaxcelt._types import Array, ArrayLike, Scalar, ScalarLike, Vec3
from jaxcelt.integrate.solve import Solution, Validity, status_code
from jaxcelt.physics.model import contact_geometry, horizontal_frame
from jaxcelt.physics.params import CeltParams

__all__ = [
    "NOSLIP_STATE_NAMES",
    "noslip_vector_field",
    "noslip_reduce",
    "noslip_full_state",
    "noslip_contact_force",
    "simulate_noslip",
    "NoSlipForce",
]

NOSLIP_STATE_NAMES = ("omega1", "omega2", "omega3", "n1", "n2", "n3", "rC1", "rC2", "rC3", "psi")


def _base(t: ScalarLike, n: Vec3, psi: ScalarLike, p: CeltParams) -> tuple[Vec3, Vec3]:
    """v_pi and f' E1 (base velocity and its rate along E1), body components (eq. 17)."""
    E1 = horizontal_frame(n, psi).E1
    amp = p.v_pi_sign * p.q_pi * p.omega_pi
    return amp * jnp.sin(p.omega_pi * t) * E1, amp * p.omega_pi * jnp.cos(p.omega_pi * t) * E1


def noslip_full_state(t: ScalarLike, z: Array, p: CeltParams) -> Array:
    """The 13-state (v, omega, n, r_C, psi) of the main model from the reduced state z (10,)."""
    w, n, rC, psi = z[0:3], z[3:6], z[6:9], z[9]
    rho = contact_geometry(n, w, p).rho
    v_pi, _ = _base(t, n, psi, p)
    v = v_pi - jnp.cross(w, rho)
    return jnp.concatenate([v, w, n, rC, psi[None]])


def noslip_reduce(y: Array) -> Array:
    """Reduced state z = (omega, n, r_C, psi) from a 13-state (drops v)."""
    return jnp.asarray(y)[3:]


class NoSlipForce(NamedTuple):
    """Contact force of the rolling stone: F [N] body components, N = F . n, |F_t|/N."""

    F: Vec3
    N: Scalar
    friction_ratio: Scalar


def _omega_dot(t, z, p):
    w, n, psi = z[0:3], z[3:6], z[9]
    geom = contact_geometry(n, w, p)
    rho = geom.rho
    _, acc = _base(t, n, psi, p)
    Bw = p.B @ w
    a_rel = acc - jnp.cross(w, jnp.cross(w, rho)) - jnp.cross(w, geom.r_dot) + p.g * n
    rhs = p.m * jnp.cross(rho, a_rel) - jnp.cross(w, Bw)
    M = p.B + p.m * (jnp.dot(rho, rho) * jnp.eye(3, dtype=rho.dtype) - jnp.outer(rho, rho))
    w_dot = jnp.linalg.solve(M, rhs)
    return w_dot, geom, a_rel


def noslip_contact_force(t: ScalarLike, z: Array, p: CeltParams) -> NoSlipForce:
    """F = m (a_rel - omega_dot x rho) with a_rel = f'E1 - w x (w x rho) - w x r_dot + g n [N]."""
    w_dot, geom, a_rel = _omega_dot(t, z, p)
    n = z[3:6]
    F = p.m * (a_rel - jnp.cross(w_dot, geom.rho))
    N = jnp.dot(F, n)
    Ft = F - N * n
    return NoSlipForce(F, N, jnp.sqrt(jnp.dot(Ft, Ft)) / N)


def noslip_vector_field(t: ScalarLike, z: Array, p: CeltParams) -> Array:
    """dz/dt of the rolling (non-slipping) stone, z = (omega, n, r_C, psi), shape (10,)."""
    w, n, psi = z[0:3], z[3:6], z[9]
    w_dot, geom, _ = _omega_dot(t, z, p)
    v_pi, _ = _base(t, n, psi, p)
    v = v_pi - jnp.cross(w, geom.rho)
    frame = horizontal_frame(n, psi)
    rC_dot = frame.to_global(v, n)
    psi_dot = (w[0] * n[0] + w[2] * n[2]) / (1.0 - n[1] ** 2)
    return jnp.concatenate([w_dot, geom.n_dot, rC_dot, psi_dot[None]])


class _NSField(eqx.Module):
    def __call__(self, t, z, args):
        return noslip_vector_field(t, z, args)


@eqx.filter_jit
def _solve_noslip(p, z0, t0, t1, ts, rtol, atol, *, solver, max_steps):
    saveat = diffrax.SaveAt(ts=ts) if ts is not None else diffrax.SaveAt(t0=True, t1=True)
    sol = diffeqsolve(
        diffrax.ODETerm(_NSField()),
        solver,
        t0,
        t1,
        None,
        z0,
        p,
        saveat=saveat,
        stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol),
        max_steps=max_steps,
        throw=False,
    )
    ys = jax.vmap(noslip_full_state, in_axes=(0, 0, None))(sol.ts, sol.ys, p)
    force = jax.vmap(noslip_contact_force, in_axes=(0, 0, None))(sol.ts, sol.ys, p)
    N = jnp.where(jnp.isfinite(force.N), force.N, jnp.inf)
    n3 = jnp.where(jnp.isfinite(ys[:, 8]), ys[:, 8], 1.0)
    kind_i = jnp.where(n3 <= 0, 2, jnp.where(N <= 0, 1, 0))
    first = jnp.argmax(kind_i > 0)
    any_bad = jnp.any(kind_i > 0)
    validity = Validity(
        first_invalid_t=jnp.where(any_bad, sol.ts[first], jnp.inf),
        first_invalid_kind=jnp.where(any_bad, kind_i[first], 0),
        first_invalid_y=jnp.where(any_bad, ys[first], jnp.nan),
        min_N=jnp.min(N),
        max_tilt=jnp.max(jnp.arccos(jnp.clip(n3, -1, 1))),
    )
    status = status_code(sol.result)  # no event here, so never 2
    return Solution(
        ts=sol.ts,
        ys=ys,
        status=status,
        num_steps=sol.stats["num_steps"],
        num_accepted_steps=sol.stats["num_accepted_steps"],
        num_rejected_steps=sol.stats["num_rejected_steps"],
        validity=validity,
    )


def simulate_noslip(
    params: CeltParams,
    y0: ArrayLike,
    t1: ArrayLike,
    *,
    ts: ArrayLike | None = None,
    t0: ArrayLike = 0.0,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 1_000_000,
) -> Solution:
    """Integrate the rolling-without-slip stone (module docstring) from ``y0`` to ``t1``.

    Args:
        params: `CeltParams`; only geometry, mass, inertia, k, g and the base forcing
            (q_pi, omega_pi, v_pi_sign) are used; no contact-law constant enters.
        y0: a 13-state (v, omega, n, r_C, psi) as made by `jaxcelt.initial_state` (v is
            ignored and replaced by the no-slip value v_pi(t0) - omega x rho) or a reduced
            10-state (omega, n, r_C, psi).
        t1, ts, t0, solver, rtol, atol, max_steps: as in `jaxcelt.simulate` (default Tsit5).

    Returns:
        `jaxcelt.Solution` with ``ys`` in the 13-state layout of the main model. Its validity
        record is evaluated at the saved times only (N > 0, n3 > 0); the friction the contact
        has to supply is `noslip_contact_force`.
    """
    y0 = jnp.asarray(y0, dtype=float)
    if y0.shape == (13,):
        z0 = noslip_reduce(y0)
    elif y0.shape == (10,):
        z0 = y0
    else:
        raise ValueError(f"'y0' must have shape (13,) or (10,), got {y0.shape}")
    if not isinstance(z0, jax.core.Tracer):
        nn = float(np.linalg.norm(np.asarray(z0[3:6])))
        if abs(nn - 1) > 1e-6 or float(z0[5]) <= 0:
            raise ValueError(f"'y0': n must be a unit vector with n3 > 0, got {np.asarray(z0[3:6])}")
    t0a = jnp.asarray(t0, dtype=float)
    t1a = jnp.asarray(t1, dtype=float)
    tsa = None if ts is None else jnp.asarray(ts, dtype=float)
    return _solve_noslip(
        params,
        z0,
        t0a,
        t1a,
        tsa,
        jnp.asarray(rtol, dtype=float),
        jnp.asarray(atol, dtype=float),
        solver=solver or diffrax.Tsit5(),
        max_steps=max_steps,
    )
