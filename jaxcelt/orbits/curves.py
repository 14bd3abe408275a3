"""Curves of fold, period-doubling and Neimark-Sacker points in two parameters (codimension-two continuation).

A period-k orbit of a periodically forced ODE dy/dt = f(t, y, args(p1, p2)) has a fold where a Floquet
multiplier is +1, a period doubling where one is -1 and a Neimark-Sacker point where a complex pair e^{+-i theta}
lies on the unit circle. In two parameters these points form curves; a curve point is a regular root of a
minimally augmented system: the orbit equations chart(P(embed(z))) - z = 0 (P the k-period stroboscopic map, z
local coordinates ``embed``/``chart`` as `jaxcelt.orbits.shooting.find_periodic_orbit` takes them) and

* fold / period doubling: one bordered test function of M -+ I (`jaxcelt.orbits.curve_fold.FoldSystem`);
* Neimark-Sacker: two entries of the 2 x 2 block of the two-bordered B = M^2 - 2 kappa M + I with kappa =
  cos(theta) an extra unknown (`jaxcelt.orbits.ns_system.NSSystem`).

`continue_bifurcation` follows the curve by pseudo-arclength continuation (`jaxcelt.orbits.branch.ArclengthStepper`,
`trace_arclength`) in u = (z, [kappa,] p1 / s1, p2 / s2) (``scale`` = (s1, s2) makes the two parameters comparable
in the arclength), so it passes turning points of the curve in either parameter. At every accepted point the chart
is re-centred on the orbit and the borders are refreshed there.

The monodromy M comes from the variational equations integrated with the orbit under one error control
(`jaxcelt.orbits.shooting.variational_map` in forward mode), not from differentiating the primal-only map: on an
orbit at an equilibrium (the trivial orbit of the Mathieu equation) the primal error estimate does not see the
tangent dynamics. Newton's Jacobian is ``jax.jacfwd`` of that solve.

Codimension-two points detected along a curve (`CODIM2_TESTS`), each located between two curve points by a
secant (Illinois) iteration in the arclength on its test function, every iterate a corrector solve:

* fold curve: ``"cusp"``, the zero of the fold's normal-form coefficient a = 1/2 <p, B(q, q)> (q, p right and
  left null vectors of M - I with <p, q> = 1, B the second derivative of the map; q oriented continuously along
  the curve, so a changes sign at a cusp); ``"1:1 resonance"``, Re prod over the other multipliers of (mu - 1);
  ``"fold-flip"``, Re prod over the other multipliers of (mu + 1);
* period-doubling curve: ``"fold-flip"``, Re prod over the other multipliers of (mu - 1) (a second multiplier
  through +1); ``"1:2 resonance"``, Re prod over the other multipliers of (mu + 1) (a second multiplier at -1);
* Neimark-Sacker curve: ``"1:1 resonance"``, ``"1:2 resonance"``, ``"1:3 resonance"``, ``"1:4 resonance"``
  (kappa = 1, -1, -1/2, 0: theta = 0, pi, 2 pi / 3, pi / 2), ``"fold-NS"``, ``"flip-NS"`` (Re prod over the
  multipliers other than the pair of (mu - 1), (mu + 1)). Past kappa = +-1 the curve goes on as a neutral-saddle
  curve (a real pair mu, 1/mu: not a bifurcation); `BifurcationCurve.kappa` tells them apart.

"The other multipliers" are all but the one nearest +1 (fold) or -1 (period doubling). The 1:1 and 1:2 tests
of fold and period-doubling curves vanish identically along the curve of an area-preserving map (a conservative
2-d system such as the Mathieu equation has a double multiplier -1 all along its period-doubling curves): leave
them out with ``detect=`` there. Not detected: the degenerate flip (cubic coefficient of the flip normal form),
the Chenciner point (first Lyapunov coefficient of the Neimark-Sacker normal form) and points where a complex pair
crosses the unit circle on a fold or period-doubling curve.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple, Unpack

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import jit_anywhere
from jaxcelt._types import Array
from jaxcelt.orbits.branch import ArclengthStepper, trace_arclength
from jaxcelt.orbits.curve_fold import FoldSystem, codim2_tests
from jaxcelt.orbits.ns_system import NS_TESTS, NSSystem
from jaxcelt.orbits.options import ShootingKeywords, ShootingOptions, resolve_options
from jaxcelt.orbits.points import BIFURCATION_POINT_KINDS
from jaxcelt.orbits.shooting import Chart

__all__ = [
    "CURVE_STATUS",
    "CODIM2_TESTS",
    "BifurcationCurve",
    "CurvePoint",
    "continue_bifurcation",
    "codim2_tests",
    "curve_to_dict",
]

CURVE_STATUS = {
    0: "converged",
    1: "converged after the step was shrunk",
    2: "end of the curve: stopped here (the reason is in `BifurcationCurve.stopped`)",
}
"""``BifurcationCurve.status`` codes (one per point)."""

CODIM2_TESTS = {
    "fold": ("cusp", "1:1 resonance", "fold-flip"),
    "period-doubling": ("fold-flip", "1:2 resonance"),
    "neimark-sacker": NS_TESTS,
}
"""curve kind -> the codimension-two points detected on it (the default of ``detect=``)"""

CURVE_DEFAULTS = ShootingOptions(rtol=1e-10, atol=1e-11, newton_tol=1e-9, newton_max_steps=8)
"""`continue_bifurcation`'s options: as `jaxcelt.orbits.branch.continue_arclength`'s (a corrector that needs more
than 8 Newton iterations has its step halved)."""

_START_TRIES = 4
"""corrector calls (of up to ``newton_max_steps`` iterations each) to refine the start point"""


class CurvePoint(NamedTuple):
    """A codimension-two point located on a curve."""

    kind: str
    """one of `CODIM2_TESTS` of the curve's kind"""
    p1: float
    p2: float
    y: np.ndarray
    """orbit state"""
    multipliers: np.ndarray
    test: float
    """its test function at the located point (0 at the point)"""
    bracket: tuple[int, int]
    """indices of the curve points it lies between"""
    converged: bool
    """the secant iteration reached |test| below 1e-6 of the bracket's largest |test|"""
    kappa: float | None = None
    """kappa = cos(theta) of the critical pair there (Neimark-Sacker curves; None otherwise)"""


