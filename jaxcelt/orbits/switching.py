"""Branch switching: the period-2k orbit born at a period doubling of a period-k branch.

At a period doubling (a `jaxcelt.orbits.points.Bifurcation` of kind "period-doubling" on a branch of
`jaxcelt.orbits.branch`) the period-k orbit has a Floquet multiplier at -1; the period-2k orbit bifurcating there
lies, to first order, along that multiplier's eigenvector. `switch_at_period_doubling` starts a Newton solve of
the period-2k problem from there, on the side where the new orbit exists; the orbit it returns starts the new
branch (`jaxcelt.orbits.branch.continue_arclength` with ``k=2k``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import jax.numpy as jnp
import numpy as np

from jaxcelt._types import Array
from jaxcelt.orbits.options import ShootingOptions, resolve_options
from jaxcelt.orbits.points import Bifurcation
from jaxcelt.orbits.shooting import PeriodicOrbit, find_periodic_orbit, stroboscopic_map, variational_map

__all__ = ["switch_at_period_doubling"]


def switch_at_period_doubling(
    vector_field: Callable[[Any, Array, Any], Array],
    bifurcation: Bifurcation,
    args_of: Callable[[Array], Any],
    period_of: Callable[[Any], Array],
    *,
    k: int = 1,
    lam: float,
    eps: float = 1e-2,
    options: ShootingOptions | None = None,
    **find_kw,
) -> PeriodicOrbit:
    """The period-2k orbit born at a period doubling of a period-k branch, found at ``lam``.

    Starts from the PD point +- ``eps`` along the eigenvector of the multiplier nearest -1 of
    the period-k monodromy there (`variational_map`), and solves the period-2k problem at
    ``lam`` (on the side of the doubling where the new orbit exists) with `find_periodic_orbit`.
    The sign giving a converged orbit that is not the period-k one (its two section points
    differ by more than eps/10) is returned; ``status`` is nonzero if neither does. ``options`` and
    ``**find_kw`` (t0, embed, chart, single solver and Newton settings) go to `find_periodic_orbit`; the
    maps at the period-k orbit use the same solver settings.
    """
    if bifurcation.kind != "period-doubling":
        raise ValueError(f"bifurcation: expected a period-doubling, got {bifurcation.kind!r}")
    single = {key: find_kw.pop(key, None) for key in ("solver", "rtol", "atol", "max_steps")}
    opts = resolve_options(options, ShootingOptions(), caller="switch_at_period_doubling", **single)
    ode = dict(t0=find_kw.get("t0", 0.0), options=opts)
    args_pd = args_of(jnp.asarray(bifurcation.value))
    y_pd = jnp.asarray(bifurcation.y)
    _, Phi, _, _ = variational_map(vector_field, y_pd, args_pd, period=period_of(args_pd), k=k, **ode)
    mu, vecs = np.linalg.eig(np.asarray(Phi))
    v = np.real(vecs[:, np.argmin(np.abs(mu + 1))])
    v = v / np.linalg.norm(v)
    args = args_of(jnp.asarray(lam))
    orb = None
    for sign in (1.0, -1.0):
        orb = find_periodic_orbit(
            vector_field, y_pd + sign * eps * v, args, period=period_of(args), k=2 * k, options=opts, **find_kw
        )
        if int(orb.status) == 0:
            y1, _, _ = stroboscopic_map(vector_field, orb.y, args, period=period_of(args), k=k, **ode)
            if float(jnp.max(jnp.abs(y1 - orb.y))) > eps / 10:
                return orb
    return orb
