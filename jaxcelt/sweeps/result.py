"""The per-lane results of a sweep, and the lane schema every sweep module shares.

A *lane* is one (parameter values, initial state) pair integrated to its stroboscopic section
times. `SweepResult` holds every lane's arrays; `LANE_FIELDS` names them (in dataset order) and
`LANE_DIMS` gives the trailing dimensions of the arrays that are more than one number per lane.
The chunk files and the merged dataset (`jaxcelt.sweeps.dataset`) are written from this schema,
and the engine (`jaxcelt.ensemble.run_lanes`) returns these fields, so it is written down once,
here.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from types import MappingProxyType

import equinox as eqx
import numpy as np

__all__ = ["SweepResult", "LANE_FIELDS", "LANE_DIMS"]


class SweepResult(eqx.Module):
    """Per-lane results of a sweep (numpy arrays; leading axis = lanes, or (values, starts)).

    Attributes (L = lanes, S = sample_periods):
        values: swept parameter value per lane, (L,)
        t_samples: stroboscopic times [s], (L, S)
        samples: states at the section, (L, S, 13) (inf after a failed solve or a stop at an
            invalid state)
        y_final: last sample (L, 13) -- where `jaxcelt.sweeps.following.follow_attractor` starts the next value
        status: `jaxcelt.STATUS` code, (L,); success = status == 0; 2 = stopped at the first
            invalid state (``stop_on_invalid=True``)
        valid: model stayed valid (N > 0, n3 > 0, denominator > 0) on all accepted steps, (L,)
        first_invalid_t [s], first_invalid_kind (`jaxcelt.INVALID_KINDS`), (L,)
        min_N [N], max_tilt [rad]: over all accepted steps (transient included), (L,)
        drift: horizontal displacement of O from the first to the last sample [m], (L,)
        max_excursion: max horizontal distance of O from its first-sample position [m], (L,)
        num_steps: solver steps (main solve), (L,)
        lyapunov: largest Lyapunov exponent [1/s] (NaN if not computed / failed), (L,)
        lyapunov_stderr: its batch-means standard error over 4 sub-windows [1/s]
            (`jaxcelt.integrate.lyapunov.exponent_stderr`; NaN where ``lyapunov`` is, or with < 4 periods), (L,)
        r_O: global position of the geometric centre at the samples [m], (L, S, 3)
    """

    name: str = eqx.field(static=True)
    values: np.ndarray
    t_samples: np.ndarray
    samples: np.ndarray
    y_final: np.ndarray
    status: np.ndarray
    valid: np.ndarray
    first_invalid_t: np.ndarray
    first_invalid_kind: np.ndarray
    min_N: np.ndarray
    max_tilt: np.ndarray
    drift: np.ndarray
    max_excursion: np.ndarray
    num_steps: np.ndarray
    lyapunov: np.ndarray
    lyapunov_stderr: np.ndarray
    r_O: np.ndarray

    @property
    def success(self) -> np.ndarray:
        return self.status == 0


LANE_FIELDS: tuple[str, ...] = tuple(
    f.name for f in dataclasses.fields(SweepResult) if f.name not in ("name", "values")
)
"""The per-lane arrays of a sweep, in dataset order: the fields of `SweepResult` but ``name`` and ``values``."""

LANE_DIMS: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        "t_samples": ("sample",),
        "samples": ("sample", "state"),
        "y_final": ("state",),
        "r_O": ("sample", "xyz"),
    }
)
"""Trailing dimensions of the lane arrays that hold more than one number per lane (the others are scalars)."""
