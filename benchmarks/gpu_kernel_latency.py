"""Benchmark: what one step of one lane costs inside the lane kernel (made for one GPU).

A map's time on a GPU is set by its longest lanes, whose steps follow one another in their
threads (`docs/bifurcation/README.md`): so the number that matters is the time of one loop
iteration of a block of lanes, not lanes per second. This script runs the map's sticking corner
(NX x NY lanes, omega_pi 10-12.13 rad/s, q_pi 0.02-0.0237 m, TRANSIENT + SAMPLE periods from rest,
stop-on-invalid, rtol 1e-8, atol 1e-10) through the lane kernel in each variant asked for:

* ``float64`` / ``mixed``: the field in float64, or in float32 with the state, sums and error
  control in float64 (``field_dtype="float32"``).

For each: compilation apart (``compile_only``), the run (best of ``--reps``), the overhead a run
pays besides the kernel (tracing, lowering, loading the compiled program: a second
``compile_only``), the kernel's loop iterations of its busiest block summed over the calls, and
the time per iteration, (run - overhead) / iterations (an upper bound on one step's latency: a
call lasts as long as its slowest block). The step
written out stage by stage (each stage its own copy of the field, constant coefficients) was
measured against the loop over the tableau's rows with this script and dropped
(`docs/performance/gpu_kernel_latency.json`). One JSON record per variant is appended to ``--json``.

    python benchmarks/gpu_kernel_latency.py --json out/gpu_kernel_latency.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

VARIANTS = ("float64", "mixed")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=32)
    ap.add_argument("--ny", type=int, default=8)
    ap.add_argument("--omega", nargs=2, type=float, default=(10.0, 12.13))
    ap.add_argument("--q", nargs=2, type=float, default=(0.02, 0.0237))
    ap.add_argument("--transient", type=int, default=7)
    ap.add_argument("--sample", type=int, default=3)
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    ap.add_argument("--json", type=Path, default=Path("out/gpu_kernel_latency.json"))
    a = ap.parse_args()

    import tempfile

    import equinox as eqx
    import jax
    import jax.numpy as jnp

    # JAX's persistent cache (a temporary directory): a run after ``compile_only`` traces and lowers
    # again but finds its program compiled; that overhead is timed apart (a second ``compile_only``)
    jax.config.update("jax_compilation_cache_dir", tempfile.mkdtemp(prefix="jaxcelt-latency-"))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)

    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
    from jaxcelt.provenance import append_run, load_average
    from jaxcelt.versions import versions

    load0 = load_average()
    ver = versions()
    print(json.dumps(ver), flush=True)
    p = jc.CeltParams.paper()
    xs, ys = np.linspace(*a.omega, a.nx), np.linspace(*a.q, a.ny)
    lane_x, lane_y = np.repeat(xs, a.ny), np.tile(ys, a.nx)
    L = a.nx * a.ny
    pb = eqx.tree_at(lambda q: q.q_pi, lanes_params(p, "omega_pi", lane_x), jnp.asarray(lane_y))
    y0 = np.tile(np.asarray(jc.initial_state(p)), (L, 1))
    for name in a.variants:
        cfg = SweepConfig(transient_periods=a.transient, sample_periods=a.sample, rtol=1e-8, atol=1e-10,
                          stop_on_invalid=True, field_dtype="float32" if name == "mixed" else None)  # fmt: skip
        kw = dict(varying=("omega_pi", "q_pi"), engine="kernel")
        t = time.perf_counter()
        run_lanes(pb, y0, cfg, compile_only=True, **kw)
        t_compile = time.perf_counter() - t
        t = time.perf_counter()
        run_lanes(pb, y0, cfg, compile_only=True, **kw)
        t_overhead = time.perf_counter() - t
        runs = []
        for _ in range(a.reps):
            t = time.perf_counter()
            out, st = run_lanes(pb, y0, cfg, stats=True, **kw)
            runs.append(time.perf_counter() - t)
        t_run = min(runs)
        rec = {
            "variant": name,
            "device_kind": jax.devices()[0].device_kind,
            "grid": [a.nx, a.ny],
            "omega_pi": list(a.omega),
            "q_pi": list(a.q),
            "periods": a.transient + a.sample,
            "rtol": 1e-8,
            "atol": 1e-10,
            "compile_s": round(t_compile, 2),
            "run_s": round(t_run, 3),
            "run_s_all": [round(x, 3) for x in runs],
            "overhead_s": round(t_overhead, 3),
            "iterations": int(st.iterations),
            "us_per_iteration": round(1e6 * max(t_run - t_overhead, 0.0) / max(st.iterations, 1), 2),
            "steps_total": int(out["num_steps"].sum()),
            "steps_max": int(out["num_steps"].max()),
            "status_counts": {str(k): int(v) for k, v in zip(*np.unique(out["status"], return_counts=True))},
            "versions": ver,
        }
        print(json.dumps({k: v for k, v in rec.items() if k != "versions"}), flush=True)
        append_run(a.json, rec, load_at_start=load0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
