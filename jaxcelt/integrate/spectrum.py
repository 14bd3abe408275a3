"""The Lyapunov spectrum by tangent dynamics with periodic QR re-orthonormalisation (Benettin et al. 1980).

The state y (dim,) is integrated with k tangent vectors, the columns of Q (dim, k), on the variational equation
built by forward-mode differentiation of the model's own right-hand side,

    d/dt y = f(t, y),        d/dt Q = J_f(t, y) Q    (``jax.linearize`` of f at y, vmapped over Q's columns),

so there is no hand-written Jacobian. Every ``segment`` (the re-orthonormalisation interval) Q is factored
Q = Q' R (QR, diag R > 0), the frame restarts from Q' and log R_ii is accumulated; the exponents are
lambda_i = (sum of log R_ii) / (elapsed time), sorted descending. With k = dim their sum is log|det| of the
tangent flow over the window divided by its length: the time average of the divergence of f (Liouville).
A standard error per exponent comes from batch means over sub-windows (`jaxcelt.integrate.lyapunov.exponent_stderr`).

One adaptive solve per segment (`jaxcelt._diffrax_adapter.solve_to`) inside a `jax.lax.scan`: pure, jittable,
vmappable over states and arguments, float64.

For the wobblestone (`celt_lyapunov_spectrum`, public as ``jaxcelt.lyapunov_spectrum``) the 8 tangent vectors
are projected on the tangent space of the contact manifold with r_C's components dropped
(`jaxcelt.integrate.lyapunov.celt_tangent_projection`) before each factorisation: the exponents are those of
the 8 physical directions, the same directions as the chart of `jaxcelt.periodic_orbit`, whose Floquet
multipliers mu_i give lambda_i = log|mu_i| / T on a periodic orbit. The other 5 directions of the 13-dimensional
state are known exactly (``trivial``).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from typing import Any, NamedTuple

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import jit_anywhere
from jaxcelt._diffrax_adapter import solve_to
from jaxcelt._types import Array
from jaxcelt.integrate.lyapunov import STDERR_BLOCKS, celt_tangent_projection, exponent_stderr
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import CeltField
from jaxcelt.physics.params import CeltParams

__all__ = ["SpectrumResult", "SPECTRUM_STATUS", "lyapunov_spectrum", "celt_lyapunov_spectrum", "CELT_PHYSICAL_DIM"]

CELT_PHYSICAL_DIM = 8
"""Physical directions of the wobblestone's state: the dimension of the contact manifold less the cyclic r_C1, r_C2."""

SPECTRUM_STATUS = {0: "success", 1: "a segment's ODE solve failed (e.g. max_steps)", 2: "non-finite tangent growth"}
"""`SpectrumResult.status` codes."""


class SpectrumResult(NamedTuple):
    """Result of `lyapunov_spectrum` / `celt_lyapunov_spectrum`; leading batch axes under ``jax.vmap``."""

    exponents: Array
    """(k,) Lyapunov exponents [1/time], sorted descending; NaN unless ``status`` is 0"""
    stderr: Array
    """(k,) batch-means standard error of each exponent over `STDERR_BLOCKS` sub-windows (`exponent_stderr`)"""
    trivial: Array
    """exponents of the directions left out of ``exponents`` and known exactly (the wobblestone: 5; generic: none)"""
    log_growth: Array
    """(n_reorth, k) log R_ii of every averaged re-orthonormalisation, columns in the order of ``exponents``"""
    time: Array
    """length of the averaging window, n_reorth x segment (the transient excluded)"""
    t_final: Array
    """time at the end of the window (t0 + (transient + n_reorth) x segment)"""
    n_reorth: int
    """re-orthonormalisations averaged over (one per segment; the transient's are not counted)"""
    y_final: Array
    """(dim,) final state"""
    status: Array
    """`SPECTRUM_STATUS`: 0 success, 1 an ODE solve failed, 2 non-finite growth"""
    num_steps: Array
    """solver steps in all, transient included"""


