"""The optimisers of a fit and their iteration loops, over the flat unknowns z of a `jaxcelt.identify.problem.Problem`.

``"lm"`` (optimistix Levenberg-Marquardt), ``"gn"`` (optimistix Gauss-Newton), ``"gn-damped"`` (`DampedGaussNewton`:
Gauss-Newton with a backtracking Armijo line search), ``"adam"`` and ``"lbfgs"`` (optax; gradient J^T r from the same
forward-mode Jacobian). Their programs are small: the residuals and the Jacobian come from the evaluation program
(`jaxcelt.identify.program`) through a host callback, and the problem is an argument of every program (the
``args`` of optimistix), so each is compiled once per shape and optimiser for the whole process, and two fits may
iterate at the same time in two threads.

`run` iterates one start; `run_batch` iterates several starts of a least-squares optimiser at once (one vmapped step
per iteration). Both return a `Trace`: the final unknowns and the per-iteration history.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
import optimistix as optx

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import jit_per_platform
from jaxcelt._types import Array
from jaxcelt.identify.options import LSQ_OPTIMISERS, FitOptions
from jaxcelt.identify.problem import Problem, theta_and_jacobian, thetas, to_device
from jaxcelt.identify.program import callback_value_and_jacobian, evaluating, kept_key, prefetch

__all__ = ["DampedGaussNewton", "Trace", "run", "run_batch", "lsq_solver"]

@jax.custom_jvp
def _residuals(zf: Array, prob: Problem) -> Array:
    """z -> r(z) with the JVP J dz, both from one callback evaluation."""
    return callback_value_and_jacobian(prob, zf)[0]


@_residuals.defjvp
def _residuals_jvp(primals, tangents):
    zf, prob = primals
    r, J = callback_value_and_jacobian(prob, zf)
    return r, J @ tangents[0]


@jax.custom_jvp
def _loss(zf: Array, prob: Problem) -> Array:
    """z -> 1/2 |r|^2 with the gradient J^T r (forward-mode J; reverse mode differentiates the JVP)."""
    r = callback_value_and_jacobian(prob, zf)[0]
    return 0.5 * jnp.sum(r**2)


@_loss.defjvp
def _loss_jvp(primals, tangents):
    zf, prob = primals
    r, J = callback_value_and_jacobian(prob, zf)
    return 0.5 * jnp.sum(r**2), jnp.dot(J.T @ r, tangents[0])


def _lsq_fn(zf: Array, prob: Problem):
    return _residuals(zf, prob), None


class DampedGaussNewton(optx.AbstractGaussNewton):
    """Gauss-Newton with step limiting: the full GN step is shortened by a backtracking Armijo
    line search (halving until the loss decreases sufficiently). Plain `optimistix.GaussNewton`
    accepts every full step; from a start 35-50% off, its first steps land in parameter regions
    where the record's integration is stiff and the loss is far larger (see docs/identification.md)."""

    rtol: float
    atol: float
    norm: Callable = optx.max_norm
    descent: optx.NewtonDescent = optx.NewtonDescent()
    search: optx.BacktrackingArmijo = optx.BacktrackingArmijo(decrease_factor=0.5, slope=0.1, step_init=1.0)
    verbose: Callable = lambda **kw: None


def lsq_solver(name: str, rtol: float, atol: float):
    """The optimistix solver of least-squares optimiser ``name``."""
    if name == "lm":
        return optx.LevenbergMarquardt(rtol=rtol, atol=atol)
    if name == "gn-damped":
        return DampedGaussNewton(rtol=rtol, atol=atol)
    return optx.GaussNewton(rtol=rtol, atol=atol)



def _lsq_init_impl(z, solver, prob):
    f_struct = jax.ShapeDtypeStruct((prob.n_residuals,), z.dtype)
    return solver.init(_lsq_fn, z, prob, {}, f_struct, None, frozenset())


def _lsq_step_impl(z, state, solver, prob):
    z, state, _ = solver.step(_lsq_fn, z, prob, {}, state, frozenset())
    done, result = solver.terminate(_lsq_fn, z, prob, {}, state, frozenset())
    # loss at the last accepted iterate; whether the termination is a success
    return z, state, 0.5 * jnp.sum(state.f_info.residual**2), done, result == optx.RESULTS.successful


