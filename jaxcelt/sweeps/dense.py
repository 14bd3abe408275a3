"""A dense trajectory at one parameter value: many states per forcing period after the transient.

Where a sweep keeps one state per forcing period (the stroboscopic section), `dense_trajectory`
saves ``points_per_period`` states per period over ``periods`` periods after ``transient_periods``,
for phase plots (paper Figs. 4-7); the section times are among the save times, exactly. Its
program is compiled once per solver, contact law, step bound and number of save times and kept
(`jaxcelt._executable_cache`); `prepare_dense_trajectory` starts that compilation ahead, on a worker
thread. `orbit` and `prepare_orbit` are the former names (deprecated: an orbit in
`jaxcelt.orbits` is a periodic orbit, this is any trajectory).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import diffrax
import jax
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import compiler_options
from jaxcelt._executable_cache import compile_in_background, compiled
from jaxcelt.integrate.solve import DEFAULT_SOLVER, simulate
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.diagnostics import centre_position
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import check_state, initial_state

__all__ = ["dense_trajectory", "prepare_dense_trajectory"]

_NAME = "orbit"
"""the program's name in `jaxcelt._executable_cache` (kept, so that stored executables stay found)"""


def _program(
    params: CeltParams,
    y0: Any,
    transient_periods: int,
    periods: int,
    points_per_period: int,
    solver: diffrax.AbstractSolver | None,
    rtol: float,
    atol: float,
    max_steps: int,
    contact_law: AbstractContactLaw | str | None,
) -> tuple[Callable, tuple, str, np.ndarray]:
    """`dense_trajectory`'s inputs checked, and its program: (function, array arguments, description, save
    times) for `jaxcelt._executable_cache.compiled` (one program per solver, law, step bound and
    number of save times; on a CPU compiled with XLA's loop emitters, as the sweep's Lyapunov stage,
    `jaxcelt._compile_options`)."""
    if y0 is None:
        y0 = initial_state(params)
    for name, v in (
        ("transient_periods", transient_periods),
        ("periods", periods),
        ("points_per_period", points_per_period),
    ):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < (0 if name == "transient_periods" else 1):
            raise ValueError(f"{name} must be an int >= {0 if name == 'transient_periods' else 1}, got {v!r}")
    w = float(params.omega_pi)
    T = 2 * np.pi / w
    k = np.arange(periods * points_per_period + 1)
    ts = T * (transient_periods + k / points_per_period)
    check_state(y0, params, name="y0")
    y0 = np.asarray(y0, dtype=np.float64)
    if y0.shape != (13,):
        raise ValueError(f"'y0' must have shape (13,), got {y0.shape}")
    for name, tol in (("rtol", rtol), ("atol", atol)):
        if not (np.ndim(tol) == 0 and np.isfinite(tol) and tol > 0):
            raise ValueError(f"{name!r} must be a positive finite number, got {tol!r}")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise ValueError(f"max_steps must be a positive int, got {max_steps!r}")
    solver, law = solver or DEFAULT_SOLVER, get_contact_law(contact_law)
    leaves, treedef = jax.tree.flatten(params)
    args = ([np.asarray(x, np.float64) for x in leaves], y0, ts, np.float64(rtol), np.float64(atol))

    def dense_program(leaves, y0, ts, rtol, atol):
        p = jax.tree.unflatten(treedef, leaves)
        sol = simulate(
            p, y0, ts[-1], ts=ts, solver=solver, rtol=rtol, atol=atol, max_steps=max_steps, contact_law=law,
            exact_ts=True,
        )  # fmt: skip
        r_O = jax.vmap(centre_position, in_axes=(0, None))(sol.ys, p)
        return sol.ys, r_O, sol.status, sol.valid

    description = repr((treedef, solver, law, max_steps))
    return dense_program, args, description, ts


def prepare_dense_trajectory(
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
    defer: bool = False,
) -> None:
    """Start compiling the program `dense_trajectory` runs with these arguments: traced now, compiled by
    XLA on a worker thread. A `dense_trajectory` call with the same settings (any parameter values and
    start) then finds it compiled, or waits for it. Worth it before work that leaves a CPU core idle,
    e.g. drawing figures. Raises as `dense_trajectory` does on bad input.

    ``defer=True``: trace and compile it on a worker thread when a sweep's Lyapunov stage starts
    (its padded last group leaves a core partly idle), or else when `dense_trajectory` or this function without
    ``defer`` first asks for it (`jaxcelt._executable_cache.start_deferred`)."""
    fn, args, description, _ = _program(
        params, y0, transient_periods, periods, points_per_period, solver, rtol, atol, max_steps, contact_law
    )
    compile_in_background(_NAME, fn, args, description, compiler_options(jax.default_backend()), defer=defer)


def dense_trajectory(
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
    ``transient_periods``; save times include the section times exactly (``exact_ts``). The
    program is compiled once per solver, law, ``max_steps`` and number of save times, and kept
    (`jaxcelt._executable_cache`; `prepare_dense_trajectory` compiles it ahead).

    Returns dict with ``ts`` (n,), ``ys`` (n, 13), ``r_O`` (n, 3) [m], ``section_index``
    (indices of the section times in ts), ``status``, ``valid``.
    """
    fn, args, description, ts = _program(
        params, y0, transient_periods, periods, points_per_period, solver, rtol, atol, max_steps, contact_law
    )
    exe = compiled(_NAME, fn, args, description, compiler_options(jax.default_backend()))
    ys, r_O, status, valid = exe(*args)
    return dict(
        ts=ts,
        ys=np.asarray(ys),
        r_O=np.asarray(r_O),
        section_index=np.arange(0, len(ts), points_per_period),
        status=int(status),
        valid=bool(valid),
    )


def _deprecated(old: str, new: Callable) -> Callable:
    def alias(*args: Any, **kwargs: Any) -> Any:
        warnings.warn(
            f"{old} is deprecated and will be removed in the next release; use jaxcelt.sweeps.dense.{new.__name__}",
            DeprecationWarning,
            stacklevel=2,
        )
        return new(*args, **kwargs)

    alias.__name__ = alias.__qualname__ = old
    alias.__doc__ = f"Deprecated: `{new.__name__}`."
    return alias


orbit = _deprecated("orbit", dense_trajectory)
prepare_orbit = _deprecated("prepare_orbit", prepare_dense_trajectory)
