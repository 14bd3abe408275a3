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
  batch slots (`_pool`): each iteration makes one step in every slot, and a slot whose lane
  finished is refilled with the next lane at once. Step slots are therefore only wasted in
  the final drain, not for every lane until the slowest one is done. The step is the
  algorithm of diffrax's loop body (PID + ClipStepSizeController, the same first-step
  choice, the validity monitor): for explicit FSAL Runge-Kutta solvers (Tsit5, the default;
  Dopri5, Dopri8, ...) written out as one fused step (`_erk_lane_step`: the monitor reads N
  from the step's last evaluation, stage inputs are materialised once, lane-constant
  parameters stay out of the slots), otherwise diffrax's own step (`_lane_step`). A Tsit5
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
  11.3 s on 2 devices vs 23.6 s on 1 (docs/bifurcation/README.md). Results agree with the
  1-device run to ~1e-11 over a few periods (tests), not bitwise (a different compiled
  program): over hundreds of periods chaotic lanes diverge from that seed like any other.

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
import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from . import _config  # noqa: F401
from ._diffrax_adapter import clip_to_end, loop_init, loop_step, t1_clip_floor, wrap_term
from ._types import Array
from .contact import AbstractContactLaw, get_contact_law
from .diagnostics import centre_position
from .lyapunov import celt_lyapunov
from .model import vector_field_and_normal
from .params import PARAM_NAMES, CeltParams
from .solve import DEFAULT_SOLVER, MonitoredSolver, _Field, _fill_implicit_tols, invalid_kind, simulate, status_code
from .state import initial_state

__all__ = [
    "SweepConfig",
    "SweepResult",
    "bifurcation",
    "sweep",
    "continuation",
    "lanes_params",
    "parse_range",
    "orbit",
    "run_lanes",
    "parameter_map",
]


@dataclasses.dataclass(frozen=True)
class SweepConfig:
    """Static settings of a sweep (everything but the parameter values and initial states)."""

    transient_periods: int = 200
    sample_periods: int = 100
    lyapunov_periods: int = 0
    """periods of tangent dynamics after the transient (0: no Lyapunov exponent)"""
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int = 1_000_000
    solver: Any = DEFAULT_SOLVER
    contact_law: Any = None
    t0: float = 0.0
    stop_on_invalid: bool = False
    """end a lane at the first accepted step whose end state is invalid (status 2, later samples inf)"""

    def __post_init__(self):
        for name in ("transient_periods", "sample_periods", "lyapunov_periods", "max_steps"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
                raise ValueError(f"{name!r} must be a non-negative int, got {v!r}")
        if self.sample_periods < 1:
            raise ValueError(f"'sample_periods' must be >= 1, got {self.sample_periods}")
        if self.max_steps < 1:
            raise ValueError(f"'max_steps' must be >= 1, got {self.max_steps}")
        for name in ("rtol", "atol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name!r} must be a positive finite number, got {v!r}")

    def attrs(self) -> dict[str, Any]:
        """Plain-python description (for dataset attributes)."""
        law = get_contact_law(self.contact_law)
        return dict(
            transient_periods=int(self.transient_periods),
            sample_periods=int(self.sample_periods),
            lyapunov_periods=int(self.lyapunov_periods),
            rtol=float(self.rtol),
            atol=float(self.atol),
            max_steps=int(self.max_steps),
            solver=type(self.solver).__name__,
            step_size_controller="PIDController + ClipStepSizeController(step_ts=section times)",
            contact_law=f"{type(law).__name__}(rolling_resistance={law.rolling_resistance})",
            t0=float(self.t0),
            stop_on_invalid=int(bool(self.stop_on_invalid)),
        )


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


def lanes_params(params: CeltParams, name: str, values: Array) -> CeltParams:
    """A batched `CeltParams` with a leading lane axis: field ``name`` = ``values``, others broadcast."""
    if name not in PARAM_NAMES:
        raise ValueError(f"unknown parameter {name!r}; known: {PARAM_NAMES}")
    values = jnp.asarray(values, dtype=jnp.float64)
    L = values.shape[0]
    pb = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(jnp.asarray(x), (L,)), params)
    return eqx.tree_at(lambda p: getattr(p, name), pb, values)


def _extras(ys: Array, p: CeltParams) -> dict[str, Array]:
    """Global motion of O from one lane's samples (S, 13); samples after a stop (inf) ignored."""
    r_O = jax.vmap(centre_position, in_axes=(0, None))(ys, p)
    dist = jnp.linalg.norm(r_O[:, :2] - r_O[0:1, :2], axis=-1)
    fin = jnp.isfinite(dist)
    last = jnp.max(jnp.where(fin, jnp.arange(dist.shape[0]), -1))
    drift = jnp.where(last >= 0, dist[jnp.maximum(last, 0)], jnp.nan)
    exc = jnp.where(last >= 0, jnp.max(jnp.where(fin, dist, -jnp.inf)), jnp.nan)
    return dict(drift=drift, max_excursion=exc, r_O=r_O)


# --------------------------------------------------------------------------------------
# Lane pool: one jitted while loop over a fixed number of batch slots that are refilled
# with the next lane as soon as a lane finishes (no slot waits for the chunk's slowest lane).
# --------------------------------------------------------------------------------------


