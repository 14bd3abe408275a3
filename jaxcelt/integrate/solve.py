"""`simulate`: the one integration entry point (diffrax underneath).

Jit-compiled once per (shapes, solver, contact law, static options); new parameter values,
initial states, t0/t1 and save times do not recompile. Vmappable over parameters and
initial states; reverse-mode differentiable through diffrax's checkpointed adjoint.

Validity of the model is monitored at the end of every accepted step by wrapping the solver
(`MonitoredSolver`): lift-off (N <= 0), the contact leaving the lower half-surface (n3 <= 0)
and a non-positive constraint denominator are recorded on the solution with the time and the
state where they were first seen; ``stop_on_invalid=True`` ends the solve there. The same
wrapper records min N and max tilt, which sweeps report per lane. ``monitor=False`` leaves it out
(``sol.validity`` is None): for differentiated solves that never read it, such as the fit's, whose
forward-mode program then has less to trace and compile (measured in docs/internals/fit-engine.md).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from jaxcelt import _config  # noqa: F401
from jaxcelt._diffrax_adapter import diffeqsolve, use_stepsize_tol
from jaxcelt._types import Array, ArrayLike, Scalar
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import CeltField, contact_loads, kinematics, normal_force_parts
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import check_state

__all__ = ["simulate", "Solution", "MonitoredSolver", "Validity", "INVALID_KINDS", "STATUS", "DEFAULT_SOLVER"]

INVALID_KINDS = {
    0: "valid",
    1: "lift-off (N <= 0)",
    2: "contact off the lower half-surface (n3 <= 0)",
    3: "constraint denominator <= 0",
}
STATUS = {
    0: "success",
    1: "max_steps reached",
    2: "stopped at invalid state",
    3: "solver failure",
    4: "stopped past validity at the heading's singularity",
}
"""Status codes of a solve or a lane. 4 is given to lanes only (`jaxcelt.ensemble`): a lane integrated on past
the model's validity ends where the stone lies on its side (`HEADING_GAP`)."""

HEADING_GAP = 1e-6
"""A lane integrated on past the model's validity (``stop_on_invalid=False``) ends, with status 4, at the first
accepted step whose end has 1 - n2² below this: the stone lies within ~0.06° of its side (n3 ≈ 0, body x2
vertical), where the heading rate (ω1 n1 + ω3 n3)/(1 - n2²) and the frame of the base's motion (MODEL.md)
are singular. Without it such a lane rejects steps until its step size collapses (status 3) or its step
budget is spent (status 1) (docs/bifurcation/max-steps.md)."""

MIN_STEP_ULPS = 10
"""A rejected step that would shrink the step below this many ULPs of t (or make it NaN) ends the
solve as a solver failure (``status == 3``): scipy's ``solve_ivp`` rule ("required step size is
less than spacing between numbers"). Without it an adaptive solve caught at a singularity (e.g. the
heading's 1/(1 - n2^2) when a stone integrated on past validity lies on its side) rejects
steps of a few ULPs until ``max_steps`` is spent (docs/bifurcation/max-steps.md)."""


class Validity(NamedTuple):
    """Monitor carried through the solve (updated only on accepted steps)."""

    first_invalid_t: Scalar
    """time at the end of the first accepted step whose end state is invalid (inf if none) [s]"""
    first_invalid_kind: Array
    """int code, `INVALID_KINDS`"""
    first_invalid_y: Array
    """state where first seen (NaN if none), (13,)"""
    min_N: Scalar
    """minimum normal force over accepted step ends [N]"""
    max_tilt: Scalar
    """maximum arccos(n3) over accepted step ends [rad]"""


@jax.jit  # traced once per signature: diffrax traces a solver step several times
def _invalid_kind(t, y, params, law) -> tuple[Array, Scalar]:
    kin = kinematics(t, y, params)
    num, den = normal_force_parts(kin, contact_loads(kin, params, law), params)
    N = num / den
    return invalid_kind(N, den, y[8]), N


def invalid_kind(N, den, n3) -> Array:
    """`INVALID_KINDS` code from the normal force N, its denominator and n3 (0: valid)."""
    return jnp.where(den <= 0, 3, jnp.where(n3 <= 0, 2, jnp.where(N <= 0, 1, 0)))


