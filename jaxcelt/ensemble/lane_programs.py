"""The jitted programs that run one chunk of lanes over the devices.

The lane pool (`jaxcelt.ensemble.pool`) runs as separate programs, each holding at most one copy of the step:
`pool_start` (every lane's start and the filled slots), `pool_advance` (the pool stepped at its width, or through
the drain's narrower widths), `pool_outputs` (per-lane results); `prepare_pool` traces them, sends them to compile
at the same time and returns the function that runs them, deciding whether the drain runs from the lanes alone.
Also what these programs share with the lane kernel's (`jaxcelt.ensemble.stroboscopic`): the stepper, the section
times and the per-lane extras.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._compile_options import compiler_options, is_wide_pool, pool_compiler_options
from jaxcelt._executable_cache import compile_later, gc_paused
from jaxcelt._types import Array
from jaxcelt.ensemble.config import SweepConfig
from jaxcelt.ensemble.lanes import LaneState
from jaxcelt.ensemble.pool import (
    PoolCarry,
    advance_pool,
    begin_pool,
    carry_from_rows,
    carry_rows,
    drain_widths,
    lane_outputs,
    narrow_pool,
    remaining_steps,
    split_lane_args,
    start_lanes,
)
from jaxcelt.ensemble.shard import LANE_AXIS, shard_lanes
from jaxcelt.ensemble.stepper import AbstractLaneStepper, FusedERKStepper, float64_times, make_stepper
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.diagnostics import centre_position
from jaxcelt.physics.params import CeltParams

__all__ = ["prepare_pool", "pool_start", "pool_advance", "pool_outputs", "lane_stepper", "section_times", "lane_extras"]


def lane_extras(ys: Array, p: CeltParams) -> dict[str, Array]:
    """Global motion of O from one lane's samples (S, 13); samples after a stop (inf) ignored."""
    r_O = jax.vmap(centre_position, in_axes=(0, None))(ys, p)
    dist = jnp.linalg.norm(r_O[:, :2] - r_O[0:1, :2], axis=-1)
    fin = jnp.isfinite(dist)
    last = jnp.max(jnp.where(fin, jnp.arange(dist.shape[0]), -1))
    drift = jnp.where(last >= 0, dist[jnp.maximum(last, 0)], jnp.nan)
    exc = jnp.where(last >= 0, jnp.max(jnp.where(fin, dist, -jnp.inf)), jnp.nan)
    return dict(drift=drift, max_excursion=exc, r_O=r_O)


def lane_stepper(cfg: SweepConfig, opaque_true: Array | None = None) -> AbstractLaneStepper:
    """The stepper of the sweep's solver (`jaxcelt.ensemble.make_stepper`)."""
    return make_stepper(
        cfg.solver, cfg.contact_law, rtol=cfg.rtol, atol=cfg.atol, max_steps=cfg.max_steps,
        stop_on_invalid=cfg.stop_on_invalid, opaque_true=opaque_true,
    )  # fmt: skip


def section_times(pb: CeltParams, transient: Array, cfg: SweepConfig) -> Array:
    """(L, S) stroboscopic times t0 + k 2 pi / omega_pi, k = transient, transient + 1, ..."""
    dt = pb.omega_pi.dtype
    T = 2 * jnp.pi / pb.omega_pi
    S = cfg.sample_periods
    return jnp.asarray(cfg.t0, dt) + T[:, None] * (transient.astype(dt) + jnp.arange(S, dtype=dt))[None, :]


def pool_times(pb: CeltParams, transient: Array, cfg: SweepConfig, stepper: AbstractLaneStepper) -> Array:
    """The section times the pool steps onto: float32 lanes of the fused step step in float64 time
    (`FusedERKStepper`), so theirs come from float64 omega_pi."""
    if isinstance(stepper, FusedERKStepper) and cfg.dtype != "float64":
        pb = jax.tree_util.tree_map(lambda x: x.astype(jnp.float64), pb)
    return section_times(pb, transient, cfg)


