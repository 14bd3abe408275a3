"""Identification benchmark: optimiser x problem on two 1 s gyro records (writes docs/fit/bench_fit.json).

Problem: two IMU-gyro records (omega in body axes, 100 Hz, 1 s each; releases tilted 10 deg
spinning at +5 rad/s and tilted 6 deg spinning at -3 rad/s) of the stone with mu, k_r, b_Ts, m_Ts
30-50 % off the paper's values; every fit starts at the paper's values. Noise: 0 and 1 % of each
channel's RMS. Each optimiser runs in a fresh process (its compilation is measured cold, without the
persistent cache); inside it the noisy fit re-uses the compiled programs. ``--cache`` adds LM runs
with the persistent XLA cache (cold fill, then a second process that reads it).

Problems (``--problems``): ``4p`` (above); ``release`` (the same two records as gyro +
accelerometer, releases with headings 0.3 and -0.5 rad, the release states fitted with the four
parameters from a guess 0.2 rad off in heading, 3 deg off in tilt and 20 % off in spin,
`jaxcelt.identify.strategies.fit_staged` over 0.3 s then 1 s, noise-free); ``chaos`` (the omega_pi = 19 record
of ``docs/fit/chaos_data.npz``: 40 periods, full state, chaotic along the truth; multiple shooting
with 40 windows, window states from the data, continuity weight 1, from the study's start 30-50 %
off, a 300 s budget per fit); ``adam-long`` (problem ``4p``, Adam with 3000 iterations: whether
its cosine schedule converges).

Usage: python benchmarks/bench_fit.py [--optimisers lm lbfgs adam] [--problems 4p release chaos adam-long]
       [--cache] [--out docs/fit/bench_fit.json]
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

sys.path.insert(0, str(Path(__file__).parent))
from _fit_problem import FREE, paper_and_true, records, release  # noqa: E402


def other_problem(problem: str, optimiser: str, max_iter: int) -> list[dict]:
    """Runs in the child process: one fit of ``problem`` ("release", "chaos" or "adam-long")."""
    import dataclasses

    import jaxcelt as jc
    from jaxcelt.identify.records import generate_data, load_data
    from jaxcelt.identify.strategies import fit_staged

    paper, true = paper_and_true()

    t0 = time.perf_counter()
    if problem == "release":
        rel = [dict(tilt=10.0, spin=5.0, heading=0.3), dict(tilt=6.0, spin=-3.0, heading=-0.5)]
        data = generate_data(true, [release(true, **r) for r in rel], 1.0, rate=100, kinds=("omega", "accel"))
        guess = [release(paper, r["tilt"] + 3.0, 0.8 * r["spin"], r["heading"] + 0.2) for r in rel]
        data = jc.MeasuredData(tuple(dataclasses.replace(tr, y0=g) for tr, g in zip(data.trajectories, guess)))
        t0 = time.perf_counter()
        res = fit_staged(data, paper, (0.3, 1.0), free=FREE, optimiser=optimiser, fit_y0=True, max_iter=max_iter)
        compile_s = sum(st["compile_time"] for st in res.stages)
        run_s = sum(st["wall_time"] for st in res.stages)
        n_iter = sum(st["n_iter"] for st in res.stages)
        truth = true
    elif problem == "chaos":
        data = load_data(Path(__file__).parents[1] / "docs" / "fit" / "chaos_data.npz")
        truth = paper.replace(omega_pi=19.0)
        t0 = time.perf_counter()
        res = jc.fit(
            data, true.replace(omega_pi=19.0), free=FREE, optimiser=optimiser, windows=40, window_states="data",
            continuity_weight=1.0, sim_rtol=1e-8, sim_atol=1e-10, max_steps=100_000, max_iter=max_iter,
            max_time=300.0,
        )  # fmt: skip
        compile_s, run_s, n_iter = res.compile_time, res.wall_time, res.n_iter
    else:  # adam-long
        data = records()
        t0 = time.perf_counter()
        res = jc.fit(data, paper, free=FREE, optimiser=optimiser, max_iter=max_iter)
        compile_s, run_s, n_iter = res.compile_time, res.wall_time, res.n_iter
        truth = true
    total = time.perf_counter() - t0
    rel = res.relative_error(truth)
    hist = [
        max(abs(h[n] - float(getattr(truth, n))) / float(getattr(truth, n)) for n in FREE) for h in res.param_history
    ]
    return [
        dict(
            problem=problem, optimiser=optimiser, noise=0.0, persistent_cache=False, n_iter=n_iter,
            converged=res.converged, loss=res.loss, values=res.values, max_rel_err_vs_true=max(rel.values()),
            compile_s=compile_s, run_s=run_s, fit_total_s=total, call_total_s=total,
            max_rel_err_every_100=hist[::100], stages=res.stages,
        )
    ]  # fmt: skip


def one(optimiser: str, max_iter: int, cache: str | None) -> list[dict]:
    """Runs in the child process: noise-free then 1 % noise fits with ``optimiser``."""
    import jax

    if cache:
        jax.config.update("jax_compilation_cache_dir", cache)
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.5)
    import jaxcelt as jc

    paper, true = paper_and_true()

    rows = []
    for noise in (0.0, 0.01):
        data = records(noise)
        t0 = time.perf_counter()
        res = jc.fit(data, paper, free=FREE, optimiser=optimiser, max_iter=max_iter)
        total = time.perf_counter() - t0
        rel = res.relative_error(true)
        rows.append(
            dict(
                problem="4p",
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
    ap.add_argument("--problems", nargs="+", default=["4p"], choices=("4p", "release", "chaos", "adam-long"))
    ap.add_argument("--child", nargs=3, metavar=("PROBLEM", "OPTIMISER", "CACHE"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        prob, opt, cache = a.child
        rows = (
            one(opt, a.max_iter, None if cache == "-" else cache)
            if prob == "4p"
            else other_problem(prob, opt, a.max_iter)
        )
        for r in rows:
            print("ROW " + json.dumps(r), flush=True)
        return 0
    import diffrax
    import equinox
    import jax
    import optax
    import optimistix

    from jaxcelt.provenance import write_result

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
    for r in rows:
        r.setdefault("problem", "4p")
    done = {(r["problem"], r["optimiser"], r["persistent_cache"]) for r in rows}
    runs = []
    for prob in a.problems:
        opts = ["adam"] if prob == "adam-long" else a.optimisers
        runs += [
            (prob, o, "-", 3000 if prob == "adam-long" else a.max_iter) for o in opts if (prob, o, False) not in done
        ]
    if "4p" in a.problems and a.cache and not any(r["persistent_cache"] for r in rows):
        d = tempfile.mkdtemp(prefix="jaxcelt-xla-")
        runs += [("4p", "lm", d, a.max_iter), ("4p", "lm", d, a.max_iter)]
    for prob, opt, cache, max_iter in runs:
        cmd = [sys.executable, __file__, "--child", prob, opt, cache, "--max-iter", str(max_iter)]
        out = subprocess.run(cmd, capture_output=True, text=True, env=os.environ | {"PYTHONUNBUFFERED": "1"})
        got = [json.loads(line[4:]) for line in out.stdout.splitlines() if line.startswith("ROW ")]
        if out.returncode or not got:
            print(out.stderr[-3000:], file=sys.stderr)
        for r in got:
            r["uptime_after"] = uptime()
            print(r, flush=True)
        rows += got
        for r in got:
            r["max_iter"] = max_iter
        write_result(a.out, meta | {"rows": rows}, load_at_start=load_at_start(meta))
    meta["uptime_after"] = uptime()
    load = float(meta["uptime_after"].split("load average:")[1].split(",")[0])
    meta["loaded"] = load > 1.5
    write_result(a.out, meta | {"rows": rows}, load_at_start=load_at_start(meta))
    print(f"wrote {a.out}")
    print(table(rows))
    return 0


def load_at_start(meta: dict) -> list[float] | None:
    """The load average in ``uptime`` when the runs began (None where it cannot be read)."""
    try:
        return [float(x.strip()) for x in meta["uptime_before"].split("load average:")[1].split(",")[:3]]
    except (KeyError, IndexError, ValueError):
        return None


def table(rows: list[dict]) -> str:
    """The markdown table of docs/identification.md (tests/test_docs_numbers.py compares them)."""
    out = [
        "| problem | optimiser | noise | cache | iterations | converged | max rel. error vs true | compile [s] | run [s] | total [s] |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]  # fmt: skip
    seen_cache = 0
    for r in rows:
        cache = "off"
        if r["persistent_cache"]:
            cache = "cold (fills it)" if seen_cache < 2 else "warm (2nd process)"
            seen_cache += 1
        out.append(
            f"| {r.get('problem', '4p')} | {r['optimiser']} | {r['noise']:g} | {cache} | {r['n_iter']} | "
            f"{'yes' if r['converged'] else 'no'} | {r['max_rel_err_vs_true']:.2g} | {r['compile_s']:.1f} | "
            f"{r['run_s']:.1f} | {r['call_total_s']:.1f} |"
        )
    return "\n".join(out)


if __name__ == "__main__":
    sys.exit(main())
