"""A lane's state between two steps, and what a finished lane reports.

A *lane* is one solve (parameters, initial state, section times t_0 < ... < t_{S-1} = t1)
advanced by a stepper (`jaxcelt.ensemble.stepper`) one step at a time. `LaneState` holds
everything the next step needs besides the lane's parameters and section times (those stay
outside, see `jaxcelt.ensemble.pool`), so a lane can be parked in the pool's lane table
between two steps and taken up again later with the very same step sequence.
"""

from __future__ import annotations

from typing import Any

import diffrax
import equinox as eqx
import jax.numpy as jnp

from jaxcelt._types import Array
from jaxcelt.integrate.solve import status_code

__all__ = ["LaneState", "LaneMonitor", "LaneOutputs", "lane_status"]


class LaneState(eqx.Module):
    """One lane between two steps (scalars unless stated; a batch of lanes has a leading axis)."""

    y: Array
    """state at ``tprev``, (13,)"""
    tprev: Array
    """end of the last accepted step [s]"""
    tnext: Array
    """end of the step to try next [s]"""
    t1: Array
    """end of the solve: the last section time [s]"""
    floor: Array
    """t1 - 100 ULP: a step end above it is moved onto t1 (`jaxcelt._diffrax_adapter.t1_clip_floor`)"""
    tols: Array
    """(rtol, atol), traced (see `jaxcelt.ensemble.stepper`)"""
    result: Any
    """`diffrax.RESULTS` item: successful, event_occurred (stopped invalid), or a failure"""
    num_steps: Array
    """steps tried so far (accepted and rejected), int32"""
    k: Array
    """section samples reached so far, int32"""
    done: Array
    """bool: t1 reached, stopped, failed or out of steps (or a padding lane)"""
    step_state: Any
    """the stepper's own state (`DiffraxStepState` or `FusedStepState`)"""


class LaneMonitor(eqx.Module):
    """The validity monitor of a lane (updated on accepted steps only)."""

    first_invalid_t: Array
    """end of the first accepted step whose end state is invalid (inf if none) [s]"""
    first_invalid_kind: Array
    """`jaxcelt.INVALID_KINDS` code of that state (0 if none)"""
    min_N: Array
    """minimum normal force over accepted step ends [N]"""
    max_tilt: Array
    """maximum tilt arccos(n3) over accepted step ends [rad]"""
    at_singularity: Array
    """bool: the lane ended past validity at the heading's singularity (status 4)"""


class LaneOutputs(eqx.Module):
    """Per-lane results from the final lane states (a batch: leading lane axis)."""

    y_final: Array
    status: Array
    num_steps: Array
    first_invalid_t: Array
    first_invalid_kind: Array
    min_N: Array
    max_tilt: Array

    def as_dict(self) -> dict[str, Array]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}


def lane_status(lane: LaneState) -> Array:
    """`jaxcelt.STATUS` code of a lane that has stopped stepping."""
    # a lane that is still "successful" but has not reached t1 ran out of steps: status 1
    ok = lane.result == diffrax.RESULTS.successful
    return jnp.where(ok, jnp.where(lane.tprev >= lane.t1, 0, 1), status_code(lane.result)).astype(jnp.int32)
