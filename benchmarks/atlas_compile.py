"""What compilation costs the atlas (writes docs/atlas/atlas_compile.json).

Runs ``jaxcelt atlas`` at its default size (the paper's parameters, the command's defaults: the drawing that
``jaxcelt bifurcation --atlas`` adds) twice in one fresh process with JAX's persistent cache off
(``JAXCELT_CACHE_DIR=off``), each run into its own fresh output directory (the continuation is resumable: a second
run into the first run's directory would read its files back instead of computing). The first run compiles every
program, the second finds them compiled in the process; the difference of the two is what compilation adds on the
critical path. It is reported for each part of the atlas (``continuation``, ``brute_force``, ``branches``,
``spectrum``: the ``seconds`` of each run's atlas.json) and for the whole command (atlas.json's ``command`` and the
wall time of the call measured here). The modules the command imports (`PRE_IMPORTED`) and JAX's CPU backend are
loaded before the first run, so that only compilation is counted; their times are reported apart (``imports_s``,
``backend_start_s``), and the modules the first run still imported are listed (``imported_during_first_run``).
Also the tracing, lowering (jaxpr to MLIR) and XLA compilation times JAX logs (``jax_log_compiles``): per run, the
sums over the programs that take more than 0.2 s, the number of programs compiled and the five slowest to compile.

    python benchmarks/atlas_compile.py [--reps 2] [--out docs/atlas/atlas_compile.json]
    python benchmarks/atlas_compile.py --smoke --out /tmp/atlas_compile_smoke.json   # a tiny atlas, 2-3 minutes

With ``--reps N`` (default 2) the measurement runs in N fresh processes, one after another, and the medians of
every part's first-run, second-run and compile seconds are reported beside every run.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _compile_log import COMMON_IMPORTS, log_compiles, pre_import  # noqa: E402

PARTS = ("continuation", "brute_force", "branches", "spectrum", "command", "call")
"""the atlas's parts (atlas.json's ``seconds``), its ``command`` total, and ``call``: the call measured here"""

PRE_IMPORTED = (
    *COMMON_IMPORTS,
    "jaxcelt",
    "scipy.linalg",
    "jaxcelt.cli",
    "jaxcelt.commands.atlas",
    "jaxcelt.sweeps.atlas",
    "jaxcelt.sweeps.dataset",
    "jaxcelt.orbits.branch",
    "jaxcelt.plotting.atlas",
)

SMOKE_ARGS = (
    "--omega", "15", "16", "--values", "2", "--starts", "4", "1", "--transient", "20", "--sample", "4",
    "--lyapunov-periods", "4", "--spectrum-periods", "4", "--brute-values", "2", "--brute-transient", "2",
    "--brute-sample", "2", "--no-branches",
)  # fmt: skip
"""a tiny atlas (values 15, 15.6, 16; four starts; a few periods everywhere; no branches): the continuation, the
brute force and the spectrum run and compile, in about a minute per process. (The branches are left out: their
programs take about a minute to compile at any size, and the continuation needs ~100 transient periods before
it finds the period-1 orbits they start from.)"""

LOGGED = {"tracing": "Finished tracing ", "lowering": "Finished jaxpr to MLIR", "xla": "Finished XLA compilation"}
"""JAX's ``jax_log_compiles`` messages by stage"""

OVER_S = 0.2
"""programs whose stage took longer than this [s] are summed and listed"""


def parse_args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/atlas/atlas_compile.json"))
    ap.add_argument("--reps", type=int, default=2, help="fresh processes, each measuring once; medians reported")
    ap.add_argument("--smoke", action="store_true", help="a tiny atlas (a check of this script, not a measurement)")
    a = ap.parse_args(argv)
    if a.reps < 1:
        ap.error(f"argument --reps: expected at least 1, got {a.reps}")
    return a


def atlas_argv(out: Path, smoke: bool) -> list[str]:
    """The command line of one run: ``jaxcelt atlas`` at its defaults (or `SMOKE_ARGS`) into ``out``."""
    return ["atlas", "--out", str(out), *(SMOKE_ARGS if smoke else ())]


