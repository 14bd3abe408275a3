"""Identification benchmark: optimiser x problem on two 1 s gyro records (writes docs/fit/bench_fit.json).

Problem: two IMU-gyro records (omega in body axes, 100 Hz, 1 s each; releases tilted 10 deg
spinning at +5 rad/s and tilted 6 deg spinning at -3 rad/s) of the stone with mu, k_r, b_Ts, m_Ts
30-50 % off the paper's values; every fit starts at the paper's values. Noise: 0 and 1 % of each
channel's RMS. Each optimiser runs in a fresh process (its compilation is measured cold, without the
persistent cache); inside it the noisy fit re-uses the compiled programs. ``--cache`` adds LM runs
with the persistent XLA cache (cold fill, then a second process that reads it).

Usage: python benchmarks/bench_fit.py [--optimisers lm lbfgs adam] [--out docs/fit/bench_fit.json]
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

FREE = ("mu", "k_r", "b_Ts", "m_Ts")


def one(optimiser: str, max_iter: int, cache: str | None) -> list[dict]:
    """Runs in the child process: noise-free then 1 % noise fits with ``optimiser``."""
    import jax

    if cache:
        jax.config.update("jax_compilation_cache_dir", cache)
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.5)
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.data import generate_data

    paper = jc.CeltParams.paper()
    true = paper.replace(mu=0.2241 * 1.4, k_r=0.4345 * 0.6, b_Ts=0.5305 * 1.5, m_Ts=0.8161 * 1.35)

    def start(spin, tilt):
        t = np.radians(tilt)
        return jc.initial_state(true, omega=(0.0, 0.0, spin), n=(np.sin(t), 0.0, np.cos(t)))

    rows = []
    for noise in (0.0, 0.01):
        data = generate_data(true, [start(5.0, 10.0), start(-3.0, 6.0)], 1.0, rate=100, kinds=("omega",), noise=noise)
        t0 = time.perf_counter()
        res = jc.fit(data, paper, free=FREE, optimiser=optimiser, max_iter=max_iter)
        total = time.perf_counter() - t0
        rel = res.relative_error(true)
        rows.append(
            dict(
                optimiser=optimiser,
                noise=noise,
                persistent_cache=bool(cache),
                n_iter=res.n_iter,
                converged=res.converged,
                loss=res.loss,
                values=res.values,
                stderr=res.stderr,
                max_rel_err_vs_true=max(rel.values()),
                compile_s=res.compile_time,
                run_s=res.wall_time,
                fit_total_s=res.total_time,
                call_total_s=total,
            )
        )
        print(json.dumps(rows[-1]), flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--optimisers", nargs="+", default=["lm", "lbfgs", "adam"])
    ap.add_argument("--max-iter", type=int, default=300)
    ap.add_argument("--cache", action="store_true", help="also LM with the persistent compilation cache")
    ap.add_argument("--resume", action="store_true", help="keep the runs already in --out")
    ap.add_argument("--out", type=Path, default=Path("docs/fit/bench_fit.json"))
    ap.add_argument("--child", nargs=2, metavar=("OPTIMISER", "CACHE"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        for r in one(a.child[0], a.max_iter, None if a.child[1] == "-" else a.child[1]):
            print("ROW " + json.dumps(r), flush=True)
        return 0
    import diffrax
    import equinox
    import jax
    import optax
    import optimistix

    def uptime():
        return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()

    meta = dict(
        versions=dict(
            jax=jax.__version__,
            diffrax=diffrax.__version__,
            equinox=equinox.__version__,
            optax=optax.__version__,
            optimistix=optimistix.__version__,
            python=platform.python_version(),
        ),
        machine=dict(platform=platform.platform(), processor=platform.processor(), cpus=os.cpu_count()),
        uptime_before=uptime(),
    )
    print(meta, flush=True)
    rows = []
    if a.resume and a.out.exists():  # results are written after every run; --resume keeps them
        prev = json.loads(a.out.read_text())
        rows = prev["rows"]
        meta["uptime_before"] = prev["uptime_before"]
    done = {(r["optimiser"], r["persistent_cache"]) for r in rows}
    runs = [(o, "-") for o in a.optimisers if (o, False) not in done]
    if a.cache and not any(r["persistent_cache"] for r in rows):
        d = tempfile.mkdtemp(prefix="jaxcelt-xla-")
        runs += [("lm", d), ("lm", d)]
    for opt, cache in runs:
        cmd = [sys.executable, __file__, "--child", opt, cache, "--max-iter", str(a.max_iter)]
        out = subprocess.run(cmd, capture_output=True, text=True, env=os.environ | {"PYTHONUNBUFFERED": "1"})
        got = [json.loads(line[4:]) for line in out.stdout.splitlines() if line.startswith("ROW ")]
        if out.returncode or not got:
            print(out.stderr[-3000:], file=sys.stderr)
        for r in got:
            r["uptime_after"] = uptime()
            print(r, flush=True)
        rows += got
        for r in got:
            r["max_iter"] = a.max_iter
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(json.dumps(meta | {"rows": rows}, indent=1))
    meta["uptime_after"] = uptime()
    load = float(meta["uptime_after"].split("load average:")[1].split(",")[0])
    meta["loaded"] = load > 1.5
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(meta | {"rows": rows}, indent=1))
    print(f"wrote {a.out}")
    print(
        "| optimiser | noise | cache | iterations | converged | max rel. error vs true | compile [s] | run [s] | total [s] |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['optimiser']} | {r['noise']:g} | {'warm' if r['persistent_cache'] else 'off'} | {r['n_iter']} | "
            f"{'yes' if r['converged'] else 'no'} | {r['max_rel_err_vs_true']:.2g} | {r['compile_s']:.1f} | "
            f"{r['run_s']:.1f} | {r['fit_total_s']:.1f} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
