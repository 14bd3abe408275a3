"""Natural-parameter continuation of periodic orbits of forced ODEs, with bifurcation detection.

A branch of period-k orbits is followed in one scalar parameter lam over a given grid of
values: each point is a Newton solve (`jaxcelt.periodic.find_periodic_orbit`, one compiled
program for the whole branch) from a secant prediction through the two previous points. The
branch stops at the first point that does not converge (typically a fold, where natural
continuation cannot pass).

Between consecutive converged points the Floquet multipliers are watched for crossings of the
unit circle, with test functions that change sign there:

* period doubling: a real multiplier through -1, tf = Re prod(1 + mu);
* fold (saddle-node / branch point): a real multiplier through +1, tf = Re prod(mu - 1);
* Neimark-Sacker: a complex pair through |mu| = 1: the number of complex multipliers outside
  the unit circle changes.

Each detected crossing is located by bisection in lam on its test function (NS: on
|mu| - 1 of the crossing pair), every bisection point being again a Newton solve.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from ._types import Array
from .periodic import (
    PeriodicOrbit,
    find_periodic_orbit,
    sort_multipliers,
    stroboscopic_map,
    variational_map,
)

__all__ = [
    "ArclengthBranch",
    "Bifurcation",
    "OrbitBranch",
    "continue_periodic_orbit",
    "continue_pseudo_arclength",
    "switch_at_period_doubling",
    "BIFURCATION_KINDS",
]

BIFURCATION_KINDS = ("period-doubling", "fold", "Neimark-Sacker")
_IMAG_TOL = 1e-8


class Bifurcation(NamedTuple):
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


class OrbitBranch(NamedTuple):
    values: np.ndarray
    """parameter values of the converged points (m,)"""
    y: np.ndarray
    """orbit states (m, n)"""
    multipliers: np.ndarray
    """Floquet multipliers (m, d), by decreasing modulus"""
    stable: np.ndarray
    """(m,) bool"""
    bifurcations: list[Bifurcation]
    """detected and located crossings, in branch order"""
    stopped_at: float | None
    """first grid value where the Newton solve failed (None if the whole grid was covered)"""


def _test_functions(mu: np.ndarray) -> dict[str, float]:
    cplx = np.abs(mu.imag) > _IMAG_TOL
    return {
        "period-doubling": float(np.prod(1 + mu).real),
        "fold": float(np.prod(mu - 1).real),
        "Neimark-Sacker": float(np.sum(cplx & (np.abs(mu) > 1))),
    }


def continue_periodic_orbit(
    vector_field: Callable[[Any, Array, Any], Array],
    y_guess: Array,
    args_of: Callable[[Array], Any],
    period_of: Callable[[Any], Array],
    values: Array,
    *,
    locate: bool = True,
    bisections: int = 40,
    **find_kw,
) -> OrbitBranch:
    """Follow the period-k orbit through ``y_guess`` (at ``values[0]``) along ``values``.

    Args:
        vector_field: ``f(t, y, args)``.
        y_guess: state near the orbit at the first value.
        args_of: ``lam -> args`` (traceable, e.g. ``lambda lam: p.at[3].set(lam)``).
        period_of: ``args -> T`` (the forcing period; may depend on lam).
        values: increasing or decreasing grid of lam (host array).
        locate: bisect each detected crossing (``bisections`` halvings of its bracket).
        **find_kw: passed to `find_periodic_orbit` (k, t0, embed, chart, solver, tolerances).

    Returns:
        `OrbitBranch`; host (numpy) arrays, one compiled Newton program for all points.
    """
    values = np.asarray(values, dtype=float)

    @jax.jit
    def solve(lam, y0):
        args = args_of(lam)
        return find_periodic_orbit(vector_field, y0, args, period=period_of(args), **find_kw)

    def run(lam, y0) -> PeriodicOrbit:
        return jax.tree_util.tree_map(np.asarray, solve(jnp.asarray(lam), jnp.asarray(y0)))

    lams, ys, mus, stable = [], [], [], []
    stopped = None
    y = np.asarray(y_guess, dtype=float)
    for lam in values:
        if len(ys) >= 2:  # secant predictor
            y = ys[-1] + (ys[-1] - ys[-2]) * (lam - lams[-1]) / (lams[-1] - lams[-2])
        orb = run(lam, y)
        if int(orb.status) != 0:
            stopped = float(lam)
            break
        lams.append(float(lam))
        ys.append(orb.y)
        mus.append(orb.multipliers)
        stable.append(bool(orb.stable))
        y = orb.y

    bifs: list[Bifurcation] = []
    for i in range(1, len(lams)):
        ta, tb = _test_functions(mus[i - 1]), _test_functions(mus[i])
        for kind in BIFURCATION_KINDS:
            if kind == "Neimark-Sacker":
                crossed = ta[kind] != tb[kind]
            else:
                crossed = np.sign(ta[kind]) != np.sign(tb[kind])
            if not crossed:
                continue
            lo, hi, y_lo, y_hi = lams[i - 1], lams[i], ys[i - 1], ys[i]
            s_lo = ta[kind]
            orb = None
            if locate:
                for _ in range(bisections):
                    mid = 0.5 * (lo + hi)
                    orb = run(mid, 0.5 * (y_lo + y_hi))
                    if int(orb.status) != 0:
                        break
                    if kind == "Neimark-Sacker":
                        same = _test_functions(orb.multipliers)[kind] == s_lo
                    else:
                        same = np.sign(_test_functions(orb.multipliers)[kind]) == np.sign(s_lo)
                    if same:
                        lo, y_lo = mid, orb.y
                    else:
                        hi, y_hi = mid, orb.y
            val = 0.5 * (lo + hi)
            at = run(val, 0.5 * (y_lo + y_hi))
            bifs.append(Bifurcation(kind, val, (lams[i - 1], lams[i]), at.multipliers, at.y))
    return OrbitBranch(
        values=np.asarray(lams),
        y=np.asarray(ys),
        multipliers=np.asarray(mus),
        stable=np.asarray(stable),
        bifurcations=bifs,
        stopped_at=stopped,
    )


class ArclengthBranch(NamedTuple):
    values: np.ndarray
    """parameter values of the converged points (m,), not monotonic past a fold"""
    y: np.ndarray
    """orbit states (m, n)"""
    tangents: np.ndarray
    """unit tangents (m, n + 1) in (y, lam), oriented along the branch"""
    multipliers: np.ndarray
    """Floquet multipliers (m, n), by decreasing modulus"""
    stable: np.ndarray
    """(m,) bool"""
    steps: np.ndarray
    """arclength step that reached each point (m,) (0 for the first)"""
    bifurcations: list[Bifurcation]
    """crossings between consecutive points, in branch order. ``value``: period doublings
    bisected in lam on Re prod(1 + mu); folds and NS interpolated linearly between the
    bracketing points (folds in the lam-component of the tangent), accurate to about the local
    step squared"""
    stopped: str
    """why the branch ended: "end value reached", "max points" or "step below ds_min"."""


def _bisect_pd(solve, ua, ub, tf_a, bisections):
    lo, hi, y_lo, y_hi = ua[-1], ub[-1], ua[:-1], ub[:-1]
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        orb = solve(jnp.asarray(mid), jnp.asarray(0.5 * (y_lo + y_hi)))
        if int(orb.status) != 0:
            break
        tf = _test_functions(np.asarray(orb.multipliers))["period-doubling"]
        if np.sign(tf) == np.sign(tf_a):
            lo, y_lo = mid, np.asarray(orb.y)
        else:
            hi, y_hi = mid, np.asarray(orb.y)
    val = 0.5 * (lo + hi)
    orb = solve(jnp.asarray(val), jnp.asarray(0.5 * (y_lo + y_hi)))
    return val, np.asarray(orb.multipliers), np.asarray(orb.y)


def continue_pseudo_arclength(
    vector_field: Callable[[Any, Array, Any], Array],
    y_guess: Array,
    args_of: Callable[[Array], Any],
    period_of: Callable[[Any], Array],
    lam0: float,
    lam_end: float,
    *,
    ds: float = 0.02,
    ds_min: float = 1e-5,
    ds_max: float = 0.2,
    max_points: int = 400,
    k: int = 1,
    t0: float = 0.0,
    rtol: float = 1e-10,
    atol: float = 1e-11,
    max_steps: int = 100_000,
    newton_tol: float = 1e-9,
    newton_max_steps: int = 8,
    bisections: int = 30,
) -> ArclengthBranch:
    """Pseudo-arclength continuation of the period-k orbit through ``y_guess`` at ``lam0``.

    Unknowns u = (y, lam); each point solves (optimistix Newton) the augmented system
    P^k(y; lam) - y = 0, t . (u - u_prev) - ds = 0 from the tangent predictor
    u_prev + ds t, where t is the unit null vector of [dP/dy - I, dP/dlam] (oriented like the
    previous tangent). Because lam is an unknown, the branch passes folds in lam. The step is
    halved when Newton fails and grown x1.5 (up to ``ds_max``) when it converges in at most 3
    iterations. Multipliers come from the variational equations (`variational_map`).

    Args:
        vector_field, args_of, period_of: as in `continue_periodic_orbit`.
        lam0, lam_end: start value and the value at which the branch stops (once passed).
        ds, ds_min, ds_max: initial, smallest and largest arclength step in (y, lam).
        max_points: points at most.
        bisections: halvings of the lam-bracket of each period doubling (a Newton solve in
            lam at fixed lam each, from the interpolated state; 0: linear interpolation only).

    Returns:
        `ArclengthBranch` (host arrays).
    """
    ode = dict(k=k, t0=t0, rtol=rtol, atol=atol, max_steps=max_steps)
    direction = np.sign(lam_end - lam0)
    if direction == 0:
        raise ValueError("lam_end must differ from lam0")

    def P_minus(u):
        y, lam = u[:-1], u[-1]
        args = args_of(lam)
        y1, ok, _ = stroboscopic_map(vector_field, y, args, period=period_of(args), **ode)
        return y1 - y, ok

    @jax.jit
    def tangent(u, t_prev):
        J = jax.jacfwd(lambda v: P_minus(v)[0])(u)
        _, _, vt = jnp.linalg.svd(J)
        t = vt[-1]
        return t * jnp.sign(jnp.dot(t, t_prev) + 1e-300)

    @jax.jit
    def corrector(u_prev, t, h):
        pred = u_prev + h * t

        def fn(u, _):
            return jnp.concatenate([P_minus(u)[0], jnp.dot(t, u - u_prev)[None] - h])

        finder = optx.Newton(rtol=newton_tol, atol=newton_tol)
        sol = optx.root_find(fn, finder, pred, max_steps=newton_max_steps, throw=False)
        u = sol.value
        res, ok = P_minus(u)
        good = (sol.result == optx.RESULTS.successful) & ok & (jnp.max(jnp.abs(res)) < 10 * newton_tol)
        return u, good, sol.stats["num_steps"]

    @jax.jit
    def floquet(u):
        args = args_of(u[-1])
        _, Phi, _, _ = variational_map(vector_field, u[:-1], args, period=period_of(args), **ode)
        return sort_multipliers(jnp.linalg.eigvals(Phi))

    @jax.jit
    def first(lam, y0):
        args = args_of(lam)
        return find_periodic_orbit(vector_field, y0, args, period=period_of(args), newton_tol=newton_tol, **ode)

    orb = first(jnp.asarray(lam0, float), jnp.asarray(y_guess, float))
    if int(orb.status) != 0:
        raise ValueError(f"y_guess: no period-{k} orbit found near it at lam0={lam0}")
    n = orb.y.shape[0]
    u = jnp.concatenate([orb.y, jnp.asarray([lam0], float)])
    t = tangent(u, jnp.zeros(n + 1).at[-1].set(direction))
    us, ts, mus, hs = [np.asarray(u)], [np.asarray(t)], [np.asarray(floquet(u))], [0.0]
    h = ds
    stopped = "max points"
    while len(us) < max_points:
        u_new, good, nsteps = corrector(u, t, h)
        if not bool(good):
            h *= 0.5
            if h < ds_min:
                stopped = "step below ds_min"
                break
            continue
        t = tangent(u_new, t)
        u = u_new
        us.append(np.asarray(u))
        ts.append(np.asarray(t))
        mus.append(np.asarray(floquet(u)))
        hs.append(h)
        if int(nsteps) <= 3:
            h = min(1.5 * h, ds_max)
        if (float(u[-1]) - lam_end) * direction >= 0:
            stopped = "end value reached"
            break

    U, TT, MU = np.asarray(us), np.asarray(ts), np.asarray(mus)
    bifs: list[Bifurcation] = []
    for i in range(1, len(U)):
        ta, tb = _test_functions(MU[i - 1]), _test_functions(MU[i])
        checks = {
            "fold": (TT[i - 1, -1], TT[i, -1]),
            "period-doubling": (ta["period-doubling"], tb["period-doubling"]),
        }
        for kind, (a, b) in checks.items():
            if np.sign(a) != np.sign(b):
                w = a / (a - b)
                val = (1 - w) * U[i - 1, -1] + w * U[i, -1]
                mu = (1 - w) * MU[i - 1] + w * MU[i]
                y = (1 - w) * U[i - 1, :-1] + w * U[i, :-1]
                if kind == "period-doubling" and bisections:
                    val, mu, y = _bisect_pd(first, U[i - 1], U[i], a, bisections)
                bifs.append(Bifurcation(kind, float(val), (U[i - 1, -1], U[i, -1]), mu, y))
        if ta["Neimark-Sacker"] != tb["Neimark-Sacker"]:
            bifs.append(
                Bifurcation(
                    "Neimark-Sacker",
                    float(0.5 * (U[i - 1, -1] + U[i, -1])),
                    (U[i - 1, -1], U[i, -1]),
                    MU[i],
                    U[i, :-1],
                )
            )
    return ArclengthBranch(
        values=U[:, -1],
        y=U[:, :-1],
        tangents=TT,
        multipliers=MU,
        stable=np.all(np.abs(MU) < 1.0, axis=1),
        steps=np.asarray(hs),
        bifurcations=bifs,
        stopped=stopped,
    )


def switch_at_period_doubling(
    vector_field: Callable[[Any, Array, Any], Array],
    bifurcation: Bifurcation,
    args_of: Callable[[Array], Any],
    period_of: Callable[[Any], Array],
    *,
    k: int = 1,
    lam: float,
    eps: float = 1e-2,
    **find_kw,
) -> PeriodicOrbit:
    """The period-2k orbit born at a period doubling of a period-k branch, found at ``lam``.

    Starts from the PD point +- ``eps`` along the eigenvector of the multiplier nearest -1 of
    the period-k monodromy there (`variational_map`), and solves the period-2k problem at
    ``lam`` (on the side of the doubling where the new orbit exists) with `find_periodic_orbit`.
    The sign giving a converged orbit that is not the period-k one (its two section points
    differ by more than eps/10) is returned; ``status`` is nonzero if neither does.
    """
    if bifurcation.kind != "period-doubling":
        raise ValueError(f"bifurcation: expected a period-doubling, got {bifurcation.kind!r}")
    ode = {key: find_kw[key] for key in ("t0", "rtol", "atol", "max_steps") if key in find_kw}
    args_pd = args_of(jnp.asarray(bifurcation.value))
    y_pd = jnp.asarray(bifurcation.y)
    _, Phi, _, _ = variational_map(vector_field, y_pd, args_pd, period=period_of(args_pd), k=k, **ode)
    mu, vecs = np.linalg.eig(np.asarray(Phi))
    v = np.real(vecs[:, np.argmin(np.abs(mu + 1))])
    v = v / np.linalg.norm(v)
    args = args_of(jnp.asarray(lam))
    orb = None
    for sign in (1.0, -1.0):
        orb = find_periodic_orbit(vector_field, y_pd + sign * eps * v, args, period=period_of(args), k=2 * k, **find_kw)
        if int(orb.status) == 0:
            y1, _, _ = stroboscopic_map(vector_field, orb.y, args, period=period_of(args), k=k, **ode)
            if float(jnp.max(jnp.abs(y1 - orb.y))) > eps / 10:
                return orb
    return orb
