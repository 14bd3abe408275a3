"""Largest Lyapunov exponent by tangent dynamics with periodic renormalisation (Benettin et al.).

The augmented system (y, dy) is integrated with a tangent field built from the model's own
right-hand side, so there is no hand-written Jacobian to drift out of step with the physics:

    d/dt y  = f(t, y),
    d/dt dy = J_f(t, y) dy ~ (f(t, y + h dy) - f(t, y)) / h        (tangent="difference", default)
    d/dt dy = J_f(t, y) dy = jax.jvp(f(t, .), (y,), (dy,))[1]       (tangent="jvp").

The difference quotient is the directional derivative of matrix-free Newton-Krylov solvers, with their step
h = sqrt(eps) sqrt(1 + |y|) / |dy| (M. Pernice & H. F. Walker, NITSOL, SIAM J. Sci. Comput. 19 (1998) 302-318; PETSc's
MATMFFD_WP), accurate to about sqrt(eps) relative: two evaluations of f side by side cost less than f and its
forward-mode derivative, and compile to a smaller program. It
is the tangent of the same discretised flow (with ``error_control="state"`` the steps are the state's in both), so
the exponents agree far inside their standard errors (docs/internals/sweep-engine.md). Every
``segment`` seconds the tangent vector is renormalised to unit length and the log of its
growth is accumulated; lambda_1 = (sum of log growths) / (elapsed time) [1/s]. One adaptive
solve per segment (diffeqsolve's steps as a plain while loop, `jaxcelt._diffrax_adapter.solve_to`)
inside a `jax.lax.scan`, so the estimator is pure, jittable, vmappable (a batch of lanes is
``jax.vmap`` of the one-lane function) and differentiable in forward mode.

For the wobblestone (`celt_lyapunov`) three choices keep the estimate meaningful:

* the segment is one forcing period T = 2 pi / omega_pi, so the segment ends are the
  stroboscopic section (they come back as ``samples``);
* the global position r_C (state components 9:12) does not feed back into the dynamics
  (MODEL.md section 8), so it is left out of the tangent norm -- otherwise the neutral
  translation direction (a perturbation of the drift speed grows linearly) pins
  lambda_1 at 0+ for every attractor;
* at each renormalisation the tangent vector is projected on the tangent space of the
  contact manifold (|n| = 1, v_A . n = 0), whose off-manifold directions are neutral
  invariants of the exact flow; on a periodic attractor the exponent is then negative
  rather than a spurious 0.

Validated against the Lorenz system (lambda_1 = 0.9056, Sprott 2003) and a weakly forced
damped Duffing oscillator (both exponents = -delta/2 by Liouville's formula when the Floquet
multipliers are complex); see ``tests/test_lyapunov.py``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from jaxcelt import _config  # noqa: F401
from jaxcelt._diffrax_adapter import solve_to
from jaxcelt._types import Array, Scalar
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import CeltField, contact_geometry
from jaxcelt.physics.params import CeltParams

__all__ = [
    "LyapunovResult",
    "largest_lyapunov",
    "celt_lyapunov",
    "celt_tangent_projection",
    "exponent_stderr",
    "CELT_NORM_MASK",
    "STDERR_BLOCKS",
    "ERROR_CONTROLS",
    "TANGENTS",
]

# numpy, not jnp: a module-level jnp array would initialise the JAX backend on import
# (then `jax.config.update("jax_num_cpu_devices", n)` could no longer be set)
CELT_NORM_MASK = np.array([1.0] * 9 + [0.0] * 3 + [1.0])
"""Weights of the 13 state components in the tangent norm: r_C (9:12) excluded."""

STDERR_BLOCKS = 4
"""Sub-windows of the batch-means standard error of the exponent (`exponent_stderr`)."""


class LyapunovResult(NamedTuple):
    """Result of `largest_lyapunov`; leading batch axes under ``jax.vmap``."""

    exponent: Scalar
    """largest Lyapunov exponent [1/time]; NaN if any segment failed"""
    log_growth: Array
    """log of the tangent growth per segment, (n_segments,)"""
    samples: Array
    """state at the end of every segment, (n_segments, dim)"""
    y_final: Array
    """final state (dim,)"""
    success: Array
    """all segment solves succeeded"""
    num_steps: Array
    """total solver steps"""
    stderr: Scalar
    """batch-means standard error of ``exponent`` over `STDERR_BLOCKS` sub-windows
    (`exponent_stderr`; NaN with fewer segments than sub-windows or if a segment failed)"""


def exponent_stderr(log_growth: Array, segment: Array, n_blocks: int = STDERR_BLOCKS) -> Array:
    """Batch-means standard error of a finite-time exponent from its per-segment log growths.

    The window's segments are split into ``n_blocks`` consecutive sub-windows (sizes differing by at
    most one segment); each gives its own exponent lambda_b = sum(log growth) / (its length), and the
    standard error of the whole window's exponent is std(lambda_b, ddof=1) / sqrt(n_blocks).

    This measures how much the estimate still moves within the window: on a chaotic attractor the
    per-segment growths fluctuate, and on a periodic orbit whose monodromy is far from normal the
    tangent vector's growth over a segment depends on its direction, which turns from segment to
    segment; both give sub-window exponents that disagree. It is a heuristic: the sub-windows are
    correlated and few, so read +-2 standard errors as a rough interval, not a confidence level.

    Args:
        log_growth: (..., n_segments) log of the tangent growth per segment.
        segment: the segment's length (broadcast against the leading axes).
        n_blocks: sub-windows (>= 2); NaN if there are fewer segments than that.
    """
    if isinstance(n_blocks, bool) or not isinstance(n_blocks, int) or n_blocks < 2:
        raise ValueError(f"exponent_stderr: 'n_blocks' must be an int >= 2, got {n_blocks!r}")
    log_growth = jnp.asarray(log_growth)
    n = log_growth.shape[-1]
    if n < n_blocks:
        return jnp.full(log_growth.shape[:-1], jnp.nan, log_growth.dtype)
    edges = np.linspace(0, n, n_blocks + 1).round().astype(int)  # the window's length is static
    seg = jnp.asarray(segment, log_growth.dtype)
    lam_b = jnp.stack(
        [jnp.sum(log_growth[..., a:b], axis=-1) / ((b - a) * seg) for a, b in zip(edges[:-1], edges[1:])], axis=-1
    )
    return jnp.std(lam_b, axis=-1, ddof=1) / np.sqrt(n_blocks)


def _unit_direction(dim: int, dtype) -> Array:
    # Fixed, generic start direction (a seeded normal draw): results are reproducible and
    # have a component along the most unstable direction with probability one.
    d = jax.random.normal(jax.random.PRNGKey(20140602), (dim,), dtype=dtype)
    return d / jnp.linalg.norm(d)


ERROR_CONTROLS = ("all", "state")
"""what the step-size control of a tangent solve measures (`largest_lyapunov`'s ``error_control``)"""

TANGENTS = ("difference", "jvp")
"""how the tangent vector's derivative J_f dy is formed (`largest_lyapunov`'s ``tangent``)"""


def _tangent_field(
    vector_field: Callable[[Any, Array, Any], Array], dim: int, tangent: str, weights: Array
) -> Callable[[Any, Array, Any], Array]:
    """The field of z = (y, dy): (f(t, y), J_f(t, y) dy) with J_f dy by ``tangent`` (`TANGENTS`): a forward difference
    with step h = sqrt(eps) sqrt(1 + |y|_w) / |dy| (|.|_w: the ``weights``' norm; h is a numerical choice, held out of
    derivatives by ``stop_gradient``), or forward-mode differentiation."""
    if tangent not in TANGENTS:
        raise ValueError(f"'tangent' must be one of {TANGENTS}, got {tangent!r}")
    if tangent == "jvp":

        def jvp_field(t, z, a):
            f, jf = jax.jvp(lambda yy: vector_field(t, yy, a), (z[:dim],), (z[dim:],))
            return jnp.concatenate([f, jf])

        return jvp_field

    def difference_field(t, z, a):
        y, dy = z[:dim], z[dim:]
        root_eps = float(np.sqrt(np.finfo(np.dtype(z.dtype)).eps))
        size = jnp.sqrt(jnp.sum(dy * dy))
        h = jax.lax.stop_gradient(
            root_eps * jnp.sqrt(1 + jnp.sqrt(jnp.sum(weights * y * y))) / jnp.where(size > 0, size, 1.0)
        )
        f = jax.vmap(lambda yy: vector_field(t, yy, a))(jnp.stack([y, y + h * dy]))  # both evaluations side by side
        return jnp.concatenate([f[0], (f[1] - f[0]) / h])

    return difference_field


def _norm_option(error_control: str, dim: int) -> dict[str, Callable[[Array], Array]]:
    """The step-size controller's ``norm`` of the scaled error of z = (y, dy): diffrax's own (the RMS norm of all of
    z: no option) or the RMS norm of its first ``dim`` components (the state)."""
    if error_control not in ERROR_CONTROLS:
        raise ValueError(f"'error_control' must be one of {ERROR_CONTROLS}, got {error_control!r}")
    return {} if error_control == "all" else {"norm": lambda e: optx.rms_norm(e[:dim])}


def largest_lyapunov(
    vector_field: Callable[[Any, Array, Any], Array],
    y0: Array,
    args: Any,
    *,
    t0: float | Array = 0.0,
    segment: float | Array,
    n_segments: int,
    n_transient_segments: int = 0,
    dy0: Array | None = None,
    norm_weights: Array | None = None,
    project: Callable[[Array, Array, Any], Array] | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 100_000,
    error_control: str = "state",
    tangent: str = "difference",
) -> LyapunovResult:
    """Largest Lyapunov exponent of dy/dt = f(t, y, args) from the orbit through ``y0``.

    Args:
        vector_field: ``f(t, y, args) -> dy/dt`` (pure, differentiable; diffrax's contract).
        y0: initial state (dim,).
        args: passed to ``f`` (e.g. `CeltParams`).
        t0: initial time.
        segment: time between renormalisations (for a forced system, its period).
        n_segments: number of segments averaged over (after the transient).
        n_transient_segments: segments integrated first whose growth is discarded
            (lets the tangent vector align with the most unstable direction).
        dy0: initial tangent vector; default a fixed generic unit vector.
        norm_weights: per-component weights (dim,) of the tangent norm (0 drops a
            component that does not feed back, e.g. a position). Default all ones.
        project: ``project(y, dy, args) -> dy`` applied before each renormalisation (e.g.
            onto the tangent space of an invariant manifold).
        solver, rtol, atol, max_steps: per-segment diffrax settings (default Tsit5 + PID).
        error_control: what the step-size control measures: ``"state"`` (default) the error of y
            alone, so that the tangent vector takes the steps the state needs (as
            DynamicalSystems.jl's tangent integrators do by default), or ``"all"``: of y and dy.
        tangent: how J_f dy is formed: ``"difference"`` (default) a forward difference of f along dy (two
            evaluations of f; accurate to about sqrt(eps) relative), or ``"jvp"``: forward-mode
            differentiation of f (see the module's docstring).

    Returns:
        `LyapunovResult`. Pure and jittable; vmap over y0/args for batches; forward-mode
        differentiable (``jax.jvp``, ``jax.jacfwd``), not reverse-mode (the solves are while loops).
    """
    y0 = jnp.asarray(y0)
    dim = y0.shape[0]
    w = jnp.ones(dim, y0.dtype) if norm_weights is None else jnp.asarray(norm_weights, y0.dtype)
    if dy0 is None:
        dy0 = _unit_direction(dim, y0.dtype)
    proj = (lambda y, dy, a: dy) if project is None else project

    def wnorm(dy):
        return jnp.sqrt(jnp.sum(w * dy**2))

    dy0 = proj(y0, jnp.asarray(dy0, y0.dtype) * w, args)
    dy0 = dy0 / wnorm(dy0)

    term = diffrax.ODETerm(_tangent_field(vector_field, dim, tangent, w))  # z = (y, dy) as one vector
    solver = solver or diffrax.Tsit5()
    controller = diffrax.PIDController(rtol=rtol, atol=atol, **_norm_option(error_control, dim))
    seg = jnp.asarray(segment, y0.dtype)
    t0 = jnp.asarray(t0, y0.dtype)

    def one(carry, k):
        y, dy, ok, steps = carry
        ta = t0 + k * seg
        # diffeqsolve's steps without its saving machinery (`jaxcelt._diffrax_adapter.solve_to`)
        z1, result, n = solve_to(solver, term, controller, ta, ta + seg, jnp.concatenate([y, dy]), args, max_steps)
        y1, dy1 = z1[:dim], z1[dim:]
        ok1 = result == diffrax.RESULTS.successful
        dy1 = proj(y1, dy1 * w, args)
        g = wnorm(dy1)
        return (y1, dy1 / g, ok & ok1, steps + n), (jnp.log(g), y1)

    n_tot = n_transient_segments + n_segments
    init = (y0, dy0, jnp.array(True), jnp.array(0))
    (yf, _, ok, steps), (logs, ys) = jax.lax.scan(one, init, jnp.arange(n_tot))
    logs, ys = logs[n_transient_segments:], ys[n_transient_segments:]
    lam = jnp.sum(logs) / (n_segments * seg)
    good = ok & jnp.all(jnp.isfinite(logs))
    lam = jnp.where(good, lam, jnp.nan)
    err = jnp.where(good, exponent_stderr(logs, seg), jnp.nan)
    return LyapunovResult(
        exponent=lam, log_growth=logs, samples=ys, y_final=yf, success=ok, num_steps=steps, stderr=err
    )


def celt_tangent_projection(y: Array, dy: Array, params: CeltParams) -> Array:
    """Project a tangent vector of the wobblestone onto the contact manifold's tangent space.

    dn <- dn - (n . dn) n keeps |n| = 1 to first order; then dv <- dv - (d c) n with
    d c = the first-order change of c = v_A . n (eq. 2; dc/dv = n since |n| = 1), and
    d r_C <- 0 (r_C does not feed back). Shapes (13,).
    """
    n = y[6:9]
    dn = dy[6:9] - jnp.dot(n, dy[6:9]) * n
    dy = dy.at[6:9].set(dn).at[9:12].set(0.0)

    def c(yy):
        g = contact_geometry(yy[6:9], yy[3:6], params)
        return jnp.dot(yy[0:3] + jnp.cross(yy[3:6], g.rho), yy[6:9])

    _, dc = jax.jvp(c, (y,), (dy,))
    return dy.at[0:3].add(-dc * n)


def celt_lyapunov(
    params: CeltParams,
    y0: Array,
    *,
    periods: int,
    transient_periods: int = 0,
    t0: float | Array = 0.0,
    contact_law: AbstractContactLaw | str | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    max_steps: int = 100_000,
    error_control: str = "state",
    tangent: str = "difference",
) -> LyapunovResult:
    """Largest Lyapunov exponent of the wobblestone [1/s], renormalised once per forcing period.

    Segments are T = 2 pi / omega_pi (eq. 17), starting at ``t0``; ``samples`` are the
    stroboscopic states at t0 + k T, k = transient_periods + 1 ... . r_C is excluded from
    the tangent norm and the tangent vector is kept on the contact manifold
    (`celt_tangent_projection`). ``max_steps`` is per period; ``error_control``, ``tangent``: `largest_lyapunov`'s. Vmappable
    over params/y0.
    """
    T = 2 * jnp.pi / params.omega_pi
    return largest_lyapunov(
        CeltField(get_contact_law(contact_law)),
        y0,
        params,
        t0=t0,
        segment=T,
        n_segments=periods,
        n_transient_segments=transient_periods,
        norm_weights=jnp.asarray(CELT_NORM_MASK, dtype=jnp.asarray(y0).dtype),
        project=celt_tangent_projection,
        solver=solver,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
        error_control=error_control,
        tangent=tangent,
    )