class MonitoredSolver(diffrax.AbstractWrappedSolver):
    """Wraps a diffrax solver; after every step evaluates validity at the step's end state.

    diffrax keeps the previous solver state when a step is rejected, so the monitor sees
    accepted steps only.
    """

    solver: diffrax.AbstractSolver
    law: AbstractContactLaw

    @property
    def term_structure(self):
        return self.solver.term_structure

    @property
    def interpolation_cls(self):  # pyright: ignore
        return self.solver.interpolation_cls

    @property
    def term_compatible_contr_kwargs(self):
        return self.solver.term_compatible_contr_kwargs

    @property
    def root_finder(self):
        return self.solver.root_finder  # pyright: ignore

    @property
    def scan_kind(self):
        # diffrax.ForwardMode reads scan_kind of Runge-Kutta solvers (the wrapper passes its
        # isinstance check); `simulate` has already set the inner one to "lax" in that case.
        return getattr(self.solver, "scan_kind", "lax")

    def order(self, terms):
        return self.solver.order(terms)

    def strong_order(self, terms):
        return self.solver.strong_order(terms)

    def error_order(self, terms):
        return self.solver.error_order(terms)

    def init(self, terms, t0, t1, y0, args):
        kind, N = _invalid_kind(t0, y0, args, self.law)
        tilt0 = jnp.arccos(jnp.clip(y0[8], -1, 1))
        mon = Validity(
            first_invalid_t=jnp.where(kind > 0, t0, jnp.inf).astype(y0.dtype),
            first_invalid_kind=kind,
            first_invalid_y=jnp.where(kind > 0, y0, jnp.nan),
            min_N=N,
            max_tilt=tilt0,
        )
        return self.solver.init(terms, t0, t1, y0, args), mon

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        inner, mon = solver_state
        y1, y_err, dense, inner, result = self.solver.step(terms, t0, t1, y0, args, inner, made_jump)
        kind, N = _invalid_kind(t1, y1, args, self.law)
        new = (kind > 0) & (mon.first_invalid_kind == 0)
        mon = Validity(
            first_invalid_t=jnp.where(new, t1, mon.first_invalid_t),
            first_invalid_kind=jnp.where(new, kind, mon.first_invalid_kind),
            first_invalid_y=jnp.where(new, y1, mon.first_invalid_y),
            min_N=jnp.minimum(mon.min_N, N),
            max_tilt=jnp.maximum(mon.max_tilt, jnp.arccos(jnp.clip(y1[8], -1, 1))),
        )
        return y1, y_err, dense, (inner, mon), result

    def func(self, terms, t0, y0, args):
        return self.solver.func(terms, t0, y0, args)


class Solution(eqx.Module):
    """Result of `simulate`. Arrays gain leading batch axes under ``jax.vmap``.

    ``ys[i]`` is the state at ``ts[i]``; entries after an early stop are ``inf`` (diffrax's
    convention). ``status``: 0 success, 1 max_steps reached, 2 stopped at an invalid state
    (``stop_on_invalid=True``), 3 other solver failure, e.g. the step size collapsed below
    `MIN_STEP_ULPS` ULPs of t (see `STATUS`). ``success`` is
    ``status == 0``; ``valid`` is False as soon as the model left its validity (even if the
    solve went on).
    """

    ts: Array
    ys: Array
    status: Array
    num_steps: Array
    num_accepted_steps: Array
    num_rejected_steps: Array
    validity: Validity | None

    @property
    def success(self) -> Array:
        return self.status == 0

    @property
    def valid(self) -> Array:
        if self.validity is None:
            raise ValueError("validity: this solution was computed with monitor=False (simulate's validity monitor off)")
        return self.validity.first_invalid_kind == 0

    def summary(self) -> str:
        """Human-readable one-trajectory summary (status, steps, validity)."""
        s = int(np.asarray(self.status).reshape(-1)[0])
        out = f"status: {STATUS[s]}; steps: {int(np.asarray(self.num_accepted_steps).reshape(-1)[0])} accepted, {int(np.asarray(self.num_rejected_steps).reshape(-1)[0])} rejected"
        if self.validity is None:
            return out + "; validity not monitored (monitor=False)"
        kind = int(np.asarray(self.validity.first_invalid_kind).reshape(-1)[0])
        out += f"; min N = {float(np.asarray(self.validity.min_N).reshape(-1)[0]):.4g} N, max tilt = {np.degrees(float(np.asarray(self.validity.max_tilt).reshape(-1)[0])):.2f} deg"
        if kind:
            out += f"; INVALID: {INVALID_KINDS[kind]} first seen at t = {float(np.asarray(self.validity.first_invalid_t).reshape(-1)[0]):.6g} s"
        return out


DEFAULT_SOLVER = diffrax.Tsit5()


