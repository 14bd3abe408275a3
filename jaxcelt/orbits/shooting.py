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
the chain rule, M = d chart . Phi . d embed (`chart_monodromy`); the Floquet multipliers are its
eigenvalues. Everything is pure and jittable; ``jax.vmap`` over guesses (or args) gives a batch in
which a failed lane is marked by ``status`` instead of raising.

`OrbitFamily` is the same problem with one parameter lam free, u = (z, lam): its residual, the
re-centring of the chart and the multipliers at a point are what `jaxcelt.orbits.branch` continues.
Solver and Newton settings are one `jaxcelt.orbits.options.ShootingOptions` (``options=``, or single
keywords).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple, Unpack

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx

from jaxcelt import _config  # noqa: F401
from jaxcelt._diffrax_adapter import diffeqsolve
from jaxcelt._types import Array, Scalar
from jaxcelt.orbits.options import ShootingKeywords, ShootingOptions, resolve_options

__all__ = [
    "ORBIT_STATUS",
    "PeriodicOrbit",
    "stroboscopic_map",
    "variational_map",
    "find_periodic_orbit",
    "OrbitFamily",
    "sort_multipliers",
    "identity_charts",
    "chart_monodromy",
    "Chart",
]

ORBIT_STATUS = {0: "converged", 1: "not converged", 2: "ODE solver failed"}
"""``PeriodicOrbit.status`` codes."""

Chart = Callable[[Array, Array, Any], Array]
"""A local parameterisation: ``embed(z, y_ref, args) -> y`` or its inverse ``chart(y, y_ref, args) -> z``."""

_DEFAULTS = ShootingOptions()


def identity_charts(embed: Chart | None, chart: Chart | None) -> tuple[Chart, Chart]:
    """``(embed, chart)`` with the identity ``(z, y_ref, args) -> z`` in place of each one that is None."""
    if embed is None:
        embed = lambda z, ref, a: z  # noqa: E731
    if chart is None:
        chart = lambda y, ref, a: y  # noqa: E731
    return embed, chart


def chart_monodromy(embed: Chart, chart: Chart, z: Array, y1: Array, y_ref: Array, args: Any, Phi: Array) -> Array:
    """The monodromy in local coordinates by the chain rule, M = d chart(y1) . Phi . d embed(z)."""
    E = jax.jacfwd(lambda zz: embed(zz, y_ref, args))(z)
    C = jax.jacfwd(lambda yy: chart(yy, y_ref, args))(y1)
    return C @ Phi @ E


def _forward_mode_solver(solver: diffrax.AbstractSolver) -> diffrax.AbstractSolver:
    # diffrax.ForwardMode needs Runge-Kutta stages in a plain lax scan (not the checkpointed one)
    if getattr(solver, "scan_kind", "lax") is None:
        solver = eqx.tree_at(lambda s: s.scan_kind, solver, "lax", is_leaf=lambda x: x is None)
    return solver


def _flow(field, y0, args, *, period, k, t0, options: ShootingOptions, forward_mode: bool):
    """diffrax solution of ``field`` from t0 to t0 + k T (t1 saved; never raises)."""
    dtype = jax.tree_util.tree_leaves(y0)[0].dtype
    solver = options.solver or diffrax.Dopri8()
    t0 = jnp.asarray(t0, dtype)
    t1 = t0 + k * jnp.asarray(period, dtype)
    return diffeqsolve(
        diffrax.ODETerm(field),
        _forward_mode_solver(solver) if forward_mode else solver,
        t0,
        t1,
        None,
        y0,
        args,
        saveat=diffrax.SaveAt(t1=True),
        stepsize_controller=diffrax.PIDController(rtol=options.rtol, atol=options.atol),
        max_steps=options.max_steps,
        adjoint=diffrax.ForwardMode() if forward_mode else diffrax.RecursiveCheckpointAdjoint(),
        throw=False,
    )


