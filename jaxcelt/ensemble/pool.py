"""The lane pool: many lanes through a fixed number of batch slots in one jitted while loop.

Each iteration makes one step (`jaxcelt.ensemble.stepper`) in every slot, vmapped; a slot
whose lane finished is refilled with the next lane at once, so step slots are only wasted in
the final drain, not for every lane until the slowest one is done. Lane order (and hence slot
assignment) is fixed and the per-lane arithmetic does not depend on the slot, so results are
deterministic and a lane's result does not depend on its neighbours.

Scheduling:

* When lanes queue for slots, every lane first runs a fraction of its time span
  (``pause_frac``, `PILOT_FRACTION`) and pauses between two steps; paused lanes wait with
  their predicted remaining cost (steps so far x remaining / elapsed span) and free slots take
  them costliest first (longest-processing-time order), so the drain runs on short lanes. A
  pause does not change a lane: it resumes with the same state and step sequence.
* The drain: once no more than `MIN_DRAIN_WIDTH` lanes have work left, the running lanes move to
  a pool of that many slots (96 to 4; `DRAIN_FACTOR`). Each width compiles the step again, so
  only pools with a queue (more lanes than slots) do this, and `jaxcelt.ensemble.run_lanes` only
  when the lanes left are predicted to be long (`DRAIN_MIN_STEPS`).
* A pool of at most `SEQUENTIAL_WIDTH` slots (the drain's last width, or a chunk of a few lanes
  per device) steps in an inner loop until one of its lanes reaches a section time, finishes or
  pauses; that loop touches only small buffers, so XLA's CPU runtime runs its kernels one after the
  other on the calling thread instead of handing them to its thread pool. The lanes that run
  longest spend most of their steps there.

Only the lane-varying parameters ride in the slots (`split_lane_args`); the others enter the
step as unbatched constants. How the loop went (iterations, step slots paid) comes back as
`PoolStats`, apart from the lanes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp

from jaxcelt._types import Array
from jaxcelt.ensemble.lanes import LaneOutputs, LaneState, lane_status
from jaxcelt.ensemble.stepper import AbstractLaneStepper

__all__ = [
    "PoolStats",
    "run_pool",
    "start_lanes",
    "lane_outputs",
    "split_lane_args",
    "DEFAULT_WIDTH",
    "MIN_DRAIN_WIDTH",
    "DRAIN_FACTOR",
    "SEQUENTIAL_WIDTH",
    "PILOT_FRACTION",
    "DRAIN_MIN_STEPS",
    "PoolCarry",
    "begin_pool",
    "advance_pool",
    "narrow_pool",
    "drain_widths",
    "pool_work",
    "remaining_steps",
    "carry_rows",
    "carry_from_rows",
]

DEFAULT_WIDTH = 96
"""pool slots per device. Each pool iteration pays a fixed cost (hundreds of XLA kernel
launches on CPU) besides its per-slot work, so wider pools finish in fewer iterations; 96 was
the fastest width for 400 lanes x 300 periods on 2 cores with the pilot pause
(``benchmarks/bench_schedule.py``; docs/internals/sweep-engine.md)."""
MIN_DRAIN_WIDTH = 4
"""the drain's last width (by default `SEQUENTIAL_WIDTH`, so that it steps in the inner loop)"""
DRAIN_FACTOR = 8
"""the drain divides the width by this while the result stays at least this times
`MIN_DRAIN_WIDTH`, then ends at `MIN_DRAIN_WIDTH`: 96 slots go straight to 4 (256: 32, then 4).
The last few lanes, which run longest when lanes are integrated on, belong in a narrow pool
(``benchmarks/bench_drain.py`` -> docs/bifurcation/drain.json); every intermediate width is
another compiled step, which costs about as much compilation as the full-width one
(``benchmarks/numba_table.py`` -> docs/performance/numba_table_400x300.json)"""
DRAIN_MIN_STEPS = 100_000
"""`jaxcelt.ensemble.run_lanes` runs the drain's narrower widths, a program of their own, only
when a lane left at the end of the full-width phase is predicted to need at least this many more
steps (`remaining_steps`); otherwise the last lanes finish at the full width. Stopping at invalid
states, the drain is then not compiled either; integrating every lane on, where lanes that stick to
the base are long, it compiles beside the pool's other programs from the start
(`jaxcelt.ensemble.lane_programs.prepare_pool`). Compiling it costs seconds; a full-width iteration costs tens of microseconds more
than a narrow one, so the drain pays for lanes of ~10^5 steps: lanes that stick to the base when
lanes are integrated on (``benchmarks/max_steps_study.py``), not the lanes of a sweep that stops
at invalid states. The decision depends on the lanes alone, so a call gives the same results
however its programs were compiled or cached."""
SEQUENTIAL_WIDTH = 4
"""widest pool that steps in the inner loop (`run_pool`). XLA's CPU runtime runs a sequence of
kernels one after the other on the calling thread when each kernel depends on the one before it,
when there are at most 8 of them, or when every buffer they touch holds at most 512 bytes;
otherwise it hands ready kernels to its thread pool, which costs microseconds per pool iteration
when the kernels are small. A step has hundreds of kernels with independent branches, so only the
last rule is within reach: 4 lanes x 13 float64 = 416 bytes."""
PILOT_FRACTION = 0.1
"""a lane pauses once after this fraction of its time span and waits for a slot with its
predicted remaining cost (``benchmarks/bench_schedule.py``)"""


