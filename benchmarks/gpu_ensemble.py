"""Benchmark: the GPU ODE ensemble anchor -- Lorenz, one parameter per trajectory, final states only.

The problem of the published GPU ensemble benchmark (repository utkarsh530/GPUODEBenchmarks, whose
diffrax script is reproduced here as the ``diffrax vmap`` engine): dx/dt = 10(y - x),
dy/dt = rho x - y - x z, dz/dt = x y - 8/3 z, rho = linspace(0, 21, N), (x, y, z)(0) = (1, 0, 0),
t in [0, 1], adaptive Tsit5 at rtol = atol = 1e-8, dt0 = 1e-3, float32 (JAX's default there), the
state at t = 1 kept. Two engines on the same device, in one process:

* ``jaxcelt kernel``: `jaxcelt.ensemble.kernel_ode.solve_lanes`, one GPU thread per trajectory in
  the lane kernel (the Lorenz field through `jaxcelt.ensemble.soa.blockwise`);
* ``diffrax vmap``: `jax.vmap` of `diffrax.diffeqsolve` over the parameters, as published.

Compilation is timed apart (``jit(...).lower(...).compile()``); the run is the best and the median
of ``--repeat`` warm calls. The final states of the two engines are compared (max |difference| over
max |state|): two programs with the same tolerance, not bitwise. The published numbers
(`PUBLISHED`) are printed beside, with their card. Appends one record to ``--json`` (through
`jaxcelt.provenance.write_result`).

    python benchmarks/gpu_ensemble.py --n 8388608 --json out/gpu_ensemble.json
    python benchmarks/gpu_ensemble.py --n 4096 --engines kernel diffrax   # a CPU smoke run (interpreted kernel)
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

PUBLISHED = {
    "source": "GPUODEBenchmarks (utkarsh530/GPUODEBenchmarks) data, Lorenz, 8,388,608 trajectories, adaptive Tsit5 1e-8",
    "card": "NVIDIA Tesla V100",
    "ms": {"DiffEqGPU EnsembleGPUKernel": 69.5, "MPGOS": 48.8, "diffrax vmap": 2611.0},
}
"""the published times quoted in the project's performance pages (ms, one call, warm)"""


def lorenz(t, y, args):
    import jax.numpy as jnp

    (rho,) = args
    return jnp.stack([10.0 * (y[1] - y[0]), rho * y[0] - y[1] - y[0] * y[2], y[0] * y[1] - (8.0 / 3.0) * y[2]])


def engines(dtype):
    import diffrax
    import jax
    import jax.numpy as jnp

    from jaxcelt.ensemble.kernel_ode import solve_lanes

    def kernel(rho):
        y0 = jnp.broadcast_to(jnp.asarray([1.0, 0.0, 0.0], dtype), (rho.shape[0], 3))
        out = solve_lanes(lorenz, y0, (rho,), 0.0, 1.0, rtol=1e-8, atol=1e-8, dt0=1e-3, dtype=dtype)
        return out["y1"], out["num_steps"], out["status"]

    def one(r):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(lambda t, y, a: lorenz(t, y, (a,))), diffrax.Tsit5(), 0.0, 1.0, 1e-3,
            jnp.asarray([1.0, 0.0, 0.0], dtype), r, stepsize_controller=diffrax.PIDController(rtol=1e-8, atol=1e-8),
        )  # fmt: skip
        return sol.ys[-1], sol.stats["num_steps"], jnp.where(sol.result == diffrax.RESULTS.successful, 0, 1)

    return {"kernel": jax.jit(kernel), "diffrax": jax.jit(jax.vmap(one))}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=8_388_608, help="trajectories")
    ap.add_argument("--repeat", type=int, default=10, help="warm calls timed per engine")
    ap.add_argument("--dtype", default="float32", choices=("float32", "float64"))
    ap.add_argument("--engines", nargs="+", default=["kernel", "diffrax"], choices=("kernel", "diffrax"))
    ap.add_argument("--json", type=Path, default=Path("out/gpu_ensemble.json"))
    a = ap.parse_args()
    if a.n < 1 or a.repeat < 1:
        print("gpu_ensemble: --n and --repeat must be >= 1", file=sys.stderr)
        return 2

    import jax

    if a.dtype == "float64":
        jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    from jaxcelt.provenance import append_run, load_average
    from jaxcelt.versions import versions

    load0 = load_average()
    dtype = jnp.dtype(a.dtype)
    rho = jnp.linspace(0.0, 21.0, a.n, dtype=dtype)
    rec = {"versions": versions(), "device": str(jax.devices()[0]), "device_kind": jax.devices()[0].device_kind,
           "trajectories": a.n, "dtype": a.dtype, "rtol": 1e-8, "atol": 1e-8, "dt0": 1e-3, "t1": 1.0,
           "repeat": a.repeat, "published": PUBLISHED, "engines": {}}  # fmt: skip
    print(json.dumps(rec["versions"]), flush=True)
    finals = {}
    for name, fn in engines(dtype).items():
        if name not in a.engines:
            continue
        t = time.perf_counter()
        compiled = fn.lower(rho).compile()
        t_compile = time.perf_counter() - t
        y, steps, status = jax.block_until_ready(compiled(rho))  # first call (not timed)
        times = []
        for _ in range(a.repeat):
            t = time.perf_counter()
            jax.block_until_ready(compiled(rho))
            times.append(time.perf_counter() - t)
        finals[name] = np.asarray(y, np.float64)
        steps = np.asarray(steps)
        rec["engines"][name] = {
            "compile_s": round(t_compile, 2),
            "best_ms": round(1e3 * min(times), 2),
            "median_ms": round(1e3 * float(np.median(times)), 2),
            "steps_total": int(steps.sum()),
            "steps_max": int(steps.max()),
            "ok_lanes": int(np.sum(np.asarray(status) == 0)),
        }
        print(name, json.dumps(rec["engines"][name]), flush=True)
    if len(finals) == 2:
        k, d = finals["kernel"], finals["diffrax"]
        rec["max_final_difference_over_max_state"] = float(np.max(np.abs(k - d)) / np.max(np.abs(d)))
        rec["diffrax_over_kernel_best"] = round(
            rec["engines"]["diffrax"]["best_ms"] / rec["engines"]["kernel"]["best_ms"], 2
        )
    print(json.dumps({k: v for k, v in rec.items() if k != "versions"}), flush=True)
    append_run(a.json, rec, load_at_start=load0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
