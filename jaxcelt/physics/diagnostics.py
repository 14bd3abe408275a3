"""Observables of a state: N, energy, tilt, constraint residuals, global position of O."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxcelt._types import Array, Scalar, ScalarLike, State
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import contact_geometry, horizontal_frame, normal_force
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import constraint_residual

__all__ = ["energy", "tilt", "centre_position", "Diagnostics", "diagnostics"]


def energy(y: State, params: CeltParams) -> Scalar:
    """Mechanical energy in the frame of the base [J] (MODEL.md section 10).

    1/2 m |v|^2 + 1/2 omega^T B omega + m g (k - r) . n; the last term is m g times the
    height of C above the plane. Conserved for mu = k_r = 0 on a fixed base.
    """
    v, w, n = y[0:3], y[3:6], y[6:9]
    geom = contact_geometry(n, w, params)
    return 0.5 * params.m * jnp.dot(v, v) + 0.5 * jnp.dot(w, params.B @ w) - params.m * params.g * jnp.dot(geom.rho, n)


def tilt(y: State) -> Scalar:
    """Angle between body x3 and the vertical, arccos(n3) [rad]."""
    return jnp.arccos(jnp.clip(y[8], -1.0, 1.0))


def centre_position(y: State, params: CeltParams) -> Array:
    """Global position of the geometric centre O: r_O = r_C - R k [m], shape (3,)."""
    n, r_C, psi = y[6:9], y[9:12], y[12]
    frame = horizontal_frame(n, psi)
    return r_C - frame.to_global(params.k, n)


class Diagnostics(NamedTuple):
    """Per-saved-state observables; each field has the leading shape of the states."""

    N: Array
    """normal force [N]"""
    energy: Array
    """mechanical energy [J] (in the base frame; not conserved on a moving base)"""
    tilt: Array
    """arccos(n3) [rad]"""
    norm_residual: Array
    """|n| - 1"""
    normal_velocity: Array
    """v_A . n [m/s], zero on the manifold"""
    height_residual: Array
    """r_C3 minus the height of C above the contact [m]"""
    r_O: Array
    """global position of the geometric centre [m], (..., 3)"""
    horizontal_momentum: Array
    """m times the horizontal global components of v [kg m/s], (..., 2)"""
    spin_momentum: Array
    """(B omega) . n [kg m^2/s] (conserved without friction, MODEL.md section 10)"""


def _one(t: ScalarLike, y: State, params: CeltParams, law: AbstractContactLaw) -> Diagnostics:
    dn, c, h = constraint_residual(y, params)
    frame = horizontal_frame(y[6:9], y[12])
    vg = frame.to_global(y[0:3], y[6:9])
    return Diagnostics(
        N=normal_force(t, y, params, law),
        energy=energy(y, params),
        tilt=tilt(y),
        norm_residual=dn,
        normal_velocity=c,
        height_residual=h,
        r_O=centre_position(y, params),
        horizontal_momentum=params.m * vg[:2],
        spin_momentum=jnp.dot(params.B @ y[3:6], y[6:9]),
    )


@jax.jit
def _many(ts, ys, params, law):
    return jax.vmap(_one, in_axes=(0, 0, None, None))(ts, ys, params, law)


def diagnostics(
    ts: Array, ys: Array, params: CeltParams, contact_law: AbstractContactLaw | str | None = None
) -> Diagnostics:
    """Observables at saved states ``ys`` (n, 13) and times ``ts`` (n,). Non-finite rows give NaN."""
    ts = jnp.asarray(ts, dtype=float)
    ys = jnp.asarray(ys, dtype=float)
    if ys.ndim == 1:
        return _one(ts, ys, params, get_contact_law(contact_law))
    return _many(ts, ys, params, get_contact_law(contact_law))