@functools.partial(jax.jit, static_argnames=("cfg", "width", "mesh", "vary"))
def pool_start(
    pb: CeltParams, y0b: Array, live: Array, transient: Array, tols: Array, *, cfg: SweepConfig, width: int, mesh: Any,
    vary: tuple[bool, ...],
) -> PoolCarry:
    """The pool's first program (per device): every lane's start (`start_lanes`) and the pool of
    ``width`` slots filled (`begin_pool`), as a `carry_rows` carry. ``vary``: `split_lane_args`."""

    def run(pb, y0b, live):
        stepper = lane_stepper(cfg)
        pv_all, params_of = split_lane_args(pb, vary)
        t0 = jnp.asarray(cfg.t0, cfg.dtype)
        lanes, samples = start_lanes(stepper, pv_all, params_of, y0b, section_times(pb, transient, cfg), live, tols, t0)
        ts_all = pool_times(pb, transient, cfg, stepper)
        if isinstance(stepper, FusedERKStepper) and cfg.dtype != "float64":
            lanes = float64_times(lanes, ts_all[:, -1])
        return carry_rows(begin_pool(lanes, samples, pv_all, ts_all, width=width))

    return shard_lanes(run, mesh, 3)(pb, y0b, live)


@functools.partial(jax.jit, static_argnames=("cfg", "mesh", "vary", "narrow_to"))
def pool_advance(
    pb: CeltParams, carry: PoolCarry, pause_frac: Array, transient: Array, until: Array, opaque_true: Array | None,
    *, cfg: SweepConfig, mesh: Any, vary: tuple[bool, ...], narrow_to: tuple[int, ...],
) -> PoolCarry:
    """The pool stepped on (per device, `advance_pool`): at its width until no more than ``until``
    lanes have work left (``narrow_to`` empty), or through the drain's narrower widths
    ``narrow_to`` to the end. ``opaque_true``: a traced True (a jit argument: XLA would fold a
    constant predicate and the fused step's kernel boundaries would vanish), or None: no kernel
    boundaries."""

    def run(pb, carry):
        stepper = lane_stepper(cfg, opaque_true)
        pv_all, params_of = split_lane_args(pb, vary)
        ts_all = pool_times(pb, transient, cfg, stepper)
        t0 = jnp.asarray(cfg.t0, cfg.dtype)
        c = carry_from_rows(carry)
        step = functools.partial(advance_pool, stepper, lane_args=pv_all, args_of=params_of, ts_all=ts_all, t0=t0,
                                 pause_frac=pause_frac)  # fmt: skip
        if not narrow_to:
            c = step(c, until=until)
        for w, nxt in zip(narrow_to, [*narrow_to[1:], 0]):
            c = step(narrow_pool(c, w), until=nxt)
        return carry_rows(c)

    return shard_lanes(run, mesh, 2)(pb, carry)


@functools.partial(jax.jit, static_argnames=("cfg", "mesh"))
def pool_outputs(
    pb: CeltParams, lanes: LaneState, samples: Array, transient: Array, *, cfg: SweepConfig, mesh: Any
) -> dict[str, Array]:
    """The per-lane outputs from the pool's final lane table and samples (per device)."""

    def run(pb, lanes, samples):
        stepper = lane_stepper(cfg)
        out = dict(lane_outputs(stepper, lanes).as_dict(), samples=samples, t_samples=pool_times(pb, transient, cfg, stepper))
        out.update(jax.vmap(lane_extras)(samples, pb))
        return out

    return shard_lanes(run, mesh, 3)(pb, lanes, samples)


def pool_config(cfg: SweepConfig, platform: str, slots: int) -> SweepConfig:
    """``cfg`` with the contact law's form for a pool of ``slots`` slots per device on ``platform``: its
    ``wide_batch`` form (the vectorised logarithm) where the pool gets wide vectors (`jaxcelt._compile_options.is_wide_pool`),
    as given otherwise."""
    if is_wide_pool(platform, slots):
        return dataclasses.replace(cfg, contact_law=get_contact_law(cfg.contact_law).wide_batch())
    return cfg


def _abstract(tree: Any, mesh: Any) -> Any:
    """``tree``'s shapes (e.g. a lowered program's ``out_info``) with the lane-axis sharding of ``mesh``: a program taking
    it is compiled for the arrays the pool's programs hand on."""
    spec = None if mesh is None else jax.sharding.NamedSharding(mesh, jax.sharding.PartitionSpec(LANE_AXIS))
    return jax.tree_util.tree_map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=spec), tree)


def _host_slots(carry: PoolCarry) -> PoolCarry:
    """``carry`` with the slots' lane states and lane indices copied to the host (a few hundred numbers), enough for
    `remaining_steps`: computed on the device, its dozen operations were each a program compiled on a first call."""
    slots = carry.slots._replace(lane=jax.device_get(carry.slots.lane))
    return carry._replace(slots=slots, lane=np.asarray(carry.lane))


