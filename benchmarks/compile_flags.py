"""Compile and run time of jaxcelt's two heaviest programs with and without two XLA CPU flags that
cut compile time (``FLAGS`` below), side by side in one run. An evaluation: the flags are not set by
jaxcelt (measured: the pool compiles with ~20 % less CPU time but runs ~20 % slower).

Programs: (1) the main job's lane pool (96 lanes, the default `SweepConfig` of
``jaxcelt bifurcation``: compile only), then a 96-lane run of 40 + 8 periods (compiled apart,
timed warm); (2) the four-parameter Levenberg-Marquardt fit of ``benchmarks/bench_fit.py``
(two 1 s gyro records, noise-free). Each setting runs in fresh processes (``XLA_FLAGS`` unset or
``FLAGS``), alternating, ``--reps`` times; wall and process CPU seconds are reported (CPU time is
less sensitive to other load on a shared machine). The stroboscopic samples of the two settings
are compared: different compiled programs agree to a tolerance, not bitwise.

    .venv/bin/python benchmarks/compile_flags.py --reps 2 --out docs/performance/compile_flags.json
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FLAGS = "--xla_cpu_use_fusion_emitters=false --xla_llvm_disable_expensive_passes=true"

CHILD = r"""
import json, sys, time, numpy as np
w0, c0 = time.perf_counter(), time.process_time()
import jax, jaxcelt as jc
from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
from jaxcelt.identify.records import generate_data
out = {"XLA_FLAGS": __import__("os").environ.get("XLA_FLAGS", "")}
p = jc.CeltParams.paper()
vals = np.linspace(10.0, 20.0, 96)
y0 = np.tile(np.asarray(jc.initial_state(p)), (96, 1))

def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    r = fn()
    return r, time.perf_counter() - w, time.process_time() - c

cfg = SweepConfig()  # the main job's settings (jaxcelt bifurcation defaults)
_, out["pool_compile_wall"], out["pool_compile_cpu"] = timed(
    lambda: run_lanes(lanes_params(p, "omega_pi", vals), y0, cfg, pad_to=96, width=96, compile_only=True))
small = SweepConfig(transient_periods=40, sample_periods=8)
run = lambda: run_lanes(lanes_params(p, "omega_pi", vals), y0, small, pad_to=96, width=96)
_, out["small_first_wall"], _ = timed(run)
res, out["small_run_wall"], out["small_run_cpu"] = timed(run)
np.save(sys.argv[1], np.asarray(res.samples if hasattr(res, "samples") else res["samples"]))
paper = p
true = paper.replace(mu=0.2241 * 1.4, k_r=0.4345 * 0.6, b_Ts=0.5305 * 1.5, m_Ts=0.8161 * 1.35)
def start(spin, tilt):
    t = np.radians(tilt)
    return jc.initial_state(true, omega=(0.0, 0.0, spin), n=(np.sin(t), 0.0, np.cos(t)))
data = generate_data(true, [start(5.0, 10.0), start(-3.0, 6.0)], 1.0, rate=100, kinds=("omega",), noise=0.0)
fr, out["fit_wall"], out["fit_cpu"] = timed(lambda: jc.fit(data, paper, free=("mu", "k_r", "b_Ts", "m_Ts"), optimiser="lm", max_iter=300))
out.update(fit_compile=fr.compile_time, fit_run=fr.wall_time, fit_iters=fr.n_iter, fit_converged=fr.converged,
           fit_max_rel_err=max(fr.relative_error(true).values()))
print("RESULT " + json.dumps(out))
"""


def child(flag: str, samples: str) -> dict:
    env = dict(os.environ)
    env.pop("XLA_FLAGS", None)
    if flag == "1":
        env["XLA_FLAGS"] = FLAGS
    r = subprocess.run([sys.executable, "-c", CHILD, samples], env=env, capture_output=True, text=True, check=True)
    line = [ln for ln in r.stdout.splitlines() if ln.startswith("RESULT ")][-1]
    return json.loads(line[7:])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--out", default="docs/performance/compile_flags.json")
    a = ap.parse_args()
    import numpy as np

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.versions import versions_string

    load0 = load_average()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(a.reps):
            for flag in ("0", "1"):
                f = os.path.join(tmp, f"s{flag}_{rep}.npy")
                r = child(flag, f)
                r.update(rep=rep, with_flags=flag == "1", uptime=os.popen("uptime").read().strip())
                rows.append(r)
                print({k: (round(v, 3) if isinstance(v, float) else v) for k, v in r.items()}, flush=True)
        s0, s1 = np.load(os.path.join(tmp, "s0_0.npy")), np.load(os.path.join(tmp, "s1_0.npy"))
        ok = np.isfinite(s0) & np.isfinite(s1)
        max_diff = float(np.max(np.abs(s0[ok] - s1[ok]))) if ok.any() else None
        same_nan = bool(np.array_equal(np.isfinite(s0), np.isfinite(s1)))

    def med(key, flag):
        return float(np.median([r[key] for r in rows if r["with_flags"] == flag]))

    keys = (
        "pool_compile_wall",
        "pool_compile_cpu",
        "small_run_wall",
        "small_run_cpu",
        "fit_wall",
        "fit_cpu",
        "fit_compile",
        "fit_run",
    )
    summary = {
        k: {"off": med(k, False), "on": med(k, True), "ratio_off_over_on": med(k, False) / med(k, True)} for k in keys
    }
    out = dict(
        flags=FLAGS.split(),
        versions=versions_string(),
        machine=platform.processor() or platform.machine(),
        cpu_count=os.cpu_count(),
        summary_median=summary,
        pool_samples_max_abs_diff_on_vs_off=max_diff,
        pool_samples_same_finite_pattern=same_nan,
        rows=rows,
        date=time.strftime("%Y-%m-%d %H:%M:%S"),
    )
    write_result(a.out, out, load_at_start=load0)
    for k, v in summary.items():
        print(f"{k:20s} off {v['off']:8.2f}  on {v['on']:8.2f}  off/on {v['ratio_off_over_on']:.2f}")
    print("samples max |on - off|:", max_diff, "same finite pattern:", same_nan)


if __name__ == "__main__":
    main()
