"""Fitting strategies built on `jaxcelt.identify.api.fit`: growing spans (`fit_staged`), several starts
(`multistart`, with `random_guesses`), and the profile likelihood of one parameter (`profile_likelihood`).

Each takes the fit's configuration as `fit`'s keywords (``**fit_kw``), which may include ``options=FitOptions(...)``;
keywords given with it override its fields.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt.identify.api import fit_with, prepare
from jaxcelt.identify.optimisers import run_batch
from jaxcelt.identify.options import LSQ_OPTIMISERS, NOT_FREE, FitOptions
from jaxcelt.identify.problem import STATE_SCALE
from jaxcelt.identify.program import evaluate
from jaxcelt.identify.records import MeasuredData
from jaxcelt.identify.result import FitResult, make_result
from jaxcelt.identify.transforms import transform_of
from jaxcelt.physics.params import PARAM_NAMES, CeltParams
from jaxcelt.physics.state import project_state

__all__ = ["fit_staged", "multistart", "random_guesses", "profile_likelihood"]


def config_of(fit_kw: dict[str, Any]) -> FitOptions:
    """The `FitOptions` of `fit`'s keywords ``fit_kw``: ``options`` if given, with the other keywords replacing its
    fields."""
    kw = dict(fit_kw)
    base = kw.pop("options", None)
    if base is None:
        return FitOptions(**kw)
    if not isinstance(base, FitOptions):
        raise ValueError(f"options must be a FitOptions, got {type(base).__name__}")
    return base.replace(**kw) if kw else base


# ----------------------------------------------------------------------------- growing spans
def _truncate(data: MeasuredData, t_end: float) -> MeasuredData:
    trs = []
    for tr in data.trajectories:
        keep = tr.ts <= tr.ts[0] + t_end + 1e-9
        trs.append(dataclasses.replace(tr, ts=tr.ts[keep], obs={k: v[keep] for k, v in tr.obs.items()}))
    return MeasuredData(tuple(trs), data.meta)


def fit_staged(data: MeasuredData, params0: CeltParams, spans: Sequence[float], **fit_kw) -> FitResult:
    """`fit` on the first ``spans[0]`` seconds of every record, then on longer spans, each fit
    started from the last one's parameters, release states (``fit_y0``), sensor rotation and time
    offsets. Over a short span the loss is nearly quadratic in a roughly known release and in the
    offsets, which over the whole record would trap the fit in a local minimum (measured in
    ``scripts/fit_sensor_study.py``). Returns the last fit (make the last span cover the records),
    with every stage's iterations, loss and times in ``stages``."""
    if not spans or any(not (s > 0) for s in spans):
        raise ValueError(f"fit_staged: spans must be positive durations [s], got {spans!r}")
    config = config_of(fit_kw)
    p, res = params0, None
    y0s = [tr.y0 for tr in data.trajectories]
    stages: list[dict[str, Any]] = []
    for span in spans:
        d = _truncate(data, float(span))
        d = MeasuredData(tuple(dataclasses.replace(tr, y0=y) for tr, y in zip(d.trajectories, y0s)), d.meta)
        res = fit_with(d, p, config)
        stages.append(
            dict(span=float(span), n_iter=res.n_iter, loss=res.loss, converged=res.converged,
                 compile_time=res.compile_time, wall_time=res.wall_time)
        )  # fmt: skip
        p = res.params
        config = config.replace(sensor_rotation=res.nuisance["rotation_vector"], time_offset=res.nuisance["time_offset"])
        if config.fit_y0:
            states = np.asarray(res.z["states"])[:, 0] * STATE_SCALE
            y0s = [np.asarray(project_state(jnp.asarray(s), p)) for s in states]
    res.stages = stages
    return res


# ----------------------------------------------------------------------------- multi-start, profile likelihood
def multistart(
    data: MeasuredData,
    params0: CeltParams,
    guesses: Sequence[dict[str, float]],
    *,
    vmapped: bool | None = None,
    **fit_kw,
) -> tuple[FitResult, dict[str, Any]]:
    """Fits from several initial guesses; returns the best (lowest loss) and a summary.

    With a least-squares optimiser (``"lm"``, ``"gn"``, ``"gn-damped"``) and ``vmapped=True`` every
    start iterates at once: one vmapped optimiser step per iteration, and the ODE solves of all
    starts in one vmapped program per iteration; a start that has terminated keeps its iterate
    while the others go on. ``guesses``: dicts of starting values of free parameters (the others,
    the problem's fixed values and multiple-shooting window states, from ``params0``); the returned
    fits share the batch's timings. Otherwise (``vmapped=False``, optax optimisers) the fits run one
    after another, sharing one compilation; there a guess may also set fixed parameters. Default
    (None): vmapped on an accelerator, one after another on the CPU, where a vmapped adaptive solve
    steps every start until the stiffest is done (measured 2x slower for 8 starts on 2 cores,
    ``benchmarks/bench_multistart.py``). ``fit_kw``: as for `fit` (``callback`` receives the
    lowest loss over the starts).

    Summary: per fit its start, values, loss, converged; per parameter the spread (min, max) over
    the converged fits whose loss is within 1e-6 relative of the best (the fits that found the same
    optimum) and how many did; ``vmapped``, ``compile_time`` and ``wall_time`` [s] of the whole call.
    """
    if not guesses:
        raise ValueError("multistart: 'guesses' is empty")
    t0 = time.perf_counter()
    config = config_of(fit_kw)
    if vmapped is None:
        vmapped = jax.default_backend() != "cpu"
    vmapped = bool(vmapped) and config.optimiser in LSQ_OPTIMISERS
    if vmapped:
        results = _fit_batch(data, params0, guesses, config)
        compile_time = results[0].compile_time
    else:
        results = [fit_with(data, params0.replace(**g), config) for g in guesses]
        compile_time = results[0].compile_time
    best = min(results, key=lambda r: r.loss if np.isfinite(r.loss) else np.inf)
    same = [r for r in results if r.converged and abs(r.loss - best.loss) <= 1e-6 * abs(best.loss) + 1e-12]
    summary = dict(
        fits=[
            dict(start=dict(g), values=r.values, loss=r.loss, converged=r.converged, n_iter=r.n_iter)
            for g, r in zip(guesses, results, strict=True)
        ],
        n_at_best=len(same),
        spread={n: (min(r.values[n] for r in same), max(r.values[n] for r in same)) for n in best.free} if same else {},
        vmapped=vmapped,
        compile_time=compile_time,
        wall_time=time.perf_counter() - t0 - compile_time,
    )
    return best, summary


