"""Lane steppers: one step of one lane, exactly as `jaxcelt.simulate` would take it.

A stepper advances a `LaneState` by one step of diffrax's integration loop: the solver step,
``PIDController`` inside ``ClipStepSizeController(step_ts=section times)`` inside
`jaxcelt.integrate.solve.MinStepController` (as `simulate` builds it), diffeqsolve's
first-step choice and end-of-interval clipping, the validity monitor and the stop-on-invalid
event. Because the controller steps onto every section time, the end of an accepted step that
lands on the next section time *is* that sample: ``step`` says when (``hit``).

Two final steppers share the interface `AbstractLaneStepper`:

* `DiffraxStepper`: diffrax's own solver step (`MonitoredSolver` around any solver) through
  `jaxcelt._diffrax_adapter.loop_step`. Equal to `simulate` step for step.
* `FusedERKStepper`: explicit FSAL Runge-Kutta tableaus (Tsit5, the default; Dopri5,
  Dopri8, ...) written out as one straight-line step; the monitor reads N from the step's last
  (FSAL) evaluation, and the stage inputs are materialised once (`kernel_boundary`). Tsit5
  lanes equal `simulate` to rounding with the same step counts; Dopri8, whose error weights
  cancel strongly, may move a few steps (tests/test_sweep.py).

`make_stepper` picks the fused one when the solver allows it. The relative and absolute
tolerances travel in the lane state (``tols``) rather than in the stepper: as constants XLA
would fold them differently from `simulate`, where they are jit arguments (1-ulp changes of the
error norm flip accept/reject decisions and a lane would no longer equal `simulate`).
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from typing import Any, ClassVar

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._diffrax_adapter import clip_to_end, loop_init, loop_step, t1_clip_floor, wrap_term
from jaxcelt._types import Array
from jaxcelt.ensemble.lanes import LaneMonitor, LaneState
from jaxcelt.integrate.solve import (
    HEADING_GAP,
    MinStepController,
    MonitoredSolver,
    _fill_implicit_tols,
    invalid_kind,
    step_too_small,
)
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import CeltField, field_time, vector_field_and_normal
from jaxcelt.physics.params import CeltParams

__all__ = [
    "AbstractLaneStepper",
    "DiffraxStepper",
    "FusedERKStepper",
    "DiffraxStepState",
    "FusedStepState",
    "make_stepper",
    "erk_tableau",
    "float64_times",
    "kernel_boundary",
]


class DiffraxStepState(eqx.Module):
    """`DiffraxStepper`'s part of a lane: diffrax's solver and controller states."""

    solver_state: Any
    controller_state: Any


class FusedStepState(eqx.Module):
    """`FusedERKStepper`'s part of a lane: the FSAL derivative and the validity monitor."""

    f: Array
    """dy/dt at ``tprev`` (the first stage of the next step), (13,)"""
    first_invalid_t: Array
    first_invalid_kind: Array
    min_N: Array
    min_n3: Array
    """min n3 over accepted step ends (max tilt = arccos of it: arccos is decreasing)"""
    at_singularity: Array
    """bool: the lane ended past validity at the heading's singularity (`jaxcelt.integrate.solve.HEADING_GAP`)"""


def _controller(tols: Array, ts: Array) -> MinStepController:
    # the controller `simulate(..., exact_ts=True)` builds, tolerances traced (module docstring)
    pid = diffrax.PIDController(rtol=tols[0], atol=tols[1])
    return MinStepController(diffrax.ClipStepSizeController(pid, step_ts=ts))


def _section_hit(ts: Array, k: Array, keep: Array, tprev: Array) -> tuple[Array, Array]:
    """(is this accepted step's end the next section time, the new section count)."""
    S = ts.shape[0]
    hit = keep & (k < S) & (ts[jnp.minimum(k, S - 1)] <= tprev)
    return hit, k + hit.astype(jnp.int32)


