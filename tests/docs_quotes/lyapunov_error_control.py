"""Quoted texts of the paragraph "The tangent's steps set by the state" of the sweep engine's internals page:
benchmarks/lyapunov_stage.py with ``--error-control all`` and ``state`` at one commit, alternating, three fresh
processes each, and benchmarks/main_job_compile.py at the commits before and after, alternating, four each
(docs/performance/lyapunov_error_control/), each computed from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

import statistics

import numpy as np

from .files import _exponent_gap, _runs_of, _same_regimes, _stage_rows, _sweep_each, _sweep_median, _warm_each

PAGE = "docs/internals/sweep-engine.md"
STAGE = "docs/performance/lyapunov_error_control/stage_{commit}_{i}.json"
STAGE_COMMIT = "c3c20f5"
MAIN = "docs/performance/lyapunov_error_control/main_job_compile_{commit}_{i}.json"
MAIN_COMMITS = ("1ada94a", "c3c20f5")  # before (error control on y and dy), after (on y alone)


def _stage(control: str) -> list[dict]:
    """The stage's rows of the three runs with ``--error-control control`` (each checked to have run so)."""
    return _stage_rows(STAGE.format(commit=control, i="{i}"), STAGE_COMMIT, {"lyapunov_error_control": control})


def stage_ab() -> str:
    """The stage's warm calls and compilation with each error control, in words."""
    a, b = _stage("all"), _stage("state")

    def mr(rows, key):
        v = [r[key] for r in rows]
        return f"{statistics.median(v):.2f} s ({min(v):.2f}–{max(v):.2f} s)"

    ratio = statistics.median(_warm_each(a)) / statistics.median(_warm_each(b))
    return (
        f"its warm calls took {', '.join(f'{x:.2f}' for x in _warm_each(b))} s against "
        f"{', '.join(f'{x:.2f}' for x in _warm_each(a))} s ({ratio:.2f}× by the medians); XLA compiled it in "
        f"{mr(b, 'xla_compile_s')} against {mr(a, 'xla_compile_s')}"
    )


def exponents() -> str:
    """How far the exponents of the two settings are apart (the first run of each), in words."""
    d, z = _exponent_gap(_stage("all")[0], _stage("state")[0])
    return (
        f"over its {d.size} lanes the exponents differ by at most {d.max():.3f} 1/s, {z.max():.2f} of the "
        f"lane's standard error (median {np.median(z):.1e})"
    )


def main_job_ab() -> str:
    """The main job's whole command at the two commits (four fresh processes each, alternating), in words."""
    before, after = (_runs_of(MAIN, c, 4) for c in MAIN_COMMITS)
    _same_regimes(before + after)
    return (
        f"the sweep's warm run took {_sweep_each(after, 1)} s against {_sweep_each(before, 1)} s "
        f"({_sweep_median(before, 1) / _sweep_median(after, 1):.2f}× by the medians), its first (compiling) run "
        f"{_sweep_each(after, 0)} s against {_sweep_each(before, 0)} s; every run gave the same regimes"
    )


QUOTES = [(PAGE, stage_ab), (PAGE, exponents), (PAGE, main_job_ab)]

SETTINGS = [
    (PAGE, "within 2 % of the known answers"),  # tests/test_lyapunov.py's tolerance
]
