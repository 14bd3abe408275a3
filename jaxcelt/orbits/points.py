"""Bifurcation points of periodic orbits: detected on a branch, located, differentiated.

Detection. Between consecutive points of a branch (`jaxcelt.orbits.branch`) the Floquet multipliers
are watched for crossings of the unit circle, with test functions that change sign there
(`test_functions`):

* period doubling: a real multiplier through -1, tf = Re prod(1 + mu);
* fold (saddle-node / turning point): a real multiplier through +1, tf = Re prod(mu - 1); on a
  pseudo-arclength branch, the sign change of the parameter component of the tangent;
* Neimark-Sacker: a complex pair through |mu| = 1: the number of complex multipliers outside
  the unit circle changes (located on max |mu| - 1 of the complex ones, `ns_function`).

Location on the branch (`bisect_crossing`): bisection in the parameter on the test function,
every bisection point a Newton solve at fixed parameter (`detect_on_natural_branch`,
`detect_on_arclength_branch`).

Refinement and differentiation (`locate_bifurcation`):

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
The bordered test function (`bordered_test_function`, with `bordering_vectors`) is the building block
of minimally augmented systems: continuing these points in two parameters reuses it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple, Unpack

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jax.flatten_util import ravel_pytree

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array, Scalar
from jaxcelt.orbits.options import ShootingKeywords, ShootingOptions, resolve_options
from jaxcelt.orbits.shooting import Chart, identity_charts, sort_multipliers, stroboscopic_map

__all__ = [
    "BIFURCATION_KINDS",
    "BIFURCATION_POINT_KINDS",
    "Bifurcation",
    "BifurcationPoint",
    "test_functions",
    "ns_function",
    "bisect_crossing",
    "detect_on_natural_branch",
    "detect_on_arclength_branch",
    "bordering_vectors",
    "bordered_test_function",
    "locate_bifurcation",
    "locate_period_doubling",
    "locate_fold",
]

BIFURCATION_KINDS = ("period-doubling", "fold", "Neimark-Sacker")
"""The crossings detected on a branch, in the order they are checked on a natural branch."""

BIFURCATION_POINT_KINDS = {"period-doubling": 1.0, "fold": -1.0}
"""kind -> shift s of the test matrix M + s I (`locate_bifurcation`)"""

_IMAG_TOL = 1e-8
_DEFAULTS = ShootingOptions(newton_tol=1e-10)

# ---------------------------------------------------------------------------------------------------------------------
# detection and location on a branch (host side, numpy)


class Bifurcation(NamedTuple):
    """A crossing detected and located on a branch."""

    kind: str
    """one of `BIFURCATION_KINDS`"""
    value: float
    """located parameter value"""
    bracket: tuple[float, float]
    """the continuation points it was detected between"""
    multipliers: np.ndarray
    """multipliers at the located value"""
    y: np.ndarray
    """orbit state at the located value"""


def test_functions(mu: np.ndarray) -> dict[str, float]:
    """Test functions of `BIFURCATION_KINDS` at multipliers ``mu`` (Neimark-Sacker: a count, not a sign)."""
    cplx = np.abs(mu.imag) > _IMAG_TOL
    return {
        "period-doubling": float(np.prod(1 + mu).real),
        "fold": float(np.prod(mu - 1).real),
        "Neimark-Sacker": float(np.sum(cplx & (np.abs(mu) > 1))),
    }


test_functions.__test__ = False  # not a pytest test


def ns_function(mu: np.ndarray) -> float:
    """max |mu| - 1 over the complex multipliers (its zero is a Neimark-Sacker point)."""
    cplx = np.abs(mu.imag) > _IMAG_TOL
    return float(np.max(np.abs(mu[cplx])) - 1.0) if np.any(cplx) else -1.0


def _pd_function(mu: np.ndarray) -> float:
    return test_functions(mu)["period-doubling"]


_BISECTED = {"period-doubling": _pd_function, "Neimark-Sacker": ns_function}
"""crossings of an arclength branch located by bisection in lam (folds: interpolation of the tangent's
lam-component, since at a fold no orbit exists past it at fixed lam)"""

Solve = Callable[[Array, Array], Any]
"""``solve(lam, y_guess) -> orbit`` with ``.status``, ``.y``, ``.multipliers`` (a Newton solve at fixed lam)"""


def bisect_crossing(
    solve: Solve,
    lo: float,
    hi: float,
    y_lo: np.ndarray,
    y_hi: np.ndarray,
    same_side: Callable[[np.ndarray], bool],
    bisections: int,
) -> tuple[float, np.ndarray, np.ndarray]:
    """(value, multipliers, state) of a crossing in [lo, hi], by ``bisections`` halvings.

    Each midpoint is solved from the mean of the bracketing states; ``same_side(multipliers)`` says whether it
    lies on ``lo``'s side. A failed solve ends the bisection. The result is solved at the bracket's midpoint.
    """
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        orb = solve(jnp.asarray(mid), jnp.asarray(0.5 * (y_lo + y_hi)))
        if int(orb.status) != 0:
            break
        if same_side(np.asarray(orb.multipliers)):
            lo, y_lo = mid, np.asarray(orb.y)
        else:
            hi, y_hi = mid, np.asarray(orb.y)
    val = 0.5 * (lo + hi)
    orb = solve(jnp.asarray(val), jnp.asarray(0.5 * (y_lo + y_hi)))
    return val, np.asarray(orb.multipliers), np.asarray(orb.y)


def detect_on_natural_branch(
    solve: Solve, lams: list[float], ys: list[np.ndarray], mus: list[np.ndarray], *, bisections: int
) -> list[Bifurcation]:
    """Crossings between consecutive points of a natural-parameter branch, each bisected on its test function
    (``bisections`` = 0: solved at the middle of its bracket)."""
    bifs: list[Bifurcation] = []
    for i in range(1, len(lams)):
        ta, tb = test_functions(mus[i - 1]), test_functions(mus[i])
        for kind in BIFURCATION_KINDS:
            if kind == "Neimark-Sacker":
                crossed = ta[kind] != tb[kind]
                same = lambda mu, kind=kind, s=ta[kind]: test_functions(mu)[kind] == s  # noqa: E731
            else:
                crossed = np.sign(ta[kind]) != np.sign(tb[kind])
                same = lambda mu, kind=kind, s=ta[kind]: np.sign(test_functions(mu)[kind]) == np.sign(s)  # noqa: E731
            if crossed:
                val, mu, y = bisect_crossing(solve, lams[i - 1], lams[i], ys[i - 1], ys[i], same, bisections)
                bifs.append(Bifurcation(kind, val, (lams[i - 1], lams[i]), mu, y))
    return bifs


def detect_on_arclength_branch(
    solve: Solve, lam: np.ndarray, y: np.ndarray, tangents: np.ndarray, mus: np.ndarray, *, bisections: int
) -> list[Bifurcation]:
    """Crossings between consecutive points of a pseudo-arclength branch.

    Folds: where the lam-component of the tangent changes sign, interpolated linearly in it (accurate to about
    the local step squared). Period doublings and Neimark-Sacker points: interpolated linearly in their test
    function, then (``bisections`` > 0) bisected in lam on it.
    """
    bifs: list[Bifurcation] = []
    for i in range(1, len(y)):
        ta, tb = test_functions(mus[i - 1]), test_functions(mus[i])
        checks = {
            "fold": (tangents[i - 1, -1], tangents[i, -1]),
            "period-doubling": (ta["period-doubling"], tb["period-doubling"]),
        }
        if ta["Neimark-Sacker"] != tb["Neimark-Sacker"]:
            checks["Neimark-Sacker"] = (ns_function(mus[i - 1]), ns_function(mus[i]))
        for kind, (a, b) in checks.items():
            if np.sign(a) != np.sign(b) or kind == "Neimark-Sacker":
                w = float(np.clip(a / (a - b), 0.0, 1.0)) if a != b else 0.5
                val = (1 - w) * lam[i - 1] + w * lam[i]
                mu = (1 - w) * mus[i - 1] + w * mus[i]
                yy = (1 - w) * y[i - 1] + w * y[i]
                if kind in _BISECTED and bisections:
                    tf_of, s = _BISECTED[kind], np.sign(a)
                    same = lambda m, tf_of=tf_of, s=s: np.sign(tf_of(m)) == s  # noqa: E731
                    val, mu, yy = bisect_crossing(solve, lam[i - 1], lam[i], y[i - 1], y[i], same, bisections)
                bifs.append(Bifurcation(kind, float(val), (lam[i - 1], lam[i]), mu, yy))
    return bifs


# ---------------------------------------------------------------------------------------------------------------------
# refinement by Newton on the augmented system, differentiable by the implicit function theorem


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


def bordering_vectors(A: Array) -> tuple[Array, Array]:
    """(b, c): left and right singular vectors of the smallest singular value of A, its near-null vectors."""
    U, _, Vt = jnp.linalg.svd(A)
    return U[:, -1], Vt[-1]


def bordered_test_function(A: Array, b: Array, c: Array) -> Scalar:
    """g of the bordered system [[A, b], [c^T, 0]] [v; g] = [0; 1]: zero exactly where A is singular, smooth there."""
    n = A.shape[0]
    border = jnp.block([[A, b[:, None]], [c[None, :], jnp.zeros((1, 1))]])
    rhs = jnp.zeros(n + 1).at[n].set(1.0)
    return jnp.linalg.solve(border, rhs)[n]


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
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> BifurcationPoint:
    """Refine a period-doubling or fold point of a period-k orbit; differentiable in ``theta``.

    Args:
        vector_field: ``f(t, y, args)``, T-periodic in t.
        y_guess, lam_guess: a nearby orbit state (at ``t0``) and parameter value, e.g. a `Bifurcation`
            of `jaxcelt.orbits.branch.continue_natural` or `jaxcelt.orbits.branch.continue_arclength`.
        args_of: ``(lam, theta) -> args`` (traceable in both).
        period_of: ``args -> T`` (may depend on lam and theta).
        theta: pytree of float arrays, the parameters the point is differentiated in.
        kind: ``"period-doubling"`` (a multiplier at -1) or ``"fold"`` (+1).
        k, t0: as in `jaxcelt.orbits.shooting.stroboscopic_map`.
        embed, chart: local coordinates around ``y_guess`` as in
            `jaxcelt.orbits.shooting.find_periodic_orbit` (default identity); the periodicity condition
            and the monodromy M are taken in them (a model with constraints or cyclic
            coordinates needs them: its trivial multipliers at 1 would make every point a fold).
        options: `jaxcelt.orbits.options.ShootingOptions` (default: newton_tol 1e-10, the others
            `ShootingOptions`' defaults); ``newton_tol`` is the tolerance on z = (y, lam).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``;
            each one given overrides it.

    Returns:
        `BifurcationPoint`. ``jax.grad``/``jax.jacfwd`` of ``.value`` or ``.y`` with respect to
        ``theta`` give the implicit-function-theorem derivative of the located point; guesses
        carry no derivative.
    """
    if kind not in BIFURCATION_POINT_KINDS:
        raise ValueError(f"kind must be one of {sorted(BIFURCATION_POINT_KINDS)}, got {kind!r}")
    opts = resolve_options(options, _DEFAULTS, caller="locate_bifurcation", **settings)
    newton_tol = opts.newton_tol
    shift = BIFURCATION_POINT_KINDS[kind]
    y_guess = jnp.asarray(y_guess, dtype=float)
    if y_guess.ndim != 1:
        raise ValueError(f"y_guess must be a 1-D state, got shape {y_guess.shape}")
    embed, chart = identity_charts(embed, chart)
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
            y1, ok, _ = stroboscopic_map(vector_field, embed(ww, ref, args), args, period=T, k=k, t0=t0, options=opts)
            w1 = chart(y1, ref, args)
            return w1, (w1, ok)

        M, (w1, ok) = jax.jacfwd(P, has_aux=True)(w)
        return w1, M, ok

    def F(z, th, b, c):
        y, lam = z[:n], z[n]
        y1, M, _ = map_and_monodromy(y, lam, th)
        g = bordered_test_function(M + shift * eye, b, c)
        return jnp.concatenate([y1 - y, g[None]])

    def bordering_at(z, th):
        _, M, _ = map_and_monodromy(z[:n], z[n], th)
        return bordering_vectors(M + shift * eye)

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
        max_steps=opts.newton_max_steps,
        throw=False,
    )
    z_root = jax.lax.stop_gradient(sol.value)
    y1, M, ok = map_and_monodromy(z_root[:n], z_root[n], th0)
    b1, c1 = bordering_vectors(M + shift * eye)
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
