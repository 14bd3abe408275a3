"""Where a sweep step's time goes: per-lane cost of one vector-field evaluation, diffrax's
Tsit5 step with `MonitoredSolver` (what `simulate` runs: 6 RHS + RK bookkeeping + the monitor's
extra normal-force evaluation), the pool's fused step (`jaxcelt.sweep._erk_lane_step`: 6 RHS,
monitor from the FSAL evaluation, PID + section clipping) with and without its stage-input
kernel boundaries, and the full pool iteration is `bench_pool_width.py`'s business. Each part
is vmapped over the lanes inside one jitted loop (no dispatch), best of 5, one JAX device.
`step_parts` is also what ``bench_sweep.py`` uses for its per-evaluation costs.

    .venv/bin/python benchmarks/bench_step_parts.py [--width 32] [--samples 100] [--out docs/bifurcation]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import jaxcelt as jc
from jaxcelt.contact import get_contact_law
from jaxcelt.model import vector_field
from jaxcelt.solve import _invalid_kind
from jaxcelt.sweep import (
    SweepConfig,
    _erk_lane_step,
    _erk_tableau,
    _kernel_boundary,
    _lane_init,
    _pool_parts,
    lanes_params,
)

PARTS = (
    "rhs",
    "monitor",
    "diffrax tsit5 step + monitor",
    "fused step, no stage boundaries",
    "fused step (pool)",
)


def _best_us_per_lane(f, x, n_lanes: int, reps: int) -> float:
    jax.block_until_ready(f(x))  # compile
    best = np.inf
    for _ in range(5):  # best of 5: the least disturbed by other processes
        t = time.perf_counter()
        jax.block_until_ready(f(x))
        best = min(best, time.perf_counter() - t)
    return best / (reps * n_lanes) * 1e6


def step_parts(p, vals, y0, *, reps: int = 2000, n_samples: int = 100, parts=PARTS) -> dict[str, float]:
    """µs per lane of each part in ``parts`` (see `PARTS`), lanes = (omega_pi values, y0 (L, 13))."""
    law = get_contact_law(None)
    pb = lanes_params(p, "omega_pi", vals)
    L = len(vals)
    out: dict[str, float] = {}

    def loop(fn):
        def body(i, y):
            o = jax.vmap(lambda pp, yy: fn(0.1 * i, yy, pp))(pb, y)
            # every output component feeds the carry: otherwise XLA drops the unused parts of
            # the right-hand side and the timing is too small (an earlier version did that)
            return y + 1e-30 * jnp.sum(jnp.atleast_2d(o.T).T, axis=-1, keepdims=True)

        return jax.jit(lambda y: jax.lax.fori_loop(0, reps, body, y))

    evals = {
        "rhs": lambda t, y, pp: vector_field(t, y, pp, law),
        "monitor": lambda t, y, pp: _invalid_kind(t, y, pp, law)[1],
    }
    for name in parts:
        if name in evals:
            out[name] = _best_us_per_lane(loop(evals[name]), y0, L, reps)
    if not any(name in parts for name in PARTS[2:]):
        return out

    cfg = SweepConfig(transient_periods=0, sample_periods=n_samples, stop_on_invalid=True)
    _, solver, term = _pool_parts(cfg)
    tab = _erk_tableau(cfg)
    tols = jnp.asarray([1e-8, 1e-10])
    ts = (2 * jnp.pi / pb.omega_pi)[:, None] * jnp.arange(float(n_samples))[None]
    st0 = jax.jit(jax.vmap(lambda pp, y, t: _lane_init(cfg, pp, y, t, tols)))(pb, y0, ts)
    # diffrax's path needs its own solver state (the fused step's lane state has none)
    st_d = dict(st0, sstate=jax.jit(jax.vmap(lambda s: solver.init(term, s["tprev"], s["tnext"], s["y"], s["p"])))(st0))

    def diffrax_step(s):  # the wrapped diffrax Tsit5 step + validity monitor, as in `simulate`
        y1, _, _, ss, _ = jax.vmap(lambda s: solver.step(term, s["tprev"], s["tnext"], s["y"], s["p"], s["sstate"], False))(s)  # fmt: skip
        return dict(s, y=y1, sstate=ss)

    def fused(boundaries):
        def step(s, flag):
            b = _kernel_boundary(flag) if boundaries else (lambda x: x)
            return jax.vmap(lambda s: _erk_lane_step(cfg, tab, s, b))(s)[0]

        return step

    runs = {
        "diffrax tsit5 step + monitor": (lambda s, flag: diffrax_step(s), st_d),
        "fused step, no stage boundaries": (fused(False), st0),
        "fused step (pool)": (fused(True), st0),
    }
    for name, (step, st) in runs.items():
        if name in parts:
            # the boundary's predicate is a jit argument, opaque to XLA, as in the pool
            f = jax.jit(lambda st, flag, step=step: jax.lax.fori_loop(0, reps, lambda i, s: step(s, flag), st))
            out[name] = _best_us_per_lane(lambda st, f=f: f(st, jnp.asarray(True)), st, L, reps)
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--width", type=int, default=32, help="lanes (omega_pi 16..18, spinning a little)")
    ap.add_argument("--samples", type=int, default=100, help="section times the clip controller steps onto")
    ap.add_argument("--out", type=Path, default=None, help="folder for step_parts.json (optional)")
    a = ap.parse_args()
    p = jc.CeltParams.paper()
    y0 = jnp.tile(jnp.asarray(jc.initial_state(p)), (a.width, 1)).at[:, 3:6].add(0.3)
    res = {"width": a.width, "load_average_at_start": os.getloadavg()}
    res["us_per_lane"] = step_parts(p, np.linspace(16, 18, a.width), y0, n_samples=a.samples)
    for k, v in res["us_per_lane"].items():
        print(f"{k:34s} {v:7.3f} us/lane", flush=True)
    if a.out is not None:
        from jaxcelt.versions import versions

        res["versions"] = versions()
        a.out.mkdir(parents=True, exist_ok=True)
        (a.out / "step_parts.json").write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
