"""The options of a fit: one frozen, keyword-only object, `FitOptions`, checked once when it is made.

`jaxcelt.identify.api.fit` accepts every field as a keyword (``fit(data, params0, free=..., windows=4)``) or the
whole object (``fit(data, params0, options=FitOptions(...))``); the strategies (`jaxcelt.identify.strategies`) and the
problem builder (`jaxcelt.identify.problem.build_problem`) take the object, never long argument lists. The options
hold no data and no starting values: the same options fit any records from any start.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from jaxcelt._options import with_keywords
from jaxcelt.physics.params import PARAM_NAMES

__all__ = ["FitOptions", "OPTIMISERS", "LSQ_OPTIMISERS", "STEPS_PER_SECOND", "NOT_FREE"]

OPTIMISERS = ("lm", "gn", "gn-damped", "adam", "lbfgs")
"""Optimiser names: optimistix least squares (``lm``, ``gn``, ``gn-damped``), optax (``adam``, ``lbfgs``)."""

LSQ_OPTIMISERS = ("lm", "gn", "gn-damped")
"""The optimistix least-squares optimisers (`jaxcelt.identify.strategies.multistart` runs them vmapped)."""

STEPS_PER_SECOND = 2000
"""Default step budget of a fit's solves per second of window (rounded up to whole seconds): a
record of the stone's normal motion needs a few hundred steps per second at rtol 1e-8; the cap
makes a trial point in a stiff parameter region fail fast (``benchmarks/bench_fit.py``)."""

NOT_FREE = ("v_pi_sign", "derivative_exact", "omega_pi", "q_pi")
"""Parameters that cannot be fitted: reading switches and the per-record forcing values."""


@dataclasses.dataclass(frozen=True, kw_only=True)
class FitOptions:
    """Everything that configures a fit (the data and the starting parameters are arguments of `fit`).

    Attributes:
        free: names of the parameters to fit (any float fields of `CeltParams` except `NOT_FREE`).
        optimiser: ``"lm"`` (optimistix Levenberg-Marquardt), ``"gn"`` (plain Gauss-Newton, full
            steps), ``"gn-damped"`` (Gauss-Newton with a backtracking line search), all with
            forward-mode Jacobians; ``"adam"`` (cosine-decayed step) or ``"lbfgs"`` (zoom line
            search), optax, with the gradient J^T r from the same forward-mode Jacobian.
        weights: extra weight per observation kind (default 1; residuals are already /sigma).
        transforms: per-parameter transforms overriding `jaxcelt.identify.transforms.DEFAULT_TRANSFORMS`
            (else `Positive`).
        windows: number of multiple-shooting windows per record (1 = single shooting).
        window_states: ``"optimise"`` (window initial states are unknowns, initialised from the
            data or from a simulation at params0, tied by the continuity penalty) or ``"data"``
            (fixed to the projected measured states; needs ``"state"`` observations).
        fit_y0: also optimise the first window's initial state (else: the record's known y0, or
            its first projected full-state sample).
        sensor_rotation: rotation vector (3,) [rad] from body to sensor axes of the gyro
            (``"omega"``) and accelerometer (``"accel"``) observations: h_sensor = R h_body
            (`jaxcelt.identify.observe.rotation_matrix`); default none. With ``fit_rotation`` it is the
            starting value of a fitted rotation shared by all records.
        time_offset: model time minus record time [s] (scalar or one per record), i.e. the phase
            of the base's motion at the record's t = 0; default 0. With ``fit_time_offset`` the
            starting value of a fitted offset per record.
        continuity_weight: weight of the continuity and gauge residuals (residual scale
            `STATE_SCALE` / sqrt(weight)).
        max_iter: iteration budget. rtol, atol: optimistix termination (relative/absolute change
            of z and of the loss).
        sim_rtol, sim_atol, max_steps: integrator settings. max_steps per solve (default
            `STEPS_PER_SECOND` per second of the longest window, at least that many): a trial
            point of the optimiser in a stiff parameter region fails fast at the cap and is rejected.
        learning_rate: Adam initial step size in z (log-relative units for `Positive`
            parameters), decayed by a cosine schedule to 1e-3 of it over ``max_iter``.
        gtol: optax optimisers stop, converged, when |grad loss| <= gtol |grad loss at start|.
        uncertainty: compute standard errors, intervals and correlations.
        max_time: wall-clock budget [s] for the iterations (checked after each iteration;
            compilation included); the fit stops unconverged when it is spent.
        callback: called as ``callback(iteration, loss, values)`` after each iteration (progress).

    Raises:
        ValueError: naming the field, for an unknown optimiser or parameter, a parameter that cannot be
            fitted, repeated or no free parameters, ``max_iter`` or ``windows`` < 1, or an unknown
            ``window_states``.
    """

    free: Sequence[str] = ("mu", "k_r", "b_Ts", "m_Ts")
    optimiser: str = "lm"
    weights: dict[str, float] | None = None
    transforms: dict[str, Any] | None = None
    windows: int = 1
    window_states: str = "optimise"
    fit_y0: bool = False
    sensor_rotation: Any = None
    fit_rotation: bool = False
    time_offset: Any = 0.0
    fit_time_offset: bool = False
    continuity_weight: float = 1e4
    max_iter: int = 100
    rtol: float = 1e-8
    atol: float = 1e-8
    sim_rtol: float = 1e-8
    sim_atol: float = 1e-10
    max_steps: int | None = None
    learning_rate: float = 0.02
    gtol: float = 1e-9
    uncertainty: bool = True
    max_time: float | None = None
    callback: Callable[[int, float, dict[str, float]], None] | None = None

    def __post_init__(self):
        free = tuple(self.free)
        object.__setattr__(self, "free", free)
        if self.optimiser not in OPTIMISERS:
            raise ValueError(f"fit: optimiser must be one of {OPTIMISERS}, got {self.optimiser!r}")
        mi = self.max_iter
        if isinstance(mi, bool) or not isinstance(mi, int) or mi < 1:
            raise ValueError(f"fit: max_iter must be a positive int, got {mi!r}")
        for n in free:
            if n not in PARAM_NAMES:
                raise ValueError(f"fit: unknown parameter {n!r}; known: {PARAM_NAMES}")
            if n in NOT_FREE:
                raise ValueError(f"fit: {n!r} is a reading switch or a per-record forcing value and cannot be fitted")
        if len(set(free)) != len(free) or not free:
            raise ValueError(f"fit: 'free' must be a non-empty tuple of distinct names, got {free}")
        if self.windows < 1:
            raise ValueError(f"fit: windows must be >= 1, got {self.windows}")
        if self.window_states not in ("data", "optimise"):
            raise ValueError(f"fit: window_states must be 'data' or 'optimise', got {self.window_states!r}")

    def replace(self, **changes) -> FitOptions:
        """A copy with ``changes`` (checked again)."""
        return dataclasses.replace(self, **changes)

    def steps_per_solve(self, spans: Sequence[float]) -> int:
        """``max_steps``, or its default for records of durations ``spans`` [s]: `STEPS_PER_SECOND` per
        second of the longest window (whole seconds, at least one)."""
        if self.max_steps is not None:
            return self.max_steps
        span = max(spans) / max(int(self.windows), 1)
        return int(STEPS_PER_SECOND * max(1.0, np.ceil(span)))

    @classmethod
    def from_keywords(cls, keywords: dict[str, Any], options: FitOptions | None) -> FitOptions:
        """The options of a call given ``keywords`` (name -> value, every field) and perhaps ``options``: the
        keywords alone, or ``options`` with each keyword that differs from its default overriding that field (the
        rule of every options object in jaxcelt)."""
        if options is None:
            return cls(**keywords)
        defaults = {f.name: f.default for f in dataclasses.fields(cls)}
        given = {n: v for n, v in keywords.items() if not _is_default(v, defaults[n])}
        return with_keywords(cls, options, options, given, caller="fit")


def _is_default(value: Any, default: Any) -> bool:
    if value is default:
        return True
    if isinstance(value, np.ndarray) or isinstance(default, np.ndarray) or type(value) is not type(default):
        return False
    try:
        return bool(value == default)
    except (TypeError, ValueError):
        return False