def part_seconds(first: dict, second: dict) -> dict[str, dict]:
    """Per part of `PARTS`: the first run's and second run's seconds and their difference (``compile_s``: what
    compilation adds on the critical path); a part missing from either run (not run) is left out."""
    return {
        p: dict(first_s=first[p], second_s=second[p], compile_s=round(first[p] - second[p], 3))
        for p in PARTS
        if first.get(p) is not None and second.get(p) is not None
    }


def logged_summary(logged: list[tuple[str, str, float]], over_s: float = OVER_S) -> dict:
    """JAX's logged (stage, program, seconds): per stage the sum over the entries above ``over_s`` and over all;
    the number of programs compiled (XLA compilations); the five slowest XLA compilations."""
    out: dict = {}
    for stage in LOGGED:
        s = [v for k, _, v in logged if k == stage]
        out[f"{stage}_s_over_{over_s:g}"] = round(sum(v for v in s if v > over_s), 3)
        out[f"{stage}_s_all"] = round(sum(s), 3)
    xla = sorted(((v, n) for k, n, v in logged if k == "xla"), reverse=True)
    out["programs_compiled"] = len(xla)
    out[f"programs_over_{over_s:g}"] = sum(v > over_s for v, _ in xla)
    out["top5_xla"] = [[n, round(v, 3)] for v, n in xla[:5]]
    out[f"xla_over_{over_s:g}"] = [[n, round(v, 3)] for v, n in xla if v > over_s]
    return out


def medians(reps: list[dict]) -> dict[str, dict]:
    """Per part and quantity, the median over the fresh processes (a part absent in some process: over the rest);
    under ``logged_first_run`` and ``logged_second_run`` the medians of the logged numbers of each run."""
    out: dict = {}
    for p in PARTS:
        rows = [r["parts"][p] for r in reps if p in r["parts"]]
        if rows:
            out[p] = {k: round(statistics.median(row[k] for row in rows), 3) for k in rows[0]}
    for i, name in enumerate(("logged_first_run", "logged_second_run")):
        rows = [r["runs"][i]["logged"] for r in reps]
        out[name] = {k: round(statistics.median(row[k] for row in rows), 3) for k, v in rows[0].items()
                     if isinstance(v, int | float)}  # fmt: skip
    return out


def main(argv=None) -> int:
    a = parse_args(argv)
    if a.reps > 1:
        return _repeated(a)
    os.environ["JAXCELT_CACHE_DIR"] = "off"
    imports_s = pre_import(PRE_IMPORTED)  # the modules the command imports on its first run (reported apart)
    import jax

    t = time.perf_counter()
    jax.devices()  # JAX's CPU backend (the atlas command keeps JAX's device count), started before the first run
    backend_start_s = time.perf_counter() - t

    from jaxcelt.cli import main as cli
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    logged: list[tuple[str, str, float]] = []

    class Collect(logging.Handler):
        def emit(self, record):
            msg = record.getMessage()
            for stage, head in LOGGED.items():
                if msg.startswith(head):
                    m = re.fullmatch(r"Finished (?:tracing|jaxpr to MLIR module conversion|XLA compilation of) (.*?)"
                                 r"(?: for jit)? in ([0-9.eE+-]+) sec", msg)  # fmt: skip
                    if m:
                        logged.append((stage, m[1], float(m[2])))

    log_compiles(Collect())
    res: dict = dict(
        smoke=a.smoke,
        argv=atlas_argv(Path("DIR"), a.smoke),
        cpu_count=os.cpu_count(),
        load_average_at_start=os.getloadavg(),
        pre_imported=list(PRE_IMPORTED),
        imports_s=round(imports_s, 3),
        backend_start_s=round(backend_start_s, 3),
        runs=[],
    )
    summaries = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(2):
            out = Path(tmp) / f"run{i}"  # a fresh directory each run: nothing resumed
            n0, mods0 = len(logged), set(sys.modules)
            t, c = time.perf_counter(), time.process_time()
            rc = cli(atlas_argv(out, a.smoke))
            whole, cpu = time.perf_counter() - t, time.process_time() - c
            summary = json.loads((out / "atlas.json").read_text())
            summaries.append(summary)
            run = dict(exit_code=rc, seconds={**summary["seconds"], "call": round(whole, 3)}, call_cpu_s=round(cpu, 3),
                       logged=logged_summary(logged[n0:]))  # fmt: skip
            if i == 0:
                run["imported_during_first_run"] = sorted({".".join(m.split(".")[:2]) for m in set(sys.modules) - mods0})
            res["runs"].append(run)
    first, second = res["runs"]
    res["parts"] = part_seconds(first["seconds"], second["seconds"])
    res["same_atlas"] = (summaries[0]["continuation"] == summaries[1]["continuation"]
                         and [b["n_points"] for b in summaries[0]["branches"]]
                         == [b["n_points"] for b in summaries[1]["branches"]])  # fmt: skip
    res["versions"] = versions()
    res["devices"] = len(jax.devices())
    res["load_average_at_end"] = os.getloadavg()
    write_result(a.out, res, load_at_start=res["load_average_at_start"])
    _report(res)
    return 0


