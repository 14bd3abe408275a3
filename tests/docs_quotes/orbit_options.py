"""Quotes of the compilation page (``docs/internals/compilation.md``), section "Orbit and spectrum programs": the loop
emitters for the programs of periodic orbits, their continuation and the Lyapunov spectrum (`jit_anywhere`), measured
side by side on two commits, alternately: ``benchmarks/orbit_compile.py`` and ``benchmarks/atlas_compile.py --reps 1``
(two and four runs on each, ``docs/performance/orbit_options_ab/``)."""

from __future__ import annotations

import statistics

from .files import _runs_of, _same_orbit

PAGE = "docs/internals/compilation.md"
BEFORE, AFTER = "ac452e8", "3a21ef2"
ORBIT_RUNS, ATLAS_RUNS = 2, 4
DIR = "docs/performance/orbit_options_ab"


def _orbit(commit: str) -> list[dict]:
    return _runs_of(DIR + "/orbit_compile_{commit}_{i}.json", commit, ORBIT_RUNS)


def _atlas(commit: str) -> list[dict]:
    return _runs_of(DIR + "/atlas_compile_{commit}_{i}.json", commit, ATLAS_RUNS)


def _program(d: dict, name: str) -> float:
    return sum(s for n, s in d["xla_over_0_2_s"] if n == f"jit({name})")


def _row(label: str, runs_of, f) -> str:
    """A table row: the label, then 'median (lo–hi)' of each commit's runs of ``f``."""
    cells = []
    for c in (BEFORE, AFTER):
        v = [f(d) for d in runs_of(c)]
        cells.append(f"{statistics.median(v):.1f} s ({min(v):.1f}–{max(v):.1f})")
    return f"| {label} | {cells[0]} | {cells[1]} |"


ORBIT_ROWS = (
    ("`periodic_orbit` + `continue_orbit`, wall", lambda d: d["periodic_orbit_s"] + d["continue_orbit_s"]),
    ("XLA compilation, all programs", lambda d: d["xla_total_s"]),
    ("of which `jit(_orbit)`", lambda d: _program(d, "_orbit")),
    ("`jit(corrector)`", lambda d: _program(d, "corrector")),
    ("`jit(multipliers)`", lambda d: _program(d, "multipliers")),
    ("`jit(tangent)`", lambda d: _program(d, "tangent")),
)

ATLAS_ROWS = (
    ("whole command, first run", lambda d: d["parts"]["command"]["first_s"]),
    ("whole command, second run", lambda d: d["parts"]["command"]["second_s"]),
    ("continuation, first run", lambda d: d["parts"]["continuation"]["first_s"]),
    ("continuation, second run", lambda d: d["parts"]["continuation"]["second_s"]),
    ("branches, first run", lambda d: d["parts"]["branches"]["first_s"]),
    ("branches, second run", lambda d: d["parts"]["branches"]["second_s"]),
    ("spectrum, first run", lambda d: d["parts"]["spectrum"]["first_s"]),
    ("spectrum, second run", lambda d: d["parts"]["spectrum"]["second_s"]),
    ("XLA compilation, first run", lambda d: d["runs"][0]["logged"]["xla_s_all"]),
)


def orbit_same() -> str:
    return f"{_same_orbit(_orbit(BEFORE) + _orbit(AFTER))} equal to six decimals"


def atlas_same() -> str:
    ds = _atlas(BEFORE) + _atlas(AFTER)
    assert all(d["same_atlas"] for d in ds)
    return f"in each of the {len(ds)} processes"


QUOTES = [
    *[(PAGE, lambda r=r: _row(r[0], _orbit, r[1])) for r in ORBIT_ROWS],
    *[(PAGE, lambda r=r: _row(r[0], _atlas, r[1])) for r in ATLAS_ROWS],
    (PAGE, orbit_same),
    (PAGE, atlas_same),
]

SETTINGS = [
    (PAGE, "two runs on each commit"),
    (PAGE, "four runs on each commit"),
]