def _pool_parts(cfg: SweepConfig):
    law = get_contact_law(cfg.contact_law)
    solver = MonitoredSolver(solver=_fill_implicit_tols(cfg.solver, cfg.rtol, cfg.atol), law=law)
    # wrapped as diffeqsolve wraps it, so that lanes equal `simulate` step for step
    term = wrap_term(diffrax.ODETerm(_Field(law)))
    return law, solver, term


def _controller(tols: Array, ts: Array):
    # the same controller `simulate(..., exact_ts=True)` builds; the tolerances are traced
    # there too (jit arguments): as constants XLA would fold them differently (1-ulp changes
    # of the error norm flip accept/reject decisions and the lane would not equal `simulate`)
    pid = diffrax.PIDController(rtol=tols[0], atol=tols[1])
    return diffrax.ClipStepSizeController(pid, step_ts=ts)


def _erk_tableau(cfg: SweepConfig) -> Any:
    """Butcher tableau of an explicit FSAL Runge-Kutta solver (Tsit5, Dopri5, Dopri8, ...) or None.

    For these the pool runs its own fused step (`_erk_lane_step`); any other solver (implicit,
    non-FSAL) runs diffrax's own step (`_lane_step`)."""
    tab = getattr(cfg.solver, "tableau", None)
    if isinstance(cfg.solver, diffrax.AbstractERK) and tab is not None and tab.fsal and tab.b_error is not None:
        return tab
    return None


def _lane_init(cfg: SweepConfig, p: CeltParams, y0: Array, ts: Array, tols: Array) -> dict[str, Any]:
    """diffeqsolve's initialisation (controller.init picks the first step, solver.init)."""
    law, solver, term = _pool_parts(cfg)
    t0 = jnp.asarray(cfg.t0, jnp.float64)
    t1 = ts[-1]
    fused = _erk_tableau(cfg) is not None
    tnext, cstate, sstate = loop_init(solver, term, _controller(tols, ts), t0, t1, y0, p, solver_state=not fused)
    if not fused:
        state = dict(sstate=sstate, cstate=cstate)
    else:
        # the fused step's state: the FSAL derivative and the monitor, from one evaluation
        f0, (N, den) = vector_field_and_normal(t0, y0, p, law)
        kind = invalid_kind(N, den, y0[8])
        state = dict(
            f=f0,
            first_invalid_t=jnp.where(kind > 0, t0, jnp.inf),
            first_invalid_kind=kind,
            min_N=N,
            min_n3=y0[8],
        )
    floor = t1_clip_floor(t1)
    k0 = (ts[0] <= t0).astype(jnp.int32)  # a section time at t0 is the initial state itself
    stop0 = jnp.asarray(cfg.stop_on_invalid) & (_lane_monitor(state)[1] > 0)
    return dict(
        p=p,
        ts=ts,
        tols=tols,
        t1=t1,
        floor=floor,
        y=y0,
        tprev=t0,
        tnext=tnext,
        result=diffrax.RESULTS.where(stop0, diffrax.RESULTS.event_occurred, diffrax.RESULTS.successful),
        num_steps=jnp.zeros((), jnp.int32),
        k=k0,
        done=stop0,
        **state,
    )


def _lane_monitor(st: dict[str, Any]) -> tuple[Array, Array, Array, Array]:
    """(first_invalid_t, first_invalid_kind, min_N, max_tilt) of a slot, either step kernel."""
    if "sstate" in st:
        mon = st["sstate"][1]
        return mon.first_invalid_t, mon.first_invalid_kind, mon.min_N, mon.max_tilt
    # max over steps of arccos(n3) = arccos(min n3): arccos is decreasing
    return st["first_invalid_t"], st["first_invalid_kind"], st["min_N"], jnp.arccos(jnp.clip(st["min_n3"], -1, 1))


def _combine(y0: Array, coeffs: Any, ks: list[Array]) -> Array:
    """y0 + sum_j coeffs[j] ks[j] over the non-zero coefficients (tableau constants)."""
    out = y0
    for a, k in zip(np.asarray(coeffs, dtype=float), ks):
        if a != 0.0:
            out = out + a * k
    return out


def _kernel_boundary(opaque_true: Array) -> Callable[[Array], Array]:
    """x -> x, materialised: a conditional on a predicate XLA cannot see (a runtime True).

    XLA's CPU fusion copies cheap producers into every consumer kernel, so without this each
    of the right-hand side's ~40 kernels recomputes the stage input y0 + sum_j a_ij k_j for
    the components it reads; a conditional is a kernel boundary, after which they read one
    buffer instead (measured: a Tsit5 lane-step 3.0 -> 2.1 us on one core, 32 lanes). The
    other branch is never taken; it returns NaN so that it could not pass unnoticed, and it
    differs from the first so that XLA does not fold the conditional away.
    """

    def boundary(x: Array) -> Array:
        return jax.lax.cond(opaque_true, lambda x: x, lambda x: jnp.full_like(x, jnp.nan), x)

    return boundary