def _start(
    t0: Array, y0: Array, ts: Array, tols: Array, tnext: Array, step_state: Any, kind0: Array, stop_on_invalid: bool
) -> LaneState:
    t1 = ts[-1]
    k0 = (ts[0] <= t0).astype(jnp.int32)  # a section time at t0 is the initial state itself
    stop0 = jnp.asarray(stop_on_invalid) & (kind0 > 0)
    return LaneState(
        y=y0,
        tprev=t0,
        tnext=tnext,
        t1=t1,
        floor=t1_clip_floor(t1),
        tols=tols,
        result=diffrax.RESULTS.where(stop0, diffrax.RESULTS.event_occurred, diffrax.RESULTS.successful),
        num_steps=jnp.zeros((), jnp.int32),
        k=k0,
        done=stop0,
        step_state=step_state,
    )


class AbstractLaneStepper(eqx.Module):
    """Steps one lane; `jax.vmap` it over a batch of lanes (the pool does)."""

    section_window: ClassVar[bool] = False
    """whether ``step`` reads only ``ts[lane.k]`` and ``ts[lane.k + 1]`` (so that the pool may
    pass a window of the next two section times, inf past the last)"""

    @abc.abstractmethod
    def init(self, t0: Array, y0: Array, ts: Array, p: CeltParams, tols: Array) -> LaneState:
        """diffeqsolve's initialisation: the first step size, the stepper's state; a lane invalid
        at t0 with ``stop_on_invalid`` starts done (status 2)."""

    @abc.abstractmethod
    def step(self, lane: LaneState, p: CeltParams, ts: Array) -> tuple[LaneState, Array]:
        """One step (accepted or rejected): (the new lane, whether its end is the next section sample)."""

    @abc.abstractmethod
    def monitor(self, lane: LaneState) -> LaneMonitor:
        """The lane's validity monitor."""


class DiffraxStepper(AbstractLaneStepper):
    """diffrax's own step: one iteration of diffeqsolve's loop body (any solver)."""

    solver: MonitoredSolver
    term: diffrax.AbstractTerm
    max_steps: int
    stop_on_invalid: bool

    def init(self, t0, y0, ts, p, tols):
        tnext, cstate, sstate = loop_init(self.solver, self.term, _controller(tols, ts), t0, ts[-1], y0, p)
        state = DiffraxStepState(solver_state=sstate, controller_state=cstate)
        return _start(t0, y0, ts, tols, tnext, state, sstate[1].first_invalid_kind, self.stop_on_invalid)

    def step(self, lane, p, ts):
        R = diffrax.RESULTS
        st = lane.step_state
        keep, y1, tprev, tnext, sstate, cstate, sres, cres = loop_step(
            self.solver, self.term, _controller(lane.tols, ts), lane.t1, lane.floor, lane.tprev, lane.tnext,
            lane.y, p, st.solver_state, st.controller_state,
        )  # fmt: skip
        y = jnp.where(keep, y1, lane.y)
        sstate = jax.tree_util.tree_map(lambda a, b: jnp.where(keep, a, b), sstate, st.solver_state)
        sres = R.where(keep, sres, R.successful)
        result = R.where(lane.result == R.successful, sres, lane.result)
        result = R.where(result == R.successful, cres, result)
        num_steps = lane.num_steps + 1
        hit, k = _section_hit(ts, lane.k, keep, tprev)
        if self.stop_on_invalid:
            # diffrax.Event(cond = state invalid) without root finding: ends at the first accepted
            # step whose end state is invalid -- exactly where the monitor first records it
            ev = keep & (sstate[1].first_invalid_kind > 0) & (result == R.successful)
            result = R.where(ev, R.event_occurred, result)
        ok = result == R.successful
        done = ~ok | (tprev >= lane.t1) | (num_steps >= self.max_steps)
        new = LaneState(
            y=y,
            tprev=tprev,
            tnext=tnext,
            t1=lane.t1,
            floor=lane.floor,
            tols=lane.tols,
            result=result,
            num_steps=num_steps,
            k=k,
            done=done,
            step_state=DiffraxStepState(solver_state=sstate, controller_state=cstate),
        )
        return new, hit

    def monitor(self, lane):
        mon = lane.step_state.solver_state[1]
        return LaneMonitor(mon.first_invalid_t, mon.first_invalid_kind, mon.min_N, mon.max_tilt, jnp.zeros((), bool))


