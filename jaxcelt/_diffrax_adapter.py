"""The diffrax and equinox internals jaxcelt relies on, in one place.

jaxcelt uses diffrax's public API everywhere except where it has to reproduce what
`diffrax.diffeqsolve` does inside its loop: the lane pool (`jaxcelt.ensemble`) steps many
solves side by side in its own while loop and must take the same steps as `diffeqsolve`, the
Lyapunov exponent's per-period solves take them in a smaller program (`solve_to`), and
`jaxcelt.integrate.solve` passes diffrax's "use the step-size tolerances" marker to an implicit solver's
root finder. Every `diffrax.diffeqsolve` of jaxcelt goes through `diffeqsolve` here, which
computes diffeqsolve's end-of-interval threshold by a loop instead of 100 unrolled steps
(`compact_end_rounding`). The names below are not re-exported by diffrax or equinox, or mirror
the body of diffrax's integration loop (``diffrax/_integrate.py``: ``loop``, ``body_fun_aux``,
``_clip_to_end``), so they can change in any release. The versions they were written against
are the ranges pinned in ``pyproject.toml``; ``tests/test_ensemble_adapter.py`` checks that the
installed diffrax and equinox are inside them, that the names still exist, and that
`loop_init` + `loop_step` and `solve_to` take the same steps as `diffrax.diffeqsolve` on a small ODE.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import threading
from typing import Any

import diffrax
import equinox as eqx
import equinox.internal as eqxi
import jax
import jax.numpy as jnp
from diffrax._root_finder import use_stepsize_tol  # not re-exported at top level
from diffrax._term import WrapTerm  # what diffeqsolve wraps terms in (not re-exported)

from jaxcelt._types import Array

__all__ = [
    "use_stepsize_tol",
    "wrap_term",
    "t1_clip_floor",
    "clip_to_end",
    "loop_init",
    "loop_step",
    "solve_to",
    "forward_only",
    "runtime_checks_as_nan",
    "compact_end_rounding",
    "diffeqsolve",
]


@contextlib.contextmanager
def runtime_checks_as_nan():
    """While tracing inside this context, equinox's runtime checks (`eqx.error_if`, e.g.
    diffeqsolve's "saveat.ts must lie between t0 and t1" on traced save times) return NaN
    instead of raising through a host callback -- what ``EQX_ON_ERROR=nan`` does, for these traces
    only. A program with a host callback is never stored in JAX's persistent compilation cache;
    without them, a second process loads it instead of compiling it again. Only for programs whose
    inputs are validated beforehand (a NaN then marks a failure the caller handles).

    equinox routes a check on traced values through a jitted helper whose trace (made once per
    process, in the default mode) is cached; inside the context the checks go to the un-jitted
    implementation with ``on_error="nan"`` instead."""
    import equinox._errors as eqx_errors  # private: the check's implementation and its jitted wrapper

    old = eqx_errors.branched_error_if_impl_jit

    def as_nan(x, pred, index, msgs, *, on_error):
        return eqx_errors.branched_error_if_impl(x, pred, index, msgs, on_error="nan" if on_error == "default" else on_error)

    eqx_errors.branched_error_if_impl_jit = as_nan
    try:
        yield
    finally:
        eqx_errors.branched_error_if_impl_jit = old


def wrap_term(term: diffrax.AbstractTerm) -> diffrax.AbstractTerm:
    """``term`` as `diffeqsolve` hands it to the solver and controller of a forward solve.

    diffeqsolve wraps every term in ``WrapTerm(term, direction)``; with it,
    ``PIDController.init`` takes diffrax's fixed first trial step (0.01) instead of the
    ODETerm-only heuristic, so a loop that wants the same steps as diffeqsolve must wrap too."""
    return WrapTerm(term, jnp.asarray(1))


def t1_clip_floor(t1: Array) -> Array:
    """t1 - 100 ULP: diffeqsolve rounds a proposed step end above this onto t1."""
    # diffeqsolve unrolls these 100 steps (~1 500 HLO operations, one large kernel to compile);
    # a loop gives the same value for a fraction of the compilation
    return jax.lax.fori_loop(0, 100, lambda _, f: eqxi.prevbefore(f), t1)


_CHAIN = 100
"""How many ``eqxi.prevbefore`` calls diffeqsolve's loop chains to make t1 - 100 ULP."""
_CHAIN_SOURCE = f"for _ in range({_CHAIN}):\n        t1_clip_floor = eqxi.prevbefore(t1_clip_floor)"
_PENDING = threading.local()
"""Per thread: inside `compact_end_rounding`, how many calls of the current chain are still to come."""


