"""Step census of the omega_pi x q_pi map: how much work a 400 x 400 x 300-period map is, from any device.

A pool iteration steps every slot once, so the time of a map on an accelerator is bounded below by
(1) the work, the lane-steps of all lanes, at the widest pool's measured slot-steps per second, and
(2) the latency, the longest lane's steps one after the other at the measured cost of an iteration
of the narrowest pool. Step counts do not depend on the device (up to the rounding of another
compiled program), so this script counts them on a coarser grid of the same box on whatever device
JAX sees (made for the CPU) and projects both bounds to the full map with the rates
``benchmarks/gpu_map.py`` measured on a GPU (``--rates``, default docs/performance/gpu_map.json).

With ``--stiff-solver`` (e.g. Kvaerno5) the lanes that took more than ``--stiff-factor`` x the median
steps (the lanes where the stone sticks to the base and the regularised friction is stiff) run again
with that solver through the same pool, to count how many sequential steps it needs there.

    python benchmarks/map_step_census.py --nx 40 --ny 40 --stiff-solver Kvaerno5 \\
        --json docs/performance/map_step_census.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

FULL_GRID = (400, 400)
OMEGA = (10.0, 20.0)
Q = (0.02, 0.06)


def _quantiles(steps: np.ndarray) -> dict[str, float]:
    return {f"q{int(q * 100)}": float(np.quantile(steps, q)) for q in (0.5, 0.9, 0.99)}


def _gpu_rates(path: Path, dtype: str, rtol: float) -> dict | None:
    """The widest and narrowest measured pools for this dtype and rtol (and without the per-stage
    kernel boundaries, which the engine leaves out on accelerators)."""
    if not path.exists():
        return None
    runs = [
        r
        for r in json.loads(path.read_text())["runs"]
        if "grid" in r and r["dtype"] == dtype and r["rtol"] == rtol and not r.get("kernel_boundaries", False)
    ]
    if not runs:
        return None
    widest = max(runs, key=lambda r: (r["width"], r["lanes"] * r["steps_max"] / r["run_s"]))
    narrowest = min(runs, key=lambda r: (r["width"], r["microseconds_per_pool_iteration"]))
    return {
        "file": str(path),
        "device_kind": widest["device_kind"],
        "widest_pool_slots": widest["width"],
        "widest_pool_slot_steps_per_s": round(widest["lanes"] * widest["steps_max"] / widest["run_s"]),
        "narrowest_pool_slots": narrowest["width"],
        "narrowest_pool_us_per_iteration": narrowest["microseconds_per_pool_iteration"],
    }


def project(steps: np.ndarray, rates: dict | None, full_lanes: int, target_s: float) -> dict:
    """Both lower bounds for the full map (module docstring), in seconds, and the factors by which
    the slot-step rate and the longest lane would have to improve to meet ``target_s``."""
    mean = float(steps.mean())
    work = mean * full_lanes
    out = {"full_map_lanes": full_lanes, "lane_steps": work, "longest_lane_steps": int(steps.max())}
    if rates is None:
        return out
    work_s = work / rates["widest_pool_slot_steps_per_s"]
    latency_s = steps.max() * rates["narrowest_pool_us_per_iteration"] * 1e-6
    out.update(
        work_bound_s=round(work_s, 1),
        latency_bound_s=round(float(latency_s), 1),
        target_s=target_s,
        slot_step_rate_needed_x=round(work_s / target_s, 2),
        longest_lane_cut_needed_x=round(float(latency_s) / target_s, 2),
    )
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=40, help="omega_pi values (10 .. 20 rad/s)")
    ap.add_argument("--ny", type=int, default=40, help="q_pi values (0.02 .. 0.06 m)")
    ap.add_argument("--transient", type=int, default=270)
    ap.add_argument("--sample", type=int, default=30)
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--atol", type=float, default=1e-10)
    ap.add_argument("--max-steps", type=int, default=1_000_000)
    ap.add_argument("--dtype", default="float64", choices=("float64", "float32"))
    ap.add_argument("--stiff-solver", default=None, help="diffrax solver for the stiff lanes' second run")
    ap.add_argument("--stiff-factor", type=float, default=10.0, help="stiff lane: steps > this x the median")
    ap.add_argument("--target-s", type=float, default=60.0, help="the time the full map should take")
    ap.add_argument("--rates", type=Path, default=Path("docs/performance/gpu_map.json"))
    ap.add_argument("--json", type=Path, default=Path("out/map_step_census.json"))
    a = ap.parse_args()

    import diffrax
    import jax

    import jaxcelt as jc
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.versions import versions

    load0 = load_average()
    ver = versions()
    print(json.dumps(ver), flush=True)
    p = jc.CeltParams.paper()
    xs = np.linspace(*OMEGA, a.nx)
    ys = np.linspace(*Q, a.ny)
    kw = dict(
        transient_periods=a.transient, sample_periods=a.sample, rtol=a.rtol, atol=a.atol, stop_on_invalid=True,
        dtype=a.dtype, max_steps=a.max_steps,
    )  # fmt: skip
    t = time.perf_counter()
    ds = jc.parameter_map(p, x=("omega_pi", xs), y=("q_pi", ys), progress=True, **kw)
    wall = time.perf_counter() - t
    steps = ds["num_steps"].values.astype(np.int64)
    status = ds["status"].values
    med = float(np.median(steps))
    stiff = steps > a.stiff_factor * med
    rates = _gpu_rates(a.rates, a.dtype, a.rtol)
    full = FULL_GRID[0] * FULL_GRID[1]
    rec: dict = {
        "about": (
            "benchmarks/map_step_census.py: step counts of an omega_pi x q_pi map (from rest, stop-on-invalid, "
            "Tsit5) on a coarser grid of the same box, projected to the 400 x 400 map with the GPU rates in "
            "'rates'. The bounds are projections from measured rates, not measurements of the full map."
        ),
        "versions": ver,
        "device": str(jax.devices()[0]),
        "grid": [a.nx, a.ny],
        "box": {"omega_pi": list(OMEGA), "q_pi": list(Q)},
        "periods": a.transient + a.sample,
        "dtype": a.dtype,
        "rtol": a.rtol,
        "atol": a.atol,
        "max_steps": a.max_steps,
        "wall_s_including_compile": round(wall, 1),
        "lanes": int(steps.size),
        "steps_total": int(steps.sum()),
        "steps_mean": round(float(steps.mean()), 1),
        "steps_quantiles": _quantiles(steps),
        "steps_max": int(steps.max()),
        "status_counts": {str(k): int(v) for k, v in zip(*np.unique(status, return_counts=True))},
        "stiff_factor": a.stiff_factor,
        "stiff_lanes": int(stiff.sum()),
        "stiff_share_of_steps": round(float(steps[stiff].sum() / steps.sum()), 4),
        "stiff_lanes_at_max_steps": int(np.sum(stiff & (status == 1))),
        "stiff_box": None,
        "rates": rates,
        "projection": project(steps, rates, full, a.target_s),
        "projection_without_stiff_lanes": project(steps[~stiff], rates, full, a.target_s),
    }
    if stiff.any():
        ii, jj = np.nonzero(stiff)
        rec["stiff_box"] = {
            "omega_pi": [float(xs[ii].min()), float(xs[ii].max())],
            "q_pi": [float(ys[jj].min()), float(ys[jj].max())],
            "q_omega2_max": float(np.max(ys[jj] * xs[ii] ** 2)),
        }
    if a.stiff_solver and stiff.any():
        solver = getattr(diffrax, a.stiff_solver)()
        lanes = {"omega_pi": xs[ii], "q_pi": ys[jj]}
        t = time.perf_counter()
        again = jc.sweep_lanes(p, lanes, solver=solver, progress=True, **kw)
        s2 = again["num_steps"].values.astype(np.int64)
        st2 = again["status"].values
        rec["stiff_rerun"] = {
            "solver": a.stiff_solver,
            "wall_s_including_compile": round(time.perf_counter() - t, 1),
            "tsit5_steps_max": int(steps[stiff].max()),
            "steps_max": int(s2.max()),
            "steps_total": int(s2.sum()),
            "tsit5_steps_total": int(steps[stiff].sum()),
            "status_counts": {str(k): int(v) for k, v in zip(*np.unique(st2, return_counts=True))},
            "same_status_fraction": round(float(np.mean(st2 == status[stiff])), 4),
        }
        # no projection in seconds: an implicit step costs other than the measured Tsit5 iterations
    print(json.dumps(rec, indent=1), flush=True)
    write_result(a.json, rec, load_at_start=load0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