class PoolStats(eqx.Module):
    """How a pool ran. Inside the jitted pool: int32 counters of one device; from
    `jaxcelt.ensemble.run_lanes`: plain ints over all devices."""

    iterations: Any
    """loop iterations (every iteration steps every slot once); over devices: the busiest one's"""
    slot_steps: Any
    """step slots paid (slots x iterations, summed over the drain's widths; over devices: summed).
    At least the lanes' total step count; the excess is idle slots."""
    width: int = eqx.field(static=True)
    """slots per device at the start"""


def split_lane_args(pb: Any, vary: tuple[bool, ...]) -> tuple[tuple[Array, ...], Callable[[Any], Any]]:
    """(the lane-varying leaves of ``pb``, a function rebuilding one lane's args from them).

    ``pb``: the lanes' args (e.g. a batched `CeltParams`), leading lane axis on every leaf.
    ``vary`` (static, one flag per leaf): the leaves that differ between lanes. Only those ride
    in the slots; the others (taken from lane 0) enter the step as unbatched constants, so XLA
    computes what depends on them alone (inertia adjugate, elliptic integrals, ...) once instead
    of in every slot at every stage."""
    leaves, treedef = jax.tree_util.tree_flatten(pb)
    const = [x[0] for x in leaves]
    pv_all = tuple(x for x, v in zip(leaves, vary) if v)

    def args_of(pv):
        it = iter(pv)
        return jax.tree_util.tree_unflatten(treedef, [next(it) if v else c for v, c in zip(vary, const)])

    return pv_all, args_of


def start_lanes(
    stepper: AbstractLaneStepper,
    lane_args: tuple[Array, ...],
    args_of: Callable[[Any], Any],
    y0b: Array,
    ts_all: Array,
    live: Array,
    tols: Array,
    t0: Array,
) -> tuple[LaneState, Array]:
    """Every lane's starting state (diffeqsolve's initialisation) and the samples buffer.

    ``lane_args``/``args_of``: from `split_lane_args`; ``y0b`` (L, n); ``ts_all`` (L, S) section
    times; ``live`` (L,) bool: False marks padding lanes, which start done. A section time at
    t0 is the initial state itself: written here. Returns (lanes, samples (L, S, n), inf where
    not reached)."""
    lanes = jax.vmap(lambda pv, y, ts: stepper.init(t0, y, ts, args_of(pv), tols))(lane_args, y0b, ts_all)
    lanes = eqx.tree_at(lambda s: s.done, lanes, lanes.done | ~live)
    L, S = ts_all.shape
    samples = jnp.full((L, S, y0b.shape[-1]), jnp.inf, y0b.dtype).at[:, 0].set(jnp.where((lanes.k > 0)[:, None], y0b, jnp.inf))
    return lanes, samples


