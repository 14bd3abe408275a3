"""The compiled evaluation program of a fit: residuals and their forward-mode Jacobian, (r, J) = (r(z), dr/dz).

The only program that contains the ODE solver is this one (all records, compiled once per problem shape) and it is
shared by every optimiser, the uncertainty, multi-start and profile likelihood. With JAX's persistent cache directory
set, it is stored compiled and later processes load it (`jaxcelt._executable_cache`). On a multi-core CPU the
one-record program runs every record in its own thread (`record_parts`); elsewhere one program runs them in a
`jax.lax.map`.

The optimisers' own (small) programs reach it through `jax.pure_callback` (`callback_value_and_jacobian`), so that
they never contain the solver and are compiled once per problem structure for the whole process. The problem reaches
the callback from the caller of each optimiser program (`evaluating`), never from a module global: fits of different
data may run at the same time in different threads.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import os
import threading
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import equinox as eqx
import jax
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import compiler_options
from jaxcelt._diffrax_adapter import runtime_checks_as_nan
from jaxcelt._executable_cache import compile_in_background, compiled
from jaxcelt._types import Array
from jaxcelt.identify.problem import Problem, to_device

__all__ = [
    "evaluate",
    "evaluate_program",
    "prefetch",
    "record_parts",
    "one_record",
    "callback_value_and_jacobian",
    "evaluating",
    "evaluation_for",
    "kept_key",
]

_COMPILE_LOCK = threading.Lock()
"""One thread traces at a time (`runtime_checks_as_nan` swaps a global of equinox while tracing)."""


def cpu_workers() -> int:
    """The CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@functools.cache
def _record_pool(workers: int) -> ThreadPoolExecutor:
    """A cache: the process's thread pool of ``workers`` threads for the records (thread-safe executor, shared by
    every fit)."""
    return ThreadPoolExecutor(max_workers=workers, thread_name_prefix="jaxcelt-fit")


def one_record(prob: Problem, i: int) -> tuple[Problem, np.ndarray, np.ndarray]:
    """Record ``i`` as a problem of its own, the columns of its unknowns in the flat vector and the
    rows of its residuals (misfit block, then penalty block) in the whole problem's residuals."""
    rec, R = prob.rec, prob.n_records
    cut = lambda a: np.asarray(a)[i : i + 1]  # noqa: E731  (host slicing: no eager program)
    sub_rec = dataclasses.replace(
        rec,
        ts=cut(rec.ts),
        obs=jax.tree.map(cut, rec.obs),
        mask=jax.tree.map(cut, rec.mask),
        inv_sigma=jax.tree.map(cut, rec.inv_sigma),
        fixed_states=cut(rec.fixed_states),
        omega_pi=cut(rec.omega_pi),
        q_pi=cut(rec.q_pi),
        offset0=cut(rec.offset0),
    )
    sub = dataclasses.replace(prob, rec=sub_rec)
    P, nr, k13 = len(prob.free), 3 * prob.fit_rotation, 13 * len(rec.free_windows)
    no = R * prob.fit_time_offset
    cols = np.concatenate(
        [np.arange(P + nr), [P + nr + i] if prob.fit_time_offset else [], P + nr + no + i * k13 + np.arange(k13)]
    ).astype(int)
    lm, lp = sub.n_misfit, sub.n_residuals - sub.n_misfit
    rows = np.concatenate([i * lm + np.arange(lm), R * lm + i * lp + np.arange(lp)]).astype(int)
    return sub, cols, rows


def record_parts(prob: Problem) -> list[tuple[Problem, np.ndarray, np.ndarray]] | None:
    """How `evaluate` splits ``prob``: on a CPU with several cores, one part per record (see
    `one_record`), evaluated in parallel threads by the one-record program (the records share
    its shapes); None: all records by one program (`jax.lax.map`)."""
    R, workers = prob.n_records, min(prob.n_records, cpu_workers())
    if R == 1 or workers == 1 or jax.default_backend() != "cpu":
        return None
    return [one_record(prob, i) for i in range(R)]


def prefetch(prob: Problem, zf: np.ndarray) -> None:
    """Start compiling the evaluation program `evaluate` will run at unknowns shaped like ``zf``
    in the background (traced now), so that the optimiser's own programs are traced and compiled
    meanwhile."""
    parts = record_parts(prob)
    if parts is None:
        evaluate_program(prob, zf, background=True)
    else:  # the records share one program
        evaluate_program(parts[0][0], np.asarray(zf)[..., parts[0][1]], background=True)


