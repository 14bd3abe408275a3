"""Following attractors through a parameter: each value starts where the previous value ended.

`follow_attractor` walks the values in order (up, down, or both) and starts each value from the
previous value's final state (the last stroboscopic sample; base phase omega_pi t = 0 mod 2 pi
there, so the restart at t0 = 0 is phase consistent), like DynamicalSystems.jl's default
continuation of attractors by recurrence. Whatever attractor a start settled on is followed until
it disappears; run up and down, branches that differ show hysteresis and coexisting attractors.
It is sequential over values but vmapped over several starts.

This is the brute-force counterpart of `jaxcelt.orbits` (periodic orbits found by Newton on the
stroboscopic map and continued along their branch, stable or not): it follows any attractor,
periodic or not, but only stable ones, and only as far as it stays attracting. `continuation` is
its former name.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from jaxcelt.physics.params import CeltParams
from jaxcelt.sweeps.api import starts_per_value, sweep
from jaxcelt.sweeps.options import SweepOptions, resolve_options
from jaxcelt.sweeps.result import LANE_FIELDS, SweepResult

__all__ = ["follow_attractor", "continuation"]

_DEFAULTS = {"transient_periods": 100, "sample_periods": 50}
"""`follow_attractor`'s sampling without ``options``: each value starts near its attractor already"""


def follow_attractor(
    params: CeltParams,
    name: str,
    values: Any,
    *,
    direction: str = "up",
    y0: Any = None,
    options: SweepOptions | None = None,
    **keywords: Any,
) -> dict[str, SweepResult]:
    """Sweep ``name`` over ``values`` starting each value from the previous value's final state.

    Args:
        direction: ``"up"`` (increasing values), ``"down"`` or ``"both"`` (up, then down
            starting from the up sweep's last state) -- hysteresis and coexisting
            attractors show as differing branches.
        y0: None, (13,) or (K, 13): K starts followed side by side (vmapped).
        options, keywords: as `jaxcelt.sweeps.api.sweep` (`jaxcelt.sweeps.options.SweepOptions`), but
            without ``options`` the defaults are ``transient_periods=100``, ``sample_periods=50``;
            ``t0`` is 0 for every step (the final state of a step sits at a section time, base
            phase 0, so the restart is phase consistent); ``progress`` shows a bar over values.

    Returns:
        ``{"up": SweepResult, "down": SweepResult}`` (the requested directions), values in
        sweep order, lane arrays shaped (L_v, K, ...).
    """
    opts = resolve_options(options, keywords, caller="follow_attractor", defaults=_DEFAULTS)
    if direction not in ("up", "down", "both"):
        raise ValueError(f"direction must be 'up', 'down' or 'both', got {direction!r}")
    values = np.sort(np.atleast_1d(np.asarray(values, dtype=np.float64)))
    y = starts_per_value(params, y0, 1)[0]  # (K, 13)
    step_opts = opts.replace(progress=False)
    out: dict[str, SweepResult] = {}
    dirs = ["up", "down"] if direction == "both" else [direction]
    for d in dirs:
        vs = values if d == "up" else values[::-1]
        steps = []
        it = vs
        if opts.progress:
            from tqdm.auto import tqdm

            it = tqdm(vs, desc=f"following {d}", unit="value")
        for v in it:
            r = sweep(params, name, [v], y0=y[None], options=step_opts)
            steps.append(r)
            ok = r.status[0] == 0
            # a failed step restarts the next value from the last good state
            y = np.where(ok[:, None], r.y_final[0], y)
        merged = {k: np.concatenate([getattr(s, k) for s in steps], axis=0) for k in ("values", *LANE_FIELDS)}
        out[d] = SweepResult(name=name, **merged)
    return out


continuation = follow_attractor
"""`follow_attractor` under its former name (kept: ``jaxcelt.continuation`` is public)."""