def _combine(y0: Array, coeffs: Any, ks: list[Array]) -> Array:
    """y0 + sum_j coeffs[j] ks[j] over the non-zero coefficients (tableau constants)."""
    out = y0
    for a, k in zip(np.asarray(coeffs, dtype=float).tolist(), ks):  # python floats: weakly typed (float32 lanes)
        if a != 0.0:
            out = out + a * k
    return out


def kernel_boundary(opaque_true: Array) -> Callable[[Array], Array]:
    """x -> x, materialised: a conditional on a predicate XLA cannot see (a runtime True).

    XLA's CPU fusion copies cheap producers into every consumer kernel, so without this each
    of the right-hand side's ~40 kernels recomputes the stage input y0 + sum_j a_ij k_j for
    the components it reads; a conditional is a kernel boundary, after which they read one
    buffer instead (``benchmarks/bench_step_parts.py``). The other branch is never taken; it
    returns NaN so that it could not pass unnoticed, and it differs from the first so that XLA
    does not fold the conditional away.
    """

    def boundary(x: Array) -> Array:
        return jax.lax.cond(opaque_true, lambda x: x, lambda x: jnp.full_like(x, jnp.nan), x)

    return boundary


class FusedERKStepper(AbstractLaneStepper):
    """`DiffraxStepper`'s step for an explicit FSAL Runge-Kutta tableau, fused into one straight-line step.

    The same algorithm as diffrax's loop body with ``PIDController`` (I-control, diffrax's
    defaults) inside ``ClipStepSizeController(step_ts=ts)``: stages k_i = dt f(t0 + c_i dt,
    y0 + sum_j a_ij k_j), y1 = y0 + sum b_i k_i, error sum e_i k_i, the RMS error ratio and
    factor clip(0.9 err^(-1/q), [1, 10] if accepted else [0.2, 0.9]) with q the error order
    diffrax gives its controller (Tsit5 5, Dopri8 8), the next step clipped onto the next
    section time and onto t1, a collapsed step size ending the lane (`jaxcelt.integrate.solve.step_too_small`).
    The last stage is f(t1, y1) (FSAL); its normal force and
    denominator feed the validity monitor, so monitoring costs no extra evaluation
    (`MonitoredSolver` evaluates N once more per step). Without diffrax's generic stage loop,
    stage buffer and dense-output bookkeeping, XLA fuses the step into fewer kernels.
    ``opaque_true``: a traced True for `kernel_boundary` on every stage input (None: no
    boundaries). Only the equality tests against `simulate` would notice if diffrax's PID
    controller changed its algorithm.
    """

    section_window: ClassVar[bool] = True

    solver: MonitoredSolver
    """only for the first step size (diffeqsolve's choice, as `DiffraxStepper`)"""
    term: diffrax.AbstractTerm
    law: AbstractContactLaw
    tableau: Any
    error_order: Any
    """exactly what diffrax's controller is given: ``solver.error_order(term)``"""
    max_steps: int
    stop_on_invalid: bool
    opaque_true: Array | None = None

    def init(self, t0, y0, ts, p, tols):
        # the controller's first step needs no solver state: the fused step's state is the FSAL
        # derivative and the monitor, from one evaluation
        tnext, _, _ = loop_init(self.solver, self.term, _controller(tols, ts), t0, ts[-1], y0, p, solver_state=False)
        f0, (N, den) = vector_field_and_normal(t0, y0, p, self.law)
        kind = invalid_kind(N, den, y0[8])
        state = FusedStepState(
            f=f0, first_invalid_t=jnp.where(kind > 0, t0, jnp.inf), first_invalid_kind=kind, min_N=N, min_n3=y0[8],
            at_singularity=jnp.zeros((), bool),
        )  # fmt: skip
        return _start(t0, y0, ts, tols, tnext, state, kind, self.stop_on_invalid)

    def step(self, lane, p, ts):
        R = diffrax.RESULTS
        tab, st = self.tableau, lane.step_state
        boundary = (lambda x: x) if self.opaque_true is None else kernel_boundary(jnp.asarray(self.opaque_true))
        t1, y0, t0 = lane.t1, lane.y, lane.tprev
        dt = lane.tnext - t0
        dts = dt.astype(y0.dtype)  # float32 lanes step in float64 time (`float64_times`); float64: no-op
        ks = [st.f * dts]
        float64 = y0.dtype == jnp.float64
        for c, a in zip(np.asarray(tab.c, dtype=float).tolist(), tab.a_lower):
            yi = boundary(_combine(y0, a, ks))
            # float32 lanes: the forcing phase from one period, not from t (`jaxcelt.physics.model.field_time`)
            ti = t0 + c * dt if float64 else field_time(t0, p.omega_pi, y0.dtype, c * dt)
            fi, aux = vector_field_and_normal(ti, yi, p, self.law)
            ks.append(fi * dts)
        b = np.asarray(tab.b_sol, dtype=float)
        fsal_is_y1 = b[-1] == 0.0 and np.array_equal(np.asarray(tab.a_lower[-1], dtype=float), b[:-1])
        y1 = yi if fsal_is_y1 else _combine(y0, b, ks)
        y_err = _combine(jnp.zeros_like(y0), tab.b_error, ks)
        y_err = jnp.where(jnp.isnan(y_err), jnp.inf, y_err)
        # diffrax PIDController.adapt_step_size (pcoeff = dcoeff = 0, icoeff = 1)
        pid = diffrax.PIDController(rtol=lane.tols[0], atol=lane.tols[1])
        y1s = jnp.where(jnp.isnan(y1).any(), y0, y1)
        scaled = pid.norm(y_err / (pid.atol + jnp.maximum(jnp.abs(y0), jnp.abs(y1s)) * pid.rtol))
        keep = scaled < 1
        inv = 1 / scaled
        factor = jnp.clip(
            pid.safety * inv ** (1.0 / self.error_order),
            jnp.where(keep, 1.0, pid.factormin),
            jnp.where(keep, pid.factormax, pid.safety),
        )
        tprev = jnp.where(keep, lane.tnext, t0)
        tnext = tprev + dt * factor.astype(dt.dtype)
        # section times: the accepted step's end *is* the sample when it lands on ts[k]
        S = ts.shape[0]
        hit, k = _section_hit(ts, lane.k, keep, tprev)
        tnext = jnp.where(k < S, jnp.minimum(ts[jnp.minimum(k, S - 1)], tnext), tnext)  # diffrax's _clip_t
        small = step_too_small(keep, tprev, tnext)  # `MinStepController`
        tprev, tnext = clip_to_end(tprev, tnext, t1, lane.floor, keep)
        # validity monitor at the accepted step's end (N, den from the FSAL evaluation)
        N, den = aux
        kind = invalid_kind(N, den, y1[8])
        new_invalid = keep & (kind > 0) & (st.first_invalid_kind == 0)
        result = R.where(small & (lane.result == R.successful), R.dt_min_reached, lane.result)
        if self.stop_on_invalid:
            result = R.where(new_invalid & (result == R.successful), R.event_occurred, result)
        # past validity, the stone lying on its side: the heading's singularity ends the lane (status 4)
        past = (st.first_invalid_kind > 0) | (kind > 0)
        singular = keep & past & (1 - y1[7] * y1[7] < HEADING_GAP) & (result == R.successful)
        result = R.where(singular, R.event_occurred, result)
        num_steps = lane.num_steps + 1
        done = (result != R.successful) | (tprev >= t1) | (num_steps >= self.max_steps)
        state = FusedStepState(
            f=jnp.where(keep, fi, st.f),
            first_invalid_t=jnp.where(new_invalid, tprev, st.first_invalid_t),
            first_invalid_kind=jnp.where(new_invalid, kind, st.first_invalid_kind),
            min_N=jnp.where(keep, jnp.minimum(st.min_N, N), st.min_N),
            min_n3=jnp.where(keep, jnp.minimum(st.min_n3, y1[8]), st.min_n3),
            at_singularity=st.at_singularity | singular,
        )
        new = LaneState(
            y=jnp.where(keep, y1, y0),
            tprev=tprev,
            tnext=tnext,
            t1=t1,
            floor=lane.floor,
            tols=lane.tols,
            result=result,
            num_steps=num_steps,
            k=k,
            done=done,
            step_state=state,
        )
        return new, hit

    def monitor(self, lane):
        st = lane.step_state
        return LaneMonitor(
            st.first_invalid_t, st.first_invalid_kind, st.min_N, jnp.arccos(jnp.clip(st.min_n3, -1, 1)), st.at_singularity
        )


