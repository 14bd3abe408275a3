"""One process with a JAX device per core against one single-device process per core, pinned.

The 400 x 300 sweep of `bench_sweep.py` (omega_pi 10..20 rad/s from rest, rtol 1e-8, Tsit5, lane pool
of 96 slots per device), stopping lanes at invalid states and integrating every lane on, three ways
in one run, alternating, each timed after compilation:

* ``devices``: one process, ``jax_num_cpu_devices = cores``, lanes sharded over the devices (what
  ``jaxcelt bifurcation`` does on a CPU);
* ``processes``: ``devices=jaxcelt.HostProcesses(cores)``, one worker process per core, each pinned
  to its core with one JAX device, taking the lanes that device would get (lane d, d + cores, ...);
  the time includes sending the lanes and receiving the results;
* the numba DP5(4) ensemble (``_numba_model.dopri_ensemble``, one thread per core), for the ratio.

Both jaxcelt variants run the same lanes with the same settings, but as different compiled programs
(one program over several devices against one single-device program per process), which may round
differently: a lane that has left the model's validity is chaotic, and over hundreds of periods it may
then take other steps. The script records each variant's total steps and how many lanes differ.

    .venv/bin/python benchmarks/bench_processes.py --out docs/bifurcation   # -> processes.json
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=300)
    ap.add_argument("--sample", type=int, default=100)
    ap.add_argument("--reps", type=int, default=3, help="alternating runs of each variant per mode (medians reported)")
    ap.add_argument("--modes", default="stop,on", help="'stop' (stop at invalid states), 'on' (integrate on)")
    ap.add_argument("--out", type=Path, default=None, help="folder for processes.json (optional)")
    a = ap.parse_args()
    cores = len(os.sched_getaffinity(0))
    transient = a.periods - a.sample
    import jax

    jax.config.update("jax_num_cpu_devices", cores)  # one device per core, before JAX starts
    import jaxcelt as jc

    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)

    sys.path.insert(0, str(HERE))
    import _numba_model as nm

    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    V = versions()
    print(" ".join(f"{k}={v}" for k, v in V.items()), flush=True)
    res: dict = dict(
        versions=V,
        cores=cores,
        load_average_at_start=os.getloadavg(),
        config=dict(n_freq=a.n_freq, periods=a.periods, sample=a.sample, rtol=1e-8, atol=1e-10, solver="Tsit5"),
    )
    devs = jax.devices()
    pb = lanes_params(p, "omega_pi", vals)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    P, B, Bi = nm.pack(p)
    PP = np.tile(P, (len(vals), 1))
    PP[:, nm.WPI] = vals
    TS = np.stack([2 * np.pi / w * np.arange(transient, a.periods) for w in vals])
    nm.dopri_ensemble(y0[:2].copy(), TS[:2, :1].copy(), PP[:2].copy(), B, Bi, 1e-8, 1e-10, 10**7, True)
    for mode in a.modes.split(","):
        stop = mode == "stop"
        cfg = SweepConfig(
            transient_periods=transient, sample_periods=a.sample, rtol=1e-8, atol=1e-10, stop_on_invalid=stop
        )
        t = time.perf_counter()
        run_lanes(pb, y0, cfg, pad_to=len(vals), compile_only=True, devices=devs, stats=True)
        compile_devices = time.perf_counter() - t
        hp = jc.HostProcesses(cores)
        t = time.perf_counter()
        run_lanes(pb, y0, cfg, pad_to=len(vals), compile_only=True, devices=hp, stats=True)
        compile_workers = time.perf_counter() - t  # worker start (imports) and compilation, in parallel
        runs: dict = {"devices": [], "processes": [], "numba": []}
        for _ in range(a.reps):
            t = time.perf_counter()
            out, _ = run_lanes(pb, y0, cfg, pad_to=len(vals), devices=devs, stats=True)
            runs["devices"].append(time.perf_counter() - t)
            t = time.perf_counter()
            got, _ = run_lanes(pb, y0, cfg, pad_to=len(vals), devices=hp, stats=True)
            runs["processes"].append(time.perf_counter() - t)
            t = time.perf_counter()
            _, st_nb, _, status_nb = nm.dopri_ensemble(y0, TS, PP, B, Bi, 1e-8, 1e-10, 10**6, stop)
            runs["numba"].append(time.perf_counter() - t)
            print(mode, {k: round(v[-1], 2) for k, v in runs.items()}, flush=True)
        hp.close()
        steps, status, samples = got["num_steps"], got["status"], got["samples"]
        fin = np.isfinite(out["samples"]) & np.isfinite(samples)  # stopped lanes' later samples are inf
        with np.errstate(invalid="ignore"):
            diff = np.abs(samples - out["samples"])
        med = {k: float(np.median(v)) for k, v in runs.items()}
        res[mode] = dict(
            seconds=med,
            seconds_each_run=runs,
            compile_seconds_devices=compile_devices,
            worker_start_and_compile_seconds=compile_workers,
            total_steps_devices=int(out["num_steps"].sum()),
            total_steps_processes=int(steps.sum()),
            total_steps_numba=int(st_nb.sum()),
            lanes_with_other_steps_or_status=int(np.sum((steps != out["num_steps"]) | (status != out["status"]))),
            max_abs_sample_difference=float(np.max(diff, where=fin, initial=0.0)),
            status_counts_devices={int(k): int(v) for k, v in zip(*np.unique(out["status"], return_counts=True))},
            status_counts_processes={int(k): int(v) for k, v in zip(*np.unique(status, return_counts=True))},
            status_counts_numba={int(k): int(v) for k, v in zip(*np.unique(status_nb, return_counts=True))},
            ratio_numba_over_devices=med["numba"] / med["devices"],
            ratio_numba_over_processes=med["numba"] / med["processes"],
        )
        print(
            mode,
            json.dumps(res[mode]["seconds"]),
            "lanes that differ:",
            res[mode]["lanes_with_other_steps_or_status"],
            flush=True,
        )
    if a.out is not None:
        write_result(a.out / "processes.json", res, load_at_start=res["load_average_at_start"])
        print("wrote", a.out / "processes.json")


if __name__ == "__main__":
    main()