def lane_outputs(stepper: AbstractLaneStepper, lanes: LaneState) -> LaneOutputs:
    """Per-lane results from the final lane states."""
    mon = jax.vmap(stepper.monitor)(lanes)
    return LaneOutputs(
        y_final=lanes.y,
        status=jnp.where(mon.at_singularity, 4, jax.vmap(lane_status)(lanes)).astype(jnp.int32),
        num_steps=lanes.num_steps,
        first_invalid_t=mon.first_invalid_t,
        first_invalid_kind=mon.first_invalid_kind.astype(jnp.int32),
        min_N=mon.min_N,
        max_tilt=mon.max_tilt,
    )


class _Slots(NamedTuple):
    lane: LaneState
    resumed: Array  # paused once and taken up again (a lane pauses only once)
    args: tuple[Array, ...]  # the lane-varying args (`split_lane_args`)
    ts: Array


class PoolCarry(NamedTuple):
    """The pool between two of its phases (`begin_pool`, `advance_pool`, `narrow_pool`): what a
    later phase, possibly another compiled program, needs to go on exactly where the last one
    stopped. Scalars are 0-d (one device's pool)."""

    slots: _Slots
    lane: Array  # lane index in each slot (L: empty)
    nxt: Array  # queue position of the next lane not yet started
    wait: Array  # (L,) paused lanes' predicted remaining cost (-inf: not waiting)
    lanes: LaneState  # the lane table (a lane is written back when done or paused)
    resumed: Array  # (L,)
    samples: Array
    iters: Array
    slot_steps: Array
    queue: Array  # (L,) the lanes with work at the start, in order
    n_queue: Array  # how many of them


_SCALARS = ("nxt", "iters", "slot_steps", "n_queue")


def carry_rows(carry: PoolCarry) -> PoolCarry:
    """``carry`` with its scalars as (1,) arrays: every leaf has a leading axis, so that the
    carries of several devices' pools concatenate along it (`jaxcelt.ensemble.shard`)."""
    return carry._replace(**{k: getattr(carry, k)[None] for k in _SCALARS})


def carry_from_rows(carry: PoolCarry) -> PoolCarry:
    """The inverse of `carry_rows` (inside one device's part)."""
    return carry._replace(**{k: getattr(carry, k)[0] for k in _SCALARS})


def _where_rows(mask: Array, a: Any, b: Any) -> Any:
    return jax.tree_util.tree_map(
        lambda x, y: jnp.where(jnp.reshape(mask, mask.shape + (1,) * (x.ndim - 1)), x, y), a, b
    )


def _take(lane: Array, lanes: LaneState, resumed: Array, lane_args: tuple[Array, ...], ts_all: Array) -> _Slots:
    j = jnp.minimum(lane, resumed.shape[0] - 1)
    return _Slots(jax.tree_util.tree_map(lambda x: x[j], lanes), resumed[j], tuple(x[j] for x in lane_args), ts_all[j])


def _lane_at(pos: Array, queue: Array, n_queue: Array) -> Array:
    L = queue.shape[0]
    return jnp.where(pos < n_queue, queue[jnp.minimum(pos, L - 1)], L).astype(jnp.int32)


def pool_work(carry: PoolCarry) -> Array:
    """Lanes with work left: in a slot, queued, or paused and waiting."""
    L = carry.wait.shape[0]
    return jnp.sum(carry.lane < L) + jnp.maximum(carry.n_queue - carry.nxt, 0) + jnp.sum(carry.wait > -jnp.inf)