def float64_times(lanes: LaneState, t1: Array) -> LaneState:
    """Lanes (a batch) with their times in float64 and the state as it is: how `FusedERKStepper` steps
    float32 lanes. In float32 time a lane's steps cannot shrink below ~10 ULPs of t (7.6e-5 s at
    t = 120 s, `jaxcelt.integrate.solve.step_too_small`), which a lane sticking to the base needs; with the
    field's forcing phase taken from one period (`jaxcelt.physics.model.field_time`) the stage times stay
    exact too. ``t1``: the lanes' last section times in float64 (from float64 omega_pi)."""
    f64 = jnp.float64
    st = lanes.step_state
    return eqx.tree_at(
        lambda s: (s.tprev, s.tnext, s.t1, s.floor, s.step_state.first_invalid_t),
        lanes,
        (lanes.tprev.astype(f64), lanes.tnext.astype(f64), t1, jax.vmap(t1_clip_floor)(t1),
         st.first_invalid_t.astype(f64)),
    )  # fmt: skip


def erk_tableau(solver: diffrax.AbstractSolver) -> Any:
    """Butcher tableau of an explicit FSAL Runge-Kutta solver with an error estimate (Tsit5,
    Dopri5, Dopri8, ...), for which `make_stepper` picks `FusedERKStepper`; else None."""
    tab = getattr(solver, "tableau", None)
    if isinstance(solver, diffrax.AbstractERK) and tab is not None and tab.fsal and tab.b_error is not None:
        return tab
    return None


