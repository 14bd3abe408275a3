"""The sweeps: lanes of the engine over parameter values and starts, as results or datasets.

A *lane* is one (parameter values, initial condition) pair. For every lane the stone is
integrated for ``transient_periods`` forcing periods T = 2 pi / omega_pi (eq. 17) and then
sampled stroboscopically at t_k = t0 + (transient_periods + k) T, k = 0 .. sample_periods-1.
The samples are solver states, not interpolants: the stepper steps exactly onto every t_k
(as `jaxcelt.simulate` with ``exact_ts=True``, diffrax's ``ClipStepSizeController(step_ts=ts)``).

* `sweep`: one `CeltParams` field over values, from one or several starts -> `SweepResult`;
* `bifurcation`: `sweep` over omega_pi (the paper's Fig. 3);
* `parameter_map`: a grid of two fields -> `xarray.Dataset` with regime labels;
* `sweep_lanes`: any batch of lanes (parameters and start per lane) -> `xarray.Dataset`.

All take their settings as one `jaxcelt.sweeps.options.SweepOptions` (``options=``) or as its
fields as keywords. How the lanes run -- chunks, resume, devices, processes -- is
`jaxcelt.sweeps.driver`; the dataset files are `jaxcelt.sweeps.dataset`.
"""

from __future__ import annotations

from typing import Any

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from jaxcelt.ensemble.stroboscopic import lanes_params
from jaxcelt.physics.params import PARAM_NAMES, CeltParams
from jaxcelt.physics.state import initial_state
from jaxcelt.sweeps.driver import run_batch
from jaxcelt.sweeps.options import SweepOptions, resolve_options
from jaxcelt.sweeps.result import SweepResult

__all__ = ["sweep", "bifurcation", "parameter_map", "sweep_lanes", "starts_per_value"]


def starts_per_value(params: CeltParams, y0: Any, n_values: int) -> np.ndarray:
    """The starts of every value: y0 None (at rest, `initial_state`), (13,), (K, 13) or (n_values, K, 13)
    -> (n_values, K, 13)."""
    if y0 is None:
        y0 = initial_state(params)
    y = np.asarray(y0, dtype=np.float64)
    if y.ndim == 1:
        y = y[None]
    if y.ndim == 2:
        y = np.broadcast_to(y[None], (n_values, *y.shape))
    if y.ndim != 3 or y.shape[0] != n_values or y.shape[2] != 13:
        raise ValueError(f"y0 must have shape (13,), (K, 13) or (n_values, K, 13); got {np.shape(y0)}")
    return np.ascontiguousarray(y)


