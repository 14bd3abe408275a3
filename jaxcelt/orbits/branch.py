"""Natural-parameter continuation of periodic orbits of forced ODEs, with bifurcation detection.

A branch of period-k orbits is followed in one scalar parameter lam over a given grid of
values: each point is a Newton solve (`jaxcelt.orbits.shooting.find_periodic_orbit`, one compiled
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

from jaxcelt._types import Array
from jaxcelt.orbits.shooting import (
    Chart,
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
    "branch_to_dict",
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


def _ns_function(mu: np.ndarray) -> float:
    """max |mu| - 1 over the complex multipliers (its zero is a Neimark-Sacker point)."""
    cplx = np.abs(mu.imag) > _IMAG_TOL
    return float(np.max(np.abs(mu[cplx])) - 1.0) if np.any(cplx) else -1.0


def _pd_function(mu: np.ndarray) -> float:
    return _test_functions(mu)["period-doubling"]


_BISECTED = {"period-doubling": _pd_function, "Neimark-Sacker": _ns_function}
"""crossings located by bisection in lam (folds: interpolation of the tangent's lam-component,
since at a fold no orbit exists past it at fixed lam)"""


class ArclengthBranch(NamedTuple):
    values: np.ndarray
    """parameter values of the converged points (m,), not monotonic past a fold"""
    y: np.ndarray
    """orbit states (m, n)"""
    tangents: np.ndarray
    """unit tangents (m, d + 1) in (z, lam), each in the chart around its own point, oriented
    along the branch"""
    multipliers: np.ndarray
    """Floquet multipliers (m, n), by decreasing modulus"""
    stable: np.ndarray
    """(m,) bool"""
    steps: np.ndarray
    """arclength step that reached each point (m,) (0 for the first)"""
    bifurcations: list[Bifurcation]
    """crossings between consecutive points, in branch order. ``value``: period doublings
    bisected in lam on Re prod(1 + mu), Neimark-Sacker points on max |mu| - 1 of the complex
    multipliers; folds interpolated linearly in the lam-component of the tangent between the
    bracketing points (accurate to about the local step squared)"""
    stopped: str
    """why the branch ended: "end value reached", "max points" or "step below ds_min" (for a
    window, one reason for each end)"""
    start: int = 0
    """index of the starting point (``y_guess``'s orbit) in the branch"""


def _bisect(solve, ua, ub, tf_of, tf_a, bisections):
    """Bisect [ua, ub] (rows (y, lam)) on the sign of ``tf_of(multipliers)``; Newton at fixed lam."""
    lo, hi, y_lo, y_hi = ua[-1], ub[-1], ua[:-1], ub[:-1]
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        orb = solve(jnp.asarray(mid), jnp.asarray(0.5 * (y_lo + y_hi)))
        if int(orb.status) != 0:
            break
        tf = tf_of(np.asarray(orb.multipliers))
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
    lam_end: float | tuple[float, float],
    *,
    ds: float = 0.02,
    ds_min: float = 1e-5,
    ds_max: float = 0.2,
    max_points: int = 400,
    k: int = 1,
    t0: float = 0.0,
    embed: Chart | None = None,
    chart: Chart | None = None,
    solver: Any = None,
    rtol: float = 1e-10,
    atol: float = 1e-11,
    max_steps: int = 100_000,
    newton_tol: float = 1e-9,
    newton_max_steps: int = 8,
    bisections: int = 30,
    callback: Callable[[int, float, bool], None] | None = None,
) -> ArclengthBranch:
    """Pseudo-arclength continuation of the period-k orbit through ``y_guess`` at ``lam0``.

    Unknowns u = (z, lam) with z = chart(y) local coordinates (the state itself by default);
    each point solves (optimistix Newton) the augmented system chart(P^k(embed(z); lam)) - z = 0,
    t . (u - u_prev) - ds = 0 from the tangent predictor u_prev + ds t, where t is the unit null
    vector of [dG/dz, dG/dlam] (oriented like the previous tangent). Because lam is an unknown,
    the branch passes folds in lam. The chart is re-centred on every accepted point (the
    previous tangent is carried over by the chain rule), so a branch may travel far from where
    it started. The step is halved when Newton fails and grown x1.5 (up to ``ds_max``) when it
    converges in at most 3 iterations. Multipliers come from the variational equations
    (`variational_map`), in chart coordinates.

    Args:
        vector_field, args_of, period_of: as in `continue_periodic_orbit`.
        lam0: start value (the parameter of ``y_guess``).
        lam_end: the value at which the branch stops (once passed), or a window ``(lo, hi)``
            around lam0: the branch is followed both ways from lam0 until each end leaves the
            window (it may turn at folds and come back through lam0 on another sheet).
        ds, ds_min, ds_max: initial, smallest and largest arclength step in (z, lam).
        max_points: points at most (shared by the two ends of a window).
        embed, chart: local coordinates as in `jaxcelt.orbits.shooting.find_periodic_orbit`
            (``embed(z, y_ref, args)``, ``chart(y, y_ref, args)``); default identity.
        solver: diffrax solver (default Dopri8).
        bisections: halvings of the lam-bracket of each period doubling (a Newton solve at
            fixed lam each, from the interpolated state; 0: linear interpolation only).
        callback: called as ``callback(n_points, lam, accepted)`` after every corrector attempt
            (e.g. a progress bar).

    Returns:
        `ArclengthBranch` (host arrays; ``y`` are states, ``tangents`` in the chart of each point).
    """
    ode = dict(k=k, t0=t0, solver=solver, rtol=rtol, atol=atol, max_steps=max_steps)
    window = None
    if np.ndim(lam_end) == 1:
        window = tuple(float(x) for x in lam_end)
        if len(window) != 2 or not (window[0] < lam0 < window[1]):
            raise ValueError(f"lam_end: a window (lo, hi) must have lo < lam0 < hi, got {lam_end!r} (lam0={lam0})")
    elif np.sign(lam_end - lam0) == 0:
        raise ValueError("lam_end must differ from lam0")
    if embed is None:
        embed = lambda z, ref, a: z  # noqa: E731
    if chart is None:
        chart = lambda y, ref, a: y  # noqa: E731

    def G(u, ref):
        z, lam = u[:-1], u[-1]
        args = args_of(lam)
        y1, ok, _ = stroboscopic_map(vector_field, embed(z, ref, args), args, period=period_of(args), **ode)
        return chart(y1, ref, args) - z, ok

    @jax.jit
    def tangent(u, ref, t_prev):
        J = jax.jacfwd(lambda v: G(v, ref)[0])(u)
        _, _, vt = jnp.linalg.svd(J)
        t = vt[-1]
        return t * jnp.sign(jnp.dot(t, t_prev) + 1e-300)

    @jax.jit
    def recentre(u, t, ref):
        """(u, t) in the chart around the state of u (the new reference) and that state."""
        args = args_of(u[-1])
        y = embed(u[:-1], ref, args)

        def to_new(v):
            a = args_of(v[-1])
            return jnp.concatenate([chart(embed(v[:-1], ref, a), y, a), v[-1:]])

        u_new, t_new = jax.jvp(to_new, (u,), (t,))
        return u_new, t_new / jnp.linalg.norm(t_new), y

    @jax.jit
    def corrector(u_prev, t, h, ref):
        pred = u_prev + h * t

        def fn(u, _):
            return jnp.concatenate([G(u, ref)[0], jnp.dot(t, u - u_prev)[None] - h])

        finder = optx.Newton(rtol=newton_tol, atol=newton_tol)
        sol = optx.root_find(fn, finder, pred, max_steps=newton_max_steps, throw=False)
        u = sol.value
        res, ok = G(u, ref)
        good = (sol.result == optx.RESULTS.successful) & ok & jnp.all(jnp.isfinite(u))
        good = good & (jnp.max(jnp.abs(res)) < 10 * newton_tol)
        return u, good, sol.stats["num_steps"]

    @jax.jit
    def floquet(u, ref):
        z, lam = u[:-1], u[-1]
        args = args_of(lam)
        y = embed(z, ref, args)
        y1, Phi, _, _ = variational_map(vector_field, y, args, period=period_of(args), **ode)
        E = jax.jacfwd(lambda zz: embed(zz, ref, args))(z)
        C = jax.jacfwd(lambda yy: chart(yy, ref, args))(y1)
        return sort_multipliers(jnp.linalg.eigvals(C @ Phi @ E))

    fkw = dict(ode, embed=embed, chart=chart, newton_tol=newton_tol)

    @jax.jit
    def first(lam, y0):
        args = args_of(lam)
        return find_periodic_orbit(vector_field, y0, args, period=period_of(args), **fkw)

    orb = first(jnp.asarray(lam0, float), jnp.asarray(y_guess, float))
    if int(orb.status) != 0:
        raise ValueError(f"y_guess: no period-{k} orbit found near it at lam0={lam0}")
    z0 = chart(orb.y, orb.y, args_of(jnp.asarray(lam0, float)))
    u0 = jnp.concatenate([z0, jnp.asarray([lam0], float)])
    mu0 = np.asarray(floquet(u0, orb.y))

    def trace(direction, passed, budget):
        """Points after the start, following the branch from lam0 in ``direction``."""
        ref, u = orb.y, u0
        t = tangent(u, ref, jnp.zeros(u.shape[0]).at[-1].set(direction))
        out = dict(y=[], lam=[], t=[np.asarray(t)], mu=[], h=[])
        h, stopped = ds, "max points"
        while len(out["y"]) < budget:
            u_new, good, nsteps = corrector(u, t, h, ref)
            if callback is not None:
                callback(len(out["y"]) + 1, float(u_new[-1]) if bool(good) else float(u[-1]), bool(good))
            if not bool(good):
                h *= 0.5
                if h < ds_min:
                    stopped = "step below ds_min"
                    break
                continue
            u, t, ref = recentre(u_new, t, ref)
            t = tangent(u, ref, t)
            out["y"].append(np.asarray(ref))
            out["lam"].append(float(u[-1]))
            out["t"].append(np.asarray(t))
            out["mu"].append(np.asarray(floquet(u, ref)))
            out["h"].append(h)
            if int(nsteps) <= 3:
                h = min(1.5 * h, ds_max)
            if passed(out["lam"][-1]):
                stopped = "end value reached"
                break
        return out, stopped

    if window is None:
        direction = np.sign(lam_end - lam0)
        fwd, stopped = trace(direction, lambda lam: (lam - lam_end) * direction >= 0, max_points - 1)
        bwd = dict(y=[], lam=[], t=[np.asarray(fwd["t"][0])], mu=[], h=[])
    else:
        lo, hi = window
        outside = lambda lam: not (lo <= lam <= hi)  # noqa: E731
        bwd, s_lo = trace(-1.0, outside, (max_points - 1) // 2)
        fwd, s_hi = trace(1.0, outside, max_points - 1 - len(bwd["y"]))
        stopped = f"decreasing end: {s_lo}; increasing end: {s_hi}"
    # one branch ordered along the arclength: the backward part reversed (tangents flipped)
    ys = bwd["y"][::-1] + [np.asarray(orb.y)] + fwd["y"]
    lams = bwd["lam"][::-1] + [float(lam0)] + fwd["lam"]
    ts = [-x for x in bwd["t"][1:][::-1]] + [np.asarray(fwd["t"][0])] + fwd["t"][1:]
    mus = bwd["mu"][::-1] + [mu0] + fwd["mu"]
    hs = bwd["h"][::-1] + [0.0] + fwd["h"]

    Y, LAM, TT, MU = np.asarray(ys), np.asarray(lams), np.asarray(ts), np.asarray(mus)
    bifs: list[Bifurcation] = []
    for i in range(1, len(Y)):
        ta, tb = _test_functions(MU[i - 1]), _test_functions(MU[i])
        checks = {
            "fold": (TT[i - 1, -1], TT[i, -1]),
            "period-doubling": (ta["period-doubling"], tb["period-doubling"]),
        }
        if ta["Neimark-Sacker"] != tb["Neimark-Sacker"]:
            checks["Neimark-Sacker"] = (_ns_function(MU[i - 1]), _ns_function(MU[i]))
        for kind, (a, b) in checks.items():
            if np.sign(a) != np.sign(b) or kind == "Neimark-Sacker":
                w = float(np.clip(a / (a - b), 0.0, 1.0)) if a != b else 0.5
                val = (1 - w) * LAM[i - 1] + w * LAM[i]
                mu = (1 - w) * MU[i - 1] + w * MU[i]
                y = (1 - w) * Y[i - 1] + w * Y[i]
                if kind in _BISECTED and bisections:
                    ua, ub = np.r_[Y[i - 1], LAM[i - 1]], np.r_[Y[i], LAM[i]]
                    val, mu, y = _bisect(first, ua, ub, _BISECTED[kind], a, bisections)
                bifs.append(Bifurcation(kind, float(val), (LAM[i - 1], LAM[i]), mu, y))
    return ArclengthBranch(
        values=LAM,
        y=Y,
        tangents=TT,
        multipliers=MU,
        stable=np.all(np.abs(MU) < 1.0, axis=1),
        steps=np.asarray(hs),
        bifurcations=bifs,
        stopped=stopped,
        start=len(bwd["y"]),
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


def _complex_pairs(mu: np.ndarray) -> list[list[float]]:
    return [[float(z.real), float(z.imag)] for z in np.asarray(mu)]


def branch_to_dict(branch: ArclengthBranch, state_names: tuple[str, ...] | None = None) -> dict[str, Any]:
    """A JSON-ready dict of a branch: per point the parameter, state, |mu|max and stability; the
    bifurcations with their multipliers (complex as [re, im] pairs)."""
    y = np.asarray(branch.y)
    names = state_names or tuple(f"y{i}" for i in range(y.shape[1]))
    mu = np.asarray(branch.multipliers)
    return {
        "values": [float(v) for v in branch.values],
        "state": {n: [float(v) for v in y[:, i]] for i, n in enumerate(names)},
        "max_abs_multiplier": [float(v) for v in np.max(np.abs(mu), axis=1)],
        "multipliers": [_complex_pairs(m) for m in mu],
        "stable": [bool(s) for s in branch.stable],
        "start": int(branch.start),
        "stopped": branch.stopped,
        "bifurcations": [
            {
                "kind": b.kind,
                "value": float(b.value),
                "bracket": [float(b.bracket[0]), float(b.bracket[1])],
                "multipliers": _complex_pairs(b.multipliers),
                "multipliers_abs": [float(a) for a in np.abs(b.multipliers)],
                "state": dict(zip(names, map(float, np.asarray(b.y)), strict=True)),
            }
            for b in branch.bifurcations
        ],
    }
