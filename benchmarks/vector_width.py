"""The lane pool's program with XLA's default 256-bit vectors against 512-bit (AVX-512) vectors.

The 400 x 300 sweep of `bench_sweep.py` (omega_pi 10..20 rad/s from rest, rtol 1e-8, Tsit5, the
lane pool on one JAX device per core), stopping lanes at invalid states and integrating every lane
on, with the pool's program compiled two ways:

* ``256``: XLA's CPU default (LLVM's preferred vector width, 256 bits: 4 doubles per vector);
* ``512``: ``xla_cpu_prefer_vector_width=512``, what ``jaxcelt`` compiles the pool with on a CPU
  (``jaxcelt._compile_options.pool_compiler_options``, for pools of at least 64 slots per device;
  the sweep here has 96).

Both variants run the contact law's ``wide_batch`` form (the pool's choice for wide pools); only the
vector width differs. The library gives 512-bit vectors only to pools of at least 64 slots per
device, so with fewer than 64 lanes per core the two variants are the same program.

Each variant runs in a fresh process (compilation timed apart, then ``--runs`` timed runs); the
variants alternate, ``--reps`` processes each, and the medians are reported with their ratio. The
two programs round differently, so a lane that has left the model's validity (chaotic) may take other
steps over hundreds of periods: each variant's total steps and status counts are recorded.
The CPU's model name and vector ISA are recorded from ``/proc/cpuinfo`` (``roofline.cpu_facts``).

    .venv/bin/python benchmarks/vector_width.py --out docs/bifurcation   # -> vector_width.json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
VARIANTS = ("256", "512")


def child(variant: str, mode: str, n_freq: int, periods: int, sample: int, runs: int) -> dict:
    import jax

    jax.config.update("jax_num_cpu_devices", len(os.sched_getaffinity(0)))
    import numpy as np

    import jaxcelt as jc
    import jaxcelt._compile_options as co
    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes

    if variant == "256":
        co.WIDE_VECTORS.clear()  # the pool compiled with XLA's defaults
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, n_freq)
    cfg = SweepConfig(
        transient_periods=periods - sample, sample_periods=sample, rtol=1e-8, atol=1e-10, stop_on_invalid=mode == "stop"
    )
    pb = lanes_params(p, "omega_pi", vals)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (n_freq, 1))
    kw = dict(pad_to=n_freq, devices=jax.devices())
    t = time.perf_counter()
    run_lanes(pb, y0, cfg, compile_only=True, stats=True, **kw)
    compile_s = time.perf_counter() - t
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        out, st = run_lanes(pb, y0, cfg, stats=True, **kw)
        times.append(time.perf_counter() - t)
    status = np.bincount(np.asarray(out["status"]), minlength=4)
    return dict(
        variant=variant, mode=mode, compile_s=compile_s, run_s=times, steps=int(np.sum(out["num_steps"])),
        status_counts=status.tolist(), iterations=st.iterations, slot_steps=st.slot_steps,
    )  # fmt: skip


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=300)
    ap.add_argument("--sample", type=int, default=100)
    ap.add_argument("--reps", type=int, default=2, help="fresh processes per variant and mode, alternating")
    ap.add_argument("--runs", type=int, default=2, help="timed runs per process (after compilation)")
    ap.add_argument("--modes", default="stop,on", help="'stop' (stop at invalid states), 'on' (integrate on)")
    ap.add_argument("--out", type=Path, default=None, help="folder for vector_width.json (optional)")
    ap.add_argument("--child", nargs=2, metavar=("VARIANT", "MODE"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        row = child(*a.child, a.n_freq, a.periods, a.sample, a.runs)
        print("ROW " + json.dumps(row), flush=True)
        return 0
    sys.path.insert(0, str(HERE))
    from roofline import cpu_facts

    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    V = versions()
    print(" ".join(f"{k}={v}" for k, v in V.items()), flush=True)
    res: dict = dict(
        versions=V, cpu=cpu_facts(), cores=len(os.sched_getaffinity(0)), load_average_at_start=os.getloadavg(),
        config=dict(n_freq=a.n_freq, periods=a.periods, sample=a.sample, rtol=1e-8, atol=1e-10, solver="Tsit5"),
        rows=[], summary={},
    )  # fmt: skip
    common = ["--n-freq", str(a.n_freq), "--periods", str(a.periods), "--sample", str(a.sample), "--runs", str(a.runs)]
    for mode in a.modes.split(","):
        for _ in range(a.reps):
            for v in VARIANTS:
                cmd = [sys.executable, __file__, "--child", v, mode, *common]
                done = subprocess.run(cmd, capture_output=True, text=True, check=True)
                row = json.loads(next(ln[4:] for ln in done.stdout.splitlines() if ln.startswith("ROW ")))
                res["rows"].append(row)
                print(json.dumps(row), flush=True)
        med = {}
        for v in VARIANTS:
            rows = [r for r in res["rows"] if r["mode"] == mode and r["variant"] == v]
            med[v] = dict(
                run_s=statistics.median(t for r in rows for t in r["run_s"]),
                compile_s=statistics.median(r["compile_s"] for r in rows),
                steps=rows[0]["steps"],
                status_counts=rows[0]["status_counts"],
            )
        med["speedup_512"] = med["256"]["run_s"] / med["512"]["run_s"]
        res["summary"][mode] = med
        print(mode, json.dumps(med), flush=True)
    res["load_average_at_end"] = os.getloadavg()
    if a.out is not None:
        write_result(a.out / "vector_width.json", res, load_at_start=res["load_average_at_start"])
        print("wrote", a.out / "vector_width.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