def stroboscopic_map(
    vector_field: Callable[[Any, Array, Any], Array],
    y0: Array,
    args: Any,
    *,
    period: Scalar,
    k: int = 1,
    t0: Scalar = 0.0,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> tuple[Array, Array, Array]:
    """(y(t0 + k T), success, number of steps) of dy/dt = f(t, y, args) from y(t0) = y0.

    Forward-mode differentiable (``jax.jvp``/``jax.jacfwd``); never raises on a failed solve
    (``success`` is False and the state is whatever diffrax returned, typically inf).
    ``options`` (`ShootingOptions`; its Newton fields are unused) or the keywords ``solver``, ``rtol``
    (default 1e-11), ``atol`` (1e-12), ``max_steps`` (100 000) set the solve (`resolve_options`).
    """
    opts = resolve_options(options, _DEFAULTS, caller="stroboscopic_map", **settings)
    sol = _flow(vector_field, jnp.asarray(y0), args, period=period, k=k, t0=t0, options=opts, forward_mode=True)
    return sol.ys[-1], sol.result == diffrax.RESULTS.successful, sol.stats["num_steps"]


def variational_map(
    vector_field: Callable[[Any, Array, Any], Array],
    y0: Array,
    args: Any,
    *,
    period: Scalar,
    k: int = 1,
    t0: Scalar = 0.0,
    forward_mode: bool = False,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> tuple[Array, Array, Array, Array]:
    """(y(t0 + k T), monodromy Phi (n, n), success, steps) from the variational equations.

    (y, Phi) is integrated as one ODE, d Phi/dt = J_f(t, y) Phi (J Phi by forward-mode
    differentiation of ``f``), Phi(t0) = I, with the step-size controller watching Phi too.
    This is the accurate monodromy: the derivative of the primal-only discrete flow (what
    `jax.jacfwd` of `stroboscopic_map` gives) can be far off where the primal error estimate
    does not see the tangent dynamics (e.g. at an equilibrium y = 0, where steps grow unbounded).
    Options as in `stroboscopic_map`. ``forward_mode=True`` makes the solve forward-mode differentiable
    (``jax.jvp``/``jax.jacfwd``, e.g. derivatives of the monodromy in the state and parameters, as
    `jaxcelt.orbits.curves` needs); the default is reverse-mode differentiable instead.
    """
    opts = resolve_options(options, _DEFAULTS, caller="variational_map", **settings)
    y0 = jnp.asarray(y0)

    def field(t, state, a):
        y, Phi = state
        f = lambda yy: vector_field(t, yy, a)  # noqa: E731
        fy, JPhi = jax.vmap(lambda col: jax.jvp(f, (y,), (col,)), in_axes=1, out_axes=(None, 1))(Phi)
        return fy, JPhi

    state0 = (y0, jnp.eye(y0.shape[0], dtype=y0.dtype))
    sol = _flow(field, state0, args, period=period, k=k, t0=t0, options=opts, forward_mode=forward_mode)
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
    root_finder: optx.AbstractRootFinder | None = None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
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
        options: `ShootingOptions` (default: its own defaults, Dopri8, rtol 1e-11, atol 1e-12,
            max_steps 100 000, newton_tol 1e-9, newton_max_steps 30).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``;
            each one given overrides it (`resolve_options`).
        root_finder: an optimistix root finder (default ``optx.Newton(newton_tol, newton_tol)``).

    Returns:
        `PeriodicOrbit`. ``status`` is 0 only if the root finder succeeded, the residual is
        at most ``newton_tol`` (x10 slack) and the final solve succeeded; a solver failure
        anywhere gives 2, otherwise 1.
    """
    opts = resolve_options(options, _DEFAULTS, caller="find_periodic_orbit", **settings)
    y_guess = jnp.asarray(y_guess)
    embed, chart = identity_charts(embed, chart)
    z0 = chart(y_guess, y_guess, args)

    def residual_fn(z, _):
        # a non-finite start integrates over zero time (a failed lane costs nothing under vmap)
        finite = jnp.all(jnp.isfinite(z))
        T = jnp.where(finite, period, 0.0)
        y1, _, _ = stroboscopic_map(vector_field, embed(z, y_guess, args), args, period=T, k=k, t0=t0, options=opts)
        return chart(y1, y_guess, args) - z

    finder = root_finder or optx.Newton(rtol=opts.newton_tol, atol=opts.newton_tol)
    sol = optx.root_find(residual_fn, finder, z0, max_steps=opts.newton_max_steps, throw=False)
    z = sol.value
    y = embed(z, y_guess, args)
    T = jnp.where(jnp.all(jnp.isfinite(y)), period, 0.0)
    y1, Phi, ok, steps = variational_map(vector_field, y, args, period=T, k=k, t0=t0, options=opts)
    Pz = chart(y1, y_guess, args)
    M = chart_monodromy(embed, chart, z, y1, y_guess, args, Phi)
    res = jnp.max(jnp.abs(Pz - z))
    finite = jnp.all(jnp.isfinite(Pz)) & jnp.all(jnp.isfinite(M))
    mu = jnp.where(finite, 1.0, jnp.nan) * jnp.linalg.eigvals(jnp.where(finite, M, 0.0))
    good = (sol.result == optx.RESULTS.successful) & (res <= 10 * opts.newton_tol)
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


class OrbitFamily(NamedTuple):
    """Period-k orbits of dy/dt = f(t, y, args_of(lam)) as one parameter lam varies: what a branch continues.

    The unknowns of a branch point are u = (z, lam), z the local coordinates (``chart``) around a reference
    state ``y_ref`` (re-centred as the branch travels). `jaxcelt.orbits.branch` continues a family through its
    methods; they are pure and jittable.
    """

    vector_field: Callable[[Any, Array, Any], Array]
    args_of: Callable[[Array], Any]
    """``lam -> args`` (traceable)"""
    period_of: Callable[[Any], Array]
    """``args -> T``, the forcing period"""
    k: int = 1
    t0: Scalar = 0.0
    embed: Chart | None = None
    chart: Chart | None = None
    options: ShootingOptions = _DEFAULTS

    def residual(self, u: Array, y_ref: Array) -> tuple[Array, Array]:
        """(chart(P(embed(z)); lam) - z, success of the solve) at u = (z, lam)."""
        embed, chart = identity_charts(self.embed, self.chart)
        z, lam = u[:-1], u[-1]
        args = self.args_of(lam)
        y1, ok, _ = stroboscopic_map(
            self.vector_field, embed(z, y_ref, args), args, period=self.period_of(args), k=self.k, t0=self.t0,
            options=self.options,
        )  # fmt: skip
        return chart(y1, y_ref, args) - z, ok

    def recentre(self, u: Array, t: Array, y_ref: Array) -> tuple[Array, Array, Array]:
        """(u, t) in the chart around the state of u (the new reference), and that state; t stays a unit vector."""
        embed, chart = identity_charts(self.embed, self.chart)
        y = embed(u[:-1], y_ref, self.args_of(u[-1]))

        def to_new(v):
            a = self.args_of(v[-1])
            return jnp.concatenate([chart(embed(v[:-1], y_ref, a), y, a), v[-1:]])

        u_new, t_new = jax.jvp(to_new, (u,), (t,))
        return u_new, t_new / jnp.linalg.norm(t_new), y

    def multipliers(self, u: Array, y_ref: Array) -> Array:
        """Floquet multipliers at u in chart coordinates (`variational_map`), by decreasing modulus."""
        embed, chart = identity_charts(self.embed, self.chart)
        z, args = u[:-1], self.args_of(u[-1])
        y = embed(z, y_ref, args)
        y1, Phi, _, _ = variational_map(
            self.vector_field, y, args, period=self.period_of(args), k=self.k, t0=self.t0, options=self.options
        )
        return sort_multipliers(jnp.linalg.eigvals(chart_monodromy(embed, chart, z, y1, y_ref, args, Phi)))

    def solve(self, lam: Array, y_guess: Array, options: ShootingOptions | None = None) -> PeriodicOrbit:
        """`find_periodic_orbit` at fixed lam from ``y_guess`` (``options``: default the family's)."""
        args = self.args_of(lam)
        return find_periodic_orbit(
            self.vector_field, y_guess, args, period=self.period_of(args), k=self.k, t0=self.t0, embed=self.embed,
            chart=self.chart, options=options or self.options,
        )  # fmt: skip