def _erk_lane_step(
    cfg: SweepConfig, tab: Any, st: dict[str, Any], boundary: Callable[[Array], Array] = lambda x: x
) -> tuple[dict[str, Any], Array]:
    """`_lane_step` for an explicit FSAL Runge-Kutta tableau, fused into one straight-line step.

    The same algorithm as diffrax's loop body with ``PIDController`` (I-control, diffrax's
    defaults) inside ``ClipStepSizeController(step_ts=ts)``: stages k_i = dt f(t0 + c_i dt,
    y0 + sum_j a_ij k_j), y1 = y0 + sum b_i k_i, error sum e_i k_i, the RMS error ratio and
    factor clip(0.9 err^(-1/q), [1, 10] if accepted else [0.2, 0.9]) with q the error order
    diffrax gives its controller (Tsit5 5, Dopri8 8), the next step
    clipped onto the next section time and onto t1. The last stage is f(t1, y1) (FSAL); its
    normal force and denominator feed the validity monitor, so monitoring costs no extra
    evaluation (diffrax's `MonitoredSolver` evaluates N once more per step). Without diffrax's
    generic stage loop, stage buffer and dense-output bookkeeping, XLA fuses the step into
    fewer kernels (``benchmarks/bench_step_parts.py``). Tsit5 lanes agree with `simulate` to
    rounding (the arithmetic order differs), with the same step counts (tests); Dopri8's
    strongly cancelling error weights let rounding move a few steps (module docstring).
    ``boundary``: applied to every stage input (`_kernel_boundary`; identity by default).
    """
    R = diffrax.RESULTS
    law = get_contact_law(cfg.contact_law)
    p, ts, t1, y0, t0 = st["p"], st["ts"], st["t1"], st["y"], st["tprev"]
    dt = st["tnext"] - t0
    ks = [st["f"] * dt]
    for c, a in zip(np.asarray(tab.c, dtype=float), tab.a_lower):
        yi = boundary(_combine(y0, a, ks))
        fi, aux = vector_field_and_normal(t0 + c * dt, yi, p, law)
        ks.append(fi * dt)
    b = np.asarray(tab.b_sol, dtype=float)
    fsal_is_y1 = b[-1] == 0.0 and np.array_equal(np.asarray(tab.a_lower[-1], dtype=float), b[:-1])
    y1 = yi if fsal_is_y1 else _combine(y0, b, ks)
    y_err = _combine(jnp.zeros_like(y0), tab.b_error, ks)
    y_err = jnp.where(jnp.isnan(y_err), jnp.inf, y_err)
    # diffrax PIDController.adapt_step_size (pcoeff = dcoeff = 0, icoeff = 1)
    pid = diffrax.PIDController(rtol=st["tols"][0], atol=st["tols"][1])
    y1s = jnp.where(jnp.isnan(y1).any(), y0, y1)
    scaled = pid.norm(y_err / (pid.atol + jnp.maximum(jnp.abs(y0), jnp.abs(y1s)) * pid.rtol))
    keep = scaled < 1
    inv = 1 / scaled
    order = cfg.solver.error_order(_pool_parts(cfg)[2])  # exactly what diffrax's controller is given
    factor = jnp.clip(
        pid.safety * inv ** (1.0 / order),
        jnp.where(keep, 1.0, pid.factormin),
        jnp.where(keep, pid.factormax, pid.safety),
    )
    tprev = jnp.where(keep, st["tnext"], t0)
    tnext = tprev + dt * factor
    # section times: the accepted step's end *is* the sample when it lands on ts[k]
    S = ts.shape[0]
    hit = keep & (st["k"] < S) & (ts[jnp.minimum(st["k"], S - 1)] <= tprev)
    k = st["k"] + hit.astype(jnp.int32)
    tnext = jnp.where(k < S, jnp.minimum(ts[jnp.minimum(k, S - 1)], tnext), tnext)  # diffrax's _clip_t
    tprev, tnext = clip_to_end(tprev, tnext, t1, st["floor"], keep)
    # validity monitor at the accepted step's end (N, den from the FSAL evaluation)
    N, den = aux
    kind = invalid_kind(N, den, y1[8])
    new_invalid = keep & (kind > 0) & (st["first_invalid_kind"] == 0)
    result = st["result"]
    if cfg.stop_on_invalid:
        result = R.where(new_invalid & (result == R.successful), R.event_occurred, result)
    num_steps = st["num_steps"] + 1
    done = (result != R.successful) | (tprev >= t1) | (num_steps >= cfg.max_steps)
    new = dict(
        st,
        y=jnp.where(keep, y1, y0),
        f=jnp.where(keep, fi, st["f"]),
        tprev=tprev,
        tnext=tnext,
        first_invalid_t=jnp.where(new_invalid, tprev, st["first_invalid_t"]),
        first_invalid_kind=jnp.where(new_invalid, kind, st["first_invalid_kind"]),
        min_N=jnp.where(keep, jnp.minimum(st["min_N"], N), st["min_N"]),
        min_n3=jnp.where(keep, jnp.minimum(st["min_n3"], y1[8]), st["min_n3"]),
        result=result,
        num_steps=num_steps,
        k=k,
        done=done,
    )
    return new, hit


