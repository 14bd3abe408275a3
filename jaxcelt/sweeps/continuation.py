"""Global continuation of the forced wobblestone's attractors over one parameter (`continue_attractors`).

At every value of a `jaxcelt.CeltParams` field the same fresh starts (`jaxcelt.attractor_starts`) and the
seeds handed on by the previous value's attractors run as lanes of `jaxcelt.sweeps.api.sweep` (the lane
engine, stroboscopic samples); the attractors are identified in the section coordinates
(v, omega, n, cos psi, sin psi) -- the position r_C on the base is cyclic and left out, psi is an angle --
periodic ones refined by `jaxcelt.periodic_orbit` (Floquet multipliers), the others by their section point
sets (and lambda_1 with ``lyapunov_periods > 0``); lanes that left the model's validity (lift-off,
n3 <= 0) are "tipping over". Matching, basin fractions, the dataset and the resumable files are the
model-agnostic `jaxcelt.sweeps.continuation_core`; settings are one `ContinuationOptions`.
"""

from __future__ import annotations

import json
from typing import Any

import jax
import numpy as np

from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.physics.params import PARAM_NAMES, CeltParams
from jaxcelt.sweeps.api import sweep
from jaxcelt.sweeps.census import AttractorStarts, attractor_starts
from jaxcelt.sweeps.continuation_core import LaneBatch, Refined, SectionModel, continue_section_attractors
from jaxcelt.sweeps.continuation_options import ContinuationOptions, resolve_continuation_options
from jaxcelt.sweeps.options import SweepOptions

__all__ = ["continue_attractors", "celt_section_model", "celt_section_coords", "DEFAULT_STARTS"]

DEFAULT_STARTS: dict[str, Any] = dict(psi0=(0.0, 2 * np.pi), tilt=(-0.1, 0.1), n=(16, 4))
"""Fresh starts when none are given: `jaxcelt.attractor_starts` on a 16 x 4 grid of heading psi0 over a full
turn and tilt in +-0.1 rad, at rest on the base (64 starts)."""
_PAD = 16  # lanes per value are padded to a multiple of this with copies of the last (discarded)


def celt_section_coords(y: np.ndarray) -> np.ndarray:
    """Section coordinates (..., 11) of wobblestone states (..., 13): (v, omega, n, cos psi, sin psi)."""
    y = np.asarray(y, dtype=float)
    with np.errstate(invalid="ignore"):  # a failed lane's inf samples give NaN coordinates (the lane is marked)
        return np.concatenate([y[..., 0:9], np.cos(y[..., 12:13]), np.sin(y[..., 12:13])], axis=-1)


def _lane_options(o: ContinuationOptions) -> SweepOptions:
    base = o.sweep if o.sweep is not None else SweepOptions(stop_on_invalid=True)
    return base.replace(transient_periods=o.transient_periods, sample_periods=o.sample_periods,
                        lyapunov_periods=o.lyapunov_periods, out=None, progress=False, on_chunk=None)  # fmt: skip


