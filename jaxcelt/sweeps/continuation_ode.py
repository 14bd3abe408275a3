"""A `SectionModel` for any periodically forced ODE dy/dt = f(t, y, args): lanes by diffrax, refinement by shooting.

`forced_ode_model` turns a vector field, the map from the continued parameter's value to the field's
``args`` and the forcing period into what `jaxcelt.sweeps.continuation_core.continue_section_attractors`
needs: a lane runner (all lanes of a value in one vmapped `diffrax.diffeqsolve`, sampled at
t_j = (transient + j) T; a lane whose solve fails is marked, never raises), the section coordinates and a
refiner (`jaxcelt.orbits.shooting.find_periodic_orbit`: Newton on the stroboscopic map, Floquet multipliers).
It is how the known-answer tests run the forced two-well Duffing oscillator through the same continuation
as the wobblestone.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._compile_options import jit_anywhere
from jaxcelt._diffrax_adapter import diffeqsolve
from jaxcelt.orbits.shooting import find_periodic_orbit
from jaxcelt.sweeps.continuation_core import LaneBatch, Refined, SectionModel, _identity
from jaxcelt.sweeps.continuation_options import ContinuationOptions

__all__ = ["forced_ode_model"]

_PAD = 8  # lanes are padded to a multiple of this (fewer recompilations as the number of seeds changes)


def _traced(x: Any) -> Any:
    """Numbers as float64 arrays (traced, not static: a new value does not recompile)."""
    return jax.tree_util.tree_map(lambda v: jnp.asarray(v, dtype=float), x)


@eqx.filter_jit
def _lanes(field, solver, y0s, args, period, transient, n_samples, rtol, atol, max_steps):
    ts = (transient + jnp.arange(n_samples)) * period

    def one(y0):
        sol = diffeqsolve(
            diffrax.ODETerm(field), solver, t0=0.0, t1=ts[-1], dt0=None, y0=y0, args=args,
            saveat=diffrax.SaveAt(ts=ts), stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol),
            max_steps=max_steps, throw=False,
        )  # fmt: skip
        return sol.ys, sol.result == diffrax.RESULTS.successful

    ys, ok = jax.vmap(one)(y0s)
    return ts, ys, ok


@jit_anywhere
def _orbit(field, y, args, period, t0, *, k, options):
    orb = find_periodic_orbit(field, y, args, period=period, k=k, t0=t0, options=options)
    return orb.status, orb.y, jnp.abs(orb.multipliers)


def forced_ode_model(
    vector_field: Callable[[Any, Any, Any], Any],
    args_of: Callable[[float], Any],
    period_of: Callable[[float], float],
    *,
    key: str,
    valid: Callable[[np.ndarray], np.ndarray] | None = None,
    coords: Callable[[np.ndarray], np.ndarray] | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-9,
    atol: float = 1e-11,
    max_steps: int = 200_000,
    state_names: tuple[str, ...] | None = None,
) -> SectionModel:
    """The `SectionModel` of dy/dt = f(t, y, args), T-periodic in t.

    Args:
        vector_field: ``f(t, y, args)`` (JAX).
        args_of: the continued parameter's value -> ``args`` (a pytree of arrays).
        period_of: the value -> forcing period T [time units]; lanes start at t = 0, a section time.
        key: text naming the model and its fixed parameters (part of the resume fingerprint).
        valid: ``valid(samples (L, S, d)) -> (L, S) bool``: where the model holds; a lane with an invalid
            sample has left its validity (outcome "tipping over"). None: always valid.
        coords: section coordinates (see `SectionModel`); None: the state.
        solver, rtol, atol, max_steps: diffrax settings of the lanes (default Tsit5, 1e-9, 1e-11, 200 000);
            the refinement takes `ContinuationOptions.shooting`.
    """
    for nm, x in (("rtol", rtol), ("atol", atol)):
        if not (np.isfinite(x) and x > 0):
            raise ValueError(f"forced_ode_model: {nm!r} must be a positive number, got {x!r}")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise ValueError(f"forced_ode_model: 'max_steps' must be a positive int, got {max_steps!r}")
    if not callable(vector_field):
        raise ValueError("forced_ode_model: 'vector_field' must be callable")
    solver = solver if solver is not None else diffrax.Tsit5()

    def run(value: float, y0: np.ndarray, o: ContinuationOptions) -> LaneBatch:
        L = y0.shape[0]
        Lp = -(-L // _PAD) * _PAD
        yp = np.concatenate([y0, np.repeat(y0[-1:], Lp - L, axis=0)]) if Lp > L else y0
        ts, ys, ok = _lanes(vector_field, solver, jnp.asarray(yp), _traced(args_of(value)), _traced(period_of(value)),
                            int(o.transient_periods), int(o.sample_periods), rtol, atol, max_steps)  # fmt: skip
        ys, ok = np.asarray(ys)[:L], np.asarray(ok)[:L]
        finite = np.all(np.isfinite(ys), axis=(1, 2))
        outcome = np.where(ok & finite, 0, 2)
        if valid is not None:
            inside = np.all(np.asarray(valid(np.where(np.isfinite(ys), ys, 0.0))), axis=1)
            outcome = np.where((outcome == 0) & ~inside, 1, outcome)
        return LaneBatch(samples=ys, t_samples=np.broadcast_to(np.asarray(ts), ys.shape[:2]), outcome=outcome)

    def refine(value: float, state: np.ndarray, t: float, k: int, o: ContinuationOptions) -> Refined:
        status, y, mu = _orbit(vector_field, jnp.asarray(state), _traced(args_of(value)), _traced(period_of(value)),
                               _traced(t), k=int(k), options=o.shooting)  # fmt: skip
        name = {0: "converged", 1: "not converged", 2: "solver failed"}.get(int(status), "error")
        return Refined(status=name, state=np.asarray(y), multipliers=np.asarray(mu))

    return SectionModel(run=run, coords=coords or _identity, refine=refine, key=str(key), state_names=state_names)
