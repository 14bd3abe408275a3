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

from ._types import Array
from .periodic import PeriodicOrbit, find_periodic_orbit

__all__ = ["Bifurcation", "OrbitBranch", "continue_periodic_orbit", "BIFURCATION_KINDS"]

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