class BifurcationCurve(NamedTuple):
    """A curve of fold or period-doubling points from `continue_bifurcation` (host arrays, m points in curve
    order)."""

    kind: str
    """"fold", "period-doubling" or "neimark-sacker\""""
    p1: np.ndarray
    """(m,)"""
    p2: np.ndarray
    """(m,)"""
    y: np.ndarray
    """orbit states (m, n) at the section time"""
    multipliers: np.ndarray
    """Floquet multipliers (m, d) in chart coordinates, by decreasing modulus; one is at +1 (fold) or -1, or a
    pair at e^{+-i theta} (Neimark-Sacker)"""
    tests: dict[str, np.ndarray]
    """test function of each detected kind of point (m,) (`CODIM2_TESTS`)"""
    status: np.ndarray
    """(m,) `CURVE_STATUS` codes"""
    tangents: np.ndarray
    """unit tangents (m, d + 2) in u = (z, p1 / s1, p2 / s2), each in the chart around its own point, oriented
    along the curve"""
    steps: np.ndarray
    """arclength step that reached each point (0 for the start)"""
    points: list[CurvePoint]
    """the located codimension-two points, in curve order"""
    stopped: tuple[str, str]
    """why each end stopped (decreasing end, increasing end; "not traced" for an end not followed):
    "left the bounds", "max points" or "step below ds_min\""""
    start: int
    """index of the start point"""
    kappa: np.ndarray | None = None
    """(m,) kappa = cos(theta) of the pair e^{+-i theta} on the unit circle (Neimark-Sacker curves; None
    otherwise). |kappa| > 1: a neutral saddle (a real pair mu, 1/mu), not a Neimark-Sacker point"""

    @property
    def theta(self) -> np.ndarray | None:
        """(m,) the pair's angle arccos(kappa) in [0, pi] (nan where |kappa| > 1); None but on Neimark-Sacker
        curves."""
        if self.kappa is None:
            return None
        k = np.asarray(self.kappa)
        return np.where(np.abs(k) <= 1.0, np.arccos(np.clip(k, -1.0, 1.0)), np.nan)


