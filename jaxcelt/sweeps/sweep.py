"""Parameter sweeps: bifurcation diagrams, continuation, multi-start, chunking and sharding.

A *lane* is one (parameter value, initial condition) pair. For every lane the stone is
integrated for ``transient_periods`` forcing periods T = 2 pi / omega_pi (eq. 17) and then
sampled stroboscopically at t_k = t0 + (transient_periods + k) T, k = 0 .. sample_periods-1.
The samples are solver states, not interpolants: `jaxcelt.simulate` is called with
``exact_ts=True`` (diffrax's ``ClipStepSizeController(step_ts=ts)``), so the controller
steps exactly onto every t_k.

Execution model
---------------
* Lanes are processed in chunks of ``chunk_size`` (the unit of resumable writing). A chunk
  runs as **one** jitted while loop over ``width``
  batch slots (`jaxcelt.ensemble.run_pool`): each iteration makes one step in every slot, and a slot whose lane
  finished is refilled with the next lane at once. Step slots are therefore only wasted in
  the final drain, not for every lane until the slowest one is done. The step is the
  algorithm of diffrax's loop body (PID + ClipStepSizeController, the same first-step
  choice, the validity monitor): for explicit FSAL Runge-Kutta solvers (Tsit5, the default;
  Dopri5, Dopri8, ...) written out as one fused step (`jaxcelt.ensemble.FusedERKStepper`: the monitor reads N
  from the step's last evaluation, stage inputs are materialised once, lane-constant
  parameters stay out of the slots), otherwise diffrax's own step (`jaxcelt.ensemble.DiffraxStepper`). A Tsit5
  lane equals `jaxcelt.simulate` to rounding with the same step count (tests); with
  Dopri8, whose error weights cancel strongly, rounding moves the step-size sequence
  slightly (a few steps in ~400, samples ~1e-9 apart at rtol 1e-7). Lane order (and hence
  slot assignment) is fixed and the per-lane arithmetic does not depend on the slot, so
  results are deterministic and a lane's result does not depend on its neighbours (a lane
  that hits ``max_steps`` is flagged and the others are unchanged: same steps and status,
  samples to rounding). What is guaranteed, and tested: a lane gives the same step count and
  status and samples equal to ~1e-10 over a few periods whatever the pool width, device count,
  schedule or neighbours; bitwise only when the *same* compiled program runs again on the same
  machine (a resumed sweep). Two different compiled programs (another width, device count, or a
  CPU with another vector ISA, AVX2 vs AVX-512) may round differently, and over hundreds of
  periods chaotic lanes then diverge from that seed like any other perturbation.
  When lanes queue for slots, every lane first runs a tenth of its time span
  (`PILOT_FRACTION`) and pauses between two steps; paused lanes wait with their predicted
  remaining cost (steps so far x remaining / elapsed span) and free slots take them costliest
  first (longest-processing-time order), so the drain runs on short lanes. A pause does not
  change a lane: it resumes with the same state and step sequence (tested to rounding).
  ``sort_by_cost=True`` orders lanes by the cost proxy 1/omega_pi (time span of a period),
  longest first. The optional Lyapunov stage then runs
  vmapped over the successful lanes in groups of ``width`` ordered by the measured
  main-solve step count.
* ``stop_on_invalid=True`` ends a lane at the first accepted step whose end state is
  invalid (lift-off N <= 0, n3 <= 0, denominator <= 0; the model does not hold past it):
  status 2, samples after the stop inf, no Lyapunov exponent. Default False (integrate on
  and report where validity was lost), as in `simulate`.
* Chunks are sharded over all local JAX devices with `jax.shard_map` on a 1-D
  ``Mesh(jax.local_devices(), ("lanes",))``: each device runs its own vmapped solve over its
  slice of the chunk (no cross-device synchronisation inside the time loop). The chunk is
  padded to a multiple of the device count with copies of its last lane (discarded).
  On CPU one XLA computation uses about one core, so split the CPU into K devices *before*
  the first JAX operation: ``jax.config.update("jax_num_cpu_devices", K)`` (or
  ``XLA_FLAGS=--xla_force_host_platform_device_count=K``); the CLI does this by default
  (``--host-devices auto`` = number of cores). Measured on 2 cores: 400 x 300 periods in
  3.69 s on 2 devices vs 7.9 s on 1 (stopping at invalid states, compile apart;
  docs/bifurcation/bench_sweep_400x300.json). Results agree with the
  1-device run to ~1e-11 over a few periods (tests), not bitwise (a different compiled
  program): over hundreds of periods chaotic lanes diverge from that seed like any other.
  The devices of one process share XLA's CPU thread pool; ``devices=HostProcesses("auto")``
  (`jaxcelt.ensemble.processes`; ``--host-processes auto``) runs the lanes in one pinned
  single-device worker process per core instead (no shared pool; how the two compare is
  measured in docs/bifurcation/processes.json).

Multi-host (several processes or machines, each with local devices)
-------------------------------------------------------------------
Call ``jax.distributed.initialize(...)`` at the start of every process (on SLURM, with no
arguments: it reads the job's environment), then make the *same* call -- `sweep`,
`bifurcation` or `parameter_map` with the same ``out``, a directory all processes share --
in every process. Process i computes the chunks whose index is i mod ``jax.process_count()``
(each over its *local* devices; hosts never wait for each other inside a chunk) and writes
them to ``out/chunks``; after a barrier (`jax.experimental.multihost_utils.sync_global_devices`)
process 0 reads them all back, writes ``out/sweep.nc`` and returns the result; the other
processes return None. A chunk is the same computation whichever process runs it, so the
dataset equals a one-process run's (to the rounding of another compiled program if the
processes have other device counts; tested with 2 processes on one machine). An interrupted
multi-process sweep resumes like any other, with any number of processes.

Continuation
------------
`continuation` walks the values in order (up, down, or both) and starts each value from the
previous value's final state (the last stroboscopic sample; base phase omega_pi t = 0 mod
2 pi there, so the restart at t0 = 0 is phase consistent), like DynamicalSystems.jl's
default. It is sequential over values but vmapped over several initial conditions.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import compiler_options
from jaxcelt._executable_cache import compile_in_background, compiled
from jaxcelt.ensemble import DEFAULT_WIDTH as DEFAULT_WIDTH
from jaxcelt.ensemble import MIN_DRAIN_WIDTH as MIN_DRAIN_WIDTH
from jaxcelt.ensemble import PILOT_FRACTION as PILOT_FRACTION
from jaxcelt.ensemble.stroboscopic import SweepConfig, check_engine, lanes_params, run_lanes, run_lanes_with_stats
from jaxcelt.ensemble.stroboscopic import _erk_tableau as _erk_tableau  # noqa: F401  (tests)
from jaxcelt.integrate.solve import DEFAULT_SOLVER, simulate
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.diagnostics import centre_position
from jaxcelt.physics.params import PARAM_NAMES, CeltParams
from jaxcelt.physics.state import check_state, initial_state

__all__ = [
    "SweepConfig",
    "SweepResult",
    "bifurcation",
    "sweep",
    "continuation",
    "lanes_params",
    "parse_range",
    "orbit",
    "prepare_orbit",
    "run_lanes",
    "run_lanes_with_stats",
    "parameter_map",
    "sweep_lanes",
]


class SweepResult(eqx.Module):
    """Per-lane results of a sweep (numpy arrays; leading axis = lanes, or (values, starts)).

    Attributes (L = lanes, S = sample_periods):
        values: swept parameter value per lane, (L,)
        t_samples: stroboscopic times [s], (L, S)
        samples: states at the section, (L, S, 13) (inf after a failed solve or a stop at an
            invalid state)
        y_final: last sample (L, 13) -- the start of a continuation step
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


