"""Periodic orbits of periodically forced ODEs and their Floquet multipliers (model-agnostic).

For dy/dt = f(t, y, args) with forcing period T, the stroboscopic map over k periods is

    P(y) = flow of f from t0 to t0 + k T, starting at y,

integrated by diffrax at tight tolerances with forward-mode differentiation
(`diffrax.ForwardMode`), so that Jacobians of P are exact derivatives of the discrete flow.
A period-k orbit is a root of G(z) = chart(P(embed(z))) - z, where ``embed``/``chart`` map
local coordinates z (of dimension d) to the state y and back. The identity chart is the
default; a model with constraints (an invariant manifold) or cyclic coordinates supplies one
that parameterises the manifold and drops the cyclic components, so that the Newton system is
square and the monodromy matrix dG/dz + I has only the physical multipliers.

The root is found by `optimistix.root_find` (Newton by default; its Jacobian is `jax.jacfwd`
of the discrete map, so Newton converges quadratically to the root of the map actually
computed). At the root the monodromy matrix comes from the variational equations integrated
with the orbit under one error control (`variational_map`), mapped to local coordinates by
the chain rule, M = d chart . Phi . d embed; the Floquet multipliers are its eigenvalues. Everything is pure and jittable; ``jax.vmap`` over guesses (or args) gives a
batch in which a failed lane is marked by ``status`` instead of raising.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array, Scalar

__all__ = [
    "ORBIT_STATUS",
    "PeriodicOrbit",
    "stroboscopic_map",
    "variational_map",
    "find_periodic_orbit",
    "sort_multipliers",
]

ORBIT_STATUS = {0: "converged", 1: "not converged", 2: "ODE solver failed"}
"""``PeriodicOrbit.status`` codes."""

Chart = Callable[[Array, Array, Any], Array]


def _forward_mode_solver(solver: diffrax.AbstractSolver) -> diffrax.AbstractSolver:
    # diffrax.ForwardMode needs Runge-Kutta stages in a plain lax scan (not the checkpointed one)
    if getattr(solver, "scan_kind", "lax") is None:
        solver = eqx.tree_at(lambda s: s.scan_kind, solver, "lax", is_leaf=lambda x: x is None)
    return solver


def stroboscopic_map(
    vector_field: Callable[[Any, Array, Any], Array],
    y0: Array,
    args: Any,
    *,
    period: Scalar,
    k: int = 1,
    t0: Scalar = 0.0,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-11,
    atol: float = 1e-12,
    max_steps: int = 100_000,
) -> tuple[Array, Array, Array]:
    """(y(t0 + k T), success, number of steps) of dy/dt = f(t, y, args) from y(t0) = y0.

    Forward-mode differentiable (``jax.jvp``/``jax.jacfwd``); never raises on a failed solve
    (``success`` is False and the state is whatever diffrax returned, typically inf).
    """
    y0 = jnp.asarray(y0)
    solver = _forward_mode_solver(solver or diffrax.Dopri8())
    t0 = jnp.asarray(t0, y0.dtype)
    t1 = t0 + k * jnp.asarray(period, y0.dtype)
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(vector_field),
        solver,
        t0,
        t1,
        None,
        y0,
        args,
        saveat=diffrax.SaveAt(t1=True),
        stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol),
        max_steps=max_steps,
        adjoint=diffrax.ForwardMode(),
        throw=False,
    )
    return sol.ys[-1], sol.result == diffrax.RESULTS.successful, sol.stats["num_steps"]


def variational_map(
    vector_field: Callable[[Any, Array, Any], Array],
    y0: Array,
    args: Any,
    *,
    period: Scalar,
    k: int = 1,
    t0: Scalar = 0.0,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-11,
    atol: float = 1e-12,
    max_steps: int = 100_000,
) -> tuple[Array, Array, Array, Array]:
    """(y(t0 + k T), monodromy Phi (n, n), success, steps) from the variational equations.

    (y, Phi) is integrated as one ODE, d Phi/dt = J_f(t, y) Phi (J Phi by forward-mode
    differentiation of ``f``), Phi(t0) = I, with the step-size controller watching Phi too.
    This is the accurate monodromy: the derivative of the primal-only discrete flow (what
    `jax.jacfwd` of `stroboscopic_map` gives) can be far off where the primal error estimate
    does not see the tangent dynamics (e.g. at an equilibrium y = 0, where steps grow unbounded).
    """
    y0 = jnp.asarray(y0)
    n = y0.shape[0]
    solver = solver or diffrax.Dopri8()
    t0 = jnp.asarray(t0, y0.dtype)
    t1 = t0 + k * jnp.asarray(period, y0.dtype)

    def field(t, state, a):
        y, Phi = state
        f = lambda yy: vector_field(t, yy, a)  # noqa: E731
        fy, JPhi = jax.vmap(lambda col: jax.jvp(f, (y,), (col,)), in_axes=1, out_axes=(None, 1))(Phi)
        return fy, JPhi

    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(field),
        solver,
        t0,
        t1,
        None,
        (y0, jnp.eye(n, dtype=y0.dtype)),
        args,
        saveat=diffrax.SaveAt(t1=True),
        stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol),
        max_steps=max_steps,
        throw=False,
    )
    y1, Phi = (x[-1] for x in sol.ys)
    return y1, Phi, sol.result == diffrax.RESULTS.successful, sol.stats["num_steps"]


def sort_multipliers(mu: Array) -> Array:
    """Multipliers sorted by decreasing modulus (ties: by decreasing imaginary part)."""
    order = jnp.lexsort((-jnp.imag(mu), -jnp.abs(mu)))
    return mu[order]


class PeriodicOrbit(eqx.Module):
    """A period-k orbit of a forced ODE (`find_periodic_orbit`); leading batch axes under vmap."""

    z: Array
    """local coordinates of the section point (d,)"""
    y: Array
    """state at the section time t0 (embed(z))"""
    residual: Scalar
    """max-norm of chart(P(embed(z))) - z at the returned z"""
    monodromy: Array
    """d(chart o P o embed)/dz at z, (d, d), from the variational equations (`variational_map`)"""
    monodromy_full: Array
    """dP/dy at y, (n, n): the state-space monodromy, including directions the chart leaves out"""
    multipliers: Array
    """Floquet multipliers (complex, (d,)), sorted by decreasing modulus"""
    status: Array
    """`ORBIT_STATUS` code: 0 converged, 1 Newton did not converge, 2 ODE solver failed"""
    newton_steps: Array
    """Newton iterations taken"""
    ode_steps: Array
    """solver steps of the variational solve (one pass over k periods)"""

    @property
    def converged(self) -> Array:
        return self.status == 0

    @property
    def stable(self) -> Array:
        """All multipliers strictly inside the unit circle."""
        return jnp.all(jnp.abs(self.multipliers) < 1.0, axis=-1)


def find_periodic_orbit(
    vector_field: Callable[[Any, Array, Any], Array],
    y_guess: Array,
    args: Any,
    *,
    period: Scalar,
    k: int = 1,
    t0: Scalar = 0.0,
    embed: Chart | None = None,
    chart: Chart | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-11,
    atol: float = 1e-12,
    max_steps: int = 100_000,
    newton_tol: float = 1e-9,
    newton_max_steps: int = 30,
    root_finder: optx.AbstractRootFinder | None = None,
) -> PeriodicOrbit:
    """Period-k orbit of dy/dt = f(t, y, args) near ``y_guess``, with its Floquet multipliers.

    Args:
        vector_field: ``f(t, y, args)``, T-periodic in t.
        y_guess: a state near the orbit at the section time ``t0``.
        args: passed to ``f`` (may be traced / batched).
        period: forcing period T (may be traced, e.g. 2 pi / omega from ``args``).
        k: periods per return (k = 2 for a period-doubled orbit).
        t0: section time (phase of the forcing).
        embed, chart: ``embed(z, y_ref, args) -> y`` and ``chart(y, y_ref, args) -> z``, a local
            parameterisation of the state space (or of an invariant manifold in it) around
            ``y_ref = y_guess``; ``chart(embed(z)) == z`` is required. Default: identity.
        solver, rtol, atol, max_steps: diffrax settings of one map evaluation (default Dopri8).
        newton_tol: convergence tolerance in z (max-norm of the Newton step and the residual).
        newton_max_steps: Newton iterations at most.
        root_finder: an optimistix root finder (default ``optx.Newton(newton_tol, newton_tol)``).

    Returns:
        `PeriodicOrbit`. ``status`` is 0 only if the root finder succeeded, the residual is
        at most ``newton_tol`` (x10 slack) and the final solve succeeded; a solver failure
        anywhere gives 2, otherwise 1.
    """
    y_guess = jnp.asarray(y_guess)
    if embed is None:
        embed = lambda z, ref, a: z  # noqa: E731
    if chart is None:
        chart = lambda y, ref, a: y  # noqa: E731
    z0 = chart(y_guess, y_guess, args)

    def G(z):
        # a non-finite start integrates over zero time (a failed lane costs nothing under vmap)
        finite = jnp.all(jnp.isfinite(z))
        y1, ok, steps = stroboscopic_map(
            vector_field,
            embed(z, y_guess, args),
            args,
            period=jnp.where(finite, period, 0.0),
            k=k,
            t0=t0,
            solver=solver,
            rtol=rtol,
            atol=atol,
            max_steps=max_steps,
        )
        return chart(y1, y_guess, args), (ok, steps)

    def residual_fn(z, _):
        return G(z)[0] - z

    finder = root_finder or optx.Newton(rtol=newton_tol, atol=newton_tol)
    sol = optx.root_find(residual_fn, finder, z0, max_steps=newton_max_steps, throw=False)
    z = sol.value
    y = embed(z, y_guess, args)
    y1, Phi, ok, steps = variational_map(
        vector_field,
        y,
        args,
        period=jnp.where(jnp.all(jnp.isfinite(y)), period, 0.0),
        k=k,
        t0=t0,
        solver=solver,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
    )
    Pz = chart(y1, y_guess, args)
    # chain rule: M = d chart(y1) . Phi . d embed(z)
    E = jax.jacfwd(lambda zz: embed(zz, y_guess, args))(z)
    C = jax.jacfwd(lambda yy: chart(yy, y_guess, args))(y1)
    M = C @ Phi @ E
    res = jnp.max(jnp.abs(Pz - z))
    finite = jnp.all(jnp.isfinite(Pz)) & jnp.all(jnp.isfinite(M))
    mu = jnp.where(finite, 1.0, jnp.nan) * jnp.linalg.eigvals(jnp.where(finite, M, 0.0))
    good = (sol.result == optx.RESULTS.successful) & (res <= 10 * newton_tol)
    status = jnp.where(~(ok & finite), 2, jnp.where(good, 0, 1)).astype(jnp.int32)
    return PeriodicOrbit(
        z=z,
        y=y,
        residual=res,
        monodromy=M,
        monodromy_full=Phi,
        multipliers=sort_multipliers(mu),
        status=status,
        newton_steps=sol.stats["num_steps"],
        ode_steps=steps,
    )