def continue_bifurcation(
    vector_field: Callable[[Any, Array, Any], Array],
    y_guess: Array,
    args_of: Callable[[Array, Array], Any],
    period_of: Callable[[Any], Array],
    p_start: tuple[float, float],
    bounds: tuple[tuple[float, float], tuple[float, float]],
    *,
    kind: str = "fold",
    direction: float = 0.0,
    scale: tuple[float, float] = (1.0, 1.0),
    ds: float = 0.02,
    ds_min: float = 1e-6,
    ds_max: float = 0.2,
    max_points: int = 400,
    k: int = 1,
    t0: float = 0.0,
    embed: Chart | None = None,
    chart: Chart | None = None,
    detect: Sequence[str] | None = None,
    locate_steps: int = 12,
    callback: Callable[[int, float, bool], None] | None = None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> BifurcationCurve:
    """Continue a fold, period-doubling or Neimark-Sacker point of a period-k orbit in two parameters (p1, p2).

    Args:
        vector_field: ``f(t, y, args)``, T-periodic in t.
        y_guess: a state near the critical orbit at ``p_start`` (at the section time ``t0``).
        args_of: ``(p1, p2) -> args`` (traceable in both; e.g. two fields of `jaxcelt.CeltParams` set with
            ``dataclasses.replace``).
        period_of: ``args -> T``, the forcing period (may depend on p1, p2).
        p_start: (p1, p2) near a point of the curve; the start is refined at fixed p2 (Newton on the augmented
            system with p1 free), so p2 must be a parameter the curve crosses there. Neimark-Sacker: kappa starts
            at cos(arg mu) of the complex multiplier nearest the unit circle at the guess.
        bounds: ((p1_lo, p1_hi), (p2_lo, p2_hi)): each end of the curve stops once it leaves this box.
        kind: ``"fold"`` (a multiplier +1), ``"period-doubling"`` (-1) or ``"neimark-sacker"`` (a complex pair
            e^{+-i theta}; kappa = cos(theta) is returned in `BifurcationCurve.kappa`).
        direction: +1 / -1 follow the curve from the start towards increasing / decreasing p2 only; 0 both ways.
        scale: (s1, s2): the arclength is measured in (z, p1 / s1, p2 / s2).
        ds, ds_min, ds_max: initial, smallest and largest arclength step; the step is halved when the corrector
            fails and grown x1.5 when it converges in at most 3 Newton iterations.
        max_points: points at most (shared by the two ends).
        k, t0: as in `jaxcelt.orbits.shooting.stroboscopic_map`.
        embed, chart: local coordinates as in `jaxcelt.orbits.shooting.find_periodic_orbit` (default identity;
            e.g. `jaxcelt.orbits.celt.celt_embed` / `celt_chart` for the wobblestone).
        detect: names from ``CODIM2_TESTS[kind]`` to detect and locate (default all of them).
        locate_steps: secant iterations locating each detected point (0: linear interpolation of the test
            function between the bracketing points).
        callback: ``callback(n_points, p2, accepted)`` after every corrector attempt.
        options: `jaxcelt.orbits.options.ShootingOptions` (default `CURVE_DEFAULTS`: rtol 1e-10, atol 1e-11,
            newton_tol 1e-9, newton_max_steps 8).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``; each one given
            overrides it.

    Returns:
        `BifurcationCurve` (host arrays, in curve order from the decreasing-p2 end).
    """
    if kind not in CODIM2_TESTS:
        raise ValueError(f"kind must be one of {sorted(CODIM2_TESTS)}, got {kind!r}")
    detect = tuple(CODIM2_TESTS[kind] if detect is None else detect)
    unknown = sorted(set(detect) - set(CODIM2_TESTS[kind]))
    if unknown:
        raise ValueError(f"detect: {unknown} are not detected on a {kind} curve (choose from {CODIM2_TESTS[kind]})")
    if direction not in (-1, 0, 1):
        raise ValueError(f"direction must be -1, 0 or +1, got {direction!r}")
    (lo1, hi1), (lo2, hi2) = bounds
    if not (lo1 <= p_start[0] <= hi1 and lo2 <= p_start[1] <= hi2):
        raise ValueError(f"p_start {tuple(p_start)} lies outside bounds {bounds}")
    opts = resolve_options(options, CURVE_DEFAULTS, caller="continue_bifurcation", **settings)
    embed, chart = embed or _identity, chart or _identity
    s1, s2 = (float(x) for x in scale)
    if kind == "neimark-sacker":
        curve = NSSystem(vector_field, args_of, period_of, (s1, s2), k, t0, embed, chart, opts)
    else:
        curve = FoldSystem(
            vector_field, args_of, period_of, BIFURCATION_POINT_KINDS[kind], (s1, s2), k, t0, embed, chart, opts,
            "cusp" in detect,
        )  # fmt: skip
    start_of, stepper = _stepper(curve)

    # the start: the chart around y_guess, borders there (and kappa of the pair nearest the unit circle), Newton
    # at fixed p2
    y_guess = jnp.asarray(y_guess, dtype=float)
    p1, p2 = jnp.asarray(p_start[0], float), jnp.asarray(p_start[1], float)
    z0 = chart(y_guess, y_guess, args_of(p1, p2))
    u, ref = start_of(z0, jnp.stack([p1 / s1, p2 / s2]), y_guess)
    fixed_p2 = jnp.zeros(u.shape[0]).at[-1].set(1.0)
    good = False
    for _ in range(_START_TRIES):
        u_new, good, _ = stepper.corrector(u, fixed_p2, 0.0, ref)
        if not bool(jnp.all(jnp.isfinite(u_new))):
            break
        u, _, ref = stepper.recentre(u_new, fixed_p2, ref)
        if bool(good):
            break
    if not bool(good):
        raise ValueError(
            f"y_guess, p_start: no {kind} point of a period-{k} orbit found near them at p2 = {p_start[1]}"
        )
    host = lambda tree: jax.tree_util.tree_map(np.asarray, tree)  # noqa: E731
    u0, ref0, obs0 = np.asarray(u), host(ref), host(stepper.observe(u, ref))

    def stop(uu):
        q1, q2 = uu[-2] * s1, uu[-1] * s2
        return None if (lo1 <= q1 <= hi1 and lo2 <= q2 <= hi2) else "left the bounds"

    steps = dict(ds=ds, ds_min=ds_min, ds_max=ds_max, callback=callback, stop=stop)
    never = lambda lam: False  # noqa: E731
    empty = dict(ref=[], lam=[], t=[], obs=[], h=[], u=[], shrunk=[])
    bwd, fwd, s_lo, s_hi = empty, empty, "not traced", "not traced"
    if direction <= 0:
        bwd, s_lo = trace_arclength(
            stepper, u, ref, -1.0, never, (max_points - 1) // (2 if direction == 0 else 1), **steps
        )
    if direction >= 0:
        fwd, s_hi = trace_arclength(stepper, u, ref, 1.0, never, max_points - 1 - len(bwd["u"]), **steps)
    t_start = fwd["t"][0] if fwd["t"] else -bwd["t"][0]

    # one curve in order: the decreasing-p2 end reversed (tangents flipped)
    U = bwd["u"][::-1] + [u0] + fwd["u"]
    REF = bwd["ref"][::-1] + [ref0] + fwd["ref"]
    OBS = bwd["obs"][::-1] + [obs0] + fwd["obs"]
    TT = [-x for x in bwd["t"][1:][::-1]] + [np.asarray(t_start)] + fwd["t"][1:]
    H = bwd["h"][::-1] + [0.0] + fwd["h"]
    shrunk = bwd["shrunk"][::-1] + [False] + fwd["shrunk"]
    m, start = len(U), len(bwd["u"])
    status = np.where(np.asarray(shrunk), 1, 0)
    if s_lo != "not traced":
        status[0] = 2
    if s_hi != "not traced":
        status[-1] = 2

    def tests_of(obs) -> dict[str, float]:
        out = curve.tests(obs, kind)
        return {name: out[name] for name in detect}

    tests = [tests_of(o) for o in OBS]
    points: list[CurvePoint] = []
    for i in range(1, m):
        for name in detect:
            a, b = tests[i - 1][name], tests[i][name]
            if np.sign(a) == np.sign(b):
                continue
            # along the curve from point i-1 (its chart and tangent; the tangent is oriented along the curve)
            u_a, ref_a, t_a = jnp.asarray(U[i - 1]), jax.tree_util.tree_map(jnp.asarray, REF[i - 1]), TT[i - 1]
            h_b = float(np.dot(t_a, _in_chart(curve, U[i], REF[i], REF[i - 1]) - U[i - 1]))
            points.append(_locate(stepper, curve, tests_of, name, u_a, ref_a, jnp.asarray(t_a), h_b, a, b,
                                  locate_steps, (i - 1, i), OBS[i - 1], OBS[i]))  # fmt: skip

    p = np.asarray(U)[:, -2:] * np.array([s1, s2])
    return BifurcationCurve(
        kind=kind,
        p1=p[:, 0],
        p2=p[:, 1],
        y=np.asarray([o["y"] for o in OBS]),
        multipliers=np.asarray([o["multipliers"] for o in OBS]),
        tests={name: np.asarray([t[name] for t in tests]) for name in detect},
        status=status,
        tangents=np.asarray(TT),
        steps=np.asarray(H),
        points=points,
        stopped=(s_lo, s_hi),
        start=start,
        kappa=np.asarray([float(o["kappa"]) for o in OBS]) if kind == "neimark-sacker" else None,
    )


def _identity(z: Array, ref: Array, args: Any) -> Array:
    return z


@functools.lru_cache(maxsize=16)
def _cached_stepper(curve: FoldSystem | NSSystem) -> tuple[Callable, ArclengthStepper]:
    return jit_anywhere(curve.start, filter_jit=False), ArclengthStepper.build(
        curve.residual, curve.recentre, curve.observe, newton_tol=curve.options.newton_tol,
        newton_max_steps=curve.options.newton_max_steps,
    )  # fmt: skip


def _stepper(curve: FoldSystem | NSSystem) -> tuple[Callable, ArclengthStepper]:
    """The jitted stepper of ``curve``, kept for the next call with the same functions and settings (so that a
    second call does not compile again); built afresh where a setting is unhashable."""
    try:
        hash(curve)
    except TypeError:
        return _cached_stepper.__wrapped__(curve)
    return _cached_stepper(curve)


def _in_chart(curve: FoldSystem | NSSystem, u: np.ndarray, ref: Any, ref_new: Any) -> np.ndarray:
    """u (in the chart of ``ref``) in the chart of ``ref_new``."""
    a, e = curve.args(jnp.asarray(u)), curve.extra
    y = curve.embed(jnp.asarray(u[:-e]), jnp.asarray(ref[0]), a)
    return np.concatenate([np.asarray(curve.chart(y, jnp.asarray(ref_new[0]), a)), u[-e:]])


def _locate(stepper, curve, tests_of, name, u_a, ref_a, t_a, h_b, ta, tb, iters, bracket, obs_a, obs_b):
    """A zero of test ``name`` between two curve points: Illinois iteration on the arclength h from point a (each
    iterate a corrector solve from a along its tangent); linear interpolation if ``iters`` is 0 or a solve
    fails."""
    lo, hi, f_lo, f_hi = 0.0, h_b, ta, tb
    obs, f, side = None, None, 0
    for _ in range(iters):
        h = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        u, good, _ = stepper.corrector(u_a, t_a, h, ref_a)
        if not bool(good):
            obs = None
            break
        obs = jax.tree_util.tree_map(np.asarray, stepper.observe(u, ref_a))
        f = tests_of(obs)[name]
        if np.sign(f) == np.sign(f_lo):
            lo, f_lo = h, f
            f_hi = f_hi / 2 if side == -1 else f_hi
            side = -1
        else:
            hi, f_hi = h, f
            f_lo = f_lo / 2 if side == 1 else f_lo
            side = 1
        if abs(f) <= 1e-6 * max(abs(ta), abs(tb)):
            break
    if obs is None:  # linear interpolation between the bracketing points
        w = ta / (ta - tb)
        u = (1 - w) * np.asarray(u_a) + w * np.asarray(_in_chart(curve, np.asarray(u_a + h_b * t_a), ref_a, ref_a))
        mu = (1 - w) * obs_a["multipliers"] + w * obs_b["multipliers"]
        y = (1 - w) * obs_a["y"] + w * obs_b["y"]
        f, conv = 0.0, False
    else:
        u, mu, y = np.asarray(u), obs["multipliers"], obs["y"]
        conv = abs(f) <= 1e-6 * max(abs(ta), abs(tb))
    s1, s2 = curve.scale
    kappa = float(u[-3]) if curve.extra == 3 else None
    return CurvePoint(name, float(u[-2] * s1), float(u[-1] * s2), np.asarray(y), np.asarray(mu), float(f), bracket,
                      bool(conv), kappa)  # fmt: skip


def _pairs(mu: np.ndarray) -> list[list[float]]:
    return [[float(z.real), float(z.imag)] for z in np.asarray(mu)]


def curve_to_dict(curve: BifurcationCurve, names: tuple[str, str] = ("p1", "p2")) -> dict[str, Any]:
    """A JSON-ready dict of a curve: both parameters (named ``names``), the states, the multipliers (complex as
    [re, im] pairs), the status per point, the test functions and the located points."""
    n1, n2 = names
    return {
        "kind": curve.kind,
        n1: [float(v) for v in curve.p1],
        n2: [float(v) for v in curve.p2],
        "state": [[float(v) for v in y] for y in curve.y],
        "multipliers": [_pairs(m) for m in curve.multipliers],
        "status": [int(s) for s in curve.status],
        "status_codes": {str(k): v for k, v in CURVE_STATUS.items()},
        "tests": {k: [float(v) for v in vals] for k, vals in curve.tests.items()},
        "stopped": list(curve.stopped),
        "start": int(curve.start),
        **({} if curve.kappa is None else {"kappa": [float(v) for v in curve.kappa]}),
        "points": [
            {
                "kind": pt.kind, n1: pt.p1, n2: pt.p2, "state": [float(v) for v in pt.y],
                "multipliers": _pairs(pt.multipliers), "test": pt.test, "bracket": list(pt.bracket),
                "converged": pt.converged, **({} if pt.kappa is None else {"kappa": pt.kappa}),
            }
            for pt in curve.points
        ],
    }  # fmt: skip
