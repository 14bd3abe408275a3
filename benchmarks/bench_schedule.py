"""Pool scheduling A/B: slots per device x pilot pause, interleaved in one process.

The 400 x 300 stop-at-invalid sweep of ``bench_sweep.py`` (rtol 1e-8), run through
`jaxcelt.ensemble.run_lanes` with each configuration in turn, ``--reps`` rounds. Every
configuration is compiled first (timed apart); the rounds interleave the configurations, so
this VM's slow drift (10-20 % between minutes) hits them alike. Lanes are bitwise the same
in every configuration (checked here); only the schedule differs.

    .venv/bin/python benchmarks/bench_schedule.py --configs Tsit5:64:0,Tsit5:96:0.1 --reps 3 \\
        --out docs/bifurcation
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import jax
import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", default="Tsit5:64:0,Tsit5:96:0,Tsit5:96:0.1", help="SOLVER:WIDTH:PILOT,...")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--integrate-on", action="store_true", help="no stop at invalid states")
    ap.add_argument("--out", type=Path, default=None, help="folder for schedule.json (optional)")
    a = ap.parse_args()
    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)

    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
    from jaxcelt.integrate.solvers import make_solver
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    configs = [(s, int(w), float(f)) for s, w, f in (c.split(":") for c in a.configs.split(","))]
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    pb = lanes_params(p, "omega_pi", vals)

    def cfg(solver):
        return SweepConfig(
            transient_periods=200, sample_periods=100, rtol=1e-8, atol=1e-10,
            stop_on_invalid=not a.integrate_on, solver=make_solver(solver),
        )  # fmt: skip

    res = dict(versions=versions(), devices=len(jax.devices()), load_average_at_start=os.getloadavg(), rows=[])
    print(res["versions"], flush=True)
    rows = {}
    for s, w, f in configs:
        t = time.perf_counter()
        run_lanes(pb, y0, cfg(s), width=w, compile_only=True, varying=("omega_pi",))
        rows[(s, w, f)] = dict(solver=s, width_per_device=w, pilot_fraction=f, compile_s=time.perf_counter() - t, run_s=[])
    first = {}
    for r in range(a.reps):
        for s, w, f in configs:
            t = time.perf_counter()
            out = run_lanes(pb, y0, cfg(s), width=w, varying=("omega_pi",), pilot_fraction=f)
            row = rows[(s, w, f)]
            row["run_s"].append(time.perf_counter() - t)
            row.update(iterations=int(out["pool_iterations"][0]), slots=int(out["pool_slot_steps"][0]))
            row["steps"] = int(out["num_steps"].sum())
            row["idle_fraction"] = 1 - row["steps"] / row["slots"]
            if s in first:  # same solver: same lanes, bitwise
                for key in ("samples", "num_steps", "status"):
                    assert np.array_equal(first[s][key], out[key], equal_nan=True), (s, w, f, key)
            first.setdefault(s, out)
        print(r, {f"{s}:{w}:{f}": round(rows[(s, w, f)]["run_s"][-1], 2) for s, w, f in configs}, flush=True)
    for row in rows.values():
        row["run_s_median"] = float(np.median(row["run_s"]))
        res["rows"].append(row)
        print(
            f"{row['solver']:7s} width {row['width_per_device']:4d} pilot {row['pilot_fraction']:<4}: "
            f"run {row['run_s_median']:.2f} s (median of {a.reps}), compile {row['compile_s']:.1f} s, "
            f"{row['iterations']} iterations, idle slots {row['idle_fraction']:.3f}"
        )
    if a.out is not None:
        write_result(a.out / "schedule.json", res, load_at_start=res["load_average_at_start"])


if __name__ == "__main__":
    main()
