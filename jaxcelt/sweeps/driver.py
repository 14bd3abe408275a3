"""Running a batch of lanes: chunks, resumable writing, several processes.

Every sweep (`jaxcelt.sweeps.api`) hands its lanes -- batched parameters, one start per lane --
to `run_batch`, which orders them (``sort_by_cost``), cuts them into chunks, runs each chunk on
the lane engine (`jaxcelt.ensemble.run_lanes`), writes each finished chunk (``out``,
`jaxcelt.sweeps.dataset.SweepWriter`), reads back the chunks an interrupted run left, and splits
the chunks over the processes of a `jax.distributed` run. It returns every lane's arrays in lane
order (the `jaxcelt.sweeps.result.LANE_FIELDS`).

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
  and report where validity was lost), as in `jaxcelt.simulate`.
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
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

import jax
import numpy as np

from jaxcelt.ensemble.config import SweepConfig, check_engine
from jaxcelt.ensemble.stroboscopic import run_lanes
from jaxcelt.physics.params import CeltParams
from jaxcelt.sweeps.options import SweepOptions
from jaxcelt.sweeps.result import LANE_FIELDS

__all__ = ["run_batch"]


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
    for key in LANE_FIELDS:
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


def run_batch(
    pb_all: CeltParams,
    lane_y0: np.ndarray,
    cfg: SweepConfig,
    *,
    params: CeltParams,
    names: Sequence[str],
    lane_values: np.ndarray,
    n_starts: int,
    options: SweepOptions,
    desc: str,
) -> tuple[dict[str, np.ndarray] | None, Any]:
    """Chunking, resumable writing and the multi-process split of a batch of lanes, shared by
    every sweep: (lane results in lane order or None on a process other than 0 of a multi-process
    run, the `jaxcelt.sweeps.dataset.SweepWriter` or None).

    ``pb_all``, ``lane_y0``: the lanes' batched parameters and starts; ``cfg``: ``options.config()``;
    ``params``, ``names``, ``lane_values``, ``n_starts``: what the dataset's manifest records;
    ``options``: the execution settings (``chunk_size``, ``sort_by_cost``, ``devices``, ``width``,
    ``engine``, ``out``, ``progress``, ``on_chunk``); ``desc``: the progress bar's label."""
    o = options
    if not np.all(np.asarray(pb_all.omega_pi) > 0):
        raise ValueError("stroboscopic sampling needs omega_pi > 0 in every lane")
    check_engine(o.engine, cfg.solver)
    L = lane_y0.shape[0]
    order = np.arange(L)
    if o.sort_by_cost:
        order = np.argsort(np.asarray(pb_all.omega_pi), kind="stable")  # longest period first
    cs = L if o.chunk_size is None else max(1, min(int(o.chunk_size), L))  # no padding beyond the lanes
    chunks = [order[i : i + cs] for i in range(0, L, cs)]
    writer = None
    done: dict[int, dict[str, np.ndarray]] = {}
    if o.out is not None:
        from jaxcelt.sweeps.dataset import SweepWriter

        writer = SweepWriter(
            o.out,
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
        devices=o.devices, width=o.width, varying=tuple(names), progress=o.progress, desc=desc, on_chunk=o.on_chunk,
        engine=o.engine,
    )  # fmt: skip
    return lanes, writer
