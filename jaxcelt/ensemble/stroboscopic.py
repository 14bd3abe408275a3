"""Stroboscopic lanes: each (parameters, initial state) solved to its section times, many at once.

For a lane with forcing frequency omega_pi the section times are t0 + (transient + k) 2 pi /
omega_pi, k = 0 .. S-1 (`SweepConfig`); the stepper steps exactly onto them, so the samples are
solver states. `run_lanes` runs one chunk of lanes: padded and dealt round-robin over the
devices (`jaxcelt.ensemble.shard`), through the pool (`jaxcelt.ensemble.pool`: a start program,
the full-width phase, the drain's narrow width when the lanes left are long, the outputs; each one
jitted call over the devices), then the optional Lyapunov stage; or hands the chunk to an
`jaxcelt.ensemble.runners.AbstractLaneRunner` (worker processes). Chunking, resumable writing and
several processes of a distributed run are `jaxcelt.sweeps.driver`'s business.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Sequence
from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import jit_per_platform
from jaxcelt._executable_cache import compile_later, gc_paused, start_deferred
from jaxcelt._types import Array
from jaxcelt.ensemble.config import ENGINES, SweepConfig, check_engine
from jaxcelt.ensemble.kernel import BLOCK, kernel_supported, make_segment, run_kernel_lanes
from jaxcelt.ensemble.lane_programs import lane_extras, lane_stepper, prepare_pool, section_times
from jaxcelt.ensemble.pool import (
    DEFAULT_WIDTH,
    DRAIN_FACTOR,
    DRAIN_MIN_STEPS,
    MIN_DRAIN_WIDTH,
    PILOT_FRACTION,
    PoolStats,
    start_lanes,
)
from jaxcelt.ensemble.runners import AbstractLaneRunner
from jaxcelt.ensemble.shard import dealt_positions, device_mesh, pad_lanes, shard_lanes
from jaxcelt.ensemble.stepper import float64_times
from jaxcelt.integrate.lyapunov import celt_lyapunov
from jaxcelt.physics.params import PARAM_NAMES, CeltParams

__all__ = [
    "SweepConfig", "lanes_params", "run_lanes", "run_lanes_with_stats", "ENGINES", "check_engine",
    "LYAPUNOV_GROUP_WIDTH", "lyapunov_groups",
]  # fmt: skip

LYAPUNOV_GROUP_WIDTH = 16
"""lanes per device in one group of the Lyapunov stage (at most the pool's width). The stage is a vmapped solve: the
lanes of a group step in lockstep, every lane of the group computed until its slowest one ends each period, and the
group's compiled width is fixed before the main solve tells how many lanes succeeded, so its last group is padded.
On a CPU the cost per lane of a group is about flat from 12 to 96 lanes per device and rises below (fixed costs per
loop iteration), while the padding grows with the width: 16 wastes at most 15 lanes' work per device
(``benchmarks/lyapunov_stage.py``; docs/internals/sweep-engine.md)."""


def lyapunov_groups(ok: np.ndarray, per_device: int, n_devices: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The Lyapunov stage's groups of the lanes ``ok`` (in the order given: costliest first), each as (the lane at
    every position of the sharded group, the positions holding a lane of its own rather than padding).

    A group has ``per_device`` x ``n_devices`` positions; device d holds the contiguous block of positions
    d per_device ... (d + 1) per_device - 1, and the group's lanes are dealt over the devices round-robin (lane j
    of the group to device j mod n_devices), so every device gets a share of the costly and of the cheap lanes,
    and of the padding of the last group (copies of its last lane)."""
    G = per_device * n_devices
    deal = dealt_positions(G, n_devices)  # position i holds the group's lane deal[i]
    groups = []
    for i in range(0, len(ok), G):
        part = ok[i : i + G]
        groups.append((pad_lanes(part, G)[deal], deal < len(part)))
    return groups


def lanes_params(params: CeltParams, name: str, values: Array) -> CeltParams:
    """A batched `CeltParams` with a leading lane axis: field ``name`` = ``values``, others broadcast."""
    if name not in PARAM_NAMES:
        raise ValueError(f"unknown parameter {name!r}; known: {PARAM_NAMES}")
    values = jnp.asarray(values, dtype=jnp.float64)
    L = values.shape[0]
    pb = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(jnp.asarray(x), (L,)), params)
    return eqx.tree_at(lambda p: getattr(p, name), pb, values)


