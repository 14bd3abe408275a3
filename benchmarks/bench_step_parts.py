"""Where a sweep step's time goes: per-lane cost of one vector-field evaluation, diffrax's
Tsit5 step with `MonitoredSolver` (what `simulate` runs: 6 RHS + RK bookkeeping + the monitor's
extra normal-force evaluation), the pool's fused step (`jaxcelt.ensemble.FusedERKStepper`: 6 RHS,
monitor from the FSAL evaluation, PID + section clipping) with and without its stage-input
kernel boundaries, and the full pool iteration is `bench_pool_width.py`'s business. Each part
is vmapped over the lanes inside one jitted loop (no dispatch), best of 5, one JAX device,
compiled with XLA's default options and the default contact law, as a narrow pool runs (a wide
pool's program is compiled with 512-bit vectors on a CPU and runs the law's ``wide_batch`` form,
whose effect `roofline.py` and `vector_width.py` measure).
`step_parts` is also what ``bench_sweep.py`` uses for its per-evaluation costs.

    .venv/bin/python benchmarks/bench_step_parts.py [--width 32] [--samples 100] [--out docs/bifurcation]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxcelt as jc
from jaxcelt.ensemble import lanes_params, make_stepper
from jaxcelt.integrate.solve import DEFAULT_SOLVER, _invalid_kind
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import vector_field

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

    def stepper(opaque_true=None):  # the pool's stepper for the default solver (fused Tsit5)
        kw = dict(rtol=1e-8, atol=1e-10, max_steps=1_000_000, stop_on_invalid=True, opaque_true=opaque_true)
        return make_stepper(DEFAULT_SOLVER, None, **kw)

    fused0 = stepper()
    solver, term = fused0.solver, fused0.term  # `MonitoredSolver` around Tsit5, the wrapped term
    tols = jnp.asarray([1e-8, 1e-10])
    ts = (2 * jnp.pi / pb.omega_pi)[:, None] * jnp.arange(float(n_samples))[None]
    t0 = jnp.asarray(0.0)
    st0 = jax.jit(jax.vmap(lambda pp, y, t: fused0.init(t0, y, t, pp, tols)))(pb, y0, ts)
    # diffrax's path needs its own solver state (the fused step's lane state has none)
    ss0 = jax.jit(jax.vmap(lambda s, pp: solver.init(term, s.tprev, s.tnext, s.y, pp)))(st0, pb)

    def diffrax_step(s, flag):  # the wrapped diffrax Tsit5 step + validity monitor, as in `simulate`
        st, ss = s
        y1, _, _, ss, _ = jax.vmap(lambda s, pp, ss: solver.step(term, s.tprev, s.tnext, s.y, pp, ss, False))(st, pb, ss)  # fmt: skip
        return eqx.tree_at(lambda s: s.y, st, y1), ss

    def fused(boundaries):
        def step(s, flag):
            fs = stepper(flag if boundaries else None)
            return jax.vmap(lambda s, pp, t: fs.step(s, pp, t))(s, pb, ts)[0]

        return step

    runs = {
        "diffrax tsit5 step + monitor": (diffrax_step, (st0, ss0)),
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
        from jaxcelt.provenance import write_result
        from jaxcelt.versions import versions

        res["versions"] = versions()
        write_result(a.out / "step_parts.json", res, load_at_start=res["load_average_at_start"])


if __name__ == "__main__":
    main()