def _lane_step(cfg: SweepConfig, st: dict[str, Any]) -> tuple[dict[str, Any], Array]:
    """One iteration of diffrax's integration loop (`diffrax._integrate.loop.body_fun_aux`) for
    one lane, with exact section saving (the controller steps onto every section time, so the
    accepted step's end state *is* the sample) and the stop-on-invalid event. Returns the new
    state and whether this step's end is a section sample."""
    R = diffrax.RESULTS
    _, solver, term = _pool_parts(cfg)
    p, ts, t1 = st["p"], st["ts"], st["t1"]
    keep, y1, tprev, tnext, sstate, cstate, sres, cres = loop_step(
        solver, term, _controller(st["tols"], ts), t1, st["floor"], st["tprev"], st["tnext"], st["y"], p,
        st["sstate"], st["cstate"],
    )  # fmt: skip
    y = jnp.where(keep, y1, st["y"])
    sstate = jax.tree_util.tree_map(lambda a, b: jnp.where(keep, a, b), sstate, st["sstate"])
    sres = R.where(keep, sres, R.successful)
    result = R.where(st["result"] == R.successful, sres, st["result"])
    result = R.where(result == R.successful, cres, result)
    num_steps = st["num_steps"] + 1
    S = ts.shape[0]
    hit = keep & (st["k"] < S) & (ts[jnp.minimum(st["k"], S - 1)] <= tprev)
    k = st["k"] + hit.astype(jnp.int32)
    if cfg.stop_on_invalid:
        # diffrax.Event(cond = state invalid) without root finding: ends at the first accepted
        # step whose end state is invalid -- exactly where the monitor first records it
        ev = keep & (sstate[1].first_invalid_kind > 0) & (result == R.successful)
        result = R.where(ev, R.event_occurred, result)
    ok = result == R.successful
    done = ~ok | (tprev >= t1) | (num_steps >= cfg.max_steps)
    new = dict(
        st,
        y=y,
        tprev=tprev,
        tnext=tnext,
        sstate=sstate,
        cstate=cstate,
        result=result,
        num_steps=num_steps,
        k=k,
        done=done,
    )
    return new, hit


def _lane_status(st: dict[str, Any]) -> Array:
    # a lane that is still "successful" but has not reached t1 ran out of steps: status 1
    ok = st["result"] == diffrax.RESULTS.successful
    return jnp.where(ok, jnp.where(st["tprev"] >= st["t1"], 0, 1), status_code(st["result"])).astype(jnp.int32)


def _param_split(pb: CeltParams, vary: tuple[bool, ...]) -> tuple[tuple[Array, ...], Callable[[Any], CeltParams]]:
    """(the lane-varying leaves of ``pb``, a function rebuilding one lane's params from them).

    ``vary`` (static, one flag per leaf of ``pb``): the parameters that differ between lanes.
    Only those ride in the slots; the others enter the step as unbatched constants, so XLA
    computes what depends on them alone (inertia adjugate, elliptic integrals, b_Ts^m_Ts, ...)
    once instead of in every slot at every stage."""
    leaves, treedef = jax.tree_util.tree_flatten(pb)
    const = [x[0] for x in leaves]
    pv_all = tuple(x for x, v in zip(leaves, vary) if v)

    def params_of(pv):
        it = iter(pv)
        return jax.tree_util.tree_unflatten(treedef, [next(it) if v else c for v, c in zip(vary, const)])

    return pv_all, params_of


def _section_times(pb: CeltParams, transient: Array, cfg: SweepConfig) -> Array:
    """(L, S) stroboscopic times t0 + k 2 pi / omega_pi, k = transient, transient + 1, ..."""
    T = 2 * jnp.pi / pb.omega_pi
    S = cfg.sample_periods
    return jnp.asarray(cfg.t0, jnp.float64) + T[:, None] * (transient + jnp.arange(S, dtype=jnp.float64))[None, :]


_SLOT_ONLY = ("p", "ts")  # slot fields rebuilt from the lane's parameters, not stored per lane


def _init_lanes(
    pb: CeltParams, y0b: Array, live: Array, transient: Array, tols: Array, cfg: SweepConfig, vary: tuple[bool, ...]
) -> tuple[dict[str, Array], Array]:
    """Every lane's starting state (diffeqsolve's initialisation) and the samples buffer.

    ``live`` (L,) bool: False marks padding lanes, which start done. A section time at t0
    (transient 0) is the initial state itself: written here."""
    pv_all, params_of = _param_split(pb, vary)
    ts_all = _section_times(pb, transient, cfg)
    st = jax.vmap(lambda pv, y, ts: _lane_init(cfg, params_of(pv), y, ts, tols))(pv_all, y0b, ts_all)
    ls = {k: v for k, v in st.items() if k not in _SLOT_ONLY}
    ls["done"] = ls["done"] | ~live
    ls["resumed"] = jnp.zeros_like(ls["done"])  # paused once and taken up again (pauses only once)
    L, S = y0b.shape[0], cfg.sample_periods
    samples = jnp.full((L, S, 13), jnp.inf).at[:, 0].set(jnp.where((ls["k"] > 0)[:, None], y0b, jnp.inf))
    return ls, samples


