"""Quotes of the compilation page (``docs/internals/compilation.md``): diffeqsolve's end-of-interval threshold by a
loop, measured side by side on two commits, alternately: ``benchmarks/bench_fit.py --optimisers lm`` (five runs on
each, ``docs/fit/programs_ab/bench_fit_lm_*``) and ``benchmarks/orbit_compile.py`` (three on each,
``docs/orbits/compile_ab/``)."""

from __future__ import annotations

import statistics

from .files import _fit_same, _fit_table_rows, _lm_runs, _runs_of, _same_orbit

PAGE = "docs/internals/compilation.md"
BEFORE, AFTER = "c2eb159", "8ea00d0"


def _lm(commit: str) -> list[dict]:
    return _lm_runs("docs/fit/programs_ab/bench_fit_lm_{commit}_{i}.json", commit, 5)


def _orbit(commit: str) -> list[dict]:
    return _runs_of("docs/orbits/compile_ab/orbit_compile_{commit}_{i}.json", commit, 3)


def _med(values) -> float:
    return statistics.median(values)


def _fit_rows() -> list[str]:
    return _fit_table_rows(_lm(BEFORE), _lm(AFTER))


def _program(d: dict, name: str) -> float:
    return sum(s for n, s in d["xla_over_0_2_s"] if n == f"jit({name})")


def _orbit_rows() -> list[str]:
    rows = []
    for label, f in (
        ("`periodic_orbit` + `continue_orbit`, wall", lambda d: d["periodic_orbit_s"] + d["continue_orbit_s"]),
        ("XLA compilation, all programs", lambda d: d["xla_total_s"]),
        ("of which `jit(_orbit)`", lambda d: _program(d, "_orbit")),
        ("`jit(corrector)`", lambda d: _program(d, "corrector")),
        ("`jit(multipliers)`", lambda d: _program(d, "multipliers")),
        ("`jit(tangent)`", lambda d: _program(d, "tangent")),
    ):
        cells = [f"{_med(f(d) for d in _orbit(c)):.1f} s" for c in (BEFORE, AFTER)]
        rows.append(f"| {label} | {cells[0]} | {cells[1]} |")
    return rows


def _orbit_same() -> str:
    return f"the same orbit on both commits ({_same_orbit(_orbit(BEFORE) + _orbit(AFTER))}"


QUOTES = [
    *[(PAGE, lambda i=i: _fit_rows()[i]) for i in range(3)],
    (PAGE, lambda: _fit_same(_lm(BEFORE) + _lm(AFTER))),
    *[(PAGE, lambda i=i: _orbit_rows()[i]) for i in range(6)],
    (PAGE, _orbit_same),
]

SETTINGS = [
    (PAGE, "five times alternately"),
    (PAGE, "three times alternately"),
    (PAGE, "omega_pi = 15.6 rad/s"),
    (PAGE, "to 15.7 rad/s"),
    (PAGE, "exactly as 0.7 does"),
]