def celt_section_model(params: CeltParams, name: str) -> SectionModel:
    """The wobblestone as a `SectionModel` with the field ``name`` of ``params`` continued: lanes of
    `jaxcelt.sweeps.api.sweep`, coordinates `celt_section_coords`, refinement `jaxcelt.periodic_orbit`."""

    def run(value: float, y0: np.ndarray, o: ContinuationOptions) -> LaneBatch:
        so = _lane_options(o)
        L = y0.shape[0]
        Lp = -(-L // _PAD) * _PAD  # few distinct batch sizes: few compilations as the number of seeds changes
        yp = np.concatenate([y0, np.repeat(y0[-1:], Lp - L, axis=0)]) if Lp > L else y0
        r = sweep(params, name, [value], y0=yp, options=so)
        r = jax.tree_util.tree_map(lambda x: np.asarray(x)[:, :L], r)
        status, valid = np.asarray(r.status)[0], np.asarray(r.valid)[0]
        outcome = np.where(np.isin(status, (2, 4)), 1, np.where(status != 0, 2, np.where(valid, 0, 1)))  # 4: on its side
        have = o.lyapunov_periods > 0
        return LaneBatch(
            samples=np.asarray(r.samples)[0], t_samples=np.asarray(r.t_samples)[0], outcome=outcome,
            lyapunov=np.asarray(r.lyapunov, float)[0] if have else None,
            lyapunov_stderr=np.asarray(r.lyapunov_stderr, float)[0] if have else None,
        )  # fmt: skip

    def refine(value: float, state: np.ndarray, t: float, k: int, o: ContinuationOptions) -> Refined:
        from jaxcelt.orbits.celt import periodic_orbit

        so = _lane_options(o)
        orb = periodic_orbit(params.replace(**{name: value}), state, k=int(k), t0=float(t),
                             contact_law=so.contact_law, options=o.shooting)  # fmt: skip
        st = int(orb.status)
        status = {0: "converged", 1: "not converged", 2: "solver failed"}.get(st, "error")
        return Refined(status=status, state=np.asarray(orb.y), multipliers=np.abs(np.asarray(orb.multipliers)))

    from jaxcelt.provenance import machine, source_commit
    from jaxcelt.sweeps.dataset import _jsonable
    from jaxcelt.versions import versions

    pjson = json.dumps(_jsonable(params.as_dict()), sort_keys=True)
    attrs = {
        "params_json": pjson,
        "versions_json": json.dumps(versions(), sort_keys=True),
        "provenance_json": json.dumps({**source_commit(), "machine": machine()}, sort_keys=True),
        "section_coordinates": "v1 v2 v3 omega1 omega2 omega3 n1 n2 n3 cos(psi) sin(psi)",
        "model": "Awrejcewicz & Kudra (2014), DNC 3(2) 123-132; equations in MODEL.md",
    }
    return SectionModel(run=run, coords=celt_section_coords, refine=refine, key=f"wobblestone {name} {pjson}",
                        state_names=tuple(STATE_NAMES), attrs=attrs)  # fmt: skip


def continue_attractors(
    params: CeltParams,
    name: str,
    values: Any,
    *,
    starts: AttractorStarts | Any = None,
    options: ContinuationOptions | None = None,
    **keywords: Any,
):
    """Global continuation of the wobblestone's attractors over ``values`` of the field ``name``.

    Args:
        params: the stone and the base; the field ``name`` is replaced by each value.
        name: a `CeltParams` field (``"omega_pi"``, ``"q_pi"``, ``"mu"``, ...).
        values: 1-D finite values, continued in this order.
        starts: `jaxcelt.AttractorStarts` or states (N, 13), the same at every value; None:
            `attractor_starts` (params, **`DEFAULT_STARTS`) (64 starts at rest).
        options: `ContinuationOptions` (lane lengths, tolerances, matching, seeds, refinement, ``sweep``
            for the lane engine's settings, ``out`` for resumable files, ``progress``); or its fields as
            keywords, which replace those of ``options``.

    Returns:
        `xarray.Dataset` (attractor id x value: basin fraction and its binomial error, kind, period, largest
        Floquet multiplier modulus, representative section state; tipping-over fraction per value; each fresh
        lane's outcome; see `jaxcelt.sweeps.continuation_result`). `continuation_summary` turns it into a
        JSON-ready table.
    """
    o = resolve_continuation_options(options, keywords, caller="continue_attractors")
    if not isinstance(params, CeltParams):
        raise ValueError(f"continue_attractors: 'params' must be a CeltParams, got {type(params).__name__}")
    if name not in PARAM_NAMES:
        raise ValueError(f"continue_attractors: 'name' must be a CeltParams field, got {name!r}; known: {PARAM_NAMES}")
    if np.ndim(getattr(params, name)) != 0:
        raise ValueError(f"continue_attractors: 'params' must be a single parameter set (scalar {name})")
    try:
        vals = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"continue_attractors: 'values' must be numbers, got {values!r}") from None
    if vals.ndim != 1 or vals.size == 0 or not np.all(np.isfinite(vals)):
        raise ValueError(
            f"continue_attractors: 'values' must be a non-empty 1-D array of finite numbers, got {values!r}"
        )
    for v in vals:  # every value must make valid parameters (ValueError naming the field)
        params.replace(**{name: float(v)})
    if name == "omega_pi" and not np.all(vals > 0):
        raise ValueError("continue_attractors: 'values' of omega_pi must be > 0 (stroboscopic sampling)")
    if o.sweep is not None and not isinstance(o.sweep, SweepOptions):
        raise ValueError(f"continue_attractors: 'sweep' must be a SweepOptions or None, got {type(o.sweep).__name__}")
    if starts is None:
        starts = attractor_starts(params, **DEFAULT_STARTS)
    y0 = starts.y0 if isinstance(starts, AttractorStarts) else starts
    try:
        y0 = np.asarray(y0, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("continue_attractors: 'starts' must be AttractorStarts or states (N, 13)") from None
    if y0.ndim != 2 or y0.shape[1] != 13 or y0.shape[0] == 0 or not np.all(np.isfinite(y0)):
        raise ValueError(f"continue_attractors: 'starts' must be finite states of shape (N, 13), got {y0.shape}")
    lane_coords = dict(psi0=starts.psi0, tilt=starts.tilt) if isinstance(starts, AttractorStarts) else None
    return continue_section_attractors(celt_section_model(params, name), name, vals, y0, lane_coords=lane_coords,
                                       options=o)  # fmt: skip
