"""How a sweep runs: `SweepOptions`, the one keyword-only options object of every sweep.

`jaxcelt.sweeps.api.sweep`, `bifurcation`, `parameter_map`, `sweep_lanes` and
`jaxcelt.sweeps.following.follow_attractor` take the same settings: the stroboscopic sampling and
the solver (which make up the engine's `jaxcelt.ensemble.SweepConfig`, part of a dataset's
fingerprint) and how the lanes are executed (chunking, pool width, engine, devices, output
directory, progress). They are documented here once. Each function accepts them either as
keywords (``sweep(params, "mu", values, rtol=1e-9)``) or as ``options=SweepOptions(...)``;
keywords given beside ``options`` replace its fields.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from jaxcelt._options import with_keywords
from jaxcelt.ensemble.config import SweepConfig
from jaxcelt.integrate.solve import DEFAULT_SOLVER

__all__ = ["SweepOptions", "resolve_options"]


@dataclasses.dataclass(frozen=True, kw_only=True)
class SweepOptions:
    """Settings of a sweep (everything but the parameters, the swept values and the starts).

    Sampling and solver (the engine's `jaxcelt.ensemble.SweepConfig`, see `config`):

    Attributes:
        transient_periods: forcing periods T = 2 pi/omega_pi discarded before sampling.
        sample_periods: stroboscopic samples kept, at t0 + (transient + k) T, k = 0 .. S-1 (hit
            exactly: the samples are solver states).
        lyapunov_periods: > 0 also integrates the tangent dynamics for that many periods after the
            transient (`jaxcelt.integrate.lyapunov.celt_lyapunov`) -> ``lyapunov`` [1/s]; 0: off.
        lyapunov_error_control: what the step-size control of the tangent solve measures: ``"state"``
            (default) the state's error alone, ``"all"`` the state's and the tangent vector's
            (`jaxcelt.integrate.lyapunov.largest_lyapunov`'s ``error_control``). Part of the dataset's
            fingerprint when ``lyapunov_periods > 0``.
        lyapunov_tangent: how the tangent vector's derivative is formed: ``"difference"`` (default) a
            forward difference of the field, ``"jvp"`` forward-mode differentiation
            (`jaxcelt.integrate.lyapunov.largest_lyapunov`'s ``tangent``). Part of the dataset's
            fingerprint when ``lyapunov_periods > 0``.
        rtol, atol, max_steps, solver, contact_law, t0: as in `jaxcelt.simulate` (``solver=None``:
            `jaxcelt.integrate.solve.DEFAULT_SOLVER`).
        stop_on_invalid: end each lane at its first invalid state (lift-off, n3 <= 0): status 2,
            samples after the stop inf, no Lyapunov exponent. Default False (the model is
            integrated on, validity reported), as in `jaxcelt.simulate`.
        dtype: the lanes' arithmetic, ``"float64"`` (default) or ``"float32"`` (faster on GPUs;
            use rtol >= 1e-6; results come back as float64 arrays, the Lyapunov stage runs in
            float64). With the explicit solvers' fused step and in the lane kernel the times stay
            float64 and the field gets the forcing phase from one period
            (`jaxcelt.physics.model.field_time`); with other solvers float32 lanes step in float32
            time, and a step below ~10 ULPs of t ends a lane (status 3). Part of the dataset's
            fingerprint.
        field_dtype: mixed precision in the lane kernel: ``"float32"`` evaluates the field in float32
            while the state, its sums and the error control stay float64; None (default): off.
        stiffness: the lane kernel's stiffness switch (`jaxcelt.ensemble.stiff`): ``"auto"`` steps a
            lane with Rodas4P while its explicit steps are stability-limited (a stone sticking to the
            base); ``"off"`` (default): explicit steps only.

    Execution (results do not depend on these beyond rounding, see `jaxcelt.sweeps.driver`):

    Attributes:
        chunk_size: lanes per jitted solve, the unit of resumable writing (default: all lanes in
            one chunk).
        sort_by_cost: order lanes by the cost proxy (time span per period, 1/omega_pi), most
            expensive first, before chunking (the pool then drains on cheap lanes).
        width: batch slots per device of the pool (default `jaxcelt.ensemble.DEFAULT_WIDTH`).
        engine: how lanes are stepped (`jaxcelt.ensemble.ENGINES`): ``"auto"`` (default) runs them
            in the lane kernel on a GPU (`jaxcelt.ensemble.kernel`: one thread per lane, explicit
            FSAL solvers) and in the lane pool elsewhere; ``"pool"`` or ``"kernel"`` forces one (the
            kernel off a GPU runs interpreted: slow, for tests). Both take the same steps up to
            rounding.
        devices: devices to shard each chunk over (default all local devices), or a
            `jaxcelt.HostProcesses`: worker processes, one pinned to each CPU core with one device
            each (`jaxcelt.ensemble.processes`).
        out: directory; write the dataset chunk by chunk there and resume a previous, interrupted
            run of the same sweep (`jaxcelt.sweeps.dataset`). Required when several processes run
            the sweep together (`jax.distributed`; `jaxcelt.sweeps.driver`).
        progress: tqdm bar over lanes (with ETA).
        on_chunk: ``on_chunk(chunk_index, chunk_results)`` called after each chunk.
    """

    transient_periods: int = 200
    sample_periods: int = 100
    lyapunov_periods: int = 0
    lyapunov_error_control: str = "state"
    lyapunov_tangent: str = "difference"
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int = 1_000_000
    solver: Any = None
    contact_law: Any = None
    t0: float = 0.0
    stop_on_invalid: bool = False
    dtype: Any = "float64"
    field_dtype: str | None = None
    stiffness: str = "off"
    chunk_size: int | None = None
    sort_by_cost: bool = False
    width: int | None = None
    engine: str = "auto"
    devices: Sequence[Any] | None = None
    out: str | None = None
    progress: bool = False
    on_chunk: Callable[[int, dict[str, np.ndarray]], None] | None = None

    def replace(self, **changes: Any) -> SweepOptions:
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)

    def config(self) -> SweepConfig:
        """The engine's static settings (`jaxcelt.ensemble.SweepConfig`; checked there, ValueError naming the field)."""
        return SweepConfig(
            transient_periods=int(self.transient_periods),
            sample_periods=int(self.sample_periods),
            lyapunov_periods=int(self.lyapunov_periods),
            lyapunov_error_control=self.lyapunov_error_control,
            lyapunov_tangent=self.lyapunov_tangent,
            rtol=float(self.rtol),
            atol=float(self.atol),
            max_steps=int(self.max_steps),
            solver=self.solver if self.solver is not None else DEFAULT_SOLVER,
            contact_law=self.contact_law,
            t0=float(self.t0),
            stop_on_invalid=bool(self.stop_on_invalid),
            dtype=_dtype_name(self.dtype),
            field_dtype=None if self.field_dtype is None else _dtype_name(self.field_dtype),
            stiffness=self.stiffness,
        )


def resolve_options(
    options: SweepOptions | None,
    keywords: Mapping[str, Any],
    *,
    caller: str,
    defaults: Mapping[str, Any] | None = None,
) -> SweepOptions:
    """The options of a call: ``options`` (or `SweepOptions` with ``defaults``) with ``keywords`` applied
    (`jaxcelt._options.with_keywords`: TypeError for a keyword that is no field, naming ``caller``)."""
    return with_keywords(SweepOptions, options, SweepOptions(**dict(defaults or {})), keywords, caller=caller)


def _dtype_name(dtype: Any) -> str:
    try:
        name = np.dtype(dtype).name
    except TypeError:
        name = None
    if name not in ("float64", "float32"):
        raise ValueError(f"dtype must be float64 or float32, got {dtype!r}")
    return name