def _report(res: dict) -> None:
    print(f"versions: {res['versions']}")
    print(f"imports {res['imports_s']:.2f} s, backend start {res['backend_start_s']:.2f} s (not counted)")
    print(f"{'part':>13} {'first [s]':>10} {'second [s]':>11} {'compile [s]':>12}")
    for p, d in res["parts"].items():
        print(f"{p:>13} {d['first_s']:>10.2f} {d['second_s']:>11.2f} {d['compile_s']:>12.2f}")
    for i, r in enumerate(res["runs"]):
        lg = r["logged"]
        print(f"run {i + 1}: " + ", ".join(f"{k} {v}" for k, v in lg.items() if not isinstance(v, list)))
        print(f"run {i + 1}: top 5 XLA compilations: {lg['top5_xla']}")
    if "imported_during_first_run" in res["runs"][0]:
        print(f"modules imported during the first run: {len(res['runs'][0]['imported_during_first_run'])}")
    print(f"same atlas both runs: {res['same_atlas']}")
    again = res["runs"][1]["logged"]
    if again["programs_compiled"]:
        print(f"NOTE: the second run compiled {again['programs_compiled']} programs again ({again['xla_s_all']} s of XLA "
              "compilation): a part that compiles on every call shows it in both runs, not in the difference")


def _repeated(a: argparse.Namespace) -> int:
    """Run the measurement in ``a.reps`` fresh processes (a VM's speed drifts between minutes); write every run
    and the medians."""
    import subprocess

    each = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(a.reps):
            f = Path(tmp) / f"rep{i}.json"
            cmd = [sys.executable, __file__, "--reps", "1", "--out", str(f), *(["--smoke"] if a.smoke else [])]
            subprocess.run(cmd, check=True)
            each.append(json.loads(f.read_text()))
    res = dict(smoke=a.smoke, argv=each[0]["argv"], reps=each, medians=medians(each))
    res["imports_s_median"] = round(statistics.median(r["imports_s"] for r in each), 3)
    res["backend_start_s_median"] = round(statistics.median(r["backend_start_s"] for r in each), 3)
    res["same_atlas_all"] = all(r["same_atlas"] for r in each)
    res["versions"] = each[0]["versions"]
    from jaxcelt.provenance import write_result

    write_result(a.out, res, load_at_start=each[0]["load_average_at_start"])
    print(f"medians over {a.reps} fresh processes (seconds):")
    print(f"{'part':>13} {'first [s]':>10} {'second [s]':>11} {'compile [s]':>12}")
    for p, d in res["medians"].items():
        if p in PARTS:
            print(f"{p:>13} {d['first_s']:>10.2f} {d['second_s']:>11.2f} {d['compile_s']:>12.2f}")
    for k in ("logged_first_run", "logged_second_run"):
        print(f"{k}: {res['medians'][k]}")
    print({k: v for k, v in res.items() if k not in ("reps", "medians", "versions")})
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
