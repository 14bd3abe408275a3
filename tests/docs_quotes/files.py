"""Readers of the committed result files for the quoted-number checks (``docs_quotes``).

Each check recomputes a quoted number from its JSON file (or from the test collection) and asserts
that the document contains it as written. A failure means a result file was regenerated (or a test
added) without updating the prose, or the prose was edited without a result behind it.
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def _text(rel: str) -> str:
    return (ROOT / rel).read_text(encoding="utf-8")


def _json(rel: str):
    return json.loads((ROOT / rel).read_text(encoding="utf-8"))


def _runs_of(pattern: str, commit: str, n: int) -> list[dict]:
    """The ``n`` result files ``pattern.format(commit=commit, i=i)`` (i = 1 .. n) of an alternating A/B, each checked
    to come from a clean checkout of ``commit``."""
    out = []
    for i in range(1, n + 1):
        d = _json(pattern.format(commit=commit, i=i))
        assert d["provenance"]["commit"].startswith(commit) and not d["provenance"]["dirty"], (pattern, commit, i)
        out.append(d)
    return out


def _stage_rows(pattern: str, commit: str, config: dict, layout: str = "round-robin 16", n: int = 3) -> list[dict]:
    """The ``layout`` rows of ``benchmarks/lyapunov_stage.py`` runs ``pattern.format(i=i)`` (i = 1 .. n), each checked
    to come from a clean checkout of ``commit`` and to have run with the settings ``config``."""
    rows = []
    for i in range(1, n + 1):
        d = _json(pattern.format(i=i))
        assert d["provenance"]["commit"].startswith(commit) and not d["provenance"]["dirty"], (pattern, i)
        assert all(d["config"][k] == v for k, v in config.items()), (pattern, i, config)
        rows.append(d["layouts"][layout])
    return rows


def _warm_each(rows: list[dict]) -> list[float]:
    """Every warm call of the stage rows, in run order."""
    return [x for r in rows for x in r["warm_each_s"]]


def _exponent_gap(a: dict, b: dict):
    """|lambda_a - lambda_b| over the lanes both stage rows have, and the same in units of ``a``'s standard errors."""

    def arr(r, k):
        return np.array([np.nan if x is None else x for x in r[k]])

    la, lb, ea = arr(a, "lyapunov"), arr(b, "lyapunov"), arr(a, "lyapunov_stderr")
    ok = np.isfinite(la) & np.isfinite(lb)
    d = np.abs(la - lb)[ok]
    return d, d / ea[ok]


def _sweep_each(runs: list[dict], k: int) -> str:
    """The sweep's seconds of run ``k`` of ``benchmarks/main_job_compile.py`` result files, one decimal each."""
    return ", ".join(f"{d['runs'][k]['sweep_s']:.1f}" for d in runs)


def _sweep_median(runs: list[dict], k: int) -> float:
    return statistics.median(d["runs"][k]["sweep_s"] for d in runs)


def _same_regimes(runs: list[dict]) -> None:
    """Asserts that every main-job result file's first run gave the same regimes, lane for lane."""
    labels = [[r for r in d["runs"][0]["regimes"] if "label" in r] for d in runs]
    assert all(x == labels[0] for x in labels)


def _same_orbit(ds: list[dict]) -> str:
    """'Newton steps N, branch points M, multipliers' of ``benchmarks/orbit_compile.py`` runs, each asserted the same
    in every run (the multipliers to six decimals)."""
    steps = {d["newton_steps"] for d in ds}
    points = {d["branch_points"] for d in ds}
    mults = {tuple(f"{m:.6f}" for m in d["multipliers_abs"]) for d in ds}
    assert len(steps) == len(points) == len(mults) == 1
    return f"Newton steps {steps.pop()}, branch points {points.pop()}, multipliers"


def _lm_runs(pattern: str, commit: str, n: int) -> list[dict]:
    """The no-noise Levenberg-Marquardt rows of an alternating A/B's ``benchmarks/bench_fit.py`` files (`_runs_of`)."""
    return [next(r for r in d["rows"] if r["noise"] == 0.0) for d in _runs_of(pattern, commit, n)]


def _median_range(values) -> str:
    """Seconds as the A/B tables write them: median (min–max)."""
    v = list(values)
    return f"{statistics.median(v):.2f} s ({min(v):.2f}–{max(v):.2f} s)"