def step_too_small(keep: Array, t0: Array, t1: Array) -> Array:
    """Whether a step proposal ends the solve (`MIN_STEP_ULPS`): the last step was rejected and the
    next one, from ``t0`` to ``t1``, spans fewer than `MIN_STEP_ULPS` ULPs of ``t0``, nothing at
    all (at t0 = 0 the ULP is a denormal, which XLA's CPU code flushes to zero), or is not a
    number (a NaN error estimate gives diffrax's PID controller a NaN step, which no shrinking
    would end)."""
    t0, t1 = jax.lax.stop_gradient((t0, t1))  # a decision, not a value: times may carry tangents
    ulp = jnp.abs(jnp.nextafter(t0, jnp.asarray(jnp.inf, t0.dtype)) - t0)
    dt = t1 - t0
    return ~keep & ~((dt >= MIN_STEP_ULPS * ulp) & (dt > 0))


class MinStepController(diffrax.AbstractAdaptiveStepSizeController):
    """An adaptive step-size controller that gives up where the step size collapses.

    Wraps any adaptive controller (``PIDController``, ``ClipStepSizeController``) and returns
    ``diffrax.RESULTS.dt_min_reached`` (status 3) where `step_too_small`; otherwise the wrapped
    controller's decisions unchanged. (``PIDController(dtmin=..., force_dtmin=False)`` ends a solve
    below an absolute step size, which cannot follow the spacing of floats at every t, and lets a
    NaN step through.)"""

    controller: diffrax.AbstractAdaptiveStepSizeController

    @property
    def rtol(self):
        return self.controller.rtol

    @property
    def atol(self):
        return self.controller.atol

    @property
    def norm(self):  # pyright: ignore[reportIncompatibleMethodOverride]
        return self.controller.norm

    def wrap(self, direction):
        return MinStepController(self.controller.wrap(direction))

    def init(self, terms, t0, t1, y0, dt0, args, func, error_order):
        return self.controller.init(terms, t0, t1, y0, dt0, args, func, error_order)

    def adapt_step_size(self, t0, t1, y0, y1_candidate, args, y_error, error_order, controller_state):
        keep, next_t0, next_t1, jump, state, result = self.controller.adapt_step_size(
            t0, t1, y0, y1_candidate, args, y_error, error_order, controller_state
        )
        R = diffrax.RESULTS
        small = step_too_small(keep, next_t0, next_t1)
        result = R.where(small & (result == R.successful), R.dt_min_reached, result)
        return keep, next_t0, next_t1, jump, state, result


def status_code(result) -> Array:
    """`STATUS` code of a diffrax result: 0 success, 1 max_steps, 2 event (stopped invalid), 3 other."""
    R = diffrax.RESULTS
    return jnp.where(
        result == R.successful,
        0,
        jnp.where(result == R.max_steps_reached, 1, jnp.where(result == R.event_occurred, 2, 3)),
    ).astype(jnp.int32)


def _fill_implicit_tols(solver, rtol, atol):
    # diffeqsolve would copy the controller's tolerances into an implicit solver's root finder;
    # it cannot reach through our wrapper, so do it before wrapping.
    if isinstance(solver, diffrax.AbstractImplicitSolver):
        rf = solver.root_finder
        if isinstance(rf, diffrax.VeryChord) and rf.rtol is use_stepsize_tol and rf.atol is use_stepsize_tol:
            # diffrax's default root finder reuses one Jacobian per step. The friction law's
            # Jacobian changes by ~1/sqrt(eps) within a step during stick-slip, so the chord
            # iteration diverges and steps are rejected en masse (Kvaerno5, one period from rest,
            # omega_pi = 17: 2005 accepted + 2417 rejected steps, vs 293 + 103 with full Newton;
            # docs/internals/studies.md section 3). Use full Newton unless the user chose a root finder.
            rf = optx.Newton(rtol=rtol, atol=atol, norm=optx.rms_norm)
        for attr, val in (("rtol", rtol), ("atol", atol), ("norm", optx.rms_norm)):
            if getattr(rf, attr, None) is use_stepsize_tol:
                rf = eqx.tree_at(lambda r, attr=attr: getattr(r, attr), rf, val)
        solver = eqx.tree_at(lambda s: s.root_finder, solver, rf)
    return solver