class _IntegrateEqxi:
    """What ``diffrax._integrate`` sees as ``eqxi`` (equinox.internal) once `compact_end_rounding` has been used:
    equinox.internal itself, except that inside a `compact_end_rounding` block, in that thread, each 100 chained
    ``prevbefore`` calls of diffeqsolve's loop become one call of `t1_clip_floor` (a loop). Outside such a block
    every call is equinox's own ``prevbefore``."""

    def __getattr__(self, name: str) -> Any:
        return getattr(eqxi, name)

    def prevbefore(self, x: Array) -> Array:
        pending = getattr(_PENDING, "n", None)
        if pending is None:
            return eqxi.prevbefore(x)
        if pending > 1:  # an intermediate link: only the chain's last value is used
            _PENDING.n = pending - 1
            return x
        _PENDING.n = _CHAIN
        return t1_clip_floor(x)


@functools.cache
def _install_compact_chain() -> bool:
    """Put `_IntegrateEqxi` in ``diffrax._integrate`` if its loop makes t1 - 100 ULP as diffrax 0.7 does (the chain
    verbatim, and no other ``prevbefore`` in the module); False, leaving diffrax as it is, otherwise."""
    import diffrax._integrate as integrate

    try:
        source = inspect.getsource(integrate)
    except (OSError, TypeError):  # no source installed
        return False
    if source.count(_CHAIN_SOURCE) != 1 or source.count("prevbefore(") != 1 or integrate.eqxi is not eqxi:
        return False
    integrate.eqxi = _IntegrateEqxi()
    return True


@contextlib.contextmanager
def compact_end_rounding():
    """Trace `diffrax.diffeqsolve` inside this block to get the same program with t1 - 100 ULP computed by a loop.

    diffeqsolve's loop (diffrax 0.7) computes the threshold above which a step end is rounded onto t1 as 100 chained
    ``prevbefore`` calls, unrolled: about 2 800 traced operations and, after XLA's simplification, one scalar kernel
    of 1 700 instructions per solve -- a quarter to a third of the compiled program of a `jaxcelt.simulate` solve.
    Inside this block (this thread only) the chain is `t1_clip_floor`: the same value, by a loop of 100 iterations.
    If the installed diffrax computes the threshold otherwise, the block changes nothing."""
    if not _install_compact_chain():
        yield
        return
    outer = getattr(_PENDING, "n", None)
    _PENDING.n = _CHAIN
    try:
        yield
        if _PENDING.n != _CHAIN:  # pragma: no cover - a chain cut short: diffrax is not what was checked
            raise RuntimeError("diffeqsolve's t1 - 100 ULP chain ended early; compact_end_rounding is out of date")
    finally:
        _PENDING.n = outer


def diffeqsolve(*args: Any, **kwargs: Any) -> diffrax.Solution:
    """`diffrax.diffeqsolve` traced inside `compact_end_rounding`: the same solve, a smaller program. Every solve
    jaxcelt makes with diffeqsolve goes through here."""
    with compact_end_rounding():
        return diffrax.diffeqsolve(*args, **kwargs)


def clip_to_end(tprev: Array, tnext: Array, t1: Array, floor: Array, keep: Array) -> tuple[Array, Array]:
    """diffeqsolve's bookkeeping after the controller: ``tprev`` capped at t1 and a next step
    end within ~100 ULP of t1 moved onto t1 (accepted step) or halfway there (rejected)."""
    tprev = jnp.minimum(tprev, t1)
    tnext = jnp.where(tnext > floor, jnp.where(keep, t1, tprev + 0.5 * (t1 - tprev)), tnext)
    return tprev, tnext


def loop_init(
    solver: diffrax.AbstractSolver,
    term: diffrax.AbstractTerm,
    controller: diffrax.AbstractAdaptiveStepSizeController,
    t0: Array,
    t1: Array,
    y0: Array,
    args: Any,
    *,
    solver_state: bool = True,
) -> tuple[Array, Any, Any]:
    """diffeqsolve's initialisation of a forward solve with ``dt0=None``: (first step end,
    controller state, solver state or None if ``solver_state=False``). ``term``: from
    `wrap_term`."""
    tnext, cstate = controller.init(term, t0, t1, y0, None, args, solver.func, solver.error_order(term))
    tnext = jnp.minimum(tnext, t1)
    sstate = solver.init(term, t0, tnext, y0, args) if solver_state else None
    return tnext, cstate, sstate