def _fit_table_rows(before: list[dict], after: list[dict]) -> list[str]:
    """The A/B table of a cold LM fit: whole fit, compilation, iterations (rows of `_lm_runs`)."""
    rows = []
    for label, key in (("whole fit", "fit_total_s"), ("of which compilation", "compile_s"), ("iterations", "run_s")):
        rows.append(f"| {label} | {_median_range(r[key] for r in before)} | {_median_range(r[key] for r in after)} |")
    return rows


def _fit_same(rows: list[dict]) -> str:
    """That every LM run (rows of `_lm_runs`) converged in the same number of iterations to the same error."""
    assert all(r["converged"] for r in rows)
    iters = {r["n_iter"] for r in rows}
    err = {f"{r['max_rel_err_vs_true']:.1e}" for r in rows}
    assert len(iters) == len(err) == 1
    return f"every run took {iters.pop()} iterations to the same values ({err.pop()} off the truth)"


def _sp(n) -> str:
    """An integer as the documents write it: thousands apart by spaces (1 234 567)."""
    return f"{round(n):,}".replace(",", " ")


def _bench():
    return _json("docs/bifurcation/bench_sweep_400x300.json")


def _vector_width():
    return _json("docs/bifurcation/vector_width.json")["summary"]


def _processes():
    return _json("docs/bifurcation/processes.json")


def _runs(key: str) -> str:
    """A pool timing as the benchmark table gives it: median (each run; + compile)."""
    r = _bench()[key]
    each = ", ".join(f"{x:.1f}" for x in r["seconds_each_run"])
    return f"{r['seconds']:.1f} ({each}; + {r['compile_seconds']:.1f} compile)"


def _vs(ratio: float) -> str:
    """A wall-time ratio jaxcelt / other as the docs word it."""
    return f"{ratio:.2f}× slower" if ratio >= 1 else f"{1 / ratio:.2f}× faster"


def _first_branch() -> dict:
    return next(iter(_json("docs/orbits/branches.json")["branches"].values()))


def _bif(kind: str) -> dict:
    return next(b for b in _first_branch()["branch"]["bifurcations"] if b["kind"] == kind)


def _starts() -> set[str]:
    """Distinct initial conditions over the paper-reproduction study files (same start, one name)."""
    alias = {"rest psi0=0": "rest psi0=0deg", "rest psi0=pi/2": "rest psi0=90deg"}
    ics = set()
    for f in sorted((DOCS / "paper-reproduction").glob("study_*.json")):
        ics |= {alias.get(r["ic"], r["ic"]) for r in json.loads(f.read_text())["rows"]}
    return ics


def _lambda14() -> tuple[float, float]:
    lam = [
        r["lyapunov"]
        for f in (DOCS / "paper-reproduction").glob("study_*.json")
        for r in json.loads(f.read_text())["rows"]
        if r["omega_pi"] == 14.0 and r["lyapunov"] is not None
    ]
    return min(lam), max(lam)


def _long14() -> str:
    rows = {r["kind"]: r for r in _json("docs/orbits/census_long14/census.json")["results"]["14"]["attractors"]}
    c, i, q = rows["chaotic"], rows["invalid"], rows["quasi-periodic"]
    periodic = "none periodic" if "periodic" not in rows else "some periodic"
    return (
        f"chaotic {c['fraction']:.3f} (median λ₁ {c['lyapunov']:.3f} s⁻¹), invalid {i['fraction']:.3f}, "
        f"quasi-periodic {q['fraction']:.3f}, and {periodic}"
    )


def _per_step_512(mode: str) -> float:
    """512-bit over 256-bit vectors per step: the two programs' lanes may take different step counts."""
    r = _vector_width()[mode]
    return (r["256"]["run_s"] / r["256"]["steps"]) / (r["512"]["run_s"] / r["512"]["steps"])


def _machine(rel: str) -> str:
    """The machine a result file's provenance block records, as the docs name it: 'AMD EPYC, 2 cores'."""
    m = _json(rel)["provenance"]["machine"]
    return f"{m.get('accelerator') or m['cpu']}, {m['cpu_cores_usable']} cores"


def _main_job_time() -> str:
    """The README's main-job time, the machine it ran on and the whole command's time."""
    d = _json("docs/bifurcation/summary.json")
    return (
        f"{d['wall_seconds_including_compile']:.1f} s including compilation on {_machine('docs/bifurcation/summary.json')} "
        f"(the whole command {d['command_seconds']:.1f} s"
    )


# (document, quoted text computed from the result file)