@eqx.filter_jit
def _solve(
    params: CeltParams,
    y0: Array,
    t0: Array,
    t1: Array,
    ts: Array | None,
    dt0: Array | None,
    rtol: Array,
    atol: Array,
    *,
    solver: diffrax.AbstractSolver,
    law: AbstractContactLaw,
    max_steps: int,
    stop_on_invalid: bool,
    exact_ts: bool,
    fixed_step: bool,
    adjoint: diffrax.AbstractAdjoint,
    progress: bool,
    monitor: bool,
) -> Solution:
    if fixed_step:
        controller = diffrax.ConstantStepSize()
    else:
        controller = diffrax.PIDController(rtol=rtol, atol=atol)
        if exact_ts and ts is not None:
            controller = diffrax.ClipStepSizeController(controller, step_ts=ts)
        controller = MinStepController(controller)
    mon_solver = MonitoredSolver(solver=solver, law=law) if monitor else solver
    if ts is not None:
        saveat = diffrax.SaveAt(ts=ts, solver_state=monitor)
    else:
        saveat = diffrax.SaveAt(t0=True, t1=True, solver_state=monitor)
    event = None
    if stop_on_invalid:
        event = diffrax.Event(lambda t, y, args, **kw: _invalid_kind(t, y, args, law)[0] > 0)
    sol = diffeqsolve(  # diffrax's, t1 - 100 ULP by a loop (the adapter)
        diffrax.ODETerm(CeltField(law)),
        mon_solver,
        t0,
        t1,
        dt0,
        y0,
        params,
        saveat=saveat,
        stepsize_controller=controller,
        max_steps=max_steps,
        adjoint=adjoint,
        event=event,
        throw=False,
        progress_meter=diffrax.TqdmProgressMeter() if progress else diffrax.NoProgressMeter(),
    )
    status = status_code(sol.result)
    mon = sol.solver_state[1] if monitor else None
    return Solution(
        ts=sol.ts,
        ys=sol.ys,
        status=status,
        num_steps=sol.stats["num_steps"],
        num_accepted_steps=sol.stats["num_accepted_steps"],
        num_rejected_steps=sol.stats["num_rejected_steps"],
        validity=mon,
    )


def _as_float(x, dtype, name, scalar=False):
    if x is None:
        return None
    a = jnp.asarray(x, dtype=dtype)
    if scalar and a.ndim != 0:
        raise ValueError(f"{name!r} must be a scalar, got shape {a.shape} (vmap simulate for batches)")
    if not isinstance(a, jax.core.Tracer) and not np.all(np.isfinite(np.asarray(a))):
        raise ValueError(f"{name!r} must be finite, got {np.asarray(a)}")
    return a


