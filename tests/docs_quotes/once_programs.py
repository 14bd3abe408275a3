"""Quotes of the compilation page's second section (``docs/internals/compilation.md``): programs that run once
compiled with the loop emitters, and a fit that ends on its optimiser's own evaluation, measured side by side on two
commits, alternately: ``benchmarks/bench_fit.py --optimisers lm`` (five runs on each, ``docs/fit/end_ab/``) and
``benchmarks/main_job_compile.py --reps 1`` (four on each, ``docs/bifurcation/compile_ab/``)."""

from __future__ import annotations

import statistics

from .files import _fit_same, _fit_table_rows, _lm_runs, _median_range, _runs_of

PAGE = "docs/internals/compilation.md"
BEFORE, AFTER = "2d6ecba", "376c411"


def _lm(commit: str) -> list[dict]:
    return _lm_runs("docs/fit/end_ab/bench_fit_lm_{commit}_{i}.json", commit, 5)


def _main(commit: str) -> list[dict]:
    return _runs_of("docs/bifurcation/compile_ab/main_job_compile_{commit}_{i}.json", commit, 4)


def _xla(d: dict, name: str) -> float | None:
    """XLA's compilation time of ``jit(name)`` in the first (compiling) run; None where under the log's 0.2 s."""
    got = [s for n, s in d["runs"][0]["logged_over_0_2_s"] if n == f"XLA compilation of jit({name})"]
    return sum(got) if got else None


def _fit_same_values() -> str:
    rs = _lm(BEFORE) + _lm(AFTER)
    assert len({tuple(sorted(r["values"].items())) for r in rs}) == 1  # and the very same values
    return _fit_same(rs)


def _earlier_fit() -> str:
    v = [r["fit_total_s"] for r in _lm_runs("docs/fit/programs_ab/bench_fit_lm_{commit}_{i}.json", "8ea00d0", 5)]
    return f"the same fit took {statistics.median(v):.2f} s on 8ea00d0"


def _main_rows() -> list[str]:
    overhead = [_median_range(d["command_compile_overhead_s"] for d in _main(c)) for c in (BEFORE, AFTER)]
    first = [f"{statistics.median(d['runs'][0]['command_s'] for d in _main(c)):.2f} s" for c in (BEFORE, AFTER)]
    start = [f"{statistics.median(_xla(d, 'pool_start') for d in _main(c)):.2f} s" for c in (BEFORE, AFTER)]
    return [
        f"| what compilation adds to the command | {overhead[0]} | {overhead[1]} |",
        f"| the first (compiling) run | {first[0]} | {first[1]} |",
        f"| XLA compilation of `pool_start` | {start[0]} | {start[1]} |",
    ]


def _outputs() -> str:
    before = [_xla(d, "pool_outputs") for d in _main(BEFORE)]
    after = [_xla(d, "pool_outputs") for d in _main(AFTER)]
    assert None not in before
    return f"`pool_outputs` compiled in {min(before):.2f}–{max(before):.2f} s before and in at most {max(a for a in after if a is not None):.2f} s after"


def _same_regimes() -> str:
    ds = _main(BEFORE) + _main(AFTER)
    assert all(d["same_regimes"] for d in ds)
    assert len({repr(d["runs"][0]["regimes"]) for d in ds}) == 1
    return "Both commits gave the same regimes."


def _warm() -> str:
    warm = [d["runs"][1]["command_s"] for c in (BEFORE, AFTER) for d in _main(c)]
    return f"varied between about {min(warm):.1f} and {max(warm):.1f} s in these"


QUOTES = [
    *[(PAGE, lambda i=i: _fit_table_rows(_lm(BEFORE), _lm(AFTER))[i]) for i in range(3)],
    (PAGE, _fit_same_values),
    (PAGE, _earlier_fit),
    *[(PAGE, lambda i=i: _main_rows()[i]) for i in range(3)],
    (PAGE, _outputs),
    (PAGE, _same_regimes),
    (PAGE, _warm),
]

SETTINGS = [
    (PAGE, "five runs each"),
    (PAGE, "four runs each"),
    (PAGE, "5 runs each"),
    (PAGE, "4 runs each"),
    (PAGE, "2-core AMD EPYC"),
    (PAGE, "the 5 s it is meant to take"),
]
