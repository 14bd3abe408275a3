"""Where a sweep step's time goes: per-lane cost of one vector-field evaluation, the validity
monitor, a bare diffrax Tsit5 step (6 RHS + RK bookkeeping), the monitored step, and the lane
pool's full step (controller, clipping, selects), each vmapped over W lanes inside one jitted
loop (no dispatch), best of 5. One JAX device.

    .venv/bin/python benchmarks/bench_step_parts.py [W] [n_sample_times] [--out docs/bifurcation]
"""

import json
import os
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import jaxcelt as jc
from jaxcelt.contact import get_contact_law
from jaxcelt.model import vector_field
from jaxcelt.solve import _invalid_kind
from jaxcelt.sweep import SweepConfig, _lane_init, _lane_step, _pool_parts, lanes_params

p = jc.CeltParams.paper()
args = [x for x in sys.argv[1:] if not x.startswith("--")]
OUT = Path(sys.argv[sys.argv.index("--out") + 1]) if "--out" in sys.argv else None
if OUT is not None:
    args = [x for x in args if x != str(OUT)]
W = int(args[0]) if len(args) > 0 else 32
reps = 2000
NS = int(args[1]) if len(args) > 1 else 100
RES = {"versions": None, "width": W, "load_average_at_start": os.getloadavg(), "us_per_lane": {}}
vals = np.linspace(16, 18, W)
law = get_contact_law(None)
pb = lanes_params(p, "omega_pi", vals)
y0 = jnp.tile(jnp.asarray(jc.initial_state(p)), (W, 1))
y0 = y0.at[:, 3:6].add(0.3)  # spin a bit


def timeit(name, f, x):
    jax.block_until_ready(f(x))
    dts = []
    for _ in range(5):
        t = time.perf_counter()
        jax.block_until_ready(f(x))
        dts.append(time.perf_counter() - t)
    dt = min(dts)
    RES["us_per_lane"][name] = dt / (reps * W) * 1e6
    print(f"{name:28s} {dt / (reps * W) * 1e6:7.3f} us/lane", flush=True)


def loop(fn):
    def body(i, y):
        out = jax.vmap(lambda pp, yy: fn(0.1 * i, yy, pp))(pb, y)
        return y + 1e-30 * jnp.sum(jnp.atleast_2d(out.T).T, axis=-1, keepdims=True)

    return jax.jit(lambda y: jax.lax.fori_loop(0, reps, body, y))


timeit("rhs", loop(lambda t, y, pp: vector_field(t, y, pp, law)), y0)
timeit("monitor", loop(lambda t, y, pp: _invalid_kind(t, y, pp, law)[1]), y0)
cfg = SweepConfig(transient_periods=0, sample_periods=NS, stop_on_invalid=True)
_, solver, term = _pool_parts(cfg)
tols = jnp.asarray([1e-8, 1e-10])
T = 2 * jnp.pi / pb.omega_pi
ts = T[:, None] * jnp.arange(float(NS))[None]
init = jax.jit(jax.vmap(lambda pp, y, t: _lane_init(cfg, pp, y, t, tols)))
st0 = init(pb, y0, ts)
inner = solver.solver


def bare(st):
    def body(i, s):
        y1, ye, _, ss, _ = jax.vmap(
            lambda s: inner.step(term, s["tprev"], s["tnext"], s["y"], s["p"], s["sstate"][0], False)
        )(s)
        return dict(s, y=y1, sstate=(ss, s["sstate"][1]))

    return jax.lax.fori_loop(0, reps, body, st)


timeit("tsit5 step (no monitor)", jax.jit(bare), st0)


def mon(st):
    def body(i, s):
        y1, ye, _, ss, _ = jax.vmap(
            lambda s: solver.step(term, s["tprev"], s["tnext"], s["y"], s["p"], s["sstate"], False)
        )(s)
        return dict(s, y=y1, sstate=ss)

    return jax.lax.fori_loop(0, reps, body, st)


timeit("monitored step", jax.jit(mon), st0)


def full(st):
    def body(i, s):
        s2, hit = jax.vmap(lambda s: _lane_step(cfg, s))(s)
        return s2

    return jax.lax.fori_loop(0, reps, body, st)


timeit("_lane_step (ctrl etc)", jax.jit(full), st0)
if OUT is not None:
    from jaxcelt.versions import versions

    RES["versions"] = versions()
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "step_parts.json").write_text(json.dumps(RES, indent=1))