def _lyap_lane(p: CeltParams, y_start: Array, t_start: Array, cfg: SweepConfig) -> tuple[Array, Array]:
    """(lambda_1, its batch-means standard error) of one lane [1/s] (`jaxcelt.integrate.lyapunov.exponent_stderr`)."""
    lr = celt_lyapunov(
        p,
        y_start,
        periods=cfg.lyapunov_periods,
        t0=t_start,
        contact_law=cfg.contact_law,
        solver=cfg.solver,
        rtol=cfg.rtol,
        atol=cfg.atol,
        max_steps=cfg.max_steps,  # per period: a bound, not a cost
        error_control=cfg.lyapunov_error_control,
        tangent=cfg.lyapunov_tangent,
    )
    return lr.exponent, lr.stderr


@eqx.filter_jit
def _kernel_chunk(
    pv: tuple[Array, ...],
    y0b: Array,
    live: Array,
    transient: Array,
    tols: Array,
    p_const: CeltParams,
    cfg: SweepConfig,
    vary: tuple[bool, ...],
    mesh: Any,
    interpret: bool,
) -> tuple[dict[str, Array], Array]:
    """One chunk of lanes through the lane kernel (per device): per-lane outputs and the kernel's
    loop iterations per lane. ``p_const``: the parameters with plain Python numbers (static, so
    that the kernel folds what depends on them alone); ``vary``: which of its leaves ``pv``
    replaces (one (L,) array each)."""
    leaves, treedef = jax.tree_util.tree_flatten(p_const)

    def params_of(pv):
        it = iter(pv)
        return jax.tree_util.tree_unflatten(treedef, [next(it) if v else c for v, c in zip(vary, leaves)])

    def run(pv, y0b, live):
        L = y0b.shape[0]
        pb = params_of(tuple(pv))
        pb = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(jnp.asarray(x, cfg.dtype), (L,)), pb)
        stepper = lane_stepper(cfg, None)
        ts_all = section_times(pb, transient, cfg)
        t0 = jnp.asarray(cfg.t0, cfg.dtype)
        lanes, _ = start_lanes(stepper, tuple(pv), params_of, y0b, ts_all, live, tols, t0)
        seg = make_segment(cfg, params_of, len(pv))
        # the kernel's times are float64 (`jaxcelt.ensemble.kernel`): section times from the lanes' omega_pi
        ts64 = section_times(jax.tree_util.tree_map(lambda x: x.astype(jnp.float64), pb), transient, cfg)
        lanes = float64_times(lanes, ts64[:, -1])
        out, samples, iters = run_kernel_lanes(seg, lanes, tuple(pv), ts64, interpret)
        ts_all = ts64
        out = dict(out, samples=samples, t_samples=ts_all)
        out.update(jax.vmap(lane_extras)(samples, pb))
        return out, iters

    return shard_lanes(run, mesh, 3)(pv, y0b, live)


def _lyap_chunk_impl(
    pb: CeltParams, y_start: Array, t_start: Array, cfg: SweepConfig, mesh: Any
) -> tuple[Array, Array]:
    run = jax.vmap(lambda p, y, t: _lyap_lane(p, y, t, cfg))
    return shard_lanes(run, mesh, 3)(pb, y_start, t_start)


# the Lyapunov stage (a diffrax solve with its tangent, vmapped over lanes), per platform: on a CPU
# compiled with XLA's loop emitters (`jaxcelt._compile_options`)
_lyap_chunk = jit_per_platform(_lyap_chunk_impl)


def varying_names(pb: CeltParams) -> set[str]:
    """Names of the parameters whose values differ between the lanes of ``pb`` (leading lane axis)."""
    leaves = jax.tree_util.tree_flatten_with_path(pb)[0]
    return {path[-1].name for path, x in leaves if np.any(np.asarray(x) != np.asarray(x)[:1])}