def _positive_int(name: str, x, *, zero_ok: bool = False, caller: str) -> int:
    lo = 0 if zero_ok else 1
    if isinstance(x, bool) or not isinstance(x, numbers.Integral) or x < lo:
        raise ValueError(f"{caller}: {name!r} must be an int >= {lo}, got {x!r}")
    return int(x)


def _positive_float(name: str, x, *, caller: str) -> None:
    if isinstance(x, jax.core.Tracer):
        return
    ok = not isinstance(x, bool) and np.ndim(x) == 0
    if ok:
        try:
            v = float(x)
        except (TypeError, ValueError):
            ok = False
        else:
            ok = math.isfinite(v) and v > 0
    if not ok:
        raise ValueError(f"{caller}: {name!r} must be a positive finite number, got {x!r}")


def _check_solver(solver, caller: str) -> None:
    if solver is not None and not isinstance(solver, diffrax.AbstractSolver):
        raise ValueError(f"{caller}: 'solver' must be a diffrax solver or None, got {type(solver).__name__}")


def _start_frame(dim: int, k: int, dtype) -> Array:
    # fixed, generic start frame (a seeded normal draw): reproducible, and in general position
    return jax.random.normal(jax.random.PRNGKey(19800101), (dim, k), dtype=dtype)


def _qr(q: Array) -> tuple[Array, Array]:
    """Reduced QR with diag R >= 0: (Q', log|diag R|)."""
    qq, r = jnp.linalg.qr(q)
    d = jnp.diagonal(r)
    s = jnp.where(d < 0, -1.0, 1.0).astype(q.dtype)
    return qq * s[None, :], jnp.log(jnp.abs(d))