def random_guesses(
    params0: CeltParams,
    n: int,
    *,
    free: Sequence[str] = ("mu", "k_r", "b_Ts", "m_Ts"),
    transforms: dict[str, Any] | None = None,
    spread: float = float(np.log(2.0)),
    seed: int = 0,
) -> list[dict[str, float]]:
    """``n`` starting guesses for `multistart`: the start itself (``{}``) and ``n - 1`` guesses with
    the unknown coordinates z of the free parameters drawn uniformly in [-spread, spread] (seeded),
    i.e. within a factor e^spread (default 2) of ``params0`` for positive parameters, and inside
    the range of a `Bounded` one."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"random_guesses: n must be a positive int, got {n!r}")
    if not (np.isfinite(spread) and spread > 0):
        raise ValueError(f"random_guesses: spread must be positive, got {spread!r}")
    for name in free:
        if name not in PARAM_NAMES or name in NOT_FREE:
            raise ValueError(f"random_guesses: {name!r} is not a parameter that can be fitted")
    rng = np.random.default_rng(seed)
    out: list[dict[str, float]] = [{}]
    for _ in range(n - 1):
        g = {}
        for name in free:
            tr = transform_of(name, transforms)
            th0 = jnp.asarray(float(getattr(params0, name)))
            g[name] = float(tr.forward(jnp.asarray(rng.uniform(-spread, spread)), th0))
        out.append(g)
    return out


def _fit_batch(
    data: MeasuredData, params0: CeltParams, guesses: Sequence[dict[str, float]], config: FitOptions
) -> list[FitResult]:
    """Least-squares fits from every guess at once (see `multistart`)."""
    prob, zf0 = prepare(data, params0, config)
    free = prob.free
    starts = np.repeat(np.asarray(zf0)[None], len(guesses), axis=0)
    for i, g in enumerate(guesses):
        for name, v in g.items():
            if name not in free:
                raise ValueError(f"multistart: guess {i} sets {name!r}, which is not a free parameter {free}")
            j = free.index(name)
            zj = float(prob.transforms[j].inverse(jnp.asarray(float(v)), prob.theta0[j]))
            if not np.isfinite(zj):
                raise ValueError(f"multistart: guess {i}: {name} = {v!r} is outside the range of its transform")
            starts[i, j] = zj
    t_start = time.perf_counter()
    traces = run_batch(prob, starts, config, t_start)
    r, J = evaluate(prob, np.stack([t.zf for t in traces]))
    return [make_result(prob, t, r[i], J[i], config, t_start) for i, t in enumerate(traces)]


def profile_likelihood(
    data: MeasuredData, result: FitResult, name: str, values: Sequence[float], **fit_kw
) -> dict[str, Any]:
    """Profile of the loss over one parameter: for each fixed value, the other free parameters are
    re-fitted (started from ``result``). With Gaussian noise, 2 (loss(v) - loss_min) / s^2 is
    asymptotically chi^2_1; the 95 % profile interval is where it stays below 3.84. Compare it with
    the Gauss-Newton interval ``result.ci95[name]``: agreement means the quadratic (linearised)
    picture holds; a lopsided or wider profile flags weak, nonlinear identification.

    Returns dict(values, loss, delta = 2 (loss - min loss)/s^2, interval (lo, hi) from linear
    interpolation of the 3.84 crossings (NaN where the grid does not cross), ci95_gauss_newton).
    """
    if name not in result.free:
        raise ValueError(f"profile_likelihood: {name!r} is not a free parameter of the fit ({result.free})")
    others = tuple(n for n in result.free if n != name)
    if not others:
        raise ValueError("profile_likelihood: needs at least two free parameters")
    config = config_of(fit_kw)
    config = config.replace(free=fit_kw.get("free", others), uncertainty=fit_kw.get("uncertainty", False))
    losses = []
    for v in values:
        r = fit_with(data, result.params.replace(**{name: float(v)}), config)
        losses.append(r.loss)
    vals, losses = np.asarray(values, float), np.asarray(losses)
    lmin = min(float(losses.min()), result.loss)
    delta = 2 * (losses - lmin) / result.s2
    lo = hi = np.nan
    below = delta <= 3.84
    i_best = int(np.argmin(delta))
    for i in range(i_best, 0, -1):  # left crossing
        if below[i] and not below[i - 1]:
            lo = float(np.interp(3.84, [delta[i], delta[i - 1]], [vals[i], vals[i - 1]]))
            break
    for i in range(i_best, len(vals) - 1):  # right crossing
        if below[i] and not below[i + 1]:
            hi = float(np.interp(3.84, [delta[i], delta[i + 1]], [vals[i], vals[i + 1]]))
            break
    return dict(
        name=name,
        values=vals.tolist(),
        loss=losses.tolist(),
        delta=delta.tolist(),
        interval=(lo, hi),
        ci95_gauss_newton=tuple(result.ci95[name]),
    )
