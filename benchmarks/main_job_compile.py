"""What compilation costs the main job (writes docs/bifurcation/main_job_compile.json).

Runs ``jaxcelt bifurcation`` (the quick start's main job: the paper's defaults, with figures)
twice in one fresh process with JAX's persistent cache off (``JAXCELT_CACHE_DIR=off``): the first
run compiles every program, the second finds them compiled in the process. The difference of
the two is what compilation adds to the run (tracing and XLA compilation on the critical path,
less whatever overlaps with other work). Reported for the sweep (``wall_seconds_including_compile``
of each run's summary.json) and for the whole command. The modules the command imports
(`PRE_IMPORTED`: matplotlib, xarray, h5py, ...) and JAX's CPU backend are loaded before the first
run, so that only compilation is counted; their times are reported apart (``imports_s``,
``backend_start_s``). Also the tracing and XLA compilation times JAX logs
(``jax_log_compiles``) for the programs that take more than 0.2 s.

    .venv/bin/python benchmarks/main_job_compile.py [--reps 3] [--out docs/bifurcation/main_job_compile.json]

With ``--reps N`` (default 3) the measurement runs in N fresh processes, one after another, and
the medians of the two overheads are reported beside every run.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import re
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _compile_log import COMMON_IMPORTS, log_compiles, pre_import  # noqa: E402

PRE_IMPORTED = (
    *COMMON_IMPORTS,
    "jaxcelt.cli",
    "jaxcelt.sweeps.dataset",
    "jaxcelt.sweeps.api",
    "jaxcelt.sweeps.dense",
    "jaxcelt.plotting.bifurcation",
)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/bifurcation/main_job_compile.json"))
    ap.add_argument("--reps", type=int, default=3, help="fresh processes, each measuring once; medians reported")
    a = ap.parse_args(argv)
    if a.reps > 1:
        return _repeated(a.out, a.reps)
    os.environ["JAXCELT_CACHE_DIR"] = "off"
    # the modules the command imports on its first run (not counted; their time is reported apart)
    imports_s = pre_import(PRE_IMPORTED)
    import jax

    # JAX's CPU backend with the command's device count ("auto"), started before the first run
    t = time.perf_counter()
    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)
    jax.devices()
    backend_start_s = time.perf_counter() - t

    from jaxcelt.cli import main as cli
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    logged: list[tuple[str, float]] = []

    class Collect(logging.Handler):
        def emit(self, record):
            m = re.match(r"Finished (.*) in ([0-9.]+) sec", record.getMessage())
            if m:
                logged.append((m[1], float(m[2])))

    log_compiles(Collect())
    # versions() after the runs: it starts JAX's backend, and the command sets the CPU device count first
    res: dict = dict(
        cpu_count=os.cpu_count(),
        load_average_at_start=os.getloadavg(),
        pre_imported=list(PRE_IMPORTED),
        imports_s=imports_s,
        backend_start_s=backend_start_s,
        runs=[],
    )
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(2):
            out = Path(tmp) / f"run{i}"
            n0 = len(logged)
            t, c = time.perf_counter(), time.process_time()
            rc = cli(["bifurcation", "--out", str(out)])
            whole, cpu = time.perf_counter() - t, time.process_time() - c
            summary = json.loads((out / "summary.json").read_text())
            res["runs"].append(
                dict(
                    exit_code=rc,
                    command_s=whole,
                    command_cpu_s=cpu,  # CPU time of the process (all threads) during the command
                    sweep_s=summary["wall_seconds_including_compile"],
                    regimes=summary["regimes"],
                    logged_over_0_2_s=[(k, v) for k, v in logged[n0:] if v > 0.2],
                    logged_total_s=sum(v for _, v in logged[n0:]),
                )
            )
    res["versions"] = versions()
    res["devices"] = len(jax.devices())
    first, second = res["runs"]
    res["sweep_compile_overhead_s"] = first["sweep_s"] - second["sweep_s"]
    res["command_compile_overhead_s"] = first["command_s"] - second["command_s"]
    res["same_regimes"] = first["regimes"] == second["regimes"]
    res["load_average_at_end"] = os.getloadavg()
    write_result(a.out, res, load_at_start=res["load_average_at_start"])
    print(json.dumps({k: v for k, v in res.items() if k != "runs"}, indent=1))
    for r in res["runs"]:
        print(f"command {r['command_s']:.1f} s, sweep {r['sweep_s']:.1f} s; logged: {r['logged_over_0_2_s']}")
    return 0


def _repeated(out: Path, reps: int) -> int:
    """Run the measurement in ``reps`` fresh processes (this VM's speed drifts between minutes);
    write every run and the medians of the two overheads."""
    import statistics
    import subprocess

    each = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(reps):
            f = Path(tmp) / f"rep{i}.json"
            subprocess.run([sys.executable, __file__, "--reps", "1", "--out", str(f)], check=True)
            each.append(json.loads(f.read_text()))
    res = dict(
        reps=each,
        sweep_compile_overhead_s_each=[r["sweep_compile_overhead_s"] for r in each],
        command_compile_overhead_s_each=[r["command_compile_overhead_s"] for r in each],
    )
    res["sweep_compile_overhead_s_median"] = statistics.median(res["sweep_compile_overhead_s_each"])
    res["command_compile_overhead_s_median"] = statistics.median(res["command_compile_overhead_s_each"])
    res["imports_s_median"] = statistics.median(r["imports_s"] for r in each)
    res["backend_start_s_median"] = statistics.median(r["backend_start_s"] for r in each)
    res["versions"] = each[0]["versions"]
    from jaxcelt.provenance import write_result

    write_result(out, res, load_at_start=each[0]["load_average_at_start"])
    print({k: v for k, v in res.items() if k != "reps"})
    return 0


if __name__ == "__main__":
    sys.exit(main())
