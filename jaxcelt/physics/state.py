"""Consistent initial states on the contact manifold, their validation and the projection onto it (MODEL.md section 8)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._types import ArrayLike, State
from jaxcelt.physics.model import contact_geometry, horizontal_frame
from jaxcelt.physics.params import CeltParams

__all__ = ["initial_state", "check_state", "constraint_residual", "project_state", "MANIFOLD_TOL"]

MANIFOLD_TOL = 1e-6
"""Tolerance of `check_state`: |n| - 1, v_A . n [m/s] and contact height [m]. Loose enough for
states typed with ~8 significant digits, tight enough to catch a wrong state."""


def initial_state(
    params: CeltParams,
    *,
    omega: ArrayLike = (0.0, 0.0, 0.0),
    n: ArrayLike = (0.0, 0.0, 1.0),
    psi: ArrayLike = 0.0,
    v_A: ArrayLike = (0.0, 0.0, 0.0),
    position: ArrayLike = (0.0, 0.0),
    normalize: bool = False,
) -> State:
    """A state y (13,) on the contact manifold.

    Args:
        params: the stone.
        omega: angular velocity, body components [rad/s].
        n: upward vertical in body components; must be a unit vector with n3 > 0 (contact on
            the lower half-surface). ``normalize=True`` rescales it instead of raising.
        psi: precession angle [rad] (heading of the stone relative to the base's X1 axis).
        v_A: velocity of the body point at the contact, body components [m/s]; its normal
            component must vanish (eq. 2). Zero means rolling on a base at rest.
        position: global (X1, X2) of the contact point [m].

    Returns v = v_A - omega x rho, r_C = R(-rho) + (X1, X2, 0) (MODEL.md section 8).
    """
    omega = jnp.asarray(omega, dtype=float)
    n = jnp.asarray(n, dtype=float)
    v_A = jnp.asarray(v_A, dtype=float)
    psi = jnp.asarray(psi, dtype=float)
    position = jnp.asarray(position, dtype=float)
    for name, x, shape in (
        ("omega", omega, (3,)),
        ("n", n, (3,)),
        ("v_A", v_A, (3,)),
        ("psi", psi, ()),
        ("position", position, (2,)),
    ):
        if x.shape != shape:
            raise ValueError(f"initial_state: {name!r} must have shape {shape}, got {x.shape}")
        if not isinstance(x, jax.core.Tracer) and not np.all(np.isfinite(np.asarray(x))):
            raise ValueError(f"initial_state: {name!r} must be finite, got {np.asarray(x)}")
    if not isinstance(n, jax.core.Tracer):
        nn = float(np.linalg.norm(np.asarray(n)))
        if normalize:
            if nn == 0:
                raise ValueError("initial_state: 'n' must be non-zero")
            n = n / nn
        elif abs(nn - 1) > MANIFOLD_TOL:
            raise ValueError(
                f"initial_state: 'n' must be a unit vector (|n| = {nn:.12g}); pass normalize=True to rescale"
            )
        if float(n[2]) <= 0:
            raise ValueError(
                f"initial_state: 'n' must have n3 > 0 (contact on the lower half-surface), got n = {np.asarray(n)}"
            )
        if abs(float(n[1])) >= 1 - 1e-12:
            raise ValueError("initial_state: n2 = +-1 (body x2 vertical) is the singular point of psi (eq. 6)")
        if not isinstance(v_A, jax.core.Tracer) and abs(float(jnp.dot(v_A, n))) > MANIFOLD_TOL:
            raise ValueError(
                f"initial_state: 'v_A' must be tangent to the base (v_A . n = {float(jnp.dot(v_A, n)):.3g} m/s)"
            )
    else:
        n = n / jnp.linalg.norm(n)
    return _state_on_manifold(omega, n, psi, v_A, position, params)


@jax.jit
def _state_on_manifold(omega, n, psi, v_A, position, params: CeltParams) -> State:
    # one compiled program (called eagerly, each operation would compile one of its own)
    v_A = v_A - jnp.dot(v_A, n) * n
    geom = contact_geometry(n, omega, params)
    v = v_A - jnp.cross(omega, geom.rho)
    frame = horizontal_frame(n, psi)
    r_C = frame.to_global(-geom.rho, n) + jnp.concatenate([position, jnp.zeros(1, position.dtype)])
    return jnp.concatenate([v, omega, n, r_C, psi[None]])


def constraint_residual(y: State, params: CeltParams) -> tuple[ArrayLike, ArrayLike, ArrayLike]:
    """(|n| - 1, v_A . n [m/s], height of the contact point above the base [m]) at state y."""
    v, omega, n, r_C = y[0:3], y[3:6], y[6:9], y[9:12]
    geom = contact_geometry(n, omega, params)
    v_A = v + jnp.cross(omega, geom.rho)
    # height of C above the base is -rho . n; r_C3 must equal it.
    return jnp.linalg.norm(n) - 1.0, jnp.dot(v_A, n), r_C[2] + jnp.dot(geom.rho, n)


_constraint_residual_jit = jax.jit(constraint_residual)


def check_state(y: ArrayLike, params: CeltParams, *, name: str = "y0", tol: float = MANIFOLD_TOL) -> None:
    """Raise ValueError if a concrete state is malformed or off the contact manifold.

    Checks shape (..., 13), finiteness, |n| = 1, n3 > 0, v_A . n = 0 and that r_C3 equals
    the height of C above the contact point, each to ``tol``. Traced values are not checked.
    """
    if isinstance(y, jax.core.Tracer):
        return
    arr = np.asarray(y, dtype=float)
    if arr.shape[-1:] != (13,):
        raise ValueError(f"{name!r} must have trailing shape (13,) = (v, omega, n, r_C, psi), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr.reshape(-1, 13)))[0]
        raise ValueError(f"{name!r} contains NaN/inf (first at component {bad[-1]})")
    flat = arr.reshape(-1, 13)
    if any(isinstance(x, jax.core.Tracer) for x in jax.tree_util.tree_leaves(params)):
        return  # e.g. jit(grad) with respect to mu only: the manifold check needs concrete values
    pb = params if np.ndim(params.m) == 0 else None
    for i, yi in enumerate(flat):
        p = (
            pb
            if pb is not None
            else jax.tree_util.tree_map(lambda x, i=i: x.reshape(-1)[i] if np.size(x) == len(flat) else x, params)
        )
        dn, c, h = (float(v) for v in _constraint_residual_jit(jnp.asarray(yi), p))
        where = f"{name}[{i}]" if len(flat) > 1 else name
        if abs(dn) > tol:
            raise ValueError(f"{where!r}: n (components 6:9) must be a unit vector, |n| - 1 = {dn:.3g}")
        if yi[8] <= 0:
            raise ValueError(f"{where!r}: n3 = {yi[8]:.4g} <= 0: contact off the lower half-surface")
        if abs(c) > tol:
            raise ValueError(f"{where!r}: off the contact manifold, v_A . n = {c:.3g} m/s (use jaxcelt.initial_state)")
        if abs(h) > tol:
            raise ValueError(
                f"{where!r}: r_C3 inconsistent with the contact (off by {h:.3g} m; use jaxcelt.initial_state)"
            )


def project_state(y: State, params: CeltParams) -> State:
    """Project a 13-vector onto the contact manifold (MODEL.md section 8).

    Normalises n, removes the normal component of the contact-point velocity v_A = v + omega x rho
    (eq. 2) and sets r_C3 to the height of C above the contact (-rho . n). Differentiable.
    """
    y = jnp.asarray(y)
    v, w, n, r_C, psi = y[0:3], y[3:6], y[6:9], y[9:12], y[12:13]
    n = n / jnp.linalg.norm(n)
    rho = contact_geometry(n, w, params).rho
    v_A = v + jnp.cross(w, rho)
    v_A = v_A - jnp.dot(v_A, n) * n
    v = v_A - jnp.cross(w, rho)
    r_C = r_C.at[2].set(-jnp.dot(rho, n))
    return jnp.concatenate([v, w, n, r_C, psi])