def make_stepper(
    solver: diffrax.AbstractSolver,
    contact_law: AbstractContactLaw | str | None,
    *,
    rtol: float,
    atol: float,
    max_steps: int,
    stop_on_invalid: bool,
    opaque_true: Array | None = None,
) -> AbstractLaneStepper:
    """The stepper for ``solver``: `FusedERKStepper` for an explicit FSAL tableau, else
    `DiffraxStepper`. ``rtol``/``atol`` fill an implicit solver's root-finder tolerances (as
    `simulate` does); the step-size tolerances are the lanes' ``tols``. ``opaque_true``: see
    `FusedERKStepper`."""
    law = get_contact_law(contact_law)
    wrapped = MonitoredSolver(solver=_fill_implicit_tols(solver, rtol, atol), law=law)
    term = wrap_term(diffrax.ODETerm(CeltField(law)))
    tab = erk_tableau(solver)
    if tab is None:
        return DiffraxStepper(solver=wrapped, term=term, max_steps=max_steps, stop_on_invalid=stop_on_invalid)
    return FusedERKStepper(
        solver=wrapped,
        term=term,
        law=law,
        tableau=tab,
        error_order=solver.error_order(term),
        max_steps=max_steps,
        stop_on_invalid=stop_on_invalid,
        opaque_true=opaque_true,
    )