def run_lanes(
    pb: CeltParams,
    y0b: Array,
    cfg: SweepConfig,
    *,
    devices: Sequence[Any] | AbstractLaneRunner | None = None,
    pad_to: int | None = None,
    width: int | None = None,
    compile_only: bool = False,
    varying: Sequence[str] = (),
    pilot_fraction: float = PILOT_FRACTION,
    drain_factor: int = DRAIN_FACTOR,
    min_drain_width: int = MIN_DRAIN_WIDTH,
    drain_min_steps: int = DRAIN_MIN_STEPS,
    engine: str = "auto",
    stats: bool = False,
) -> dict[str, np.ndarray] | tuple[dict[str, np.ndarray], PoolStats]:
    """Run one chunk of lanes (batched params and y0 with a leading lane axis) and return numpy arrays.

    ``width`` batch slots per device (default `DEFAULT_WIDTH`) step in one jitted while loop
    (`jaxcelt.ensemble.run_pool`); a slot whose lane finishes is refilled with the next lane at
    once, so no slot idles until the slowest lane is done (only the final drain does).
    ``pilot_fraction`` (default `PILOT_FRACTION`; 0 = off; only used when a device has more
    lanes than slots): each lane pauses once after this fraction of its time span and is taken
    up again costliest-predicted first. ``drain_factor``, ``min_drain_width``: the pool's drain
    schedule (`jaxcelt.ensemble.pool`); ``drain_min_steps`` (default `DRAIN_MIN_STEPS`): the drain's
    narrower widths, a program of their own, run only when a lane left at the end of the
    full-width phase is predicted to need at least this many more steps (0: always). The Lyapunov stage (``cfg.lyapunov_periods > 0``) then
    runs vmapped over the successful lanes in groups of `LYAPUNOV_GROUP_WIDTH` lanes per device (at most the pool's
    width), ordered by the measured main-solve step count (a cost estimate that needs no pilot run) and dealt
    round-robin over the devices (`lyapunov_groups`).

    Sharded over ``devices`` (default all local devices; lanes are dealt round-robin); padded
    to ``pad_to`` lanes (so a short last chunk reuses the compiled shape) and to a multiple
    of the device count. Padding lanes are dropped; in the pool they finish at once.
    ``devices`` may be an `jaxcelt.ensemble.runners.AbstractLaneRunner` (e.g.
    `jaxcelt.ensemble.HostProcesses`: the lanes then run in its worker processes, one per CPU core).
    ``engine``: `ENGINES` (the kernel's `PoolStats` count its loop iterations, one per step of its
    slowest lane, with ``width`` = `BLOCK`).
    ``compile_only=True``: every lane marked as padding -- compiles the kernel for these
    shapes and returns at once (used to time compilation apart from running).
    ``varying``: names of parameters to treat as differing between lanes even where this
    chunk's lanes happen to share a value (parameters that do differ are always detected),
    so that all chunks of a sweep compile to one kernel; the others are constants of the
    pool's step.

    Returns the fields of `jaxcelt.sweeps.result.SweepResult` but ``values`` (lane axis first). With
    ``stats=False`` (default) the pool's statistics are copied into every lane: ``pool_iterations``
    (the busiest device's loop iterations), ``pool_slot_steps`` (step slots paid over all devices),
    ``pool_width``; with ``stats=True`` they come apart: ``(lanes, PoolStats)``.
    """
    out, st = _run_lanes(
        pb, y0b, cfg, devices=devices, pad_to=pad_to, width=width, compile_only=compile_only, varying=varying,
        pilot_fraction=pilot_fraction, drain_factor=drain_factor, min_drain_width=min_drain_width,
        drain_min_steps=drain_min_steps, engine=engine,
    )  # fmt: skip
    if stats:
        return out, st
    L = len(out["status"])
    out["pool_iterations"] = np.full(L, st.iterations)
    out["pool_slot_steps"] = np.full(L, st.slot_steps)
    out["pool_width"] = np.full(L, st.width)
    return out


def run_lanes_with_stats(*args: Any, **kwargs: Any) -> tuple[dict[str, np.ndarray], PoolStats]:
    """Deprecated: ``run_lanes(..., stats=True)``."""
    warnings.warn(
        "run_lanes_with_stats is deprecated and will be removed in the next release; use run_lanes(..., stats=True)",
        DeprecationWarning,
        stacklevel=2,
    )
    return run_lanes(*args, stats=True, **kwargs)


