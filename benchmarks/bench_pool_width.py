"""Pool width (vmap slots per device) against cost per step slot and wasted slots.

400 lanes (omega_pi 10..20, from rest), 40 transient + 20 sampled periods, rtol 1e-8,
stop-on-invalid, lanes sharded over all host CPU devices. Wider pools amortise per-kernel
overhead but waste more slots in the final drain (which the pool narrows to 1/2, 1/4, ...
of the width, down to 16 slots; slots are counted over all widths and devices); prints one line per width
and writes JSON.

    .venv/bin/python benchmarks/bench_pool_width.py --widths 32,64,96,128 --out docs/bifurcation
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import jax


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--widths", default="32,64,96,128")
    ap.add_argument("--host-devices", default="auto")
    ap.add_argument("--out", type=Path, default=None, help="folder for pool_width.json (optional)")
    a = ap.parse_args()
    n_host = (os.cpu_count() or 1) if a.host_devices == "auto" else int(a.host_devices)
    jax.config.update("jax_num_cpu_devices", n_host)  # before the first JAX operation

    import numpy as np

    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    ndev = len(jax.devices())
    res = dict(versions=versions(), devices=ndev, load_average_at_start=os.getloadavg(), rows=[])
    print(res["versions"], flush=True)
    p = jc.CeltParams.paper()
    vals = np.linspace(10, 20, 400)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    pb = lanes_params(p, "omega_pi", vals)
    cfg = SweepConfig(transient_periods=40, sample_periods=20, stop_on_invalid=True)
    for W in [int(w) for w in a.widths.split(",")]:
        t = time.perf_counter()
        run_lanes(pb, y0, cfg, width=W, compile_only=True)
        tc = time.perf_counter() - t
        t = time.perf_counter()
        out = run_lanes(pb, y0, cfg, width=W)
        tr = time.perf_counter() - t
        slots = int(out["pool_slot_steps"][0])  # summed over devices
        steps = int(out["num_steps"].sum())
        row = dict(width_per_device=W, compile_s=tc, run_s=tr, steps=steps, slots=slots,
                   wasted=1 - steps / slots, us_per_slot=tr / slots * 1e6)  # fmt: skip
        res["rows"].append(row)
        print(row, flush=True)
    if a.out is not None:
        write_result(a.out / "pool_width.json", res, load_at_start=res["load_average_at_start"])


if __name__ == "__main__":
    main()
