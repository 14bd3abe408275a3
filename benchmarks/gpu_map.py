"""Benchmark: an omega_pi x q_pi regime map on whatever device JAX sees (made for one GPU).

One `jaxcelt.parameter_map` of NX x NY lanes from rest, TRANSIENT + SAMPLE forcing periods,
stop-on-invalid (as ``jaxcelt map``), no Lyapunov stage. Compilation is timed apart: the pool's
kernel is compiled first for the very shapes of the map (``run_lanes(..., compile_only=True)``),
then the map runs on the compiled kernel. Appends one JSON record per run (versions, device,
dtype, tolerances, compile and run seconds, lanes/s, step counts, regime counts, and the run's own
provenance) to the list ``"runs"`` of ``--json`` (written through `jaxcelt.provenance.write_result`)
and saves the regime labels (``--labels``, .npz) so that float32 and float64 maps can be compared
cell by cell.

    python benchmarks/gpu_map.py --nx 400 --ny 400 --dtype float64 --json out/gpu_map.json
    python benchmarks/gpu_map.py --nx 400 --ny 400 --dtype float32 --rtol 1e-6 --atol 1e-8 ...
    python benchmarks/gpu_map.py --compare out/labels_float64_400x400.npz out/labels_float32_400x400.npz
    python benchmarks/gpu_map.py --check --json out/gpu_map.json

On a GPU the lanes run in the lane kernel (`jaxcelt.ensemble.kernel`, ``engine="auto"``);
``--engine pool`` forces the lane pool. ``--check`` runs a small map of cheap lanes through both
engines on the same device and records how far they agree (status, steps, samples).
JAX's persistent compilation cache (a temporary directory) keeps the map from compiling twice.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np


def compare(a: Path, b: Path) -> dict:
    A, B = np.load(a), np.load(b)
    same = A["category"] == B["category"]
    out = {
        "maps": [str(a), str(b)],
        "cells": int(same.size),
        "same_category_fraction": round(float(same.mean()), 4),
        "same_status_fraction": round(float((A["status"] == B["status"]).mean()), 4),
    }
    print(json.dumps(out))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=400, help="omega_pi values (10 .. 20 rad/s)")
    ap.add_argument("--ny", type=int, default=400, help="q_pi values (0.02 .. 0.06 m)")
    ap.add_argument("--transient", type=int, default=270)
    ap.add_argument("--sample", type=int, default=30)
    ap.add_argument("--dtype", default="float64", choices=("float64", "float32"))
    ap.add_argument("--field-dtype", default=None, choices=("float32",), help="mixed precision: the field in float32")
    ap.add_argument("--stiffness", default="off", choices=("off", "auto"), help="the kernel's stiffness switch")
    ap.add_argument("--omega", nargs=2, type=float, default=(10.0, 20.0), help="omega_pi range")
    ap.add_argument("--q", nargs=2, type=float, default=(0.02, 0.06), help="q_pi range")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--atol", type=float, default=1e-10)
    ap.add_argument("--chunk", type=int, default=None, help="lanes per pool launch (default: all)")
    ap.add_argument("--width", type=int, default=None, help="pool slots (default: the chunk, no queue)")
    ap.add_argument("--json", type=Path, default=Path("out/gpu_map.json"), help="JSON file whose 'runs' list gets the record")
    ap.add_argument("--labels", type=Path, default=None, help=".npz of the map's categories and status")
    ap.add_argument("--compare", nargs=2, type=Path, default=None, help="compare two --labels files and exit")
    ap.add_argument("--engine", default="auto", choices=("auto", "pool", "kernel"))
    ap.add_argument("--check", action="store_true", help="kernel against pool on a small map of cheap lanes")
    ap.add_argument("--check-dtypes", nargs="+", default=["float64"], choices=("float64", "float32"))
    a = ap.parse_args()
    from jaxcelt.provenance import append_run

    if a.compare:
        rec = compare(*a.compare)
        append_run(a.json, {"comparison": rec})
        return 0

    import tempfile

    import jax

    jax.config.update("jax_compilation_cache_dir", tempfile.mkdtemp(prefix="jaxcelt-gpu-map-"))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    if a.check:
        rec = check(a)
        append_run(a.json, {"check": rec})
        return 0

    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
    from jaxcelt.plotting.map import map_categories
    from jaxcelt.provenance import load_average
    from jaxcelt.versions import versions

    load0 = load_average()
    ver = versions()
    print(json.dumps(ver), flush=True)
    p = jc.CeltParams.paper()
    xs = np.linspace(*a.omega, a.nx)
    ys = np.linspace(*a.q, a.ny)
    L = a.nx * a.ny
    cs = min(a.chunk or L, L)
    W = a.width or cs
    kw = dict(
        transient_periods=a.transient, sample_periods=a.sample, rtol=a.rtol, atol=a.atol, stop_on_invalid=True,
        dtype=a.dtype, field_dtype=a.field_dtype, stiffness=a.stiffness,
    )  # fmt: skip
    # compile for the map's own shapes: chunk 0's lanes, padded to the chunk size, all marked padding
    lane_x = np.repeat(xs, a.ny)[:cs]
    lane_y = np.tile(ys, a.nx)[:cs]
    import equinox as eqx
    import jax.numpy as jnp

    pb = eqx.tree_at(lambda q: q.q_pi, lanes_params(p, "omega_pi", lane_x), jnp.asarray(lane_y))
    y0 = np.tile(np.asarray(jc.initial_state(p)), (cs, 1))
    cfg = SweepConfig(**kw)
    t = time.perf_counter()
    run_lanes(pb, y0, cfg, pad_to=cs, width=W, compile_only=True, varying=("omega_pi", "q_pi"), engine=a.engine)
    t_compile = time.perf_counter() - t
    print(f"compile {t_compile:.1f} s", flush=True)
    t = time.perf_counter()
    ds = jc.parameter_map(p, x=("omega_pi", xs), y=("q_pi", ys), chunk_size=cs, width=W, engine=a.engine, **kw)
    t_run = time.perf_counter() - t
    steps = ds["num_steps"].values
    status = ds["status"].values
    cat, cats = map_categories(ds["regime"].values, ds["period"].values)
    rec = {
        "versions": ver,
        "device": str(jax.devices()[0]),
        "device_kind": jax.devices()[0].device_kind,
        "grid": [a.nx, a.ny],
        "lanes": L,
        "periods": a.transient + a.sample,
        "transient_periods": a.transient,
        "sample_periods": a.sample,
        "dtype": a.dtype,
        "field_dtype": a.field_dtype,
        "stiffness": a.stiffness,
        "omega_pi": list(a.omega),
        "q_pi": list(a.q),
        "rtol": a.rtol,
        "atol": a.atol,
        "chunk": cs,
        "width": W,
        "engine": a.engine,
        "engine_used": "kernel" if (a.engine == "kernel" or (a.engine == "auto" and jax.devices()[0].platform == "gpu")) else "pool",
        "compile_s": round(t_compile, 2),
        "run_s": round(t_run, 2),
        "lanes_per_s": round(L / t_run, 1),
        "steps_total": int(steps.sum()),
        "steps_max": int(steps.max()),
        "steps_median": float(np.median(steps)),
        "status_counts": {str(k): int(v) for k, v in zip(*np.unique(status, return_counts=True))},
        "regime_counts": {label: int(np.sum(cat == i)) for i, (label, _) in enumerate(cats) if np.any(cat == i)},
    }
    print(json.dumps(rec), flush=True)
    append_run(a.json, rec, load_at_start=load0)
    if a.labels:
        a.labels.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(a.labels, category=cat, status=status, omega_pi=xs, q_pi=ys)
    return 0


def pb_all(p, xs, ys):
    import equinox as eqx
    import jax.numpy as jnp

    from jaxcelt.ensemble import lanes_params

    lane_x, lane_y = np.repeat(xs, len(ys)), np.tile(ys, len(xs))
    return eqx.tree_at(lambda q: q.q_pi, lanes_params(p, "omega_pi", lane_x), jnp.asarray(lane_y))


def check(a) -> dict:
    """Kernel against pool on one device: a small map of cheap lanes (no sticking)."""
    import jax

    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig, run_lanes
    from jaxcelt.versions import versions

    p = jc.CeltParams.paper()
    xs, ys = np.linspace(15.0, 20.0, 8), np.linspace(0.04, 0.06, 8)
    pb = pb_all(p, xs, ys)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (64, 1))
    rec = {"versions": versions(), "device_kind": jax.devices()[0].device_kind, "grid": [8, 8], "omega_pi": [15, 20],
           "q_pi": [0.04, 0.06], "periods": 10}  # fmt: skip
    tols = {"float64": (1e-8, 1e-10), "float32": (1e-6, 1e-8)}
    for dtype in a.check_dtypes:
        rtol, atol = tols[dtype]
        cfg = SweepConfig(transient_periods=7, sample_periods=3, rtol=rtol, atol=atol, stop_on_invalid=True, dtype=dtype)
        res = {}
        for engine in ("kernel", "pool"):  # the kernel first: if it fails, it fails fast
            t = time.perf_counter()
            res[engine] = run_lanes(pb, y0, cfg, varying=("omega_pi", "q_pi"), engine=engine)
            rec[f"{dtype}_{engine}_s_incl_compile"] = round(time.perf_counter() - t, 2)
        A, B = res["pool"], res["kernel"]
        fin = np.isfinite(A["samples"]) & np.isfinite(B["samples"])
        scale = np.maximum(np.abs(A["samples"]), 1e-3)
        rec[dtype] = {
            "same_status": int(np.sum(A["status"] == B["status"])),
            "same_steps": int(np.sum(A["num_steps"] == B["num_steps"])),
            "max_step_difference": int(np.max(np.abs(A["num_steps"] - B["num_steps"]))),
            "same_finite_samples": bool(np.array_equal(np.isfinite(A["samples"]), np.isfinite(B["samples"]))),
            "max_sample_difference_rel": float(np.max(np.where(fin, np.abs(A["samples"] - B["samples"]) / scale, 0))),
            "status_counts": {str(k): int(v) for k, v in zip(*np.unique(B["status"], return_counts=True))},
        }
        print(json.dumps({dtype: rec[dtype]}), flush=True)
    return rec


if __name__ == "__main__":
    sys.exit(main())
