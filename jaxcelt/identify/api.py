"""`fit`: gradient-based identification of model parameters from measured trajectories.

A fit builds the least-squares problem (`jaxcelt.identify.problem`) of the records and the configuration
(`jaxcelt.identify.options.FitOptions`), iterates an optimiser (`jaxcelt.identify.optimisers`) whose residuals and
forward-mode Jacobians come from one compiled evaluation program (`jaxcelt.identify.program`), and reports the
optimum with its Gauss-Newton uncertainty (`jaxcelt.identify.result.FitResult`). A fit keeps no state between calls:
fits of different data may run at the same time in different threads. Strategies built on it (growing spans,
multi-start, profile likelihood) are in `jaxcelt.identify.strategies`.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt.identify.optimisers import run
from jaxcelt.identify.options import FitOptions
from jaxcelt.identify.problem import Problem, build_problem
from jaxcelt.identify.program import evaluate
from jaxcelt.identify.records import MeasuredData
from jaxcelt.identify.result import FitResult, make_result
from jaxcelt.physics.params import CeltParams

__all__ = ["fit", "fit_with", "prepare"]


def fit(
    data: MeasuredData,
    params0: CeltParams,
    *,
    free: Sequence[str] = ("mu", "k_r", "b_Ts", "m_Ts"),
    optimiser: str = "lm",
    weights: dict[str, float] | None = None,
    transforms: dict[str, Any] | None = None,
    windows: int = 1,
    window_states: str = "optimise",
    fit_y0: bool = False,
    sensor_rotation: Any = None,
    fit_rotation: bool = False,
    time_offset: Any = 0.0,
    fit_time_offset: bool = False,
    continuity_weight: float = 1e4,
    max_iter: int = 100,
    rtol: float = 1e-8,
    atol: float = 1e-8,
    sim_rtol: float = 1e-8,
    sim_atol: float = 1e-10,
    max_steps: int | None = None,
    learning_rate: float = 0.02,
    gtol: float = 1e-9,
    uncertainty: bool = True,
    max_time: float | None = None,
    callback: Callable[[int, float, dict[str, float]], None] | None = None,
    options: FitOptions | None = None,
) -> FitResult:
    """Fit the free parameters to measured trajectories.

    Args:
        data: `jaxcelt.identify.records.MeasuredData` (any observation kinds; several records, each with its
            own omega_pi, q_pi).
        params0: starting parameters (also the values of every parameter that is not free).
        options: the whole configuration as one `jaxcelt.FitOptions`; a keyword that differs from its default
            overrides that field of it.
        **keywords: every other parameter (``free``, ``optimiser``, ``weights``, ``windows``, ``max_iter``, ...)
            is a field of `jaxcelt.FitOptions`, documented there, with the same default.

    Returns:
        `FitResult`.
    """
    keywords = {k: v for k, v in locals().items() if k not in ("data", "params0", "options")}
    return fit_with(data, params0, FitOptions.from_keywords(keywords, options))


def prepare(data: MeasuredData, params0: CeltParams, config: FitOptions) -> tuple[Problem, np.ndarray]:
    """The problem of a fit and its flat starting unknowns z."""
    prob, z = build_problem(data, params0, config)
    return prob, prob.flatten(z)


def fit_with(data: MeasuredData, params0: CeltParams, config: FitOptions) -> FitResult:
    """`fit` with its configuration as one `FitOptions`."""
    prob, zf = prepare(data, params0, config)
    t_start = time.perf_counter()
    trace = run(prob, zf, config, t_start)
    # (r, J) at the final unknowns: the optimiser's own evaluation there, else one more
    r, J = trace.final if trace.final is not None else evaluate(prob, np.asarray(trace.zf))
    return make_result(prob, trace, r, J, config, t_start)