def _run_lanes(
    pb: CeltParams,
    y0b: Array,
    cfg: SweepConfig,
    *,
    devices: Sequence[Any] | AbstractLaneRunner | None,
    pad_to: int | None,
    width: int | None,
    compile_only: bool,
    varying: Sequence[str],
    pilot_fraction: float,
    drain_factor: int,
    min_drain_width: int,
    drain_min_steps: int,
    engine: str,
) -> tuple[dict[str, np.ndarray], PoolStats]:
    """`run_lanes` with the statistics apart (its body)."""
    check_engine(engine, cfg.solver)
    if isinstance(devices, AbstractLaneRunner):  # the whole chunk runs elsewhere (e.g. worker processes)
        kw = dict(width=width, compile_only=compile_only, pilot_fraction=pilot_fraction)
        kw.update(drain_factor=drain_factor, min_drain_width=min_drain_width, drain_min_steps=drain_min_steps)
        return devices.run(pb, y0b, cfg, pad_to=pad_to, varying=tuple(varying), engine=engine, **kw)
    mesh = device_mesh(devices)
    L = int(np.shape(y0b)[0])
    ndev = 1 if mesh is None else mesh.devices.size
    platform = (list(devices)[0] if devices else jax.local_devices()[0]).platform
    on_gpu = platform in ("gpu", "cuda", "rocm")
    use_kernel = engine == "kernel" or (engine == "auto" and on_gpu and kernel_supported(cfg.solver))
    if not use_kernel and (cfg.field_dtype not in (None, cfg.dtype) or cfg.stiffness != "off"):
        raise ValueError(
            "field_dtype, stiffness: mixed precision and the stiffness switch are the lane kernel's "
            "(engine='kernel', or 'auto' on a GPU)"
        )
    per = ndev * (BLOCK if use_kernel else 1)  # the kernel's programs take whole blocks of lanes
    Lp = math.ceil(max(L, pad_to or 0) / per) * per
    pb_np = jax.tree_util.tree_map(lambda x: pad_lanes(np.asarray(x), Lp), pb)
    y0_np = pad_lanes(np.asarray(y0b, dtype=np.float64), Lp)
    dt = np.dtype(cfg.dtype)  # the pool's arithmetic; the Lyapunov stage below stays float64
    static_cfg = dataclasses.replace(cfg, transient_periods=0)  # transient is traced: no recompiles
    transient = jnp.asarray(float(cfg.transient_periods))
    W = int(width or DEFAULT_WIDTH)
    if W < 1:
        raise ValueError(f"width must be >= 1, got {width!r}")
    for name, v, lo in (("drain_factor", drain_factor, 2), ("min_drain_width", min_drain_width, 1), ("drain_min_steps", drain_min_steps, 0)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < lo:
            raise ValueError(f"{name} must be an int >= {lo}, got {v!r}")
    nocfg = dataclasses.replace(static_cfg, lyapunov_periods=0)
    unknown = set(varying) - set(PARAM_NAMES)
    if unknown:
        raise ValueError(f"varying: unknown parameter name(s) {sorted(unknown)}")
    names = set(varying) | varying_names(pb_np)
    vary = tuple(path[-1].name in names for path, _ in jax.tree_util.tree_flatten_with_path(pb_np)[0])
    Lloc = Lp // ndev
    Wd = min(W, Lloc)
    # position i of the sharded arrays holds lane pos_lane[i]; device d holds positions
    # d Lloc ... (d + 1) Lloc - 1 and gets lanes d, d + ndev, ... (a mix of cheap and costly)
    pos_lane = dealt_positions(Lp, ndev)
    pb_p = jax.tree_util.tree_map(lambda x: x[pos_lane].astype(dt), pb_np)
    live = (pos_lane < L) & (not compile_only)
    tols = jnp.asarray([cfg.rtol, cfg.atol], dt)
    # the pilot pause only pays where lanes queue for slots
    frac = float(pilot_fraction) if pilot_fraction and Lloc > Wd else np.inf
    # kernel boundaries pay on CPU (`jaxcelt.ensemble.kernel_boundary`); on an accelerator a
    # conditional costs a device-to-host sync per stage, so none there
    opaque_true = jnp.asarray(True) if platform == "cpu" else None
    Gd = min(Wd, LYAPUNOV_GROUP_WIDTH)  # the Lyapunov stage's lanes per device (`LYAPUNOV_GROUP_WIDTH`)
    G = Gd * ndev
    lyap_fn = _lyap_chunk(platform)
    # The Lyapunov stage's program and the pool's are traced here, one after the other, and
    # compiled by XLA on worker threads at the same time (XLA releases the GIL while compiling); all
    # are then called as compiled programs. Later chunks of the same shapes find them in JAX's caches.
    # The stage's goes first: it runs after the pool, but its program is traced while the CPU is still free and
    # compiles beside the pool's, instead of being traced while the pool's programs compile on every core.
    lyap_compiled = None
    if cfg.lyapunov_periods > 0 and not compile_only:
        example = (jax.tree_util.tree_map(lambda x: x[:1].repeat(G, 0), pb_np), np.zeros((G, 13)), np.zeros(G))
        with gc_paused():
            lyap_lowered = lyap_fn.lower(*example, static_cfg, mesh)
        lyap_compiled = compile_later(lyap_lowered.compile)
    if use_kernel:
        leaves, treedef = jax.tree_util.tree_flatten(pb_p)
        p_const = jax.tree_util.tree_unflatten(treedef, [x[0].item() for x in leaves])
        kcfg = dataclasses.replace(static_cfg, lyapunov_periods=0)
        pool_args = (tuple(x for x, v in zip(leaves, vary) if v), y0_np[pos_lane].astype(dt), live, transient, tols,
                     p_const, kcfg, vary, mesh, not on_gpu)  # fmt: skip
        with gc_paused():
            pool_lowered = _kernel_chunk.lower(*pool_args)
        pool_compiled = compile_later(pool_lowered.compile)
    else:
        # the pool's programs (`jaxcelt.ensemble.lane_programs`), sent to compile now; run below
        run_pool_programs = prepare_pool(
            pb_p, y0_np[pos_lane].astype(dt), live, transient, tols, cfg=nocfg, width=Wd, lanes_per_device=Lloc,
            mesh=mesh, vary=vary, pause_frac=frac, opaque_true=opaque_true, platform=platform,
            drain=(int(drain_factor), int(min_drain_width)), drain_min_steps=drain_min_steps, compile_only=compile_only,
        )  # fmt: skip
    if use_kernel:
        out, lane_iters = pool_compiled.result()(*pool_args)
        lane_iters = np.asarray(lane_iters)  # each lane: its block's loop iterations
        stats = PoolStats(iterations=int(lane_iters.max()), slot_steps=int(lane_iters.sum()), width=BLOCK)
    else:
        out, iters, slot_steps = run_pool_programs()
        stats = PoolStats(iterations=int(np.asarray(iters).max()), slot_steps=int(np.sum(np.asarray(slot_steps))), width=Wd)
    out = jax.tree_util.tree_map(np.asarray, jax.block_until_ready(out))
    inv = np.empty_like(pos_lane)
    inv[pos_lane] = np.arange(Lp)
    out = {k: v[inv][:L] for k, v in out.items()}
    # a float32 pool's results in float64 arrays, as a float64 run's
    out = {k: v.astype(np.float64) if v.dtype == np.float32 else v for k, v in out.items()}
    out["valid"] = out["first_invalid_kind"] == 0
    out["lyapunov"] = np.full(L, np.nan)
    out["lyapunov_stderr"] = np.full(L, np.nan)
    if cfg.lyapunov_periods > 0 and not compile_only:
        ok = np.flatnonzero(out["status"] == 0)
        ok = ok[np.argsort(-out["num_steps"][ok], kind="stable")]  # similar cost side by side
        lyap = lyap_compiled.result()
        # the stage's last group is padded with copies of one lane, which leaves a core partly idle on a
        # CPU: programs deferred for later (e.g. the CLI's phase plots) are traced and compiled now
        start_deferred()
        for idx, own in lyapunov_groups(ok, Gd, ndev):
            lam, err = lyap(
                jax.tree_util.tree_map(lambda x, idx=idx: x[idx], pb_np),
                out["samples"][idx, 0],  # float64 (a float32 pool's samples cast up)
                out["t_samples"][idx, 0],
                static_cfg,
                mesh,
            )
            out["lyapunov"][idx[own]] = np.asarray(lam)[own]
            out["lyapunov_stderr"][idx[own]] = np.asarray(err)[own]
    return out, stats
