"""XLA's CPU loop emitters vs its fusion emitters for the main job's Lyapunov stage (writes
docs/performance/compile_options.json).

The main job's lanes (60 omega_pi values in [10, 20] rad/s from rest, paper's parameters,
100 transient periods, stop at invalid states, Tsit5 rtol 1e-8) run through the pool without
Lyapunov exponents; then the Lyapunov stage (30 periods of tangent dynamics, as
``jaxcelt bifurcation`` runs it) is traced, compiled and run with XLA's default options and with
``jaxcelt._compile_options.LOOP_EMITTERS``, each in a fresh process: trace + lowering, XLA
compilation, the best of 3 runs, and the exponents (the two programs agree to rounding).

    .venv/bin/python benchmarks/compile_options.py [--out docs/performance/compile_options.json]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path


def child(variant: str) -> dict:
    import jax

    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)
    import equinox as eqx
    import numpy as np

    import jaxcelt as jc
    from jaxcelt._compile_options import LOOP_EMITTERS
    from jaxcelt.ensemble import stroboscopic as sb
    from jaxcelt.ensemble.shard import device_mesh

    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, 60)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    cfg = sb.SweepConfig(transient_periods=100, sample_periods=30, stop_on_invalid=True)
    pb = sb.lanes_params(p, "omega_pi", vals)
    out, st = sb.run_lanes(pb, y0, cfg, varying=("omega_pi",), stats=True)
    lcfg = sb.SweepConfig(transient_periods=0, sample_periods=30, lyapunov_periods=30, stop_on_invalid=True)
    mesh = device_mesh(None)
    ndev = mesh.devices.size
    ok = np.flatnonzero(out["status"] == 0)
    # as run_lanes: the first group of the Lyapunov stage (`jaxcelt.ensemble.stroboscopic.lyapunov_groups`); the
    # committed compile_options.json was measured before it, with one group of the pool's width in contiguous blocks
    idx, own = sb.lyapunov_groups(ok, min(st.width, sb.LYAPUNOV_GROUP_WIDTH), ndev)[0]
    pb_np = jax.tree_util.tree_map(np.asarray, pb)
    args = (jax.tree_util.tree_map(lambda x: x[idx], pb_np), out["samples"][idx, 0], out["t_samples"][idx, 0], lcfg, mesh)
    fn = eqx.filter_jit(sb._lyap_chunk_impl, compiler_options=LOOP_EMITTERS if variant == "loop" else None)
    t = time.perf_counter()
    lowered = fn.lower(*args)
    trace_s = time.perf_counter() - t
    t = time.perf_counter()
    compiled = lowered.compile()
    compile_s = time.perf_counter() - t
    runs = []
    for _ in range(3):
        t = time.perf_counter()
        lam = np.asarray(jax.block_until_ready(compiled(*args))[0])  # the exponents (the stage returns them and their errors)
        runs.append(time.perf_counter() - t)
    n = int(own.sum())
    return dict(
        variant=variant, lanes=int(n), trace_lower_s=trace_s, compile_s=compile_s, run_best_of_3_s=min(runs),
        lyapunov=lam[own].tolist(),  # the group's own lanes, in the order of their positions
    )  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/performance/compile_options.json"))
    ap.add_argument("--child", choices=("default", "loop"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        print("ROW " + json.dumps(child(a.child)), flush=True)
        return 0
    import numpy as np

    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    res: dict = dict(versions=versions(), cpu_count=os.cpu_count(), load_average_at_start=os.getloadavg(), runs={})
    print(res["versions"], flush=True)
    for variant in ("default", "loop"):
        cmd = [sys.executable, __file__, "--child", variant]
        done = subprocess.run(cmd, capture_output=True, text=True, check=True)
        row = json.loads(next(ln[4:] for ln in done.stdout.splitlines() if ln.startswith("ROW ")))
        res["runs"][variant] = row
        print({k: v for k, v in row.items() if k != "lyapunov"}, flush=True)
    d, lp = (np.asarray(res["runs"][v]["lyapunov"]) for v in ("default", "loop"))
    res["lyapunov_max_abs_diff"] = float(np.max(np.abs(d - lp)))
    res["compile_ratio_loop_over_default"] = res["runs"]["loop"]["compile_s"] / res["runs"]["default"]["compile_s"]
    res["run_ratio_loop_over_default"] = res["runs"]["loop"]["run_best_of_3_s"] / res["runs"]["default"]["run_best_of_3_s"]
    res["load_average_at_end"] = os.getloadavg()
    write_result(a.out, res, load_at_start=res["load_average_at_start"])
    print(f"wrote {a.out}: compile x{res['compile_ratio_loop_over_default']:.2f}, run x{res['run_ratio_loop_over_default']:.2f}, "
          f"max |lambda difference| {res['lyapunov_max_abs_diff']:.2e}")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