def drain_widths(width: int, n_lanes: int, drain_factor: int = DRAIN_FACTOR, min_drain_width: int = MIN_DRAIN_WIDTH) -> list[int]:
    """The pool's widths: ``min(width, n_lanes)``, then, only where lanes queue for slots, the
    drain's: divided by ``drain_factor`` while the result stays at least ``drain_factor`` x
    ``min_drain_width``, and ``min_drain_width`` last (see `DRAIN_FACTOR`)."""
    widths = [min(width, n_lanes)]
    if n_lanes > widths[0]:
        while widths[-1] // drain_factor >= drain_factor * min_drain_width:
            widths.append(widths[-1] // drain_factor)
        if widths[-1] > min_drain_width:
            widths.append(min_drain_width)
    return widths


def begin_pool(lanes: LaneState, samples: Array, lane_args: tuple[Array, ...], ts_all: Array, *, width: int) -> PoolCarry:
    """The pool of ``min(width, L)`` slots filled with the first lanes that have work, in order.

    ``lanes``, ``samples``: from `start_lanes`; ``lane_args``: `split_lane_args`; ``ts_all`` (L, S)."""
    L = samples.shape[0]
    B = min(width, L)
    # the queue: lanes with work (not padding, not invalid at t0 with stop_on_invalid), in order
    queue = jnp.argsort(lanes.done, stable=True).astype(jnp.int32)
    n_queue = jnp.sum(~lanes.done).astype(jnp.int32)
    z = jnp.zeros((), jnp.int32)
    resumed = jnp.zeros_like(lanes.done)
    lane = _lane_at(jnp.arange(B, dtype=jnp.int32), queue, n_queue)
    return PoolCarry(
        slots=_take(lane, lanes, resumed, lane_args, ts_all),
        lane=lane,
        nxt=jnp.minimum(jnp.asarray(B, jnp.int32), n_queue),
        wait=jnp.full((L,), -jnp.inf),
        lanes=lanes,
        resumed=resumed,
        samples=samples,
        iters=z,
        slot_steps=z,
        queue=queue,
        n_queue=n_queue,
    )


def narrow_pool(carry: PoolCarry, width: int) -> PoolCarry:
    """The pool with ``width`` slots: the running lanes first (there must be at most ``width``)."""
    L = carry.wait.shape[0]
    keep = jnp.argsort(carry.lane >= L, stable=True)[:width]
    return carry._replace(slots=jax.tree_util.tree_map(lambda x: x[keep], carry.slots), lane=carry.lane[keep])


def remaining_steps(carry: PoolCarry, t0: Any) -> Any:
    """Each slot's predicted remaining steps: steps so far x remaining / elapsed time span (the
    pilot pause's estimate; 0 for an empty or finished slot or one that has not stepped yet).
    Works on a carry of numpy arrays too, and on `carry_rows` carries of several devices (the
    lane indices are each device's own)."""
    st = carry.slots.lane
    L = carry.samples.shape[0] // max(1, carry.nxt.size)  # lanes per device
    elapsed = st.tprev - t0
    rate = st.num_steps / (elapsed + (elapsed <= 0))
    est = (rate * (st.t1 - st.tprev)) * (elapsed > 0)
    return est * ((carry.lane < L) & ~st.done)


def advance_pool(
    stepper: AbstractLaneStepper,
    carry: PoolCarry,
    lane_args: tuple[Array, ...],
    args_of: Callable[[Any], Any],
    ts_all: Array,
    t0: Array,
    *,
    pause_frac: Array,
    until: Array | int = 0,
) -> PoolCarry:
    """Step the pool at its width (slots refilled as lanes finish) until no more than ``until``
    lanes have work left (`pool_work`). Call inside jit; see `run_pool`."""
    L = carry.samples.shape[0]
    queue, n_queue = carry.queue, carry.n_queue

    def _step(slot: _Slots):
        new, hit = stepper.step(slot.lane, args_of(slot.args), slot.ts)
        paused = ~new.done & ~slot.resumed & (new.tprev >= t0 + pause_frac * (new.t1 - t0))
        return slot._replace(lane=new), hit, paused

    step_v = jax.vmap(_step)
    no = jnp.asarray(-jnp.inf)

    def one_step(slots: _Slots, active: Array):
        stepped, hit, paused = step_v(slots)
        return _where_rows(active, stepped, slots), hit, paused, jnp.ones((), jnp.int32)

    def steps_to_event(slots: _Slots, active: Array):
        # Steps every slot until one of the active lanes reaches its next section time, finishes
        # or pauses. The inner loop sees only the slots and each lane's next two section times
        # (the window; inf past the last, lane.k counted from 0 in it), so on a narrow pool every
        # buffer it touches is small (`SEQUENTIAL_WIDTH`). The window is exact until the next
        # section time is reached, and the loop ends there.
        S = ts_all.shape[1]
        k0 = slots.lane.k
        inf = jnp.asarray(jnp.inf, ts_all.dtype)
        window = jnp.stack(
            [
                jnp.where(k0 + i < S, jnp.take_along_axis(slots.ts, jnp.minimum(k0 + i, S - 1)[:, None], 1)[:, 0], inf)
                for i in (0, 1)
            ],
            axis=-1,
        )
        inner = slots._replace(lane=eqx.tree_at(lambda s: s.k, slots.lane, jnp.zeros_like(k0)), ts=window)
        none = jnp.zeros_like(active)

        def icond(ic):
            return ~ic[3]

        def ibody(ic):
            sl, _, _, _, n = ic
            sl, hit, paused, _ = one_step(sl, active)
            event = jnp.any(active & (hit | sl.lane.done | paused))
            return sl, hit, paused, event, n + 1

        z = jnp.zeros((), jnp.int32)
        inner, hit, paused, _, n = jax.lax.while_loop(icond, ibody, (inner, none, none, ~jnp.any(active), z))
        lane = eqx.tree_at(lambda s: s.k, inner.lane, k0 + inner.lane.k)
        return slots._replace(lane=lane, resumed=inner.resumed, args=inner.args), hit, paused, n

    def body(c: PoolCarry) -> PoolCarry:
        slots, lane = c.slots, c.lane
        active = (lane < L) & ~slots.lane.done
        narrow = lane.shape[0] <= SEQUENTIAL_WIDTH and stepper.section_window
        slots, hit, paused, n_steps = (steps_to_event if narrow else one_step)(slots, active)
        w = jnp.where(active & hit, lane, L)
        samples = c.samples.at[w, slots.lane.k - 1].set(slots.lane.y, mode="drop")
        pause = active & paused
        fin = (lane < L) & (slots.lane.done | pause)

        def swap(args):
            # Write finished and paused lanes back; a paused lane waits with its predicted
            # remaining cost (steps so far x remaining / elapsed time span) as priority.
            # Free slots take the queue's next lanes, then the waiting lanes, costliest first.
            slots, lane, nxt, wait, lanes, resumed = args
            wb = jnp.where(fin, lane, L)
            slots = slots._replace(resumed=slots.resumed | pause)
            lanes = jax.tree_util.tree_map(lambda a, s: a.at[wb].set(s, mode="drop"), lanes, slots.lane)
            resumed = resumed.at[wb].set(slots.resumed, mode="drop")
            st = slots.lane
            elapsed = st.tprev - t0
            cost = st.num_steps * (st.t1 - st.tprev) / jnp.where(elapsed > 0, elapsed, 1.0)
            wait = wait.at[jnp.where(pause, lane, L)].set(cost.astype(wait.dtype), mode="drop")
            rank = jnp.cumsum(fin.astype(jnp.int32)) - 1
            from_queue = nxt + rank < n_queue
            by_cost = jnp.argsort(-wait)  # waiting lanes first (the others wait at -inf)
            pick = by_cost[jnp.clip(rank - jnp.maximum(n_queue - nxt, 0), 0, L - 1)]
            new_lane = jnp.where(from_queue, _lane_at(nxt + rank, queue, n_queue), jnp.where(wait[pick] > no, pick, L))
            new_lane = jnp.where(fin, new_lane, lane).astype(jnp.int32)
            refill = fin & (new_lane < L)
            wait = wait.at[jnp.where(refill & ~from_queue, new_lane, L)].set(no, mode="drop")
            nxt = nxt + jnp.sum(refill & from_queue).astype(jnp.int32)
            slots = _where_rows(refill, _take(new_lane, lanes, resumed, lane_args, ts_all), slots)
            lane = jnp.where(fin, jnp.where(refill, new_lane, L), lane).astype(jnp.int32)
            return slots, lane, nxt, wait, lanes, resumed

        slots, lane, nxt, wait, lanes, resumed = jax.lax.cond(
            jnp.any(fin), swap, lambda a: a, (slots, lane, c.nxt, c.wait, c.lanes, c.resumed)
        )
        iters, paid = c.iters + n_steps, c.slot_steps + n_steps * lane.shape[0]
        return c._replace(
            slots=slots, lane=lane, nxt=nxt, wait=wait, lanes=lanes, resumed=resumed, samples=samples,
            iters=iters, slot_steps=paid,
        )  # fmt: skip

    def cond(c: PoolCarry) -> Array:
        return jnp.any(c.lane < L) & (pool_work(c) > until)

    return jax.lax.while_loop(cond, body, carry)


def run_pool(
    stepper: AbstractLaneStepper,
    lanes: LaneState,
    samples: Array,
    lane_args: tuple[Array, ...],
    args_of: Callable[[Any], Any],
    ts_all: Array,
    t0: Array,
    *,
    width: int,
    pause_frac: Array,
    min_drain_width: int = MIN_DRAIN_WIDTH,
    drain_factor: int = DRAIN_FACTOR,
) -> tuple[LaneState, Array, PoolStats]:
    """The lanes that are not done yet, in order, through ``width`` slots (refilled as lanes finish).

    ``lanes``, ``samples``: from `start_lanes` (``samples`` (L, S, n) is written in place);
    ``lane_args``/``args_of``: `split_lane_args`; ``ts_all`` (L, S): section times. A lane
    pauses at the end of its first step past t0 + ``pause_frac`` (t1 - t0) (inf: never); it
    stops between two steps, so resuming it continues the very same step sequence. A pool of at
    most `SEQUENTIAL_WIDTH` slots whose stepper reads only the next two section times
    (``stepper.section_window``) steps in an inner loop until a lane reaches a section time,
    finishes or pauses: the same steps, whose kernels XLA's CPU runtime then runs without its thread
    pool. All of the drain's widths (`drain_widths`) in one program; `jaxcelt.ensemble.run_lanes`
    runs the phases (`begin_pool`, `advance_pool`, `narrow_pool`) as programs of their own. Call
    inside jit. Returns (final lanes, samples, `PoolStats`)."""
    L = samples.shape[0]
    widths = drain_widths(width, L, drain_factor, min_drain_width)
    carry = begin_pool(lanes, samples, lane_args, ts_all, width=width)
    for nxt_w in [*widths[1:], 0]:
        carry = advance_pool(stepper, carry, lane_args, args_of, ts_all, t0, pause_frac=pause_frac, until=nxt_w)
        if nxt_w:
            carry = narrow_pool(carry, nxt_w)
    stats = PoolStats(iterations=carry.iters, slot_steps=carry.slot_steps, width=widths[0])
    return carry.lanes, carry.samples, stats
