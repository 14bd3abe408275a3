"""Bifurcation points of forced-ODE periodic orbits, differentiable in the other parameters.

A period-k orbit of dy/dt = f(t, y, args(lam, theta)) loses stability at a period doubling when
a Floquet multiplier passes -1 (a fold: +1). The point (y*, lam*) is a regular root of the
augmented system

    F(y, lam; theta) = [ P(y) - y ; g(y, lam) ] = 0,

with P the k-period stroboscopic map (`jaxcelt.orbits.shooting.stroboscopic_map`) and g a well-scaled
test function of the monodromy M = dP/dy: the bordered determinant of A = M + s I (s = +1 for
period doubling, -1 for a fold),

    [ A   b ] [ v ]   [ 0 ]
    [ c^T 0 ] [ g ] = [ 1 ],

which is zero exactly where A is singular and is smooth there (b, c: approximate left/right null
vectors of A, fixed during a solve; the located point does not depend on them). The root is
refined by Newton (`optimistix.root_find`, Jacobians by `jax.jacfwd`; M itself by forward-mode
differentiation of the discrete map, so F and its Jacobian are consistent).

The derivative with respect to theta comes from the implicit function theorem,

    dz/dtheta = -(dF/dz)^{-1} dF/dtheta,   z = (y, lam),

attached to the result by a `jax.custom_jvp` whose tangent is linear in the theta tangent with
dense Jacobians computed at the root, so that both ``jax.jacfwd`` and ``jax.grad`` (reverse mode,
by transposing that linear map) work, although the ODE solve itself is forward-mode only.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jax.flatten_util import ravel_pytree

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array, Scalar
from jaxcelt.orbits.shooting import Chart, sort_multipliers, stroboscopic_map

__all__ = [
    "BIFURCATION_POINT_KINDS",
    "BifurcationPoint",
    "locate_bifurcation",
    "locate_period_doubling",
    "locate_fold",
]

BIFURCATION_POINT_KINDS = {"period-doubling": 1.0, "fold": -1.0}
"""kind -> shift s of the test matrix M + s I"""


class BifurcationPoint(eqx.Module):
    """A located bifurcation point (`locate_bifurcation`); ``value`` and ``y`` carry theta-derivatives."""

    value: Scalar
    """lam* (differentiable in theta)"""
    y: Array
    """orbit state at the section time (differentiable in theta)"""
    residual: Scalar
    """max-norm of chart(P(y)) - chart(y) at the returned point (local coordinates)"""
    test: Scalar
    """bordered test function g at the returned point (0 at the bifurcation)"""
    multipliers: Array
    """Floquet multipliers (complex), by decreasing modulus; one is -1 (or +1 for a fold)"""
    status: Array
    """0 converged, 1 Newton did not converge, 2 non-finite map or monodromy"""
    newton_steps: Array

    @property
    def converged(self) -> Array:
        return self.status == 0


def _bordering(A: Array) -> tuple[Array, Array]:
    # right/left singular vectors of the smallest singular value: near-null vectors of A
    U, _, Vt = jnp.linalg.svd(A)
    return U[:, -1], Vt[-1]


def locate_bifurcation(
    vector_field: Callable[[Any, Array, Any], Array],
    y_guess: Array,
    lam_guess: Scalar,
    args_of: Callable[[Array, Any], Any],
    period_of: Callable[[Any], Array],
    theta: Any,
    *,
    kind: str = "period-doubling",
    k: int = 1,
    t0: float = 0.0,
    embed: Chart | None = None,
    chart: Chart | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-11,
    atol: float = 1e-12,
    max_steps: int = 100_000,
    newton_tol: float = 1e-10,
    newton_max_steps: int = 30,
) -> BifurcationPoint:
    """Refine a period-doubling or fold point of a period-k orbit; differentiable in ``theta``.

    Args:
        vector_field: ``f(t, y, args)``, T-periodic in t.
        y_guess, lam_guess: a nearby orbit state (at ``t0``) and parameter value, e.g. from
            `jaxcelt.orbits.branch.continue_periodic_orbit`.
        args_of: ``(lam, theta) -> args`` (traceable in both).
        period_of: ``args -> T`` (may depend on lam and theta).
        theta: pytree of float arrays, the parameters the point is differentiated in.
        kind: ``"period-doubling"`` (a multiplier at -1) or ``"fold"`` (+1).
        k, t0, solver, rtol, atol, max_steps: as in `jaxcelt.orbits.shooting.stroboscopic_map`.
        embed, chart: local coordinates around ``y_guess`` as in
            `jaxcelt.orbits.shooting.find_periodic_orbit` (default identity); the periodicity condition
            and the monodromy M are taken in them (a model with constraints or cyclic
            coordinates needs them: its trivial multipliers at 1 would make every point a fold).
        newton_tol: Newton tolerance on z = (y, lam) (optimistix rtol = atol).
        newton_max_steps: Newton iterations at most.

    Returns:
        `BifurcationPoint`. ``jax.grad``/``jax.jacfwd`` of ``.value`` or ``.y`` with respect to
        ``theta`` give the implicit-function-theorem derivative of the located point; guesses
        carry no derivative.
    """
    if kind not in BIFURCATION_POINT_KINDS:
        raise ValueError(f"kind must be one of {sorted(BIFURCATION_POINT_KINDS)}, got {kind!r}")
    shift = BIFURCATION_POINT_KINDS[kind]
    y_guess = jnp.asarray(y_guess, dtype=float)
    if y_guess.ndim != 1:
        raise ValueError(f"y_guess must be a 1-D state, got shape {y_guess.shape}")
    if embed is None:
        embed = lambda w, ref, a: w  # noqa: E731
    if chart is None:
        chart = lambda y, ref, a: y  # noqa: E731
    ref = jax.lax.stop_gradient(y_guess)
    theta_flat, unravel = ravel_pytree(theta)
    theta_flat = jnp.asarray(theta_flat, dtype=float)
    w_guess = chart(ref, ref, args_of(jnp.asarray(lam_guess, dtype=float), unravel(jax.lax.stop_gradient(theta_flat))))
    n = w_guess.shape[0]
    eye = jnp.eye(n, dtype=y_guess.dtype)

    def map_and_monodromy(w, lam, th):
        """(chart(P(embed(w))), its Jacobian in w, success), all in local coordinates."""
        args = args_of(lam, unravel(th))
        T = period_of(args)

        def P(ww):
            y1, ok, _ = stroboscopic_map(
                vector_field,
                embed(ww, ref, args),
                args,
                period=T,
                k=k,
                t0=t0,
                solver=solver,
                rtol=rtol,
                atol=atol,
                max_steps=max_steps,
            )
            w1 = chart(y1, ref, args)
            return w1, (w1, ok)

        M, (w1, ok) = jax.jacfwd(P, has_aux=True)(w)
        return w1, M, ok

    def F(z, th, b, c):
        y, lam = z[:n], z[n]
        y1, M, _ = map_and_monodromy(y, lam, th)
        border = jnp.block([[M + shift * eye, b[:, None]], [c[None, :], jnp.zeros((1, 1))]])
        rhs = jnp.zeros(n + 1).at[n].set(1.0)
        g = jnp.linalg.solve(border, rhs)[n]
        return jnp.concatenate([y1 - y, g[None]])

    def bordering_at(z, th):
        _, M, _ = map_and_monodromy(z[:n], z[n], th)
        return _bordering(M + shift * eye)

    @jax.custom_jvp
    def attach_ift(z, th):
        return z

    @attach_ift.defjvp
    def attach_ift_jvp(primals, tangents):
        z, th = primals
        _, dth = tangents
        b, c = jax.lax.stop_gradient(bordering_at(z, th))
        Jz = jax.jacfwd(F, argnums=0)(z, th, b, c)
        Jth = jax.jacfwd(F, argnums=1)(z, th, b, c)
        dz = -jnp.linalg.solve(Jz, Jth @ dth)
        return z, dz

    th0 = jax.lax.stop_gradient(theta_flat)
    z0 = jnp.concatenate([w_guess, jnp.asarray(lam_guess, dtype=float)[None]])
    z0 = jax.lax.stop_gradient(z0)
    b0, c0 = bordering_at(z0, th0)
    sol = optx.root_find(
        lambda z, a: F(z, *a),
        optx.Newton(rtol=newton_tol, atol=newton_tol),
        z0,
        args=(th0, b0, c0),
        max_steps=newton_max_steps,
        throw=False,
    )
    z_root = jax.lax.stop_gradient(sol.value)
    y1, M, ok = map_and_monodromy(z_root[:n], z_root[n], th0)
    b1, c1 = _bordering(M + shift * eye)
    g = F(z_root, th0, b1, c1)[n]
    res = jnp.max(jnp.abs(y1 - z_root[:n]))
    finite = ok & jnp.all(jnp.isfinite(y1)) & jnp.all(jnp.isfinite(M))
    mu = jnp.linalg.eigvals(jnp.where(finite, M, 0.0))
    good = (sol.result == optx.RESULTS.successful) & (res <= 10 * newton_tol) & (jnp.abs(g) <= 10 * newton_tol)
    status = jnp.where(~finite, 2, jnp.where(good, 0, 1)).astype(jnp.int32)
    z = attach_ift(z_root, theta_flat)
    return BifurcationPoint(
        value=z[n],
        y=embed(z[:n], ref, args_of(z[n], unravel(theta_flat))),
        residual=res,
        test=g,
        multipliers=sort_multipliers(mu),
        status=status,
        newton_steps=sol.stats["num_steps"],
    )


def locate_period_doubling(*a, **kw) -> BifurcationPoint:
    """`locate_bifurcation` with ``kind="period-doubling"`` (a Floquet multiplier at -1)."""
    return locate_bifurcation(*a, kind="period-doubling", **kw)


def locate_fold(*a, **kw) -> BifurcationPoint:
    """`locate_bifurcation` with ``kind="fold"`` (a Floquet multiplier at +1)."""
    return locate_bifurcation(*a, kind="fold", **kw)
