"""The sensor model: what each observation kind of a measured record is, as a function of the state.

An observation kind names a function h(y, params, t) of the state y (13,) (MODEL.md section 8); a record stores
samples of h, possibly rotated into the axes of the sensor that took them:

===============  =====  ==================================================================
``"state"``      13     the full state (v, omega, n, r_C, psi), MODEL.md section 8
``"omega"``       3     body angular velocity [rad/s] -- what a strapped-on IMU gyro measures
``"orientation"`` 4     (n1, n2, n3, psi): vertical in body axes and precession angle [-, rad]
``"centre"``      3     global position of the geometric centre O [m] (motion capture)
``"accel"``       3     specific force at the mass centre in body axes [m/s^2] -- what an IMU
                        accelerometer at C measures (`specific_force`; depends on t)
===============  =====  ==================================================================

The IMU kinds (`SENSOR_KINDS`) are recorded in the sensor's own axes: h_sensor = R h_body with R the
`rotation_matrix` of a rotation vector (given, or fitted by `jaxcelt.identify.api.fit`).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import jax.numpy as jnp

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array, ArrayLike, State
from jaxcelt.physics.diagnostics import centre_position
from jaxcelt.physics.model import vector_field
from jaxcelt.physics.params import CeltParams

__all__ = ["OBSERVABLES", "SENSOR_KINDS", "observe", "specific_force", "rotation_matrix"]

OBSERVABLES: Mapping[str, int] = MappingProxyType({"state": 13, "omega": 3, "orientation": 4, "centre": 3, "accel": 3})
"""Observation kind -> number of channels: the state; omega (a gyro in body axes) [rad/s];
orientation (n, psi); centre (the geometric centre O, global) [m]; accel (an accelerometer at the
mass centre C in body axes: the specific force a - g, what an IMU measures) [m/s^2]. Read-only."""


SENSOR_KINDS = ("omega", "accel")
"""Observation kinds an IMU measures in its own axes (rotated by the sensor-to-body rotation)."""


def rotation_matrix(rotvec: ArrayLike) -> Array:
    """Rotation matrix exp([r]x) of a rotation vector r (3,) [rad] (Rodrigues); differentiable at 0.

    As the sensor rotation of `jaxcelt.identify.api.fit`: a vector with body components h has sensor
    components R h."""
    r = jnp.asarray(rotvec, dtype=float)
    th2 = jnp.dot(r, r)
    small = th2 < 1e-12
    th = jnp.sqrt(jnp.where(small, 1.0, th2))
    a = jnp.where(small, 1.0 - th2 / 6.0, jnp.sin(th) / th)  # sin(th)/th
    b = jnp.where(small, 0.5 - th2 / 24.0, (1.0 - jnp.cos(th)) / jnp.where(small, 1.0, th2))
    K = jnp.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    return jnp.eye(3) + a * K + b * (K @ K)


def specific_force(t: ArrayLike, y: State, params: CeltParams) -> Array:
    """Specific force at the mass centre in body axes [m/s^2]: acceleration minus gravity.

    With the body-frame derivative of v (MODEL.md section 8), a = v_dot + omega x v and gravity
    is -g n, so f = v_dot + omega x v + g n (= N (n + t) / m, the contact force per unit mass;
    g n at rest on a still base). It depends on t through the base motion."""
    v_dot = vector_field(t, y, params)[0:3]
    return v_dot + jnp.cross(y[3:6], y[0:3]) + params.g * y[6:9]


def observe(y: State, params: CeltParams, kind: str, t: ArrayLike = 0.0) -> Array:
    """Observation ``kind`` (see `OBSERVABLES`) of one state y (13,) at time t; vmap for a time
    series (only "accel" depends on t, through the base's motion)."""
    if kind == "state":
        return y
    if kind == "omega":
        return y[3:6]
    if kind == "orientation":
        return jnp.concatenate([y[6:9], y[12:13]])
    if kind == "centre":
        return centre_position(y, params)
    if kind == "accel":
        return specific_force(t, y, params)
    raise ValueError(f"unknown observation kind {kind!r}; known: {sorted(OBSERVABLES)}")