def lyapunov_spectrum(
    vector_field: Callable[[Any, Array, Any], Array],
    y0: Array,
    args: Any,
    *,
    segment: float | Array,
    n_segments: int,
    n_transient_segments: int = 0,
    k: int | None = None,
    t0: float | Array = 0.0,
    Q0: Array | None = None,
    project: Callable[[Array, Array, Any], Array] | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 100_000,
) -> SpectrumResult:
    """The k largest Lyapunov exponents of dy/dt = f(t, y, args) along the orbit through ``y0``.

    Args:
        vector_field: ``f(t, y, args) -> dy/dt`` (pure, differentiable; diffrax's contract).
        y0: initial state (dim,).
        args: passed to ``f``.
        segment: the re-orthonormalisation interval (for a forced system, its period or a fraction of it).
        n_segments: segments averaged over (after the transient); the window is n_segments x segment long.
        n_transient_segments: segments integrated first whose growth is discarded (the frame aligns with the
            Oseledets directions and the state reaches the attractor).
        k: tangent vectors (1 <= k <= dim; default dim, the whole spectrum).
        t0: initial time.
        Q0: (dim, k) initial tangent frame; default a fixed generic one.
        project: ``project(y, dy, args) -> dy`` applied to every tangent vector before each factorisation (e.g.
            onto the tangent space of an invariant manifold, dropping directions that do not feed back).
        solver, rtol, atol, max_steps: per-segment diffrax settings (default Tsit5 + PID); the error control
            covers the state and the tangent vectors.

    Returns:
        `SpectrumResult` (``trivial`` empty). Pure and jittable (validation needs concrete ints for the counts);
        vmap over y0/args for batches.

    Raises:
        ValueError: naming the parameter, for a count that is not a positive int, k out of range, a non-positive
            or non-finite segment or tolerance, a y0 that is not one vector, a Q0 of the wrong shape, a solver
            that is not a diffrax solver.
    """
    caller = "lyapunov_spectrum"
    n_segments = _positive_int("n_segments", n_segments, caller=caller)
    n_transient_segments = _positive_int("n_transient_segments", n_transient_segments, zero_ok=True, caller=caller)
    max_steps = _positive_int("max_steps", max_steps, caller=caller)
    for name, x in (("segment", segment), ("rtol", rtol), ("atol", atol)):
        _positive_float(name, x, caller=caller)
    _check_solver(solver, caller)
    y0 = jnp.asarray(y0)
    if y0.ndim != 1 or y0.shape[0] < 1:
        raise ValueError(f"{caller}: 'y0' must be one state vector (dim,), got shape {y0.shape}")
    if not jnp.issubdtype(y0.dtype, jnp.floating):
        y0 = y0.astype(float)
    dim = y0.shape[0]
    k = dim if k is None else _positive_int("k", k, caller=caller)
    if k > dim:
        raise ValueError(f"{caller}: 'k' must be at most the state's dimension {dim}, got {k}")
    if Q0 is None:
        Q0 = _start_frame(dim, k, y0.dtype)
    Q0 = jnp.asarray(Q0, y0.dtype)
    if Q0.shape != (dim, k):
        raise ValueError(f"{caller}: 'Q0' must have shape {(dim, k)}, got {Q0.shape}")

    proj = (lambda y, q, a: q) if project is None else jax.vmap(project, in_axes=(None, 1, None), out_axes=1)

    def tangent_field(t, z, a):  # z = (y, Q.ravel()) as one vector
        y, q = z[:dim], z[dim:].reshape(dim, k)
        fy, lin = jax.linearize(lambda yy: vector_field(t, yy, a), y)
        return jnp.concatenate([fy, jax.vmap(lin, in_axes=1, out_axes=1)(q).reshape(-1)])

    term = diffrax.ODETerm(tangent_field)
    solver = solver or diffrax.Tsit5()
    controller = diffrax.PIDController(rtol=rtol, atol=atol)
    seg = jnp.asarray(segment, y0.dtype)
    t0 = jnp.asarray(t0, y0.dtype)
    q0, _ = _qr(proj(y0, Q0, args))

    def one(carry, i):
        y, q, ok, steps = carry
        ta = t0 + i * seg
        z1, result, n = solve_to(
            solver, term, controller, ta, ta + seg, jnp.concatenate([y, q.reshape(-1)]), args, max_steps
        )
        y1, q1 = z1[:dim], z1[dim:].reshape(dim, k)
        q1, logs = _qr(proj(y1, q1, args))
        return (y1, q1, ok & (result == diffrax.RESULTS.successful), steps + n), logs

    n_tot = n_transient_segments + n_segments
    init = (y0, q0, jnp.array(True), jnp.array(0))
    (yf, _, ok, steps), logs = jax.lax.scan(one, init, jnp.arange(n_tot))
    logs = logs[n_transient_segments:]  # (n_segments, k)
    window = n_segments * seg
    lam = jnp.sum(logs, axis=0) / window
    order = jnp.argsort(-lam)
    lam, logs = lam[order], logs[:, order]
    finite = jnp.all(jnp.isfinite(logs))
    status = jnp.where(~ok, 1, jnp.where(finite, 0, 2))
    good = status == 0
    err = exponent_stderr(logs.T, seg) if n_segments >= STDERR_BLOCKS else jnp.full(k, jnp.nan, y0.dtype)
    return SpectrumResult(
        exponents=jnp.where(good, lam, jnp.nan),
        stderr=jnp.where(good, err, jnp.nan),
        trivial=jnp.zeros((0,), y0.dtype),
        log_growth=logs,
        time=window,
        t_final=t0 + n_tot * seg,
        n_reorth=n_segments,
        y_final=yf,
        status=status,
        num_steps=steps,
    )


@jit_anywhere
def _celt_spectrum(params, y0, t0, *, law, periods, transient, per_period, solver, rtol, atol, max_steps):
    T = 2 * jnp.pi / params.omega_pi
    res = lyapunov_spectrum(
        CeltField(law),
        y0,
        params,
        segment=T / per_period,
        n_segments=periods * per_period,
        n_transient_segments=transient * per_period,
        k=CELT_PHYSICAL_DIM,
        t0=t0,
        project=celt_tangent_projection,
        solver=solver,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
    )
    kappa = jnp.asarray(params.kappa, y0.dtype)
    trivial = jnp.stack([jnp.zeros_like(kappa)] * 4 + [-kappa])
    return res._replace(trivial=trivial)