# the optimisers' step programs (one start), with `jaxcelt._compile_options.compiler_options` of the platform
_lsq_init = jit_per_platform(_lsq_init_impl)
_lsq_step = jit_per_platform(_lsq_step_impl)


@eqx.filter_jit
def _lsq_init_batch(zs, solver, prob):
    return eqx.filter_vmap(lambda z: _lsq_init_impl(z, solver, prob))(zs)


@eqx.filter_jit
def _lsq_step_batch(zs, states, frozen, solver, prob):
    """One step of every start; a start that has terminated (``frozen``) keeps its iterate and state."""

    def one(z, state, stop):
        z2, state2, loss, done, ok = _lsq_step_impl(z, state, solver, prob)
        keep = lambda a, b: jnp.where(stop, a, b) if eqx.is_array(a) else b  # noqa: E731
        z2 = jnp.where(stop, z, z2)
        state2 = jax.tree.map(keep, state, state2, is_leaf=lambda x: x is None)
        return z2, state2, loss, done, ok

    return eqx.filter_vmap(one)(zs, states, frozen)


@functools.cache
def _optax_optimiser(name: str, learning_rate: float, max_iter: int) -> optax.GradientTransformation:
    """A cache: the optax optimiser of these settings. One object per settings, so that `_optax_step` (which takes
    the optimiser's functions as static arguments, compared by identity) is compiled once per process, not per fit."""
    if name == "adam":
        # cosine decay to 1e-3 of the initial step over the budget: constant-step Adam hovers
        # around the optimum at a distance ~ learning_rate instead of converging
        return optax.adam(optax.cosine_decay_schedule(learning_rate, max_iter, alpha=1e-3))
    return optax.lbfgs()


def _optax_step_impl(z, opt_state, optimiser, prob, linesearch: bool):
    loss_fn = lambda x: _loss(x, prob)  # noqa: E731
    if linesearch:  # L-BFGS: value and gradient kept in the state by its line search
        value, grad = optax.value_and_grad_from_state(loss_fn)(z, state=opt_state)
        updates, opt_state = optimiser.update(grad, opt_state, z, value=value, grad=grad, value_fn=loss_fn)
    else:
        value, grad = jax.value_and_grad(loss_fn)(z)
        updates, opt_state = optimiser.update(grad, opt_state, z)
    z_new = optax.apply_updates(z, updates)
    return z_new, opt_state, value, jnp.linalg.norm(grad)


_optax_step = jit_per_platform(_optax_step_impl)


@dataclasses.dataclass
class Trace:
    """The iterations of one start: final unknowns ``zf`` (flat), loss and parameter values per iteration,
    whether the optimiser's criterion was met, and the end time of every iteration (``iter_marks[0]``: the
    start; for `jaxcelt.identify.result.split_times`)."""

    zf: np.ndarray
    loss_history: list[float]
    param_history: list[dict[str, float]]
    converged: bool
    iter_marks: list[float]
    final: tuple[np.ndarray, np.ndarray] | None = None
    """(r, J) at ``zf`` where the optimiser evaluated it (None: it did not)."""


def _deadline(config: FitOptions, t_start: float, now: float) -> bool:
    return config.max_time is not None and now - t_start > config.max_time