def prepare_pool(
    pb: CeltParams,
    y0b: Array,
    live: Array,
    transient: Array,
    tols: Array,
    *,
    cfg: SweepConfig,
    width: int,
    lanes_per_device: int,
    mesh: Any,
    vary: tuple[bool, ...],
    pause_frac: float,
    opaque_true: Array | None,
    platform: str,
    drain: tuple[int, int],
    drain_min_steps: int,
    compile_only: bool,
) -> Callable[[], tuple[dict[str, Array], Array, Array]]:
    """Trace the pool's programs for one chunk of lanes (already padded, dealt over the devices and cast) and send
    them to compile on jaxcelt's worker threads; returns the function that runs them: (per-lane outputs, loop
    iterations and step slots paid per device).

    Three programs compile at the same time (`pool_start`, `pool_advance` at ``width``, `pool_outputs`); the drain's
    narrower widths (`drain_widths` with ``drain`` = (factor, minimum width)) are a fourth, run only when a lane left
    at the end of the full-width phase is predicted to need at least ``drain_min_steps`` more steps
    (`remaining_steps`). It is compiled then, when lanes stop at invalid states; with the others, when every lane is
    integrated on (``cfg.stop_on_invalid`` false: lanes that stick to the base are long) or with ``compile_only``
    (compiled and not run). Which programs run depends on the lanes alone, not on when they were compiled. Each
    program gets the contact law's form and compiler options of its width (`pool_config`,
    `jaxcelt._compile_options.pool_compiler_options`; the drain's: of its last width)."""
    widths = drain_widths(width, lanes_per_device, *drain)
    drain_cfg = pool_config(cfg, platform, widths[-1])  # the drain's program: the law's form of its last width
    cfg = pool_config(cfg, platform, width)
    adv_kw = dict(cfg=cfg, mesh=mesh, vary=vary)
    pause, no_until = jnp.asarray(pause_frac), jnp.asarray(0, jnp.int32)
    with gc_paused():
        start_lowered = pool_start.lower(pb, y0b, live, transient, tols, cfg=cfg, width=width, mesh=mesh, vary=vary)
        carry_spec = _abstract(start_lowered.out_info, mesh)
        wide_lowered = pool_advance.lower(pb, carry_spec, pause, transient, no_until, opaque_true, narrow_to=(), **adv_kw)
    wide_compiled = compile_later(functools.partial(wide_lowered.compile, pool_compiler_options(platform, width)))
    # the first and last programs run once per chunk: compiled for compile time (`jaxcelt._compile_options`)
    start_compiled = compile_later(functools.partial(start_lowered.compile, compiler_options(platform)))
    with gc_paused():
        out_lowered = pool_outputs.lower(pb, carry_spec.lanes, carry_spec.samples, transient, cfg=cfg, mesh=mesh)
    out_compiled = compile_later(functools.partial(out_lowered.compile, compiler_options(platform)))

    def drain_program():
        with gc_paused():
            lowered = pool_advance.lower(pb, carry_spec, pause, transient, no_until, opaque_true,
                                         narrow_to=tuple(widths[1:]), **(adv_kw | dict(cfg=drain_cfg)))  # fmt: skip
        return lowered.compile(pool_compiler_options(platform, widths[-1]))

    # Integrating every lane on, the lanes that stick to the base run long enough for the drain: its program is
    # sent to compile now, after the three above, so that it compiles while the full-width program compiles and
    # runs instead of after it. Stopping at invalid states, it compiles only when the lanes left need it.
    early = len(widths) > 1 and (compile_only or not cfg.stop_on_invalid)
    drain_sent = compile_later(drain_program) if early else None

    def run():
        drain_compiled = drain_sent
        carry = start_compiled.result()(pb, y0b, live, transient, tols)
        wide = wide_compiled.result()
        until = jnp.asarray(widths[1] if len(widths) > 1 else 0, jnp.int32)
        carry = wide(pb, carry, pause, transient, until, opaque_true)
        if len(widths) > 1 and np.any(np.asarray(carry.lane) < lanes_per_device):
            # the lanes left: through the narrow drain if they are predicted to need at least
            # drain_min_steps more steps, else on at the full width (the same lanes either way)
            left = float(np.max(remaining_steps(_host_slots(carry), float(cfg.t0))))
            if left >= drain_min_steps:
                if drain_compiled is None:
                    drain_compiled = compile_later(drain_program)
                carry = drain_compiled.result()(pb, carry, pause, transient, no_until, opaque_true)
            else:
                carry = wide(pb, carry, pause, transient, no_until, opaque_true)
        out = out_compiled.result()(pb, carry.lanes, carry.samples, transient)
        if compile_only and drain_compiled is not None:  # every program compiled before returning
            drain_compiled.result()
        return out, carry.iters, carry.slot_steps

    return run