def _pool(
    pb: CeltParams,
    ls: dict[str, Array],
    samples: Array,
    pause_frac: Array,
    transient: Array,
    cfg: SweepConfig,
    width: int,
    vary: tuple[bool, ...],
    opaque_true: Array,
) -> tuple[dict[str, Array], Array, Array, Array]:
    """The lanes of ``ls`` that are not done yet, in order, through ``width`` slots (refilled
    as lanes finish).

    ``ls``: every lane's state (`_init_lanes`); a lane is taken from it when a slot is free
    and written back when it is done or paused. A lane pauses at
    the end of its first step past t0 + ``pause_frac`` (t1 - t0) (inf: never): it stops
    between two steps, so resuming it from ``ls`` continues the very same step sequence.
    ``samples`` (L, S, 13): the section buffer, written in place. ``vary``: see
    `_param_split`. ``opaque_true``: a traced True (a jit argument, not a Python bool: XLA
    would fold a constant predicate and the boundary would vanish) for `_kernel_boundary`.
    Returns (ls, samples, loop iterations, step slots paid).
    """
    pv_all, params_of = _param_split(pb, vary)
    L = samples.shape[0]
    B = min(width, L)
    # the queue: lanes with work (not padding, not invalid at t0 with stop_on_invalid), in order
    queue = jnp.argsort(ls["done"], stable=True).astype(jnp.int32)
    n_queue = jnp.sum(~ls["done"]).astype(jnp.int32)
    ts_all = _section_times(pb, transient, cfg)
    t0 = jnp.asarray(cfg.t0, jnp.float64)
    tab = _erk_tableau(cfg)

    def _step(st):
        pv = st["p"]
        st = dict(st, p=params_of(pv))
        if tab is None:
            new, hit = _lane_step(cfg, st)
        else:
            new, hit = _erk_lane_step(cfg, tab, st, _kernel_boundary(jnp.asarray(opaque_true)))
        paused = ~new["done"] & ~st["resumed"] & (new["tprev"] >= t0 + pause_frac * (new["t1"] - t0))
        return dict(new, p=pv), hit, paused

    step_v = jax.vmap(_step)

    def take(lane, ls):
        j = jnp.minimum(lane, L - 1)
        st = jax.tree_util.tree_map(lambda x: x[j], ls)
        return dict(st, p=tuple(x[j] for x in pv_all), ts=ts_all[j])

    def lane_at(pos):
        return jnp.where(pos < n_queue, queue[jnp.minimum(pos, L - 1)], L).astype(jnp.int32)

    lane = lane_at(jnp.arange(B, dtype=jnp.int32))
    slots = take(lane, ls)
    no = jnp.asarray(-jnp.inf)

    def body(c):
        slots, lane, nxt, wait, ls, samples, iters, slot_steps = c
        active = (lane < L) & ~slots["done"]
        stepped, hit, paused = step_v(slots)
        slots = jax.tree_util.tree_map(
            lambda a, b: jnp.where(jnp.reshape(active, active.shape + (1,) * (a.ndim - 1)), a, b), stepped, slots
        )
        w = jnp.where(active & hit, lane, L)
        samples = samples.at[w, slots["k"] - 1].set(slots["y"], mode="drop")
        pause = active & paused
        fin = (lane < L) & (slots["done"] | pause)

        def swap(args):
            # Write finished and paused lanes back; a paused lane waits with its predicted
            # remaining cost (steps so far x remaining / elapsed time span) as priority.
            # Free slots take the queue's next lanes, then the waiting lanes, costliest first.
            slots, lane, nxt, wait, ls = args
            wb = jnp.where(fin, lane, L)
            slots = dict(slots, resumed=slots["resumed"] | pause)
            ls = jax.tree_util.tree_map(lambda a, s: a.at[wb].set(s, mode="drop"), ls, {k: slots[k] for k in ls})
            elapsed = slots["tprev"] - t0
            cost = slots["num_steps"] * (slots["t1"] - slots["tprev"]) / jnp.where(elapsed > 0, elapsed, 1.0)
            wait = wait.at[jnp.where(pause, lane, L)].set(cost.astype(wait.dtype), mode="drop")
            rank = jnp.cumsum(fin.astype(jnp.int32)) - 1
            from_queue = nxt + rank < n_queue
            by_cost = jnp.argsort(-wait)  # waiting lanes first (the others wait at -inf)
            pick = by_cost[jnp.clip(rank - jnp.maximum(n_queue - nxt, 0), 0, L - 1)]
            new_lane = jnp.where(from_queue, lane_at(nxt + rank), jnp.where(wait[pick] > no, pick, L))
            new_lane = jnp.where(fin, new_lane, lane).astype(jnp.int32)
            refill = fin & (new_lane < L)
            wait = wait.at[jnp.where(refill & ~from_queue, new_lane, L)].set(no, mode="drop")
            nxt = nxt + jnp.sum(refill & from_queue).astype(jnp.int32)
            fresh = take(new_lane, ls)
            slots = jax.tree_util.tree_map(
                lambda a, b: jnp.where(jnp.reshape(refill, refill.shape + (1,) * (a.ndim - 1)), a, b), fresh, slots
            )
            return slots, jnp.where(fin, jnp.where(refill, new_lane, L), lane).astype(jnp.int32), nxt, wait, ls

        slots, lane, nxt, wait, ls = jax.lax.cond(jnp.any(fin), swap, lambda a: a, (slots, lane, nxt, wait, ls))
        return slots, lane, nxt, wait, ls, samples, iters + 1, slot_steps + lane.shape[0]

    # The drain: once no more than half of the slots have work left (running lanes plus lanes
    # not yet started), the running lanes are gathered into a pool half as wide and go on
    # there (widths B, B/2, B/4, ... down to 16), so that the end of a chunk does not pay for
    # idle slots at the full width's cost. Per-lane results do not depend on the width
    # (same steps and statuses, samples to rounding; tested). Each width compiles the step
    # again (~9 s on CPU), so only pools with a queue (more lanes than slots) do this.
    widths = [B]
    while L > B and widths[-1] // 2 >= MIN_DRAIN_WIDTH:
        widths.append(widths[-1] // 2)
    z = jnp.zeros((), jnp.int32)
    wait = jnp.full((L,), -jnp.inf)  # paused lanes: their predicted remaining cost
    carry = (slots, lane, jnp.minimum(jnp.asarray(B, jnp.int32), n_queue), wait, ls, samples, z, z)
    for nxt_w in [*widths[1:], 0]:

        def cond(c, nxt_w=nxt_w):
            work = jnp.sum(c[1] < L) + jnp.maximum(n_queue - c[2], 0) + jnp.sum(c[3] > -jnp.inf)
            return jnp.any(c[1] < L) & (work > nxt_w)

        carry = jax.lax.while_loop(cond, body, carry)
        if nxt_w:
            slots, lane = carry[0], carry[1]
            keep = jnp.argsort(lane >= L, stable=True)[:nxt_w]  # the running lanes first
            carry = (jax.tree_util.tree_map(lambda x, keep=keep: x[keep], slots), lane[keep], *carry[2:])
    _, _, _, _, ls, samples, iters, slot_steps = carry
    return ls, samples, iters, slot_steps


def _lane_outputs(ls: dict[str, Array]) -> dict[str, Array]:
    """Per-lane results from the final lane states."""
    first_t, first_kind, min_N, max_tilt = jax.vmap(_lane_monitor)(ls)
    return dict(
        y_final=ls["y"],
        status=jax.vmap(_lane_status)(ls),
        num_steps=ls["num_steps"],
        first_invalid_t=first_t,
        first_invalid_kind=first_kind.astype(jnp.int32),
        min_N=min_N,
        max_tilt=max_tilt,
    )


def _lyap_lane(p: CeltParams, y_start: Array, t_start: Array, cfg: SweepConfig) -> Array:
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
    )
    return lr.exponent


