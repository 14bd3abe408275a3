"""Quoted texts of the paragraph "The tangent's derivative by a difference" of the sweep engine's internals page:
benchmarks/lyapunov_stage.py with ``--tangent jvp`` and ``difference`` at one commit, alternating, three fresh processes
each, and benchmarks/main_job_compile.py at the commits before and after, alternating, four each
(docs/performance/lyapunov_tangent/), each computed from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

import statistics

import numpy as np

from .files import _exponent_gap, _runs_of, _same_regimes, _stage_rows, _sweep_each, _sweep_median, _warm_each

PAGE = "docs/internals/sweep-engine.md"
STAGE = "docs/performance/lyapunov_tangent/stage_{tangent}_{i}.json"
STAGE_COMMIT = "ff16c88"
MAIN = "docs/performance/lyapunov_tangent/main_job_compile_{commit}_{i}.json"
MAIN_COMMITS = ("06005b9", "ff16c88")  # before (forward-mode tangent), after (a forward difference)


def _stage(tangent: str) -> list[dict]:
    """The stage's rows of the three runs with ``--tangent tangent`` (each checked to have run so)."""
    config = {"lyapunov_tangent": tangent, "lyapunov_error_control": "state"}
    return _stage_rows(STAGE.format(tangent=tangent, i="{i}"), STAGE_COMMIT, config)


def _mr(rows, key) -> str:
    v = [r[key] for r in rows]
    return f"{statistics.median(v):.2f} s ({min(v):.2f}–{max(v):.2f} s)"


def stage_ab() -> str:
    """The stage's warm calls, compilation and first calls with each tangent, in words."""
    a, b = _stage("jvp"), _stage("difference")
    ratio = statistics.median(_warm_each(a)) / statistics.median(_warm_each(b))
    return (
        f"its warm calls took {', '.join(f'{x:.2f}' for x in _warm_each(b))} s against "
        f"{', '.join(f'{x:.2f}' for x in _warm_each(a))} s ({ratio:.2f}× by the medians); XLA compiled it in "
        f"{_mr(b, 'xla_compile_s')} against {_mr(a, 'xla_compile_s')}, and its first call, compilation included, took "
        f"{_mr(b, 'first_call_s')} against {_mr(a, 'first_call_s')}"
    )


def exponents() -> str:
    """How far the exponents of the two tangents are apart (the first run of each), in words."""
    d, z = _exponent_gap(_stage("jvp")[0], _stage("difference")[0])
    return (
        f"Over its {d.size} lanes the exponents differ by at most {d.max():.1e} 1/s, {z.max():.1e} of the "
        f"lane's standard error (median {np.median(d):.1e} 1/s)"
    )


def main_job_ab() -> str:
    """The main job's whole command at the two commits (four fresh processes each, alternating), in words."""
    before, after = (_runs_of(MAIN, c, 4) for c in MAIN_COMMITS)

    def over(runs):
        return ", ".join(f"{d['sweep_compile_overhead_s']:.1f}" for d in runs)

    _same_regimes(before + after)
    return (
        f"the sweep's warm run took {_sweep_each(after, 1)} s against {_sweep_each(before, 1)} s "
        f"({_sweep_median(before, 1) / _sweep_median(after, 1):.2f}× by the medians), its first (compiling) run "
        f"{_sweep_each(after, 0)} s against {_sweep_each(before, 0)} s; what compilation adds to the sweep, the "
        f"difference of the two, {over(after)} s against {over(before)} s; every run gave the same regimes"
    )


QUOTES = [(PAGE, stage_ab), (PAGE, exponents), (PAGE, main_job_ab)]

SETTINGS = [
    (PAGE, "over 20 periods within 1e-5 1/s"),  # tests/test_lyapunov.py's tolerance
    (PAGE, "sqrt(ε) ≈ 1.5e-8"),  # float64's machine epsilon 2.2e-16, square root
]


ATLAS = "docs/performance/lyapunov_tangent/atlas_compile_{commit}_{i}.json"


def atlas_ab() -> str:
    """The atlas's continuation and whole command at the two commits (two fresh processes each, alternating), in words."""
    before, after = (_runs_of(ATLAS, c, 2) for c in MAIN_COMMITS)
    assert all(d["same_atlas"] for d in before + after)

    def each(runs, k, part):
        return ", ".join(f"{d['runs'][k]['seconds'][part]:.1f}" for d in runs)

    return (
        f"its continuation took {each(after, 0, 'continuation')} s against {each(before, 0, 'continuation')} s in the "
        f"first (compiling) run and {each(after, 1, 'continuation')} s against {each(before, 1, 'continuation')} s in "
        f"the second; the whole command {each(after, 0, 'command')} s against {each(before, 0, 'command')} s, and "
        f"{each(after, 1, 'command')} s against {each(before, 1, 'command')} s"
    )


QUOTES.append((PAGE, atlas_ab))
