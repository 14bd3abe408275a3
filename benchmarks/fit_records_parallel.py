"""One evaluation of a fit's residuals and Jacobian: records in parallel threads against one program
(writes docs/fit/records_parallel.json).

The problem of ``benchmarks/bench_fit.py`` (two 1 s gyro records, 4 parameters) at the paper's
values: (r, J) by ``jaxcelt.identify.program.evaluate`` (on a multi-core CPU: each record by the one-record
program in its own thread), by the all-records program (`jax.lax.map` over the records,
``evaluate_program``), and by the one-record program called for each record in turn. Compiled
first; best of ``--reps`` warm calls each; the results of the modes are compared.

    python benchmarks/fit_records_parallel.py [--reps 10] [--out docs/fit/records_parallel.json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _fit_problem import paper_and_true, records  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=10)
    ap.add_argument("--out", type=Path, default=Path("docs/fit/records_parallel.json"))
    a = ap.parse_args(argv)
    import numpy as np

    from jaxcelt.identify import program as F
    from jaxcelt.identify.options import FitOptions
    from jaxcelt.identify.problem import build_problem
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions
    paper, _ = paper_and_true()
    data = records()
    config = FitOptions(free=("mu", "k_r", "b_Ts", "m_Ts"), max_steps=2000)
    prob, z = build_problem(data, paper, config)
    zf = np.asarray(prob.flatten(z))
    parts = [F.one_record(prob, i) for i in range(prob.n_records)]
    modes = {
        "threads": lambda: F.evaluate(prob, zf),
        "one_program_lax_map": lambda: F.evaluate_program(prob, zf),
        "records_in_turn": lambda: [F.evaluate_program(p, zf[..., c]) for p, c, _ in parts],
    }
    out = dict(versions=versions(), cpus=F.cpu_workers(), load_before=os.getloadavg(), reps=a.reps, best_s={})
    results = {}
    for name, f in modes.items():
        results[name] = f()  # compile
        ts = []
        for _ in range(a.reps):
            t = time.perf_counter()
            f()
            ts.append(time.perf_counter() - t)
        out["best_s"][name] = min(ts)
        print(name, min(ts), flush=True)
    r0, J0 = results["one_program_lax_map"]
    r1, J1 = results["threads"]
    out["threads_vs_one_program_rel_diff"] = dict(
        r=float(np.linalg.norm(r1 - r0) / np.linalg.norm(r0)), J=float(np.linalg.norm(J1 - J0) / np.linalg.norm(J0))
    )
    out["speedup_threads_over_one_program"] = out["best_s"]["one_program_lax_map"] / out["best_s"]["threads"]
    out["load_after"] = os.getloadavg()
    write_result(a.out, out, load_at_start=out["load_before"])
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
