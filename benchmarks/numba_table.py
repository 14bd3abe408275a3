"""Benchmark: the main job at scale against the compiled-C floor -- jaxcelt's lane pool vs a numba ensemble.

The paper's main job at scale: N frequencies omega_pi in [10, 20] rad/s x P periods from rest (the last S
sampled), rtol 1e-8, atol 1e-10, eps = 1e-4, max_steps 10^6, in two modes:

* **stop at invalid** (the CLI's default): a lane ends at its first invalid state (lift-off, n3 <= 0);
* **integrate on**: every lane runs to its end, except that a lane past validity ends where the stone lies on
  its side (status 4, `jaxcelt.integrate.solve.HEADING_GAP`) -- on both sides.

Side by side on this machine, each measured in a **fresh process** (so that "first call" is what a user's first
sweep costs: compilation included, JAX's persistent cache off, numba's on-disk cache in an empty directory):

* ``jaxcelt``: `jaxcelt.bifurcation` (the lane pool, 2 CPU devices on 2 cores, Tsit5);
* ``numba``: a hand-written adaptive Dormand-Prince 5(4) ensemble, prange over lanes on all cores
  (``benchmarks/_numba_model.py``, the same controller and the same stop rules);
* ``scipy``: ``solve_ivp(DOP853)`` on the numba right-hand side, one lane at a time on one core, stopping
  invalid lanes by terminal events, measured on an evenly spread subset and extrapolated to all lanes by
  jaxcelt's per-lane step counts (reported per core and as if spread over all cores).

Per mode: the first call (end to end, compilation included) and the median of ``--reps`` warm calls in the
same process, lane-steps and statuses; for jaxcelt also what JAX logs of its tracing, lowering and XLA compilation
(``jax_log_compiles``, steps of at least 0.05 s) in the first call and in the warm calls. Writes one JSON file through `jaxcelt.provenance.write_result` and
prints a table with the ratios, versions and CPU.

    python benchmarks/numba_table.py --out docs/performance/numba_table_400x300.json
    python benchmarks/numba_table.py --n-freq 40 --periods 40 --sample 10 --reps 1 --out /tmp/t.json   # smoke
    python benchmarks/numba_table.py --modes on --engines jaxcelt --out /tmp/on.json   # one row, jaxcelt only

With ``--modes`` or ``--engines`` narrowed, only those rows run: the ratios need both engines, and the scipy row
needs jaxcelt stopping at invalid states (its per-lane step counts), so they are left out otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def _setup(a):
    sys.path.insert(0, str(HERE))
    import _numba_model as nm

    import jaxcelt as jc

    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    tr = a.periods - a.sample
    P, B, Bi = nm.pack(p)
    PP = np.tile(P, (len(vals), 1))
    PP[:, nm.WPI] = vals
    TS = np.stack([2 * np.pi / w * np.arange(tr, a.periods) for w in vals])
    Y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    return nm, jc, p, vals, tr, (PP, B, Bi, TS, Y0)


def child(a) -> dict:
    """One engine and mode in this (fresh) process: the first call, then ``reps`` warm calls."""
    engine, mode = a.child.split(":")
    stop = mode == "stop"
    log: list[tuple[str, float]] = []
    if engine == "jaxcelt":
        import logging
        import re

        import jax
        from _compile_log import log_compiles

        jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)

        class Log(logging.Handler):
            def emit(self, rec):
                m = re.search(r"Finished (.+?) in ([\d.]+) sec", rec.getMessage())
                if m and float(m.group(2)) >= 0.05:
                    log.append((m.group(1), float(m.group(2))))

        sys.path.insert(0, str(HERE))
        log_compiles(Log())
    nm, jc, p, vals, tr, (PP, B, Bi, TS, Y0) = _setup(a)
    if engine == "jaxcelt":

        def call():
            r = jc.bifurcation(p, vals, transient_periods=tr, sample_periods=a.sample, rtol=1e-8, atol=1e-10,
                               stop_on_invalid=stop, max_steps=10**6, sort_by_cost=True)  # fmt: skip
            return np.asarray(r.num_steps).ravel(), np.asarray(r.status).ravel()
    else:

        def call():
            _, st, _, status = nm.dopri_ensemble(Y0, TS, PP, B, Bi, 1e-8, 1e-10, 10**6, stop)
            return st, status

    t = time.perf_counter()
    steps, status = call()
    first = time.perf_counter() - t
    first_log = list(log)
    warm = []
    for _ in range(a.reps):
        t = time.perf_counter()
        steps, status = call()
        warm.append(time.perf_counter() - t)
    return {
        "first_call_s": first,
        "warm_s": float(np.median(warm)),
        "warm_each_s": warm,
        "lane_steps": int(np.sum(steps)),
        "steps_per_lane": [int(x) for x in steps],
        "status_counts": {str(int(k)): int(v) for k, v in zip(*np.unique(status, return_counts=True))},
    } | ({"first_call_compile_log": first_log, "warm_calls_compile_log": log[len(first_log):]} if engine == "jaxcelt" else {})


def _scipy(a, weights: np.ndarray) -> dict:
    sys.path.insert(0, str(HERE))
    from bench_sweep import scipy_lane

    nm, jc, p, vals, tr, (PP, B, Bi, TS, Y0) = _setup(a)
    sub = np.unique(np.linspace(0, a.n_freq - 1, a.scipy_subset).astype(int))
    nm.rhs(0.0, Y0[0], PP[0], B, Bi, np.empty(13))  # compile the RHS outside the timing
    t = time.perf_counter()
    for k in sub:
        scipy_lane(Y0[k], TS[k], PP[k], B, Bi, 1e-8, 1e-10, stop_invalid=True)
    t_sub = time.perf_counter() - t
    est = t_sub * weights.sum() / weights[sub].sum()
    cores = os.cpu_count() or 1
    return {"lanes_measured": len(sub), "subset_s": t_sub, "one_core_s": float(est), "all_cores_s": float(est / cores),
            "cores": cores}  # fmt: skip


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=300)
    ap.add_argument("--sample", type=int, default=100)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--scipy-subset", type=int, default=8)
    ap.add_argument("--out", type=Path, default=Path("docs/performance/numba_table_400x300.json"))
    ap.add_argument("--modes", default="stop,on", help="comma-separated, of stop,on (default both)")
    ap.add_argument("--engines", default="jaxcelt,numba", help="comma-separated, of jaxcelt,numba (default both)")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(child(a)))
        return 0
    if not (0 < a.sample <= a.periods) or a.n_freq < 1 or a.reps < 1:
        print("numba_table: need 0 < --sample <= --periods, --n-freq >= 1, --reps >= 1", file=sys.stderr)
        return 2
    modes, engines = a.modes.split(","), a.engines.split(",")
    if not modes or set(modes) - {"stop", "on"} or not engines or set(engines) - {"jaxcelt", "numba"}:
        print("numba_table: --modes takes stop and/or on, --engines jaxcelt and/or numba", file=sys.stderr)
        return 2
    from jaxcelt.provenance import load_average, machine, write_result
    from jaxcelt.versions import versions

    load0 = load_average()
    base = [sys.executable, __file__, "--n-freq", str(a.n_freq), "--periods", str(a.periods), "--sample",
            str(a.sample), "--reps", str(a.reps)]  # fmt: skip
    res = {"config": vars(a) | {"out": str(a.out), "rtol": 1e-8, "atol": 1e-10, "max_steps": 10**6},
           "versions": versions(), "machine": machine(), "jaxcelt_cpu_devices": os.cpu_count() or 1,
           "numba_threads": os.cpu_count() or 1, "modes": {}}  # fmt: skip
    for mode in [m for m in ("stop", "on") if m in modes]:
        row = {}
        for engine in [e for e in ("jaxcelt", "numba") if e in engines]:
            numba_cache = tempfile.mkdtemp(prefix="jaxcelt-numba-cache-")  # empty: numba compiles in the first call
            env = dict(os.environ, JAXCELT_CACHE_DIR="off", NUMBA_CACHE_DIR=numba_cache)
            env.pop("JAX_COMPILATION_CACHE_DIR", None)
            t = time.perf_counter()
            out = subprocess.run(base + ["--child", f"{engine}:{mode}"], env=env, capture_output=True, text=True)
            if out.returncode != 0:
                print(out.stderr[-3000:], file=sys.stderr)
                return 1
            row[engine] = json.loads(out.stdout.strip().splitlines()[-1]) | {"process_s": time.perf_counter() - t}
            print(mode, engine, {k: v for k, v in row[engine].items() if k != "steps_per_lane"}, flush=True)
        if "jaxcelt" in row:
            row["first_call_minus_warm_jaxcelt_s"] = row["jaxcelt"]["first_call_s"] - row["jaxcelt"]["warm_s"]
        if "jaxcelt" in row and "numba" in row:
            j, n = row["jaxcelt"], row["numba"]
            row["warm_speedup_vs_numba"] = n["warm_s"] / j["warm_s"]
            row["first_call_speedup_vs_numba"] = n["first_call_s"] / j["first_call_s"]
        res["modes"][mode] = row
    if "jaxcelt" in res["modes"].get("stop", {}):
        res["scipy_stop"] = _scipy(a, np.asarray(res["modes"]["stop"]["jaxcelt"]["steps_per_lane"], float))
        print("scipy (stop at invalid)", res["scipy_stop"], flush=True)
    print(f"\n{'mode':<18}{'numba warm':>12}{'jaxcelt warm':>14}{'ratio':>8}{'jaxcelt 1st':>13}{'numba 1st':>11}"
          f"{'steps jax/numba':>22}  statuses jax / numba")  # fmt: skip
    for mode, row in res["modes"].items():
        if "numba" not in row or "jaxcelt" not in row:
            for engine, r in row.items():
                if isinstance(r, dict):
                    print(f"{mode:<18}{engine}: warm {r['warm_s']:.1f} s, first call {r['first_call_s']:.1f} s, "
                          f"{r['lane_steps'] / 1e6:.1f}M lane-steps, {r['status_counts']}")  # fmt: skip
            continue
        j, n = row["jaxcelt"], row["numba"]
        print(f"{mode:<18}{n['warm_s']:>11.1f}s{j['warm_s']:>13.1f}s{row['warm_speedup_vs_numba']:>7.2f}x"
              f"{j['first_call_s']:>12.1f}s{n['first_call_s']:>10.1f}s"
              f"{j['lane_steps'] / 1e6:>11.1f}M /{n['lane_steps'] / 1e6:>6.1f}M  {j['status_counts']} / {n['status_counts']}")  # fmt: skip
    print(json.dumps(res["versions"]), res["machine"].get("cpu"))
    write_result(a.out, res, load_at_start=load0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
