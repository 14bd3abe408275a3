"""Multi-start identification: the starts vmapped against one after another (writes docs/fit/multistart.json).

Problem of ``benchmarks/bench_fit.py`` (two 1 s IMU-gyro records of the stone with mu, k_r, b_Ts,
m_Ts 30-50 % off the paper's values), 1 % noise, Levenberg-Marquardt. Starts: the paper's values
and ``--starts - 1`` points drawn log-uniformly within a factor 2 of them (seeded). Each mode runs
in a fresh process without the persistent compilation cache, so its compilation is measured cold:
``vmapped`` (`jaxcelt.identify.strategies.multistart(vmapped=True)`: one vmapped LM step and one vmapped solve of
all starts per iteration) and ``sequential`` (``vmapped=False``, the CPU default: the fits one
after another, sharing one compilation). Reported: compile and run time of the whole call, iterations per start,
how many starts reached the best loss and the spread of the parameters over them.

    python benchmarks/bench_multistart.py [--starts 8] [--out docs/fit/multistart.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _fit_problem import FREE, paper_and_true, records  # noqa: E402


def child(mode: str, n_starts: int) -> dict:
    import numpy as np

    from jaxcelt.identify.strategies import multistart

    paper, true = paper_and_true()
    data = records(0.01)
    rng = np.random.default_rng(0)
    guesses = [{}] + [
        {n: float(getattr(paper, n)) * float(np.exp(rng.uniform(-np.log(2), np.log(2)))) for n in FREE}
        for _ in range(n_starts - 1)
    ]
    guesses = [g if "m_Ts" not in g else g | {"m_Ts": min(g["m_Ts"], 1.9)} for g in guesses]  # Bounded(0, 2)
    t0 = time.perf_counter()
    best, summ = multistart(data, paper, guesses, free=FREE, optimiser="lm", max_iter=100, vmapped=mode == "vmapped")
    total = time.perf_counter() - t0
    return dict(
        mode=mode,
        n_starts=n_starts,
        call_total_s=total,
        compile_s=summ["compile_time"],
        run_s=summ["wall_time"],
        n_iter=[f["n_iter"] for f in summ["fits"]],
        converged=[f["converged"] for f in summ["fits"]],
        loss=[f["loss"] for f in summ["fits"]],
        n_at_best=summ["n_at_best"],
        spread_rel={n: (hi - lo) / abs(best.values[n]) for n, (lo, hi) in summ["spread"].items()},
        best_values=best.values,
        best_rel_err_vs_true=best.relative_error(true),
        starts=guesses,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, default=8)
    ap.add_argument("--out", type=Path, default=Path("docs/fit/multistart.json"))
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        print("ROW " + json.dumps(child(a.child, a.starts)), flush=True)
        return 0
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    out = dict(versions=versions(), cpus=os.cpu_count(), platform=platform.platform(), load_before=os.getloadavg())
    rows = []
    for mode in ("vmapped", "sequential"):
        env = {k: v for k, v in os.environ.items() if k != "JAX_COMPILATION_CACHE_DIR"}
        cmd = [sys.executable, __file__, "--child", mode, "--starts", str(a.starts)]
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        got = [json.loads(ln[4:]) for ln in p.stdout.splitlines() if ln.startswith("ROW ")]
        if p.returncode or not got:
            print(p.stderr[-3000:], file=sys.stderr)
            return 1
        rows += got
        print({k: v for k, v in got[0].items() if k != "starts"}, flush=True)
    out["load_after"] = os.getloadavg()
    out["rows"] = rows
    out["run_ratio_sequential_over_vmapped"] = rows[1]["run_s"] / rows[0]["run_s"]
    out["total_ratio_sequential_over_vmapped"] = rows[1]["call_total_s"] / rows[0]["call_total_s"]
    write_result(a.out, out, load_at_start=out["load_before"])
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