_LANE_FIELDS = tuple(f.name for f in dataclasses.fields(SweepResult) if f.name != "name")


def parse_range(spec: str) -> np.ndarray:
    """``"10:20:400"`` -> 400 values from 10 to 20 inclusive; ``"14,15.6,17"`` -> a list."""
    if ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise ValueError(f"range {spec!r} must be START:STOP:COUNT")
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
        if n < 1:
            raise ValueError(f"range {spec!r}: COUNT must be >= 1")
        return np.linspace(a, b, n)
    return np.array([float(s) for s in spec.split(",") if s.strip()])


# --------------------------------------------------------------------------------------
# Stroboscopic lanes on the lane engine (`jaxcelt.ensemble`): section times, the jitted
# chunk (pool, per-lane outputs, global motion), sharding over devices, the Lyapunov stage.
# --------------------------------------------------------------------------------------


def _broadcast_y0(params: CeltParams, y0: Any, n_values: int) -> np.ndarray:
    """y0: None (rest), (13,) or (K, 13) -> (n_values, K, 13)."""
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


def _sweep_config(
    transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0, stop_on_invalid,
    dtype="float64",
) -> SweepConfig:
    return SweepConfig(
        transient_periods=int(transient_periods),
        sample_periods=int(sample_periods),
        lyapunov_periods=int(lyapunov_periods),
        rtol=float(rtol),
        atol=float(atol),
        max_steps=int(max_steps),
        solver=solver if solver is not None else DEFAULT_SOLVER,
        contact_law=contact_law,
        t0=float(t0),
        stop_on_invalid=bool(stop_on_invalid),
        dtype=_dtype_name(dtype),
    )


