"""Continuation of a branch of periodic orbits in one parameter: natural and pseudo-arclength.

The algorithms are kept apart from what they continue. What is continued is an
`jaxcelt.orbits.shooting.OrbitFamily`: period-k orbits of a forced ODE as the parameter lam varies,
with unknowns u = (z, lam) (z: local coordinates around a reference state). This module only steps
along it:

* `continue_natural`: lam follows a given grid; each point is a Newton solve at fixed lam from a
  secant prediction through the two previous points (one compiled program for the whole branch).
  The branch stops at the first point that does not converge (typically a fold, which natural
  continuation cannot pass).
* `continue_arclength`: pseudo-arclength continuation (PALC). The stepper (`ArclengthStepper`) works on
  any residual G(u, ref) = 0 with one more unknown than equations: tangent predictor, Newton corrector
  on [G; t . (u - u_prev) - h], step control (halve on failure, grow on fast convergence) and turning
  points (folds in lam, where the tangent's lam-component changes sign). `trace_arclength` runs it
  from a start point in one direction. A two-parameter continuation of bifurcation points reuses them
  with its own residual.

Bifurcations along a branch are detected and located by `jaxcelt.orbits.points`; a new branch is started at a
period doubling by `jaxcelt.orbits.switching`; `branch_to_dict` writes a branch as JSON-ready data.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from collections.abc import Callable
from typing import Any, NamedTuple, Unpack

import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from jaxcelt._compile_options import jit_anywhere
from jaxcelt._types import Array
from jaxcelt.orbits.options import ShootingKeywords, ShootingOptions, resolve_options
from jaxcelt.orbits.points import Bifurcation, detect_on_arclength_branch, detect_on_natural_branch
from jaxcelt.orbits.shooting import (
    Chart,
    OrbitFamily,
    PeriodicOrbit,
    find_periodic_orbit,
    identity_charts,
)

__all__ = [
    "NaturalBranch",
    "ArclengthBranch",
    "ArclengthStepper",
    "continue_natural",
    "continue_arclength",
    "trace_arclength",
    "branch_to_dict",
]

ARCLENGTH_DEFAULTS = ShootingOptions(rtol=1e-10, atol=1e-11, newton_max_steps=8)
"""`continue_arclength`'s options: looser solver tolerances than a single orbit, and few corrector iterations
(a step that needs more is halved)."""

_COLD_NEWTON_STEPS = ShootingOptions().newton_max_steps
"""Newton iterations of the start point and of bisection solves at fixed lam (cold starts)"""


class NaturalBranch(NamedTuple):
    """A branch from `continue_natural` (host arrays)."""

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


def continue_natural(
    vector_field: Callable[[Any, Array, Any], Array],
    y_guess: Array,
    args_of: Callable[[Array], Any],
    period_of: Callable[[Any], Array],
    values: Array,
    *,
    locate: bool = True,
    bisections: int = 40,
    **find_kw,
) -> NaturalBranch:
    """Follow the period-k orbit through ``y_guess`` (at ``values[0]``) along ``values``.

    Args:
        vector_field: ``f(t, y, args)``.
        y_guess: state near the orbit at the first value.
        args_of: ``lam -> args`` (traceable, e.g. ``lambda lam: p.at[3].set(lam)``).
        period_of: ``args -> T`` (the forcing period; may depend on lam).
        values: increasing or decreasing grid of lam (host array).
        locate: bisect each detected crossing (``bisections`` halvings of its bracket).
        **find_kw: passed to `jaxcelt.orbits.shooting.find_periodic_orbit` (k, t0, embed, chart,
            ``options`` or the single solver and Newton settings).

    Returns:
        `NaturalBranch`; host (numpy) arrays, one compiled Newton program for all points.
    """
    values = np.asarray(values, dtype=float)

    @functools.partial(jit_anywhere, filter_jit=False)
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

    bifs = detect_on_natural_branch(run, lams, ys, mus, bisections=bisections if locate else 0)
    return NaturalBranch(
        values=np.asarray(lams),
        y=np.asarray(ys),
        multipliers=np.asarray(mus),
        stable=np.asarray(stable),
        bifurcations=bifs,
        stopped_at=stopped,
    )


class ArclengthBranch(NamedTuple):
    """A branch from `continue_arclength` (host arrays)."""

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
    """crossings between consecutive points, in branch order (`jaxcelt.orbits.points.detect_on_arclength_branch`):
    period doublings bisected in lam on Re prod(1 + mu), Neimark-Sacker points on max |mu| - 1 of the complex
    multipliers; folds interpolated linearly in the lam-component of the tangent between the bracketing points
    (accurate to about the local step squared)"""
    stopped: str
    """why the branch ended: "end value reached", "max points" or "step below ds_min" (for a
    window, one reason for each end)"""
    start: int = 0
    """index of the starting point (``y_guess``'s orbit) in the branch"""


class ArclengthStepper(NamedTuple):
    """One pseudo-arclength step on a residual ``G(u, ref) -> (r, ok)`` with u = (x, lam), r of size dim(u) - 1.

    ``ref`` is a reference the unknowns are measured from (the chart's centre), moved to each accepted point by
    ``recentre(u, t, ref) -> (u, t, ref)``; ``observe(u, ref)`` is what is recorded per point besides ``ref``
    (e.g. Floquet multipliers). Build one with `ArclengthStepper.build` (jitted pieces).
    """

    tangent: Callable[[Array, Any, Array], Array]
    """``(u, ref, t_prev) -> t``: unit null vector of dG/du, oriented like ``t_prev``"""
    corrector: Callable[[Array, Array, float, Any], tuple[Array, Array, Array]]
    """``(u_prev, t, h, ref) -> (u, converged, Newton steps)`` from the predictor u_prev + h t"""
    recentre: Callable[[Array, Array, Any], tuple[Array, Array, Any]]
    observe: Callable[[Array, Any], Any]

    @classmethod
    def build(cls, residual, recentre, observe, *, newton_tol: float, newton_max_steps: int) -> ArclengthStepper:
        @functools.partial(jit_anywhere, filter_jit=False)
        def tangent(u, ref, t_prev):
            J = jax.jacfwd(lambda v: residual(v, ref)[0])(u)
            _, _, vt = jnp.linalg.svd(J)
            t = vt[-1]
            return t * jnp.sign(jnp.dot(t, t_prev) + 1e-300)

        @functools.partial(jit_anywhere, filter_jit=False)
        def corrector(u_prev, t, h, ref):
            pred = u_prev + h * t

            def fn(u, _):
                return jnp.concatenate([residual(u, ref)[0], jnp.dot(t, u - u_prev)[None] - h])

            finder = optx.Newton(rtol=newton_tol, atol=newton_tol)
            sol = optx.root_find(fn, finder, pred, max_steps=newton_max_steps, throw=False)
            u = sol.value
            res, ok = residual(u, ref)
            good = (sol.result == optx.RESULTS.successful) & ok & jnp.all(jnp.isfinite(u))
            good = good & (jnp.max(jnp.abs(res)) < 10 * newton_tol)
            return u, good, sol.stats["num_steps"]

        return cls(
            tangent, corrector, jit_anywhere(recentre, filter_jit=False), jit_anywhere(observe, filter_jit=False)
        )


class _FixedOrbit(NamedTuple):
    status: int
    y: Array
    multipliers: Array


class _FixedLamSolve(NamedTuple):
    """The orbit at a fixed lam from a guess, by the branch's own corrector: with the tangent e_lam and step 0 the
    arclength condition fixes lam, so the augmented system is the periodic-orbit condition at that lam. It saves
    compiling a second Newton program for the start point and the bisections of a branch (12 s of XLA time for the
    wobblestone); where the corrector's few Newton steps do not converge, the cold solve (``cold``, more
    iterations, compiled then) takes over."""

    stepper: ArclengthStepper
    family: OrbitFamily
    cold: Callable[[Array, Array], Any]

    def __call__(self, lam: Array, y: Array) -> Any:
        lam, y = jnp.asarray(lam, float), jnp.asarray(y, float)
        _, chart = identity_charts(self.family.embed, self.family.chart)
        u = jnp.concatenate([chart(y, y, self.family.args_of(lam)), lam[None]])
        e = jnp.zeros_like(u).at[-1].set(1.0)
        u1, ok, _ = self.stepper.corrector(u, e, 0.0, y)
        if bool(ok):
            u2, _, y1 = self.stepper.recentre(u1, e, y)
            return _FixedOrbit(0, y1, self.stepper.observe(u2, y1))
        return self.cold(lam, y)


@functools.lru_cache(maxsize=16)
def _cached_family_programs(family: OrbitFamily) -> tuple[Callable, ArclengthStepper]:
    cold = dataclasses.replace(family.options, newton_max_steps=_COLD_NEWTON_STEPS)
    first = jit_anywhere(lambda lam, y0: family.solve(lam, y0, cold), filter_jit=False)
    return first, ArclengthStepper.build(
        family.residual, family.recentre, family.multipliers, newton_tol=family.options.newton_tol,
        newton_max_steps=family.options.newton_max_steps,
    )  # fmt: skip


def _family_programs(family: OrbitFamily) -> tuple[Callable, ArclengthStepper]:
    """The jitted start solve and stepper of ``family``, kept for the next branch of the same family (the same
    functions and settings, e.g. the mirror branch or another start of the same stone), which then runs without
    compiling again; built afresh where a field is unhashable."""
    try:
        hash(family)
    except TypeError:
        return _cached_family_programs.__wrapped__(family)
    return _cached_family_programs(family)


def trace_arclength(
    stepper: ArclengthStepper,
    u0: Array,
    ref0: Any,
    direction: float,
    passed: Callable[[float], bool],
    budget: int,
    *,
    ds: float,
    ds_min: float,
    ds_max: float,
    callback: Callable[[int, float, bool], None] | None = None,
    stop: Callable[[np.ndarray], str | None] | None = None,
) -> tuple[dict[str, list], str]:
    """Points after ``u0``, following the branch from it in ``direction`` of lam, and why the trace stopped.

    Returns ``dict(ref=[...], lam=[...], t=[t0, ...], obs=[...], h=[...], u=[...], shrunk=[...])`` (host values,
    ``ref`` and ``obs`` may be pytrees of arrays; ``t`` has the start's tangent first; ``u`` the accepted unknowns,
    each in the chart around its own point; ``shrunk`` whether the step was halved before that point was
    accepted) and "end value reached" (``passed(lam)``), "max points" (``budget``), "step below ds_min" or the
    reason ``stop(u)`` returned (an optional check of each accepted point on all its unknowns; None: go on).
    The step is halved when the corrector fails and grown x1.5 (up to ``ds_max``) when it converges in at most 3
    Newton iterations.
    """
    ref, u = ref0, u0
    t = stepper.tangent(u, ref, jnp.zeros(u.shape[0]).at[-1].set(direction))
    out = dict(ref=[], lam=[], t=[np.asarray(t)], obs=[], h=[], u=[], shrunk=[])
    h, stopped, shrunk = ds, "max points", False
    host = lambda tree: jax.tree_util.tree_map(np.asarray, tree)  # noqa: E731
    while len(out["ref"]) < budget:
        u_new, good, nsteps = stepper.corrector(u, t, h, ref)
        if callback is not None:
            callback(len(out["ref"]) + 1, float(u_new[-1]) if bool(good) else float(u[-1]), bool(good))
        if not bool(good):
            h *= 0.5
            shrunk = True
            if h < ds_min:
                stopped = "step below ds_min"
                break
            continue
        u, t, ref = stepper.recentre(u_new, t, ref)
        t = stepper.tangent(u, ref, t)
        out["ref"].append(host(ref))
        out["lam"].append(float(u[-1]))
        out["t"].append(np.asarray(t))
        out["obs"].append(host(stepper.observe(u, ref)))
        out["h"].append(h)
        out["u"].append(np.asarray(u))
        out["shrunk"].append(shrunk)
        shrunk = False
        if int(nsteps) <= 3:
            h = min(1.5 * h, ds_max)
        if passed(out["lam"][-1]):
            stopped = "end value reached"
            break
        reason = stop(out["u"][-1]) if stop is not None else None
        if reason is not None:
            stopped = reason
            break
    return out, stopped


def continue_arclength(
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
    bisections: int = 30,
    callback: Callable[[int, float, bool], None] | None = None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
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
    (`jaxcelt.orbits.shooting.variational_map`), in chart coordinates.

    Args:
        vector_field, args_of, period_of: as in `continue_natural`.
        lam0: start value (the parameter of ``y_guess``).
        lam_end: the value at which the branch stops (once passed), or a window ``(lo, hi)``
            around lam0: the branch is followed both ways from lam0 until each end leaves the
            window (it may turn at folds and come back through lam0 on another sheet).
        ds, ds_min, ds_max: initial, smallest and largest arclength step in (z, lam).
        max_points: points at most (shared by the two ends of a window).
        embed, chart: local coordinates as in `jaxcelt.orbits.shooting.find_periodic_orbit`
            (``embed(z, y_ref, args)``, ``chart(y, y_ref, args)``); default identity.
        options: `jaxcelt.orbits.options.ShootingOptions` (default `ARCLENGTH_DEFAULTS`: rtol 1e-10,
            atol 1e-11, newton_max_steps 8, the others `ShootingOptions`' defaults). ``newton_max_steps``
            bounds each corrector; the start point and bisection solves are cold Newton solves of up to 30
            iterations.
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``;
            each one given overrides it.
        bisections: halvings of the lam-bracket of each period doubling (a Newton solve at
            fixed lam each, from the interpolated state; 0: linear interpolation only).
        callback: called as ``callback(n_points, lam, accepted)`` after every corrector attempt
            (e.g. a progress bar).

    Returns:
        `ArclengthBranch` (host arrays; ``y`` are states, ``tangents`` in the chart of each point).
    """
    opts = resolve_options(options, ARCLENGTH_DEFAULTS, caller="continue_arclength", **settings)
    window = None
    if np.ndim(lam_end) == 1:
        window = tuple(float(x) for x in lam_end)
        if len(window) != 2 or not (window[0] < lam0 < window[1]):
            raise ValueError(f"lam_end: a window (lo, hi) must have lo < lam0 < hi, got {lam_end!r} (lam0={lam0})")
    elif np.sign(lam_end - lam0) == 0:
        raise ValueError("lam_end must differ from lam0")
    family = OrbitFamily(vector_field, args_of, period_of, k=k, t0=t0, embed=embed, chart=chart, options=opts)
    first, stepper = _family_programs(family)

    fixed = _FixedLamSolve(stepper, family, first)
    orb = fixed(jnp.asarray(lam0, float), jnp.asarray(y_guess, float))
    if int(orb.status) != 0:
        raise ValueError(f"y_guess: no period-{k} orbit found near it at lam0={lam0}")
    _, chart_ = identity_charts(embed, chart)
    z0 = chart_(orb.y, orb.y, args_of(jnp.asarray(lam0, float)))
    u0 = jnp.concatenate([z0, jnp.asarray([lam0], float)])
    mu0 = np.asarray(stepper.observe(u0, orb.y))
    steps = dict(ds=ds, ds_min=ds_min, ds_max=ds_max, callback=callback)

    if window is None:
        direction = np.sign(lam_end - lam0)
        passed = lambda lam: (lam - lam_end) * direction >= 0  # noqa: E731
        fwd, stopped = trace_arclength(stepper, u0, orb.y, direction, passed, max_points - 1, **steps)
        bwd = dict(ref=[], lam=[], t=[np.asarray(fwd["t"][0])], obs=[], h=[])
    else:
        lo, hi = window
        outside = lambda lam: not (lo <= lam <= hi)  # noqa: E731
        bwd, s_lo = trace_arclength(stepper, u0, orb.y, -1.0, outside, (max_points - 1) // 2, **steps)
        fwd, s_hi = trace_arclength(stepper, u0, orb.y, 1.0, outside, max_points - 1 - len(bwd["ref"]), **steps)
        stopped = f"decreasing end: {s_lo}; increasing end: {s_hi}"
    # one branch ordered along the arclength: the backward part reversed (tangents flipped)
    Y = np.asarray(bwd["ref"][::-1] + [np.asarray(orb.y)] + fwd["ref"])
    LAM = np.asarray(bwd["lam"][::-1] + [float(lam0)] + fwd["lam"])
    TT = np.asarray([-x for x in bwd["t"][1:][::-1]] + [np.asarray(fwd["t"][0])] + fwd["t"][1:])
    MU = np.asarray(bwd["obs"][::-1] + [mu0] + fwd["obs"])
    hs = bwd["h"][::-1] + [0.0] + fwd["h"]
    return ArclengthBranch(
        values=LAM,
        y=Y,
        tangents=TT,
        multipliers=MU,
        stable=np.all(np.abs(MU) < 1.0, axis=1),
        steps=np.asarray(hs),
        bifurcations=detect_on_arclength_branch(fixed, LAM, Y, TT, MU, bisections=bisections),
        stopped=stopped,
        start=len(bwd["ref"]),
    )


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


_RENAMED = {
    "continue_periodic_orbit": "continue_natural",
    "continue_pseudo_arclength": "continue_arclength",
    "OrbitBranch": "NaturalBranch",
}
"""Former names, kept for one release (they warn)."""


def __getattr__(name: str):
    if name in _RENAMED:
        new = _RENAMED[name]
        warnings.warn(
            f"jaxcelt.orbits.branch.{name} is deprecated and will be removed in the next release; use {new}",
            DeprecationWarning,
            stacklevel=2,
        )
        return globals()[new]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
