"""Two-parameter curves of the wobblestone's orbit bifurcations: a fold, period doubling or Neimark-Sacker point
of a period-k orbit (`jaxcelt.orbits.celt`) continued in two `CeltParams` fields by `jaxcelt.orbits.curves.continue_bifurcation`, in the
chart of the contact manifold."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Unpack

import diffrax
import equinox as eqx
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import ArrayLike
from jaxcelt.orbits.celt import GUESS_MANIFOLD_TOL, _check_params, _period, celt_chart, celt_embed
from jaxcelt.orbits.curves import BifurcationCurve, continue_bifurcation
from jaxcelt.orbits.options import ShootingKeywords, ShootingOptions, resolve_options
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import CeltField
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import check_state

CURVE_DEFAULTS = ShootingOptions(rtol=1e-10, atol=1e-11, max_steps=200_000, newton_tol=1e-9, newton_max_steps=8)
"""`continue_orbit_bifurcation`'s options (`jaxcelt.orbits.curves.CURVE_DEFAULTS` with the stone's solver steps)."""

__all__ = ["continue_orbit_bifurcation", "CURVE_DEFAULTS"]


def _curve_fields(params: CeltParams, name) -> tuple[str, ...]:
    """The CeltParams fields a curve parameter sets: ``"mu"`` -> ("mu",); ``"eps=eps_R"`` -> ("eps", "eps_R")."""
    fields = tuple(name.split("=")) if isinstance(name, str) else ()
    if not fields or len(set(fields)) != len(fields):
        raise ValueError(f"continue_orbit_bifurcation: parameter name {name!r} must be a CeltParams field or 'a=b'")
    for f in fields:
        if f not in CeltParams.__dataclass_fields__ or np.ndim(getattr(params, f)) != 0:
            raise ValueError(f"continue_orbit_bifurcation: parameter {name!r}: {f!r} is not a scalar CeltParams field")
    values = {float(getattr(params, f)) for f in fields}
    if len(values) != 1:
        raise ValueError(
            f"continue_orbit_bifurcation: parameter {name!r}: the fields it sets together differ in params "
            f"({', '.join(f'{f} = {float(getattr(params, f)):g}' for f in fields)})"
        )
    return fields


def _args_of(params: CeltParams, f1: tuple[str, ...], f2: tuple[str, ...]) -> Callable:
    """``(p1, p2) -> params`` with the fields ``f1`` set to p1 and ``f2`` to p2. The same function object comes back
    for the same stone (equal values of the other fields), so that `continue_bifurcation`'s compiled stepper,
    keyed on it, is reused by the next call rather than compiled again (a call costs minutes of compilation)."""
    others = tuple(
        (f.name, np.asarray(getattr(params, f.name)).tobytes())
        for f in dataclasses.fields(params)
        if f.name not in f1 + f2
    )
    fn, stone = _args_of_cached(others, f1, f2)
    stone.setdefault("params", params)  # any stone of this key: the fields that differ are the ones args_of sets
    return fn


@functools.lru_cache(maxsize=16)
def _args_of_cached(key: tuple, f1: tuple[str, ...], f2: tuple[str, ...]) -> tuple[Callable, dict]:
    """A cache of `_args_of`'s functions, keyed on the other fields' values (bytes): 16 stones at most."""
    fields = f1 + f2
    stone: dict = {}

    def args_of(p1, p2):
        values = [jnp.asarray(p1, float)] * len(f1) + [jnp.asarray(p2, float)] * len(f2)
        return eqx.tree_at(lambda p: [getattr(p, f) for f in fields], stone["params"], values)

    return args_of, stone


def continue_orbit_bifurcation(
    params: CeltParams,
    y_guess: ArrayLike,
    names: tuple[str, str],
    bounds: tuple[tuple[float, float], tuple[float, float]],
    *,
    kind: str = "fold",
    k: int = 1,
    direction: float = 0.0,
    scale: tuple[float, float] = (1.0, 1.0),
    ds: float = 0.05,
    ds_min: float = 1e-5,
    ds_max: float = 0.3,
    max_points: int = 60,
    detect=None,
    locate_steps: int = 12,
    callback=None,
    contact_law: AbstractContactLaw | str | None = None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> BifurcationCurve:
    """Continue a fold, period doubling or Neimark-Sacker point of a wobblestone period-k orbit in two parameters.

    `jaxcelt.orbits.curves.continue_bifurcation` in the chart of the contact manifold (`celt_embed`,
    `celt_chart`; section t0 = 0), the two parameters ``names = (p1, p2)`` being scalar `CeltParams`
    fields. A name ``"a=b"`` sets the fields a and b to one value (e.g. ``"eps=eps_R"``: both contact
    smoothing parameters together); both must be equal in ``params``. The start is the values of the
    two parameters in ``params``: the point is refined there at fixed p2 with p1 free, so ``params`` and
    ``y_guess`` should be near a located point, e.g. ``locate_orbit_bifurcation(params, y, "omega_pi",
    14.88)``'s ``value`` and ``y`` for ``names = ("omega_pi", "q_pi")``.

    Args:
        params: the stone at the start point (p1 near the bifurcation value, p2 the start of the curve).
        y_guess: (13,) orbit state at t0 = 0 near the critical orbit (within `GUESS_MANIFOLD_TOL` of the
            contact manifold).
        names: (p1, p2): two different scalar `CeltParams` fields (or ``"a=b"`` groups).
        bounds: ((p1_lo, p1_hi), (p2_lo, p2_hi)) containing the start; each end of the curve stops when it
            leaves this box.
        kind: ``"fold"`` (a multiplier at +1), ``"period-doubling"`` (-1) or ``"neimark-sacker"`` (a complex pair
            on the unit circle; `jaxcelt.orbits.curves.BifurcationCurve.kappa` is the cosine of its angle). The
            mirror orbit (psi -> psi + pi, `jaxcelt.orbits.celt`) has its own curve: start from its state.
        k: forcing periods per return.
        direction, scale, ds, ds_min, ds_max, max_points, detect, locate_steps, callback: as in
            `jaxcelt.orbits.curves.continue_bifurcation` (the arclength is measured in the 8 chart
            coordinates, m/s, rad/s, rad and 1, and in (p1 / s1, p2 / s2): choose ``scale`` so that the
            parameters move by about one unit over the range of interest).
        contact_law: the model's law.
        options: `jaxcelt.orbits.options.ShootingOptions` (default `CURVE_DEFAULTS`: Dopri8, rtol 1e-10,
            atol 1e-11, max_steps 200 000, newton_tol 1e-9, newton_max_steps 8 per corrector step).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``; each one
            given overrides it.

    Returns:
        `jaxcelt.orbits.curves.BifurcationCurve` (``p1``, ``p2``: the two parameters; ``y``: states at t0 = 0).
    """
    _check_params(params)
    if isinstance(names, str) or len(tuple(names)) != 2:
        raise ValueError(f"continue_orbit_bifurcation: 'names' must be two parameter names, got {names!r}")
    f1, f2 = (_curve_fields(params, n) for n in names)
    if set(f1) & set(f2):
        raise ValueError(f"continue_orbit_bifurcation: parameters {names[0]!r} and {names[1]!r} share a field")
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise ValueError(f"continue_orbit_bifurcation: 'k' must be a positive int, got {k!r}")
    b = np.asarray(bounds, dtype=float)
    if b.shape != (2, 2) or not np.all(np.isfinite(b)):
        raise ValueError(f"continue_orbit_bifurcation: 'bounds' must be ((lo, hi), (lo, hi)), got {bounds!r}")
    start = (float(getattr(params, f1[0])), float(getattr(params, f2[0])))
    for name, v, (lo, hi) in zip(names, start, b, strict=True):
        if not lo <= v <= hi:
            raise ValueError(
                f"continue_orbit_bifurcation: parameter {name!r} = {v:g} lies outside its bounds ({lo:g}, {hi:g})"
            )
    check_state(y_guess, params, name="y_guess", tol=GUESS_MANIFOLD_TOL)
    opts = resolve_options(options, CURVE_DEFAULTS, caller="continue_orbit_bifurcation", **settings)
    return continue_bifurcation(
        CeltField(get_contact_law(contact_law)),
        jnp.asarray(y_guess, float),
        _args_of(params, f1, f2),
        _period,
        start,
        ((float(b[0, 0]), float(b[0, 1])), (float(b[1, 0]), float(b[1, 1]))),
        kind=kind,
        direction=direction,
        scale=scale,
        ds=ds,
        ds_min=ds_min,
        ds_max=ds_max,
        max_points=max_points,
        k=k,
        embed=celt_embed,
        chart=celt_chart,
        detect=detect,
        locate_steps=locate_steps,
        callback=callback,
        options=dataclasses.replace(opts, solver=opts.solver or diffrax.Dopri8()),
    )