def simulate(
    params: CeltParams,
    y0: ArrayLike,
    t1: ArrayLike,
    *,
    ts: ArrayLike | None = None,
    t0: ArrayLike = 0.0,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    dt0: float | None = None,
    max_steps: int = 1_000_000,
    contact_law: AbstractContactLaw | str | None = None,
    stop_on_invalid: bool = False,
    exact_ts: bool = False,
    adjoint: diffrax.AbstractAdjoint | None = None,
    dtype: Any = None,
    progress: bool = False,
    monitor: bool = True,
) -> Solution:
    """Integrate the wobblestone from state ``y0`` at ``t0`` to ``t1``.

    Args:
        params: `CeltParams` (may be batched under ``jax.vmap``).
        y0: initial state (13,) on the contact manifold (see `jaxcelt.initial_state`).
        t1: final time [s].
        ts: save times (increasing, within [t0, t1]); default: t0 and t1.
        t0: initial time [s] (the base phase is omega_pi t).
        solver: any diffrax ODE solver; default `diffrax.Tsit5`. Implicit solvers work
            (e.g. ``diffrax.Kvaerno5()``) and pay off when the friction smoothing eps is tiny.
        rtol, atol: tolerances of the PID step-size controller. Ignored with ``dt0`` and a
            solver without error estimate; ``dt0`` with an adaptive solver is only the first step.
        dt0: initial (or, for non-adaptive solvers, fixed) step [s].
        max_steps: step budget; hitting it gives ``status == 1`` rather than an exception.
            A step size that collapses to a few ULPs of t ends the solve earlier, with
            ``status == 3`` (`MIN_STEP_ULPS`).
        contact_law: a law object or name (`jaxcelt.physics.contact.laws.CONTACT_LAWS`); default the
            paper's generalised Pade law (eq. 13).
        stop_on_invalid: end the solve at the first accepted step whose end state is invalid
            (lift-off or n3 <= 0). Otherwise the solve continues and the solution says where
            validity was first lost (``sol.validity``, ``sol.valid``).
        exact_ts: make the step-size controller step exactly onto ``ts`` (stroboscopic
            samples that are solver states, not interpolants).
        adjoint: diffrax adjoint; default `diffrax.RecursiveCheckpointAdjoint` (reverse mode).
        dtype: ``jnp.float64`` (default) or ``jnp.float32``.
        progress: show a tqdm progress bar (single trajectories; not under vmap).
        monitor: record validity along the solve (``sol.validity``; see the module docstring). False: no
            monitor, ``sol.validity`` is None and ``sol.valid`` raises -- a smaller program for differentiated
            solves that do not read it (``stop_on_invalid`` still works: its event does not need the monitor).

    Returns:
        `Solution` with ``ts``, ``ys`` (len(ts), 13), ``status``/``success``, step counts and
        the validity monitor.
    """
    dtype = jnp.dtype(dtype or jnp.float64)
    if dtype not in (jnp.dtype(jnp.float64), jnp.dtype(jnp.float32)):
        raise ValueError(f"dtype must be float64 or float32, got {dtype}")
    if not isinstance(params, CeltParams):
        raise TypeError(f"params must be a CeltParams, got {type(params).__name__}")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise ValueError(f"max_steps must be a positive int, got {max_steps!r}")
    for name, tol in (("rtol", rtol), ("atol", atol)):
        if np.ndim(tol) != 0:
            raise ValueError(f"{name!r} must be a scalar, got shape {np.shape(tol)}")
        if not isinstance(tol, jax.core.Tracer) and not (np.isfinite(tol) and tol > 0):
            raise ValueError(f"{name!r} must be a positive finite number, got {tol!r}")
    if not isinstance(monitor, bool):
        raise ValueError(f"'monitor' must be True or False, got {monitor!r}")
    law = get_contact_law(contact_law)
    check_state(y0, params, name="y0")
    y0a = _as_float(y0, dtype, "y0")
    if y0a.shape != (13,):
        raise ValueError(f"'y0' must have shape (13,), got {y0a.shape} (vmap simulate for batches)")
    t0a = _as_float(t0, dtype, "t0", scalar=True)
    t1a = _as_float(t1, dtype, "t1", scalar=True)
    if not isinstance(t1a, jax.core.Tracer) and not isinstance(t0a, jax.core.Tracer) and not float(t1a) > float(t0a):
        raise ValueError(f"'t1' must be greater than 't0' (got t0={float(t0a)}, t1={float(t1a)})")
    tsa = _as_float(ts, dtype, "ts")
    if tsa is not None:
        if tsa.ndim != 1 or tsa.shape[0] == 0:
            raise ValueError(f"'ts' must be a non-empty 1-D array, got shape {tsa.shape}")
        if not isinstance(tsa, jax.core.Tracer) and not isinstance(t1a, jax.core.Tracer):
            a = np.asarray(tsa)
            if np.any(np.diff(a) < 0) or a[0] < float(t0a) or a[-1] > float(t1a):
                raise ValueError("'ts' must be non-decreasing and lie within [t0, t1]")
    if solver is None:
        solver = DEFAULT_SOLVER
    fixed_step = not isinstance(solver, diffrax.AbstractAdaptiveSolver)
    if fixed_step and dt0 is None:
        raise ValueError(f"solver {type(solver).__name__} has no error estimate: pass a fixed step 'dt0'")
    if dt0 is not None and not isinstance(dt0, jax.core.Tracer) and not (np.isfinite(dt0) and dt0 > 0):
        raise ValueError(f"'dt0' must be a positive finite step, got {dt0!r}")
    solver = _fill_implicit_tols(solver, rtol, atol)
    if isinstance(adjoint, diffrax.ForwardMode) and getattr(solver, "scan_kind", "lax") is None:
        # forward-mode JVPs cannot pass diffrax's default (checkpointed) inner scan
        solver = eqx.tree_at(lambda s: s.scan_kind, solver, "lax", is_leaf=lambda x: x is None)
    if dtype == jnp.dtype(jnp.float32):
        params = jax.tree_util.tree_map(lambda x: jnp.asarray(x, jnp.float32), params)
    return _solve(
        params,
        y0a,
        t0a,
        t1a,
        tsa,
        None if dt0 is None else jnp.asarray(dt0, dtype),
        jnp.asarray(rtol, dtype),
        jnp.asarray(atol, dtype),
        solver=solver,
        law=law,
        max_steps=max_steps,
        stop_on_invalid=stop_on_invalid,
        exact_ts=exact_ts,
        fixed_step=fixed_step,
        adjoint=adjoint or diffrax.RecursiveCheckpointAdjoint(),
        progress=progress,
        monitor=monitor,
    )