def _sharded(run: Callable, mesh: Any, n_in: int) -> Callable:
    if mesh is None:
        return run
    spec = jax.sharding.PartitionSpec("lanes")
    return jax.shard_map(run, mesh=mesh, in_specs=(spec,) * n_in, out_specs=spec, check_vma=False)


@eqx.filter_jit
def _pool_chunk(
    pb: CeltParams,
    y0b: Array,
    live: Array,
    pause_frac: Array,
    transient: Array,
    tols: Array,
    cfg: SweepConfig,
    width: int,
    mesh: Any,
    vary: tuple[bool, ...],
    opaque_true: Array,
) -> tuple[dict[str, Array], Array, Array]:
    def run(pb, y0b, live):
        ls, samples = _init_lanes(pb, y0b, live, transient, tols, cfg, vary)
        ls, samples, iters, slot_steps = _pool(pb, ls, samples, pause_frac, transient, cfg, width, vary, opaque_true)
        out = dict(_lane_outputs(ls), samples=samples, t_samples=_section_times(pb, transient, cfg))
        out.update(jax.vmap(_extras)(samples, pb))
        return out, iters[None], slot_steps[None]  # loop counters: one per device

    return _sharded(run, mesh, 3)(pb, y0b, live)


@eqx.filter_jit
def _lyap_chunk(pb: CeltParams, y_start: Array, t_start: Array, cfg: SweepConfig, mesh: Any) -> Array:
    run = jax.vmap(lambda p, y, t: _lyap_lane(p, y, t, cfg))
    return _sharded(run, mesh, 3)(pb, y_start, t_start)


def _mesh(devices: Sequence[Any] | None) -> Any:
    devs = list(devices) if devices is not None else jax.local_devices()
    if len(devs) <= 1:
        return None
    return jax.sharding.Mesh(np.array(devs), ("lanes",))


def _pad(x: np.ndarray, n: int) -> np.ndarray:
    if len(x) == n:
        return x
    return np.concatenate([x, np.repeat(x[-1:], n - len(x), axis=0)])


DEFAULT_WIDTH = 96
"""pool slots per device. Each pool iteration pays a fixed cost (~330 XLA kernel launches,
~30 us on CPU) besides its per-slot work, so wider pools finish in fewer iterations; with the
pilot pause, 96 was fastest for 400 lanes x 300 periods on 2 cores
(``benchmarks/bench_schedule.py``; docs/bifurcation/README.md)."""
MIN_DRAIN_WIDTH = 16  # narrowest pool of the drain (narrower costs more per slot than it saves)
PILOT_FRACTION = 0.1
"""a lane pauses once after this fraction of its time span and waits for a slot with its
predicted remaining cost (see `_pool`; ``benchmarks/bench_schedule.py``)"""