def loop_step(
    solver: diffrax.AbstractSolver,
    term: diffrax.AbstractTerm,
    controller: diffrax.AbstractAdaptiveStepSizeController,
    t1: Array,
    floor: Array,
    tprev: Array,
    tnext: Array,
    y: Array,
    args: Any,
    sstate: Any,
    cstate: Any,
) -> tuple[Array, Array, Array, Array, Any, Any, Any, Any]:
    """One step of diffeqsolve's loop body (``body_fun_aux``) without saving or events.

    Returns (accepted, proposed y1, new tprev, new tnext, proposed solver state, controller
    state, solver result, controller result); the caller keeps y1 and the solver state only
    where the step was accepted, as diffeqsolve does. ``y``: one array (not a pytree);
    ``floor``: `t1_clip_floor` (t1)."""
    y1, y_err, _, sstate1, sres = solver.step(term, tprev, tnext, y, args, sstate, False)
    # a NaN error estimate (e.g. a NaN vector field after too large a step) rejects the step
    y_err = jnp.where(jnp.isnan(y_err), jnp.inf, y_err)
    keep, tprev1, tnext1, _, cstate1, cres = controller.adapt_step_size(
        tprev, tnext, y, y1, args, y_err, solver.error_order(term), cstate
    )
    tprev1, tnext1 = clip_to_end(tprev1, tnext1, t1, floor, keep)
    return keep, y1, tprev1, tnext1, sstate1, cstate1, sres, cres


def forward_only(solver: diffrax.AbstractSolver) -> diffrax.AbstractSolver:
    """``solver`` for a solve that is never differentiated in reverse mode: a Runge-Kutta solver with diffrax's
    default ``scan_kind`` (None: its stages in a checkpointed loop, which keeps reverse mode's memory bounded) gets
    ``scan_kind="lax"`` (the same stages in a plain `jax.lax.while_loop`): the same arithmetic in a program that
    compiles faster (the Lyapunov stage's: ``benchmarks/lyapunov_stage.py``). Other solvers, and a ``scan_kind``
    the caller chose, are returned as they are."""
    if isinstance(solver, diffrax.AbstractRungeKutta) and solver.scan_kind is None:
        return eqx.tree_at(lambda s: s.scan_kind, solver, "lax", is_leaf=lambda x: x is None)
    return solver


def solve_to(
    solver: diffrax.AbstractSolver,
    term: diffrax.AbstractTerm,
    controller: diffrax.AbstractAdaptiveStepSizeController,
    t0: Array,
    t1: Array,
    y0: Array,
    args: Any,
    max_steps: int,
) -> tuple[Array, Array, Array]:
    """``diffeqsolve(term, solver, t0, t1, None, y0, args, stepsize_controller=controller,
    max_steps=max_steps, throw=False)`` saving only y(t1), as one `jax.lax.while_loop` of
    `loop_step`: (y(t1), diffrax result, steps taken, accepted and rejected). ``y0``: one array.

    The same steps as diffeqsolve, in a smaller program: no saving, event or adjoint machinery,
    and t1's 100-ULP floor computed in a loop (`t1_clip_floor`). Differentiable in forward mode
    (``jax.jvp``, ``jax.jacfwd``); reverse mode is not supported (a while loop), so a Runge-Kutta
    solver's stages run in a plain loop (`forward_only`)."""
    R = diffrax.RESULTS
    solver = forward_only(solver)
    wterm = wrap_term(term)
    tnext, cstate, sstate = loop_init(solver, wterm, controller, t0, t1, y0, args)
    floor = t1_clip_floor(t1)

    def cond(c):
        tprev, _, _, _, _, n, result = c
        return (tprev < t1) & (result == R.successful) & (n < max_steps)

    def body(c):
        tprev, tnext, y, sstate, cstate, n, result = c
        keep, y1, tprev, tnext, sstate1, cstate, sres, cres = loop_step(
            solver, wterm, controller, t1, floor, tprev, tnext, y, args, sstate, cstate
        )
        y = jnp.where(keep, y1, y)
        sstate = jax.tree_util.tree_map(lambda a, b: jnp.where(keep, a, b), sstate1, sstate)
        result = R.where(result == R.successful, R.where(keep, sres, R.successful), result)
        result = R.where(result == R.successful, cres, result)
        return tprev, tnext, y, sstate, cstate, n + 1, result

    init = (jnp.asarray(t0), tnext, y0, sstate, cstate, jnp.zeros((), jnp.int32), R.successful)
    tprev, _, y, _, _, n, result = jax.lax.while_loop(cond, body, init)
    result = R.where((result == R.successful) & (tprev < t1), R.max_steps_reached, result)
    return y, result, n