def _checked_values(name: str, values: Any, params: CeltParams) -> np.ndarray:
    if name not in PARAM_NAMES:
        raise ValueError(f"unknown parameter {name!r}; known: {PARAM_NAMES}")
    v = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if v.ndim != 1 or v.size == 0:
        raise ValueError(f"values of {name!r} must be a non-empty 1-D array, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"values of {name!r} must be finite")
    return v


def _batched_params(params: CeltParams, lane_values: dict[str, np.ndarray]) -> CeltParams:
    names = list(lane_values)
    pb = lanes_params(params, names[0], lane_values[names[0]])
    for n in names[1:]:
        pb = eqx.tree_at(lambda p, n=n: getattr(p, n), pb, jnp.asarray(lane_values[n], jnp.float64))
    return pb


def sweep_lanes(
    params: CeltParams,
    lanes: dict[str, Any],
    *,
    y0: Any = None,
    options: SweepOptions | None = None,
    **keywords: Any,
) -> Any:
    """Any batch of lanes: lane i has the parameters ``{name: values[i]}`` (others from ``params``)
    and the start ``y0[i]``; the same engine, sampling and options as `sweep`.

    Args:
        lanes: ``{name: (L,) values}`` for any `CeltParams` fields (e.g. random draws of
            ``omega_pi``, ``q_pi`` and ``mu`` together); ``{}`` with ``y0`` (L, 13) varies the start only.
        y0: None (at rest, `initial_state`), (13,) for every lane, or (L, 13) one per lane.
        options, keywords: as `sweep` (`jaxcelt.sweeps.options.SweepOptions`).

    Returns:
        `xarray.Dataset` with dims ``(lane, sample, state)``: the variables of a sweep dataset and
        the regime labels, each varied parameter a coordinate along ``lane``; with ``out`` also
        written to ``out/sweep.nc``. In a multi-process run, process 0 returns it, the others None.
    """
    opts = resolve_options(options, keywords, caller="sweep_lanes")
    cfg = opts.config()
    if not isinstance(lanes, dict):
        raise ValueError(f"lanes must be a dict {{parameter name: values}}, got {type(lanes).__name__}")
    vals = {n: _checked_values(n, v, params) for n, v in lanes.items()}
    sizes = {len(v) for v in vals.values()}
    y = None if y0 is None else np.asarray(y0, dtype=np.float64)
    if y is not None and y.ndim == 2:
        sizes.add(y.shape[0])
    if len(sizes) != 1:
        raise ValueError(f"lanes: every parameter's values and y0 (L, 13) need the same length, got {sorted(sizes)}")
    L = sizes.pop()
    if y is None or y.ndim == 1:
        y = np.tile(starts_per_value(params, y, 1)[0, 0], (L, 1))
    if y.shape != (L, 13) or not np.all(np.isfinite(y)):
        raise ValueError(f"y0 must be finite with shape (13,) or ({L}, 13), got {np.shape(y0)}")
    for i in range(L):  # every lane's parameters must be valid (ValueError naming the field)
        params.replace(**{n: float(v[i]) for n, v in vals.items()})
    if not vals:  # starts only: omega_pi rides along (the engine needs one lane-varying leaf)
        vals = {"omega_pi": np.full(L, float(params.omega_pi))}
    names = list(vals)
    lane_values = np.stack([vals[n] for n in names], axis=1)
    lanes_out, writer = run_batch(
        _batched_params(params, vals), np.ascontiguousarray(y), cfg, params=params, names=names,
        lane_values=lane_values, n_starts=1, options=opts, desc="lanes",
    )  # fmt: skip
    if lanes_out is None:
        return None
    from jaxcelt.sweeps.dataset import to_lanes_dataset

    ds = to_lanes_dataset(lanes_out, lane_values=vals, params=params, config=cfg)
    if writer is not None:
        writer.write_dataset(ds)
    return ds


def sweep(
    params: CeltParams,
    name: str,
    values: Any,
    *,
    y0: Any = None,
    options: SweepOptions | None = None,
    **keywords: Any,
) -> SweepResult | None:
    """Sweep the scalar parameter ``name`` of `CeltParams` over ``values`` (stroboscopic sampling).

    Args:
        params: base parameters; field ``name`` is replaced by each value.
        name: any `CeltParams` field (``"omega_pi"``, ``"q_pi"``, ``"mu"``, ...).
        values: 1-D array of values (L_v,).
        y0: initial state(s): None (at rest on the base, `initial_state`), (13,), (K, 13)
            (multi-start: every value from each of K states) or (L_v, K, 13).
        options: a `jaxcelt.sweeps.options.SweepOptions`; or its fields as keywords
            (``transient_periods=200``, ``sample_periods=100``, ``lyapunov_periods=0``, ``rtol``, ``atol``,
            ``max_steps``, ``solver``, ``contact_law``, ``t0``, ``stop_on_invalid``, ``dtype``, ``chunk_size``,
            ``sort_by_cost``, ``width``, ``engine``, ``devices``, ``out``, ``progress``, ``on_chunk``), which
            replace the fields of ``options`` when both are given.

    Returns:
        `SweepResult` with lane arrays reshaped to (L_v, K, ...) when y0 has K starts, else (L_v, ...).
        In a multi-process run (`jax.distributed`), process 0 returns it and the others None.
    """
    opts = resolve_options(options, keywords, caller="sweep")
    cfg = opts.config()
    values = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if values.ndim != 1 or values.size == 0:
        raise ValueError(f"values must be a non-empty 1-D array, got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        raise ValueError("values must be finite")
    params.replace(**{name: values.min()})  # validates the range ends (raises ValueError naming the field)
    params.replace(**{name: values.max()})
    multi = y0 is not None and np.ndim(y0) >= 2
    y0v = starts_per_value(params, y0, len(values))
    Lv, K = y0v.shape[:2]
    lane_values = np.repeat(values, K)
    lane_y0 = y0v.reshape(Lv * K, 13)
    lanes, writer = run_batch(
        lanes_params(params, name, lane_values), lane_y0, cfg, params=params, names=[name], lane_values=lane_values,
        n_starts=K, options=opts, desc=f"sweep {name}",
    )  # fmt: skip
    if lanes is None:  # a process other than 0 of a multi-process sweep: its chunks are on disk
        return None
    merged = {k: v.reshape((Lv, K, *v.shape[1:])) if multi else v for k, v in lanes.items()}
    vals = lane_values.reshape(Lv, K) if multi else lane_values
    result = SweepResult(name=name, values=vals, **merged)
    if writer is not None:
        writer.finalize(result)
    return result


def bifurcation(
    params: CeltParams,
    omega_pi_values: Any,
    *,
    y0: Any = None,
    options: SweepOptions | None = None,
    **keywords: Any,
) -> SweepResult | None:
    """Bifurcation diagram data over the forcing frequency omega_pi [rad/s] (the paper's Fig. 3).

    ``sweep(params, "omega_pi", omega_pi_values, ...)``; see `sweep` and
    `jaxcelt.sweeps.options.SweepOptions` for the options. Plot
    ``result.samples[..., 4]`` (omega_2 at the section) against ``result.values``.
    """
    return sweep(params, "omega_pi", omega_pi_values, y0=y0, options=options, **keywords)


def parameter_map(
    params: CeltParams,
    x: tuple[str, Any],
    y: tuple[str, Any],
    *,
    y0: Any = None,
    options: SweepOptions | None = None,
    **keywords: Any,
) -> Any:
    """Two-parameter chart (regimes, Lyapunov exponent) over a grid of two `CeltParams` fields.

    Every grid point (x_i, y_j) (and every start) is one lane of the same engine as `sweep`:
    the same stroboscopic sampling, pool, chunked resumable writing (``out``) and sharding,
    so a lane equals the `bifurcation`/`sweep` lane with the same parameters (to the rounding
    of another compiled program, see the module docstring).

    Args:
        params: base parameters.
        x, y: ``(name, values)``: a `CeltParams` field and its 1-D values, e.g.
            ``("omega_pi", np.linspace(10, 20, 100))``, ``("q_pi", np.linspace(0.02, 0.06, 60))``.
        y0: None (at rest), (13,) or (K, 13) starts (every grid point from each).
        options, keywords: as `sweep` (`jaxcelt.sweeps.options.SweepOptions`; ``sort_by_cost`` orders
            lanes by 1/omega_pi).

    Returns:
        `xarray.Dataset` with dims ``(x_name, y_name, [start,] sample, state)``: the variables of
        a sweep dataset (`jaxcelt.sweeps.dataset`: section samples, status, validity, ``lyapunov``
        [1/s] if ``lyapunov_periods > 0``, NaN otherwise) and the regime labels ``regime``,
        ``period``, ``global_motion`` (`jaxcelt.sweeps.regimes`). With ``out`` it is also written to
        ``out/sweep.nc``. In a multi-process run (`jax.distributed`), process 0 returns it and
        the others None.
    """
    opts = resolve_options(options, keywords, caller="parameter_map")
    cfg = opts.config()
    for arg, spec in (("x", x), ("y", y)):
        if not (isinstance(spec, tuple | list) and len(spec) == 2 and isinstance(spec[0], str)):
            raise ValueError(f"{arg} must be a (parameter name, values) pair, got {spec!r}")
    (xn, xv), (yn, yv) = x, y
    if xn == yn:
        raise ValueError(f"x and y must be different parameters, both are {xn!r}")
    xs, ys = _checked_values(xn, xv, params), _checked_values(yn, yv, params)
    for a in (xs.min(), xs.max()):  # validates the grid's corners (ValueError naming the field)
        for b in (ys.min(), ys.max()):
            params.replace(**{xn: a, yn: b})
    multi = y0 is not None and np.ndim(y0) >= 2
    y0v = starts_per_value(params, y0, 1)[0]  # (K, 13)
    K = y0v.shape[0]
    nx, ny = len(xs), len(ys)
    lane_x = np.repeat(xs, ny * K)
    lane_y = np.tile(np.repeat(ys, K), nx)
    lane_y0 = np.ascontiguousarray(np.tile(y0v, (nx * ny, 1)))
    lanes, writer = run_batch(
        _batched_params(params, {xn: lane_x, yn: lane_y}), lane_y0, cfg, params=params, names=[xn, yn],
        lane_values=np.stack([lane_x, lane_y], axis=1), n_starts=K, options=opts,
        desc=f"map {xn} x {yn}",
    )  # fmt: skip
    if lanes is None:  # a process other than 0 of a multi-process map
        return None
    from jaxcelt.sweeps.dataset import to_map_dataset

    shape = (nx, ny, K) if multi else (nx, ny)
    lanes = {k: v.reshape(shape + v.shape[1:]) for k, v in lanes.items()}
    ds = to_map_dataset(lanes, x=(xn, xs), y=(yn, ys), n_starts=K if multi else 0, params=params, config=cfg)
    if writer is not None:
        writer.write_dataset(ds)
    return ds