def _dtype_name(dtype: Any) -> str:
    try:
        name = np.dtype(dtype).name
    except TypeError:
        name = None
    if name not in ("float64", "float32"):
        raise ValueError(f"dtype must be float64 or float32, got {dtype!r}")
    return name


def _run_chunked(
    pb_all: CeltParams,
    lane_y0: np.ndarray,
    cfg: SweepConfig,
    chunks: list[np.ndarray],
    pad_to: int,
    writer: Any,
    done: dict[int, dict[str, np.ndarray]],
    *,
    devices: Sequence[Any] | None,
    width: int | None,
    varying: Sequence[str],
    progress: bool,
    engine: str = "auto",
    desc: str,
    on_chunk: Callable[[int, dict[str, np.ndarray]], None] | None,
    skip: Callable[[int], bool] = lambda ci: False,
) -> dict[str, np.ndarray] | None:
    """Run the chunks of lanes not in ``done`` (each written by ``writer`` if given) and return
    every lane's results in lane order, (L, ...) per field of `SweepResult` but ``values``.

    ``skip(ci)``: chunks left to another process (multi-process sweeps); if any chunk is
    neither done nor computed here, returns None."""
    L = lane_y0.shape[0]
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=L, unit="lane", desc=desc, initial=sum(len(chunks[i]) for i in done))
    results: dict[int, dict[str, np.ndarray]] = dict(done)
    for ci, idx in enumerate(chunks):
        if ci in results or skip(ci):
            continue
        pb = jax.tree_util.tree_map(lambda x, idx=idx: np.asarray(x)[idx], pb_all)
        t_start = time.perf_counter()
        res = run_lanes(
            pb, lane_y0[idx], cfg, devices=devices, pad_to=pad_to, width=width, varying=varying, engine=engine
        )
        res["_seconds"] = np.full(len(idx), (time.perf_counter() - t_start) / len(idx))
        results[ci] = res
        if writer is not None:
            writer.write_chunk(ci, res)
        if on_chunk is not None:
            on_chunk(ci, res)
        if bar is not None:
            bar.update(len(idx))
    if bar is not None:
        bar.close()
    if len(results) < len(chunks):
        return None
    merged: dict[str, np.ndarray] = {}
    for key in _LANE_FIELDS:
        if key == "values":
            continue
        cat = np.concatenate([results[ci][key] for ci in range(len(chunks))], axis=0)
        full = np.empty_like(cat)
        full[np.concatenate(chunks)] = cat
        merged[key] = full
    return merged


def _run_all(
    pb_all: CeltParams,
    lane_y0: np.ndarray,
    cfg: SweepConfig,
    chunks: list[np.ndarray],
    pad_to: int,
    writer: Any,
    done: dict[int, dict[str, np.ndarray]],
    **kwargs,
) -> dict[str, np.ndarray] | None:
    """`_run_chunked`, split over the processes of a `jax.distributed` run when there are several.

    Process i computes the chunks with index = i (mod process count) and writes them into the
    shared ``out`` directory; after a barrier (`multihost_utils.sync_global_devices`) process 0
    reads every chunk back (recomputing any that is missing or damaged) and returns the lanes;
    the other processes return None."""
    pc, pi = jax.process_count(), jax.process_index()
    if pc == 1:
        return _run_chunked(pb_all, lane_y0, cfg, chunks, pad_to, writer, done, **kwargs)
    if writer is None:
        raise ValueError("a sweep over several processes (jax.distributed) needs out= (a directory they all share)")
    from jax.experimental import multihost_utils

    _run_chunked(pb_all, lane_y0, cfg, chunks, pad_to, writer, done, skip=lambda ci: ci % pc != pi, **kwargs)
    multihost_utils.sync_global_devices(f"jaxcelt sweep {writer.fingerprint[:16]}: chunks written")
    if pi != 0:
        return None
    return _run_chunked(pb_all, lane_y0, cfg, chunks, pad_to, writer, writer.load_done(), **kwargs)