def run(prob: Problem, zf: Array, config: FitOptions, t_start: float) -> Trace:
    """Iterate ``config.optimiser`` from the flat unknowns ``zf`` until it converges or ``config.max_iter``
    or ``config.max_time`` (counted from ``t_start``) is spent; ``config.callback`` after every iteration."""
    free, callback = prob.free, config.callback

    def values_of(zf) -> dict[str, float]:
        th = np.asarray(theta_and_jacobian(prob, zf)[0])
        return {n: float(th[i]) for i, n in enumerate(free)}

    def keep_only(zf) -> None:  # of the evaluations so far, the one at the current iterate
        entry = kept.get(kept_key(zf))
        kept.clear()
        if entry is not None:
            kept[kept_key(zf)] = entry

    loss_hist, par_hist = [], []
    kept: dict = {}
    platform = jax.default_backend()
    converged = False
    iter_marks = [time.perf_counter()]
    if config.optimiser in LSQ_OPTIMISERS:
        solver = lsq_solver(config.optimiser, config.rtol, config.atol)
        prefetch(prob, zf)
        values_of(zf)  # its small program compiles now, while the evaluation program compiles in the background
        with evaluating(prob):
            state = jax.block_until_ready(_lsq_init(platform)(zf, solver, prob))
        for it in range(config.max_iter):
            with evaluating(prob, kept):
                z_new, state, loss_acc, done, ok = jax.block_until_ready(_lsq_step(platform)(zf, state, solver, prob))
            iter_marks.append(time.perf_counter())
            zf = z_new
            keep_only(zf)
            loss_hist.append(float(loss_acc))
            par_hist.append(values_of(zf))
            if callback is not None:
                callback(it, loss_hist[-1], par_hist[-1])
            if bool(done):
                converged = bool(ok)
                break
            if _deadline(config, t_start, iter_marks[-1]):
                break
    else:
        opt = _optax_optimiser(config.optimiser, config.learning_rate, config.max_iter)
        prefetch(prob, zf)
        values_of(zf)  # compiled while the evaluation program compiles in the background
        # strongly typed like the states `_optax_step` returns (optax's init leaves some weakly typed): one
        # compilation of the step, not a second one at the second iteration
        opt_state = jax.tree.map(lambda x: jnp.asarray(x, dtype=jnp.asarray(x).dtype), opt.init(zf))
        g0 = None
        for it in range(config.max_iter):
            with evaluating(prob, kept):
                step = _optax_step(platform)(zf, opt_state, opt, prob, config.optimiser == "lbfgs")
                z_new, opt_state, value, gnorm = jax.block_until_ready(step)
            iter_marks.append(time.perf_counter())
            keep_only(zf)  # the step evaluated at zf (and at line-search points)
            loss_hist.append(float(value))
            par_hist.append(values_of(zf))
            if callback is not None:
                callback(it, loss_hist[-1], par_hist[-1])
            g = float(gnorm)
            g0 = g if g0 is None else g0
            if not np.isfinite(float(value)):
                break
            # gradient of the loss at zf (before the update) reduced by gtol: zf is the optimum
            if g <= config.gtol * g0:
                converged = True
                break
            zf = z_new
            if _deadline(config, t_start, iter_marks[-1]):
                break
    zf = np.asarray(zf)
    return Trace(zf, loss_hist, par_hist, converged, iter_marks, kept.get(kept_key(zf)))


def run_batch(prob: Problem, starts: np.ndarray, config: FitOptions, t_start: float) -> list[Trace]:
    """Iterate the least-squares optimiser ``config.optimiser`` from every start (S, n) at once: one vmapped step
    per iteration, the solves of all starts in one vmapped evaluation; a start that has terminated keeps its iterate
    while the others go on. ``config.callback`` receives the lowest loss over the starts. The starts share
    ``iter_marks``."""
    free = prob.free
    S = len(starts)
    zs = to_device(starts)
    solver = lsq_solver(config.optimiser, config.rtol, config.atol)
    prefetch(prob, starts)
    with evaluating(prob):
        states = jax.block_until_ready(_lsq_init_batch(zs, solver, prob))
    frozen, converged = np.zeros(S, bool), np.zeros(S, bool)
    loss_hist: list[list[float]] = [[] for _ in range(S)]
    par_hist: list[list[dict]] = [[] for _ in range(S)]
    iter_marks = [time.perf_counter()]
    for it in range(config.max_iter):
        with evaluating(prob):
            step = _lsq_step_batch(zs, states, jax.device_put(frozen), solver, prob)
            zs, states, loss, done, ok = jax.block_until_ready(step)
        iter_marks.append(time.perf_counter())
        loss, done, ok = np.asarray(loss), np.asarray(done), np.asarray(ok)
        th = np.asarray(thetas(prob, zs))
        for i in np.flatnonzero(~frozen):
            loss_hist[i].append(float(loss[i]))
            par_hist[i].append({n: float(th[i, j]) for j, n in enumerate(free)})
            if done[i]:
                frozen[i], converged[i] = True, bool(ok[i])
        if config.callback is not None:
            last = np.array([h[-1] if h else np.inf for h in loss_hist])
            b = int(np.argmin(np.where(np.isfinite(last), last, np.inf)))
            config.callback(it, float(last[b]), par_hist[b][-1])
        if frozen.all():
            break
        if _deadline(config, t_start, iter_marks[-1]):
            break
    zs = np.asarray(zs)
    return [Trace(zs[i], loss_hist[i], par_hist[i], bool(converged[i]), iter_marks) for i in range(S)]