def run_lanes(
    pb: CeltParams,
    y0b: Array,
    cfg: SweepConfig,
    *,
    devices: Sequence[Any] | None = None,
    pad_to: int | None = None,
    width: int | None = None,
    compile_only: bool = False,
    varying: Sequence[str] = (),
    pilot_fraction: float = PILOT_FRACTION,
) -> dict[str, np.ndarray]:
    """Run one chunk of lanes (batched params and y0 with a leading lane axis) and return numpy arrays.

    ``width`` batch slots per device (default
    `DEFAULT_WIDTH`) step in one jitted while loop; a slot whose lane finishes is refilled
    with the next lane at once, so no slot idles until the slowest lane is done (only the
    final drain does). ``pilot_fraction`` (default `PILOT_FRACTION`; 0 = off; only used
    when a device has more lanes than slots): each lane pauses once after this fraction of
    its time span and is taken up again costliest-predicted first (see `_pool`). The Lyapunov stage (``cfg.lyapunov_periods > 0``) then runs vmapped
    over the successful lanes in groups of ``width`` ordered by the measured main-solve
    step count (a cost estimate that needs no pilot run).

    Sharded over ``devices`` (default all local devices; lanes are dealt round-robin); padded
    to ``pad_to`` lanes (so a short last chunk reuses the compiled shape) and to a multiple
    of the device count. Padding lanes are dropped; in the pool they finish at once.
    ``compile_only=True`` (pool): every lane marked as padding -- compiles the kernel for
    these shapes and returns at once (used to time compilation apart from running).
    ``varying``: names of parameters to treat as differing between lanes even where this
    chunk's lanes happen to share a value (parameters that do differ are always detected),
    so that all chunks of a sweep compile to one kernel; the others are constants of the
    pool's step (see `_pool`).
    """
    mesh = _mesh(devices)
    L = int(np.shape(y0b)[0])
    ndev = 1 if mesh is None else mesh.devices.size
    Lp = math.ceil(max(L, pad_to or 0) / ndev) * ndev
    pb_np = jax.tree_util.tree_map(lambda x: _pad(np.asarray(x), Lp), pb)
    y0_np = _pad(np.asarray(y0b, dtype=np.float64), Lp)
    static_cfg = dataclasses.replace(cfg, transient_periods=0)  # transient is traced: no recompiles
    transient = jnp.asarray(float(cfg.transient_periods))
    W = int(width or DEFAULT_WIDTH)
    if W < 1:
        raise ValueError(f"width must be >= 1, got {width!r}")
    nocfg = dataclasses.replace(static_cfg, lyapunov_periods=0)
    unknown = set(varying) - set(PARAM_NAMES)
    if unknown:
        raise ValueError(f"varying: unknown parameter name(s) {sorted(unknown)}")
    path_leaves = jax.tree_util.tree_flatten_with_path(pb_np)[0]
    vary = tuple(bool(path[-1].name in varying or np.any(x != x[:1])) for path, x in path_leaves)
    Lloc = Lp // ndev
    Wd = min(W, Lloc)
    # position i of the sharded arrays holds lane pos_lane[i]; device d holds positions
    # d Lloc ... (d + 1) Lloc - 1 and gets lanes d, d + ndev, ... (a mix of cheap and costly)
    pos_lane = np.arange(Lp).reshape(-1, ndev).T.reshape(-1)
    pb_p = jax.tree_util.tree_map(lambda x: x[pos_lane], pb_np)
    live = (pos_lane < L) & (not compile_only)
    tols = jnp.asarray([cfg.rtol, cfg.atol])
    # the pilot pause only pays where lanes queue for slots
    frac = float(pilot_fraction) if pilot_fraction and Lloc > Wd else np.inf
    out, iters, slot_steps = _pool_chunk(
        pb_p, y0_np[pos_lane], live, jnp.asarray(frac), transient, tols, nocfg, Wd, mesh, vary, jnp.asarray(True)
    )
    iters, slot_steps = np.asarray(iters), int(np.sum(np.asarray(slot_steps)))
    out = jax.tree_util.tree_map(np.asarray, jax.block_until_ready(out))
    inv = np.empty_like(pos_lane)
    inv[pos_lane] = np.arange(Lp)
    out = {k: v[inv][:L] for k, v in out.items()}
    out["pool_iterations"] = np.full(L, int(iters.max()))  # the busiest device's loop iterations
    out["pool_slot_steps"] = np.full(L, slot_steps)  # step slots paid, over all devices and widths
    out["pool_width"] = np.full(L, Wd)
    out["valid"] = out["first_invalid_kind"] == 0
    out["lyapunov"] = np.full(L, np.nan)
    if cfg.lyapunov_periods > 0 and not compile_only:
        ok = np.flatnonzero(out["status"] == 0)
        ok = ok[np.argsort(-out["num_steps"][ok], kind="stable")]  # similar cost side by side
        G = W * ndev
        for i in range(0, len(ok), G):
            idx = _pad(ok[i : i + G], G)
            lam = _lyap_chunk(
                jax.tree_util.tree_map(lambda x, idx=idx: x[idx], pb_np),
                out["samples"][idx, 0],
                out["t_samples"][idx, 0],
                static_cfg,
                mesh,
            )
            n = min(G, len(ok) - i)
            out["lyapunov"][idx[:n]] = np.asarray(lam)[:n]
    return out


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
    transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0, stop_on_invalid
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
    )


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
        res = run_lanes(pb, lane_y0[idx], cfg, devices=devices, pad_to=pad_to, width=width, varying=varying)
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
    width: int | None = None,
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
            after the transient (`jaxcelt.lyapunov.celt_lyapunov`) -> ``lyapunov`` [1/s].
        rtol, atol, max_steps, solver, contact_law, t0: as in `jaxcelt.simulate`.
        chunk_size: lanes per jitted solve, the unit of resumable writing (default: all
            lanes in one chunk).
        sort_by_cost: order lanes by the cost proxy (time span per period, 1/omega_pi),
            most expensive first, before chunking (the pool then drains on cheap lanes).
        stop_on_invalid: end each lane at its first invalid state (lift-off, n3 <= 0):
            status 2, samples after the stop inf, no Lyapunov exponent. Default False (the
            model is integrated on, validity reported), as in `jaxcelt.simulate`.
        width: batch slots per device of the pool (default `DEFAULT_WIDTH`).
        devices: devices to shard each chunk over (default all local devices).
        out: directory; write the dataset chunk by chunk there and resume a previous,
            interrupted run of the same sweep (`jaxcelt.dataset`). Required when several
            processes run the sweep together (`jax.distributed`; see the module docstring).
        progress: tqdm bar over lanes (with ETA).
        on_chunk: ``on_chunk(chunk_index, chunk_results)`` called after each chunk.

    Returns:
        `SweepResult` with lane arrays reshaped to (L_v, K, ...) when y0 has K starts, else (L_v, ...).
        In a multi-process run (`jax.distributed`), process 0 returns it and the others None.
    """
    cfg = _sweep_config(
        transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0,
        stop_on_invalid,
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
    L = Lv * K
    pb_all = lanes_params(params, name, lane_values)
    if not np.all(np.asarray(pb_all.omega_pi) > 0):
        raise ValueError("stroboscopic sampling needs omega_pi > 0 in every lane")
    order = np.arange(L)
    if sort_by_cost:
        order = np.argsort(np.asarray(pb_all.omega_pi), kind="stable")  # longest period first
    cs = L if chunk_size is None else max(1, min(int(chunk_size), L))  # no padding beyond the lanes
    chunks = [order[i : i + cs] for i in range(0, L, cs)]

    writer = None
    done: dict[int, dict[str, np.ndarray]] = {}
    if out is not None:
        from .dataset import SweepWriter

        writer = SweepWriter(
            out,
            params=params,
            name=name,
            lane_values=lane_values,
            lane_y0=lane_y0,
            n_starts=K,
            config=cfg,
            chunks=chunks,
        )
        done = writer.load_done()

    lanes = _run_all(
        pb_all, lane_y0, cfg, chunks, cs, writer, done,
        devices=devices, width=width, varying=(name,),
        progress=progress, desc=f"sweep {name}", on_chunk=on_chunk,
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
    width: int | None = None,
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
        a sweep dataset (`jaxcelt.dataset`: section samples, status, validity, ``lyapunov``
        [1/s] if ``lyapunov_periods > 0``, NaN otherwise) and the regime labels ``regime``,
        ``period``, ``global_motion`` (`jaxcelt.regimes`). With ``out`` it is also written to
        ``out/sweep.nc``. In a multi-process run (`jax.distributed`), process 0 returns it and
        the others None.
    """
    cfg = _sweep_config(
        transient_periods, sample_periods, lyapunov_periods, rtol, atol, max_steps, solver, contact_law, t0,
        stop_on_invalid,
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
    L = nx * ny * K
    lane_x = np.repeat(xs, ny * K)
    lane_y = np.tile(np.repeat(ys, K), nx)
    lane_y0 = np.ascontiguousarray(np.tile(y0v, (nx * ny, 1)))
    pb_all = lanes_params(params, xn, lane_x)
    pb_all = eqx.tree_at(lambda p: getattr(p, yn), pb_all, jnp.asarray(lane_y))
    if not np.all(np.asarray(pb_all.omega_pi) > 0):
        raise ValueError("stroboscopic sampling needs omega_pi > 0 in every lane")
    order = np.arange(L)
    if sort_by_cost:
        order = np.argsort(np.asarray(pb_all.omega_pi), kind="stable")  # longest period first
    cs = L if chunk_size is None else max(1, min(int(chunk_size), L))
    chunks = [order[i : i + cs] for i in range(0, L, cs)]
    writer = None
    done: dict[int, dict[str, np.ndarray]] = {}
    if out is not None:
        from .dataset import SweepWriter

        writer = SweepWriter(
            out,
            params=params,
            name=[xn, yn],
            lane_values=np.stack([lane_x, lane_y], axis=1),
            lane_y0=lane_y0,
            n_starts=K,
            config=cfg,
            chunks=chunks,
        )
        done = writer.load_done()
    lanes = _run_all(
        pb_all, lane_y0, cfg, chunks, cs, writer, done,
        devices=devices, width=width, varying=(xn, yn),
        progress=progress, desc=f"map {xn} x {yn}", on_chunk=on_chunk,
    )  # fmt: skip
    if lanes is None:  # a process other than 0 of a multi-process map
        return None
    from .dataset import to_map_dataset

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
    ``transient_periods``; save times include the section times exactly (``exact_ts``).

    Returns dict with ``ts`` (n,), ``ys`` (n, 13), ``r_O`` (n, 3) [m], ``section_index``
    (indices of the section times in ts), ``status``, ``valid``.
    """
    if y0 is None:
        y0 = initial_state(params)
    w = float(params.omega_pi)
    T = 2 * np.pi / w
    k = np.arange(periods * points_per_period + 1)
    ts = T * (transient_periods + k / points_per_period)
    sol = simulate(
        params, y0, ts[-1], ts=ts, solver=solver, rtol=rtol, atol=atol, max_steps=max_steps,
        contact_law=contact_law, exact_ts=True,
    )  # fmt: skip
    ys = np.asarray(sol.ys)
    r_O = np.asarray(jax.vmap(centre_position, in_axes=(0, None))(sol.ys, params))
    return dict(
        ts=ts,
        ys=ys,
        r_O=r_O,
        section_index=np.arange(0, len(ts), points_per_period),
        status=int(sol.status),
        valid=bool(sol.valid),
    )