def _run_batch(
    pb_all: CeltParams,
    lane_y0: np.ndarray,
    cfg: SweepConfig,
    *,
    params: CeltParams,
    names: Sequence[str],
    lane_values: np.ndarray,
    n_starts: int,
    chunk_size: int | None,
    sort_by_cost: bool,
    devices: Sequence[Any] | None,
    width: int | None,
    out: str | None,
    progress: bool,
    engine: str = "auto",
    on_chunk: Callable[[int, dict[str, np.ndarray]], None] | None,
    desc: str,
) -> tuple[dict[str, np.ndarray] | None, Any]:
    """Chunking, resumable writing and the multi-process split of a batch of lanes, shared by
    `sweep`, `parameter_map` and `sweep_lanes`: (lane results in lane order or None on a process
    other than 0 of a multi-process run, the `jaxcelt.sweeps.dataset.SweepWriter` or None)."""
    if not np.all(np.asarray(pb_all.omega_pi) > 0):
        raise ValueError("stroboscopic sampling needs omega_pi > 0 in every lane")
    check_engine(engine, cfg.solver)
    L = lane_y0.shape[0]
    order = np.arange(L)
    if sort_by_cost:
        order = np.argsort(np.asarray(pb_all.omega_pi), kind="stable")  # longest period first
    cs = L if chunk_size is None else max(1, min(int(chunk_size), L))  # no padding beyond the lanes
    chunks = [order[i : i + cs] for i in range(0, L, cs)]
    writer = None
    done: dict[int, dict[str, np.ndarray]] = {}
    if out is not None:
        from jaxcelt.sweeps.dataset import SweepWriter

        writer = SweepWriter(
            out,
            params=params,
            name=names[0] if len(names) == 1 else list(names),
            lane_values=lane_values,
            lane_y0=lane_y0,
            n_starts=n_starts,
            config=cfg,
            chunks=chunks,
        )
        done = writer.load_done()
    lanes = _run_all(
        pb_all, lane_y0, cfg, chunks, cs, writer, done,
        devices=devices, width=width, varying=tuple(names), progress=progress, desc=desc, on_chunk=on_chunk,
        engine=engine,
    )  # fmt: skip
    return lanes, writer


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
    transient_periods: int = 200,
    sample_periods: int = 100,
    lyapunov_periods: int = 0,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 1_000_000,
    solver: diffrax.AbstractSolver | None = None,
    contact_law: AbstractContactLaw | str | None = None,
    t0: float = 0.0,
    chunk_size: int | None = None,
    sort_by_cost: bool = False,
    stop_on_invalid: bool = False,
    dtype: Any = "float64",
    width: int | None = None,
    engine: str = "auto",
    devices: Sequence[Any] | None = None,
    out: str | None = None,
    progress: bool = False,
    on_chunk: Callable[[int, dict[str, np.ndarray]], None] | None = None,
) -> Any:
    """Any batch of lanes: lane i has the parameters ``{name: values[i]}`` (others from ``params``)
    and the start ``y0[i]``; the same engine, sampling and options as `sweep`.

    Args:
        lanes: ``{name: (L,) values}`` for any `CeltParams` fields (e.g. random draws of
            ``omega_pi``, ``q_pi`` and ``mu`` together); ``{}`` with ``y0`` (L, 13) varies the start only.
        y0: None (at rest, `initial_state`), (13,) for every lane, or (L, 13) one per lane.
        other arguments: as `sweep`.

    Returns:
        `xarray.Dataset` with dims ``(lane, sample, state)``: the variables of a sweep dataset and
        the regime labels, each varied parameter a coordinate along ``lane``; with ``out`` also
        written to ``out/sweep.nc``. In a multi-process run, process 0 returns it, the others None.
    """
    cfg = _sweep_config(
        transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0,
        stop_on_invalid, dtype,
    )  # fmt: skip
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
        y = np.tile(_broadcast_y0(params, y, 1)[0, 0], (L, 1))
    if y.shape != (L, 13) or not np.all(np.isfinite(y)):
        raise ValueError(f"y0 must be finite with shape (13,) or ({L}, 13), got {np.shape(y0)}")
    for i in range(L):  # every lane's parameters must be valid (ValueError naming the field)
        params.replace(**{n: float(v[i]) for n, v in vals.items()})
    if not vals:  # starts only: omega_pi rides along (the engine needs one lane-varying leaf)
        vals = {"omega_pi": np.full(L, float(params.omega_pi))}
    names = list(vals)
    lane_values = np.stack([vals[n] for n in names], axis=1)
    lanes_out, writer = _run_batch(
        _batched_params(params, vals), np.ascontiguousarray(y), cfg, params=params, names=names,
        lane_values=lane_values, n_starts=1, chunk_size=chunk_size, sort_by_cost=sort_by_cost, devices=devices,
        width=width, out=out, progress=progress, on_chunk=on_chunk, desc="lanes", engine=engine,
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
    transient_periods: int = 200,
    sample_periods: int = 100,
    y0: Any = None,
    lyapunov_periods: int = 0,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 1_000_000,
    solver: diffrax.AbstractSolver | None = None,
    contact_law: AbstractContactLaw | str | None = None,
    t0: float = 0.0,
    chunk_size: int | None = None,
    sort_by_cost: bool = False,
    stop_on_invalid: bool = False,
    dtype: Any = "float64",
    width: int | None = None,
    engine: str = "auto",
    devices: Sequence[Any] | None = None,
    out: str | None = None,
    progress: bool = False,
    on_chunk: Callable[[int, dict[str, np.ndarray]], None] | None = None,
) -> SweepResult:
    """Sweep the scalar parameter ``name`` of `CeltParams` over ``values`` (stroboscopic sampling).

    Args:
        params: base parameters; field ``name`` is replaced by each value.
        name: any `CeltParams` field (``"omega_pi"``, ``"q_pi"``, ``"mu"``, ...).
        values: 1-D array of values (L_v,).
        transient_periods, sample_periods: forcing periods T = 2 pi/omega_pi discarded,
            then sampled (section times t0 + (transient + k) T, hit exactly).
        y0: initial state(s): None (at rest on the base, `initial_state`), (13,), (K, 13)
            (multi-start: every value from each of K states) or (L_v, K, 13).
        lyapunov_periods: > 0 also integrates the tangent dynamics for that many periods
            after the transient (`jaxcelt.integrate.lyapunov.celt_lyapunov`) -> ``lyapunov`` [1/s].
        rtol, atol, max_steps, solver, contact_law, t0: as in `jaxcelt.simulate`.
        chunk_size: lanes per jitted solve, the unit of resumable writing (default: all
            lanes in one chunk).
        sort_by_cost: order lanes by the cost proxy (time span per period, 1/omega_pi),
            most expensive first, before chunking (the pool then drains on cheap lanes).
        stop_on_invalid: end each lane at its first invalid state (lift-off, n3 <= 0):
            status 2, samples after the stop inf, no Lyapunov exponent. Default False (the
            model is integrated on, validity reported), as in `jaxcelt.simulate`.
        dtype: the lanes' arithmetic, ``"float64"`` (default) or ``"float32"`` (faster on GPUs;
            use rtol >= 1e-6; results come back as float64 arrays, the Lyapunov stage runs
            in float64). With the explicit solvers' fused step and in the lane kernel the times
            stay float64 and the field gets the forcing phase from one period
            (`jaxcelt.physics.model.field_time`); with other solvers float32 lanes step in float32
            time, and a step below ~10 ULPs of t ends a lane (status 3). Part of the
            dataset's fingerprint.
        width: batch slots per device of the pool (default `DEFAULT_WIDTH`).
        engine: how lanes are stepped (`jaxcelt.ensemble.ENGINES`): ``"auto"`` (default) runs
            them in the lane kernel on a GPU (`jaxcelt.ensemble.kernel`: one thread per lane,
            explicit FSAL solvers) and in the lane pool elsewhere; ``"pool"`` or ``"kernel"`` forces
            one (the kernel off a GPU runs interpreted: slow, for tests). Both take the same steps
            up to rounding.
        devices: devices to shard each chunk over (default all local devices), or a
            `jaxcelt.HostProcesses`: worker processes, one pinned to each CPU core with one
            device each (`jaxcelt.ensemble.processes`).
        out: directory; write the dataset chunk by chunk there and resume a previous,
            interrupted run of the same sweep (`jaxcelt.sweeps.dataset`). Required when several
            processes run the sweep together (`jax.distributed`; see the module docstring).
        progress: tqdm bar over lanes (with ETA).
        on_chunk: ``on_chunk(chunk_index, chunk_results)`` called after each chunk.

    Returns:
        `SweepResult` with lane arrays reshaped to (L_v, K, ...) when y0 has K starts, else (L_v, ...).
        In a multi-process run (`jax.distributed`), process 0 returns it and the others None.
    """
    cfg = _sweep_config(
        transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0,
        stop_on_invalid, dtype,
    )  # fmt: skip
    values = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if values.ndim != 1 or values.size == 0:
        raise ValueError(f"values must be a non-empty 1-D array, got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        raise ValueError("values must be finite")
    params.replace(**{name: values.min()})  # validates the range ends (raises ValueError naming the field)
    params.replace(**{name: values.max()})
    multi = y0 is not None and np.ndim(y0) >= 2
    y0v = _broadcast_y0(params, y0, len(values))
    Lv, K = y0v.shape[:2]
    lane_values = np.repeat(values, K)
    lane_y0 = y0v.reshape(Lv * K, 13)
    lanes, writer = _run_batch(
        lanes_params(params, name, lane_values), lane_y0, cfg, params=params, names=[name], lane_values=lane_values,
        n_starts=K, chunk_size=chunk_size, sort_by_cost=sort_by_cost, devices=devices, width=width, out=out,
        progress=progress, on_chunk=on_chunk, desc=f"sweep {name}", engine=engine,
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
    transient_periods: int = 200,
    sample_periods: int = 100,
    y0: Any = None,
    **kwargs,
) -> SweepResult:
    """Bifurcation diagram data over the forcing frequency omega_pi [rad/s] (the paper's Fig. 3).

    ``sweep(params, "omega_pi", omega_pi_values, ...)``; see `sweep` for all options. Plot
    ``result.samples[..., 4]`` (omega_2 at the section) against ``result.values``.
    """
    return sweep(
        params,
        "omega_pi",
        omega_pi_values,
        transient_periods=transient_periods,
        sample_periods=sample_periods,
        y0=y0,
        **kwargs,
    )


def _checked_values(name: str, values: Any, params: CeltParams) -> np.ndarray:
    if name not in PARAM_NAMES:
        raise ValueError(f"unknown parameter {name!r}; known: {PARAM_NAMES}")
    v = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if v.ndim != 1 or v.size == 0:
        raise ValueError(f"values of {name!r} must be a non-empty 1-D array, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"values of {name!r} must be finite")
    return v


def parameter_map(
    params: CeltParams,
    x: tuple[str, Any],
    y: tuple[str, Any],
    *,
    transient_periods: int = 200,
    sample_periods: int = 100,
    y0: Any = None,
    lyapunov_periods: int = 0,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 1_000_000,
    solver: diffrax.AbstractSolver | None = None,
    contact_law: AbstractContactLaw | str | None = None,
    t0: float = 0.0,
    chunk_size: int | None = None,
    sort_by_cost: bool = False,
    stop_on_invalid: bool = False,
    dtype: Any = "float64",
    width: int | None = None,
    engine: str = "auto",
    devices: Sequence[Any] | None = None,
    out: str | None = None,
    progress: bool = False,
    on_chunk: Callable[[int, dict[str, np.ndarray]], None] | None = None,
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
        other arguments: as `sweep` (``sort_by_cost`` orders lanes by 1/omega_pi).

    Returns:
        `xarray.Dataset` with dims ``(x_name, y_name, [start,] sample, state)``: the variables of
        a sweep dataset (`jaxcelt.sweeps.dataset`: section samples, status, validity, ``lyapunov``
        [1/s] if ``lyapunov_periods > 0``, NaN otherwise) and the regime labels ``regime``,
        ``period``, ``global_motion`` (`jaxcelt.sweeps.regimes`). With ``out`` it is also written to
        ``out/sweep.nc``. In a multi-process run (`jax.distributed`), process 0 returns it and
        the others None.
    """
    cfg = _sweep_config(
        transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0,
        stop_on_invalid, dtype,
    )  # fmt: skip
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
    y0v = _broadcast_y0(params, y0, 1)[0]  # (K, 13)
    K = y0v.shape[0]
    nx, ny = len(xs), len(ys)
    lane_x = np.repeat(xs, ny * K)
    lane_y = np.tile(np.repeat(ys, K), nx)
    lane_y0 = np.ascontiguousarray(np.tile(y0v, (nx * ny, 1)))
    lanes, writer = _run_batch(
        _batched_params(params, {xn: lane_x, yn: lane_y}), lane_y0, cfg, params=params, names=[xn, yn],
        lane_values=np.stack([lane_x, lane_y], axis=1), n_starts=K, chunk_size=chunk_size,
        sort_by_cost=sort_by_cost, devices=devices, width=width, out=out, progress=progress, on_chunk=on_chunk,
        engine=engine,
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


def continuation(
    params: CeltParams,
    name: str,
    values: Any,
    *,
    direction: str = "up",
    transient_periods: int = 100,
    sample_periods: int = 50,
    y0: Any = None,
    progress: bool = False,
    **kwargs,
) -> dict[str, SweepResult]:
    """Continuation sweep: each value starts from the previous value's final state.

    Args:
        direction: ``"up"`` (increasing values), ``"down"`` or ``"both"`` (up, then down
            starting from the up sweep's last state) -- hysteresis and coexisting
            attractors show as differing branches.
        y0: None, (13,) or (K, 13): K starts continued side by side (vmapped).
        other arguments: as `sweep` (``t0`` is 0 for every step; the final state of a step
            sits at a section time, base phase 0, so the restart is phase consistent).

    Returns:
        ``{"up": SweepResult, "down": SweepResult}`` (the requested directions), values in
        sweep order, lane arrays shaped (L_v, K, ...).
    """
    if direction not in ("up", "down", "both"):
        raise ValueError(f"direction must be 'up', 'down' or 'both', got {direction!r}")
    values = np.sort(np.atleast_1d(np.asarray(values, dtype=np.float64)))
    y = _broadcast_y0(params, y0, 1)[0]  # (K, 13)
    out: dict[str, SweepResult] = {}
    dirs = ["up", "down"] if direction == "both" else [direction]
    for d in dirs:
        vs = values if d == "up" else values[::-1]
        steps = []
        it = vs
        if progress:
            from tqdm.auto import tqdm

            it = tqdm(vs, desc=f"continuation {d}", unit="value")
        for v in it:
            r = sweep(
                params,
                name,
                [v],
                transient_periods=transient_periods,
                sample_periods=sample_periods,
                y0=y[None],
                **kwargs,
            )
            steps.append(r)
            ok = r.status[0] == 0
            # a failed step restarts the next value from the last good state
            y = np.where(ok[:, None], r.y_final[0], y)
        merged = {k: np.concatenate([getattr(s, k) for s in steps], axis=0) for k in _LANE_FIELDS}
        out[d] = SweepResult(name=name, **merged)
    return out


def _orbit_program(
    params: CeltParams,
    y0: Any,
    transient_periods: int,
    periods: int,
    points_per_period: int,
    solver: diffrax.AbstractSolver | None,
    rtol: float,
    atol: float,
    max_steps: int,
    contact_law: AbstractContactLaw | str | None,
) -> tuple[Callable, tuple, str, np.ndarray]:
    """`orbit`'s inputs checked, and its program: (function, array arguments, description, save
    times) for `jaxcelt._executable_cache.compiled` (one program per solver, law, step bound and
    number of save times; on a CPU compiled with XLA's loop emitters, as the sweep's Lyapunov stage,
    `jaxcelt._compile_options`)."""
    if y0 is None:
        y0 = initial_state(params)
    for name, v in (("transient_periods", transient_periods), ("periods", periods), ("points_per_period", points_per_period)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < (0 if name == "transient_periods" else 1):
            raise ValueError(f"{name} must be an int >= {0 if name == 'transient_periods' else 1}, got {v!r}")
    w = float(params.omega_pi)
    T = 2 * np.pi / w
    k = np.arange(periods * points_per_period + 1)
    ts = T * (transient_periods + k / points_per_period)
    check_state(y0, params, name="y0")
    y0 = np.asarray(y0, dtype=np.float64)
    if y0.shape != (13,):
        raise ValueError(f"'y0' must have shape (13,), got {y0.shape}")
    for name, tol in (("rtol", rtol), ("atol", atol)):
        if not (np.ndim(tol) == 0 and np.isfinite(tol) and tol > 0):
            raise ValueError(f"{name!r} must be a positive finite number, got {tol!r}")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise ValueError(f"max_steps must be a positive int, got {max_steps!r}")
    solver, law = solver or DEFAULT_SOLVER, get_contact_law(contact_law)
    leaves, treedef = jax.tree.flatten(params)
    args = ([np.asarray(x, np.float64) for x in leaves], y0, ts, np.float64(rtol), np.float64(atol))

    def orbit_program(leaves, y0, ts, rtol, atol):
        p = jax.tree.unflatten(treedef, leaves)
        sol = simulate(
            p, y0, ts[-1], ts=ts, solver=solver, rtol=rtol, atol=atol, max_steps=max_steps, contact_law=law,
            exact_ts=True,
        )  # fmt: skip
        r_O = jax.vmap(centre_position, in_axes=(0, None))(sol.ys, p)
        return sol.ys, r_O, sol.status, sol.valid

    description = repr((treedef, solver, law, max_steps))
    return orbit_program, args, description, ts


def prepare_orbit(
    params: CeltParams,
    y0: Any = None,
    *,
    transient_periods: int = 200,
    periods: int = 40,
    points_per_period: int = 40,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 1_000_000,
    contact_law: AbstractContactLaw | str | None = None,
    defer: bool = False,
) -> None:
    """Start compiling the program `orbit` runs with these arguments: traced now, compiled by XLA
    on a worker thread. An `orbit` call with the same settings (any parameter values and start)
    then finds it compiled, or waits for it. Worth it before work that leaves a CPU core idle,
    e.g. drawing figures. Raises as `orbit` does on bad input.

    ``defer=True``: trace and compile it on a worker thread when a sweep's Lyapunov stage starts
    (its padded last group leaves a core idle), or else when `orbit` or ``prepare_orbit`` without
    ``defer`` first asks for it (`jaxcelt._executable_cache.start_deferred`)."""
    fn, args, description, _ = _orbit_program(
        params, y0, transient_periods, periods, points_per_period, solver, rtol, atol, max_steps, contact_law
    )
    compile_in_background("orbit", fn, args, description, compiler_options(jax.default_backend()), defer=defer)


def orbit(
    params: CeltParams,
    y0: Any = None,
    *,
    transient_periods: int = 200,
    periods: int = 40,
    points_per_period: int = 40,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 1_000_000,
    contact_law: AbstractContactLaw | str | None = None,
) -> dict[str, np.ndarray]:
    """A densely saved trajectory after the transient, for phase plots (paper Figs. 4-7).

    Saves ``points_per_period`` states per forcing period over ``periods`` periods after
    ``transient_periods``; save times include the section times exactly (``exact_ts``). The
    program is compiled once per solver, law, ``max_steps`` and number of save times, and kept
    (`jaxcelt._executable_cache`; `prepare_orbit` compiles it ahead).

    Returns dict with ``ts`` (n,), ``ys`` (n, 13), ``r_O`` (n, 3) [m], ``section_index``
    (indices of the section times in ts), ``status``, ``valid``.
    """
    fn, args, description, ts = _orbit_program(
        params, y0, transient_periods, periods, points_per_period, solver, rtol, atol, max_steps, contact_law
    )
    exe = compiled("orbit", fn, args, description, compiler_options(jax.default_backend()))
    ys, r_O, status, valid = exe(*args)
    return dict(
        ts=ts,
        ys=np.asarray(ys),
        r_O=np.asarray(r_O),
        section_index=np.arange(0, len(ts), points_per_period),
        status=int(status),
        valid=bool(valid),
    )
