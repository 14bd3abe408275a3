"""Where a fit's compilation goes (writes docs/fit/compile_parts.json).

The problem of ``benchmarks/bench_fit.py`` (two 1 s gyro records, 4 parameters). For the evaluation
program (`jaxcelt.identify.problem.value_and_jacobian`: residuals and forward-mode Jacobian) it times tracing +
lowering and XLA compilation apart, counts the host callbacks in it, and -- in two fresh processes
sharing an empty persistent compilation cache -- whether the second process loads it from the cache.
Modes: ``raise``, equinox's runtime checks as host callbacks (equinox's default); ``nan``, traced
inside `jaxcelt._diffrax_adapter.runtime_checks_as_nan`; ``nan-options``, that and compiled with
XLA's CPU fusion emitters off (``FUSION_EMITTERS_OFF``; an evaluation, not what `jaxcelt.fit` does:
see docs/identification.md). Also: the best of 10
warm runs of the compiled program (the two records, all-records program).

    python benchmarks/fit_compile_parts.py [--out docs/fit/compile_parts.json]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _fit_problem import paper_and_true, records  # noqa: E402

FUSION_EMITTERS_OFF = {"xla_cpu_use_fusion_emitters": False}


def child(mode: str) -> dict:

    from jaxcelt._diffrax_adapter import runtime_checks_as_nan
    from jaxcelt.identify.options import FitOptions
    from jaxcelt.identify.problem import build_problem, value_and_jacobian
    paper, _ = paper_and_true()
    data = records()
    config = FitOptions(free=("mu", "k_r", "b_Ts", "m_Ts"), max_steps=2000)
    prob, z = build_problem(data, paper, config)
    zf = prob.flatten(z)
    ctx = runtime_checks_as_nan() if mode != "raise" else contextlib.nullcontext()
    with ctx:
        t0 = time.perf_counter()
        low = value_and_jacobian.lower(prob, zf)
        t1 = time.perf_counter()
    exe = low.compile(compiler_options=FUSION_EMITTERS_OFF) if mode == "nan-options" else low.compile()
    t2 = time.perf_counter()
    exe(prob, zf)[1].block_until_ready()
    runs = []
    for _ in range(10):
        t = time.perf_counter()
        exe(prob, zf)[1].block_until_ready()
        runs.append(time.perf_counter() - t)
    return {
        "trace_lower_s": round(t1 - t0, 3),
        "compile_s": round(t2 - t1, 3),
        "host_callbacks": low.as_text().count("callback"),
        "run_best_of_10_s": round(min(runs), 4),
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/fit/compile_parts.json"))
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(child(a.child)))
        return 0
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    out = {"versions": versions(), "cpu_count": os.cpu_count(), "load_before": os.getloadavg(), "modes": {}}
    for mode in ("raise", "nan", "nan-options"):
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, JAX_COMPILATION_CACHE_DIR=cache, JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS="0")
            runs = []
            for _ in range(2):  # the first process fills the cache, the second may read it
                r = subprocess.run([sys.executable, __file__, "--child", mode], env=env, capture_output=True, text=True)
                if r.returncode:
                    print(r.stderr)
                    return 1
                runs.append(json.loads(r.stdout.strip().splitlines()[-1]))
                print(mode, runs[-1], flush=True)
        out["modes"][mode] = {"first_process": runs[0], "second_process": runs[1]}
    out["load_after"] = os.getloadavg()
    write_result(a.out, out, load_at_start=out["load_before"])
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
