"""Quotes of "Measured side by side: the optimisers' programs and the unmonitored solve" in the fit engine's page,
computed from ``docs/fit/programs_ab/`` (``benchmarks/bench_fit.py --optimisers lm lbfgs``, three runs on each of
two commits, alternately; ``--optimisers lm``, five runs on each; ``benchmarks/fit_compile_parts.py``, three on each)."""

from __future__ import annotations

import statistics

from .files import _lm_runs, _median_range, _runs_of

FE = "docs/internals/fit-engine.md"
BEFORE, AFTER = "ea7532f", "6d479ed"


def _ab(name: str, commit: str, n: int) -> list[dict]:
    """The ``n`` result files ``docs/fit/programs_ab/{name}_{commit}_{i}.json`` of a clean checkout of ``commit``."""
    return _runs_of(f"docs/fit/programs_ab/{name}_{{commit}}_{{i}}.json", commit, n)


def _runs(commit: str) -> list[dict]:
    return [{(r["optimiser"], r["noise"]): r for r in d["rows"]} for d in _ab("bench_fit", commit, 3)]


def _med(commit: str, opt: str, noise: float) -> float:
    return statistics.median(r[(opt, noise)]["fit_total_s"] for r in _runs(commit))


def _span(commit: str) -> str:
    v = [r[("lm", 0.0)]["fit_total_s"] for r in _runs(commit)]
    return f"{min(v):.2f}–{max(v):.2f} s"


def _same() -> str:
    rs = _runs(BEFORE) + _runs(AFTER)
    assert all(r[k]["converged"] for r in rs for k in r)
    lm = {r[("lm", 0.0)]["n_iter"] for r in rs}
    lb = {r[("lbfgs", 0.0)]["n_iter"] for r in rs}
    err = {f"{r[k]['max_rel_err_vs_true']:.1e}" for r in rs for k in (("lm", 0.0), ("lbfgs", 0.0))}
    assert len(lm) == len(lb) == len(err) == 1
    return f"(LM and L-BFGS in {lm.pop()} and {lb.pop()} iterations, {err.pop()} off the truth without noise)"


def _row(label: str, opt: str, noise: float) -> str:
    return f"| {label} | {_med(BEFORE, opt, noise):.2f} s | {_med(AFTER, opt, noise):.2f} s |"


def _ratio() -> str:
    r = [_med(c, "lbfgs", 0.0) / _med(c, "lm", 0.0) for c in (BEFORE, AFTER)]
    return f"| L-BFGS cold / LM cold | {r[0]:.2f}× | {r[1]:.2f}× |"


LM_NEW = "2f69375"


def _lm(commit: str) -> list[dict]:
    return _lm_runs("docs/fit/programs_ab/bench_fit_lm_{commit}_{i}.json", commit, 5)


def _lm_rows() -> tuple[str, str]:
    cells = [_median_range(r["fit_total_s"] for r in _lm(c)) for c in (BEFORE, LM_NEW)]
    comp = [f"{statistics.median(r['compile_s'] for r in _lm(c)):.2f} s" for c in (BEFORE, LM_NEW)]
    return f"| whole fit, median (range) | {cells[0]} | {cells[1]} |", f"| of which compilation, median | {comp[0]} | {comp[1]} |"


def _parts(commit: str, key: str) -> float:
    return statistics.median(d["modes"]["nan-options"]["first_process"][key] for d in _ab("compile_parts", commit, 3))


def _parts_text() -> str:
    t = [_parts(c, "trace_lower_s") for c in (LM_NEW, BEFORE)]
    k = [_parts(c, "compile_s") for c in (LM_NEW, BEFORE)]
    return (
        f"traces and lowers in {t[0]:.2f} s against {t[1]:.2f} s and compiles in {k[0]:.2f} s against "
        f"{k[1]:.2f} s (medians)"
    )


QUOTES = [
    (FE, _same),
    (FE, lambda: _row("LM, no noise, cold", "lm", 0.0)),
    (FE, lambda: _row("L-BFGS, no noise, cold", "lbfgs", 0.0)),
    (FE, lambda: _row("L-BFGS, 1 % noise, second in the process", "lbfgs", 0.01)),
    (FE, _ratio),
    (FE, lambda: f"(LM cold {_span(BEFORE)} on ea7532f, {_span(AFTER)} on 6d479ed)"),
    (FE, lambda: _lm_rows()[0]),
    (FE, lambda: _lm_rows()[1]),
    (FE, lambda: " ".join(_parts_text().split())),
]

SETTINGS = [
    (FE, "run three times alternately on commit ea7532f"),
    (FE, "2 cores, on a slower day"),
    (FE, "the 1 %-noise fit, which runs second"),
    (FE, "L-BFGS is now within 1.5× of LM"),
    (FE, "Five more alternating pairs"),
    (FE, "the second commit 2f69375 has the fit\ncode of 6d479ed"),
    (FE, "| LM, no noise, cold (5 runs each) | ea7532f | 2f69375 |"),
    (FE, "three alternating pairs in the same\nhour"),
]