def evaluate(prob: Problem, zf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(r, J) at zf (n,) or at a batch of unknowns (..., n), split as `record_parts` says."""
    parts = record_parts(prob)
    if parts is None:
        return evaluate_program(prob, zf)
    workers = min(prob.n_records, cpu_workers())
    outs = list(_record_pool(workers).map(lambda part: evaluate_program(part[0], zf[..., part[1]]), parts))
    r = np.empty((*zf.shape[:-1], prob.n_residuals))
    J = np.zeros((*zf.shape[:-1], prob.n_residuals, zf.shape[-1]))
    for (_, cols, rows), (ri, Ji) in zip(parts, outs, strict=True):
        r[..., rows] = ri
        J[..., rows[:, None], cols[None, :]] = Ji
    return r, J


def evaluate_program(prob: Problem, zf: np.ndarray, background: bool = False):
    """(r, J) by the compiled evaluation program of ``prob``'s shape (one per batch shape), kept
    in memory and -- with JAX's persistent cache directory set -- on disk across processes
    (`jaxcelt._executable_cache`). Traced without equinox's error callbacks (save times are
    checked by `jaxcelt.identify.problem.build_problem`): a failing solve gives NaN. ``background``: only start
    compiling it (`jaxcelt._executable_cache.compile_in_background`); returns None."""
    prob = dataclasses.replace(prob, mode="fwd")
    dyn, static = eqx.partition(prob, eqx.is_array)
    leaves, treedef = jax.tree.flatten(dyn)
    zf = np.asarray(zf, dtype=float)
    lead, n = zf.shape[:-1], zf.shape[-1]
    x = to_device(zf.reshape(-1, n) if lead else zf)

    def f(leaves, x):
        pr = eqx.combine(jax.tree.unflatten(treedef, leaves), static)
        return jax.vmap(pr.value_and_jacobian)(x) if lead else pr.value_and_jacobian(x)

    description = repr(jax.tree.structure(prob)) + repr(jax.tree.leaves(static))
    with _COMPILE_LOCK, runtime_checks_as_nan():  # one thread traces (the context swaps a global)
        opts = compiler_options(jax.default_backend())
        if background:
            return compile_in_background("fit-residuals-jacobian", f, (leaves, x), description, opts)
        exe = compiled("fit-residuals-jacobian", f, (leaves, x), description, opts)
    r, J = (np.asarray(a) for a in exe(leaves, x))
    return (r.reshape(*lead, -1), J.reshape(*lead, -1, n)) if lead else (r, J)


class _Evaluation:
    """The host side of the evaluation callback for every problem of one structure (an entry of the cache
    `evaluation_for`). Its only operand is the unknowns; the problem it evaluates is handed to it by whoever runs the
    optimiser program, for exactly that call (`evaluating`)."""

    def __init__(self) -> None:
        self.problem: Problem | None = None
        self.kept: dict[bytes, tuple[np.ndarray, np.ndarray]] | None = None

    def __call__(self, zf):
        if self.problem is None:
            raise RuntimeError("the fit's evaluation callback ran outside `jaxcelt.identify.program.evaluating`")
        zf = np.asarray(zf, np.float64)
        r, J = evaluate(self.problem, zf)
        if self.kept is not None and zf.ndim == 1:
            self.kept[kept_key(zf)] = (r, J)
        return r, J


_EVALUATIONS: dict[str, _Evaluation] = {}
"""A cache: one `_Evaluation` per problem structure, so that the optimisers' compiled programs (whose callback is
that object) serve every problem of the structure. Written under `_EVALUATIONS_LOCK`."""
_EVALUATIONS_LOCK = threading.Lock()

_STEP_LOCK = threading.Lock()
"""Held while an optimiser program runs (`evaluating`): it gives the program's callback its problem, and a program
waiting in the callback holds one of the backend's execution threads (two at once can leave none for the evaluation
programs they wait for, seen on a 2-core CPU). Fits in several threads take turns step by step; their host work
between steps overlaps."""


def _structure(prob: Problem) -> str:
    dyn, static = eqx.partition(prob, eqx.is_array)
    return repr(jax.tree.structure(dyn)) + repr(jax.tree.leaves(static))


def evaluation_for(prob: Problem) -> _Evaluation:
    """The callback object of ``prob``'s structure (the same object for every problem of that structure)."""
    key = _structure(prob)
    with _EVALUATIONS_LOCK:
        return _EVALUATIONS.setdefault(key, _Evaluation())


@contextlib.contextmanager
def evaluating(prob: Problem, kept: dict[bytes, tuple[np.ndarray, np.ndarray]] | None = None) -> Iterator[None]:
    """Run an optimiser program of ``prob`` inside this block: its evaluation callback evaluates ``prob``.
    ``kept``: a dict that receives every evaluation of one start, (r, J) under `kept_key` of its unknowns (so that
    the caller need not evaluate again at the iterate it ends on).

    Why not pass the problem's arrays to the callback as operands: measured on a 2-core CPU, a callback with any
    operand besides the unknowns makes the records' evaluation programs run one after the other instead of side by
    side (a fit took 1.5x as long)."""
    evaluation = evaluation_for(prob)
    with _STEP_LOCK:
        evaluation.problem, evaluation.kept = prob, kept
        try:
            yield
        finally:
            evaluation.problem, evaluation.kept = None, None


def kept_key(zf: np.ndarray) -> bytes:
    """The key of the flat unknowns ``zf`` in `evaluating`'s ``kept``."""
    return np.asarray(zf, np.float64).tobytes()


def callback_value_and_jacobian(prob: Problem, zf: Array) -> tuple[Array, Array]:
    """(r, J) of ``prob`` at ``zf`` inside a traced optimiser program, by a host callback to `evaluate`.

    The program must run inside `evaluating` (the problem it is called with). The callback is the same object for
    every problem of ``prob``'s structure, so a compiled optimiser program serves all of them."""
    m = prob.n_residuals
    out = (jax.ShapeDtypeStruct((m,), zf.dtype), jax.ShapeDtypeStruct((m, zf.shape[-1]), zf.dtype))
    # under vmap the callback receives the whole batch of zf (leading axes) and evaluates it at once
    return jax.pure_callback(evaluation_for(prob), out, zf, vmap_method="expand_dims")