def celt_lyapunov_spectrum(
    params: CeltParams,
    y0: Array,
    *,
    periods: int = 200,
    transient_periods: int = 20,
    reorth_per_period: int = 1,
    t0: float | Array = 0.0,
    contact_law: AbstractContactLaw | str | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    max_steps: int = 200_000,
) -> SpectrumResult:
    """The wobblestone's Lyapunov spectrum [1/s]: the 8 exponents of its physical directions.

    The state (13,) lives on the contact manifold (|n| = 1, v_A . n = 0, r_C3 fixed by the contact; MODEL.md
    section 8) and r_C1, r_C2 are cyclic. 8 tangent vectors are integrated with the state and, before every
    re-orthonormalisation, projected on the manifold's tangent space with r_C's components dropped
    (`jaxcelt.integrate.lyapunov.celt_tangent_projection`), so ``exponents`` are the 8 physical ones: on a periodic
    orbit of period k T they tend to log|mu_i| / (k T) for the multipliers mu_i of `jaxcelt.periodic_orbit`
    (its chart spans the same directions). The finite-time error decays like 1/time.

    The 5 directions left out are not computed: their exponents are known exactly and returned as ``trivial``,
    (0, 0, 0, 0, -kappa): translations of r_C1 and r_C2 (the field does not depend on them), |n| (conserved by
    n_dot = -omega x n), r_C3 + rho . n (conserved), and v_A . n (decays as exp(-kappa t) with the Baumgarte gain
    kappa). The sum of all 13 is the time average of the divergence of the vector field.

    Args:
        params: the stone and the base (omega_pi sets the forcing period T = 2 pi / omega_pi).
        y0: (13,) state at time ``t0`` (on the contact manifold, e.g. ``initial_state`` or an orbit's ``y``).
        periods: forcing periods averaged over.
        transient_periods: periods integrated first whose growth is discarded.
        reorth_per_period: re-orthonormalisations per period (the segment is T / reorth_per_period; more
            of them only matter when exponents differ by much more than 1/segment).
        t0: initial time [s] (the base's phase omega_pi t0).
        contact_law: the model's law (default: the registry's).
        solver, rtol, atol, max_steps: per-segment diffrax settings (default Tsit5, rtol 1e-10, atol 1e-12,
            200 000 steps per segment).

    Returns:
        `SpectrumResult`: ``exponents`` (8,) sorted descending with ``stderr`` (8,), ``trivial`` (5,),
        ``time`` = periods x T, ``n_reorth`` = periods x reorth_per_period, ``status`` (0 success). Jitted once
        per set of counts and solver; vmappable over params / y0.

    Raises:
        ValueError: naming the parameter: params not a `CeltParams`, y0 not of shape (13,) or not finite, a count
            that is not an int of the right sign, a tolerance that is not a positive number, a solver that is not
            a diffrax solver.
    """
    caller = "lyapunov_spectrum"
    if not isinstance(params, CeltParams):
        raise ValueError(f"{caller}: 'params' must be a CeltParams, got {type(params).__name__}")
    periods = _positive_int("periods", periods, caller=caller)
    transient_periods = _positive_int("transient_periods", transient_periods, zero_ok=True, caller=caller)
    reorth_per_period = _positive_int("reorth_per_period", reorth_per_period, caller=caller)
    max_steps = _positive_int("max_steps", max_steps, caller=caller)
    for name, x in (("rtol", rtol), ("atol", atol)):
        _positive_float(name, x, caller=caller)
    _check_solver(solver, caller)
    if not isinstance(y0, jax.core.Tracer):
        arr = np.asarray(y0, dtype=float)
        if arr.shape != (13,):
            raise ValueError(f"{caller}: 'y0' must have shape (13,) = (v, omega, n, r_C, psi), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{caller}: 'y0' contains NaN/inf")
    return _celt_spectrum(
        params,
        jnp.asarray(y0, float),
        jnp.asarray(t0, float),
        law=get_contact_law(contact_law),
        periods=periods,
        transient=transient_periods,
        per_period=reorth_per_period,
        solver=solver or diffrax.Tsit5(),
        rtol=float(rtol),
        atol=float(atol),
        max_steps=max_steps,
    )
