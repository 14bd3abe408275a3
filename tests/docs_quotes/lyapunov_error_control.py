"""Quoted texts of the paragraph "The tangent's steps set by the state" of the sweep engine's internals page:
benchmarks/lyapunov_stage.py with ``--error-control all`` and ``state`` at one commit, alternating, three fresh
processes each, and benchmarks/main_job_compile.py at the commits before and after, alternating, four each
(docs/performance/lyapunov_error_control/), each computed from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

import statistics

import numpy as np

from .files import _json, _runs_of

PAGE = "docs/internals/sweep-engine.md"
STAGE = "docs/performance/lyapunov_error_control/stage_{commit}_{i}.json"
STAGE_COMMIT = "c3c20f5"
MAIN = "docs/performance/lyapunov_error_control/main_job_compile_{commit}_{i}.json"
MAIN_COMMITS = ("1ada94a", "c3c20f5")  # before (error control on y and dy), after (on y alone)


def _stage(control: str) -> list[dict]:
    """The stage's rows of the three runs with ``--error-control control`` (each checked to have run so)."""
    rows = []
    for i in range(1, 4):
        d = _json(STAGE.format(commit=control, i=i))
        assert d["provenance"]["commit"].startswith(STAGE_COMMIT) and not d["provenance"]["dirty"]
        assert d["config"]["lyapunov_error_control"] == control
        rows.append(d["layouts"]["round-robin 16"])
    return rows


def stage_ab() -> str:
    """The stage's warm calls and compilation with each error control, in words."""
    a, b = _stage("all"), _stage("state")

    def warm(rows):
        return [x for r in rows for x in r["warm_each_s"]]

    def mr(rows, key):
        v = [r[key] for r in rows]
        return f"{statistics.median(v):.2f} s ({min(v):.2f}–{max(v):.2f} s)"

    ratio = statistics.median(warm(a)) / statistics.median(warm(b))
    return (
        f"its warm calls took {', '.join(f'{x:.2f}' for x in warm(b))} s against "
        f"{', '.join(f'{x:.2f}' for x in warm(a))} s ({ratio:.2f}× by the medians); XLA compiled it in "
        f"{mr(b, 'xla_compile_s')} against {mr(a, 'xla_compile_s')}"
    )


def exponents() -> str:
    """How far the exponents of the two settings are apart (the first run of each), in words."""
    a, b = _stage("all")[0], _stage("state")[0]

    def arr(r, k):
        return np.array([np.nan if x is None else x for x in r[k]])

    la, lb, ea = arr(a, "lyapunov"), arr(b, "lyapunov"), arr(a, "lyapunov_stderr")
    ok = np.isfinite(la) & np.isfinite(lb)
    d = np.abs(la - lb)[ok]
    z = d / ea[ok]
    return (
        f"over its {int(ok.sum())} lanes the exponents differ by at most {d.max():.3f} 1/s, {z.max():.2f} of the "
        f"lane's standard error (median {np.median(z):.1e})"
    )


def main_job_ab() -> str:
    """The main job's whole command at the two commits (four fresh processes each, alternating), in words."""
    before, after = (_runs_of(MAIN, c, 4) for c in MAIN_COMMITS)

    def each(runs, k):
        return ", ".join(f"{d['runs'][k]['sweep_s']:.1f}" for d in runs)

    def med(runs, k):
        return statistics.median(d["runs"][k]["sweep_s"] for d in runs)

    labels = [[r for r in d["runs"][0]["regimes"] if "label" in r] for d in before + after]
    assert all(x == labels[0] for x in labels)  # the same regimes, lane for lane
    return (
        f"the sweep's warm run took {each(after, 1)} s against {each(before, 1)} s ({med(before, 1) / med(after, 1):.2f}× "
        f"by the medians), its first (compiling) run {each(after, 0)} s against {each(before, 0)} s; every run gave "
        f"the same regimes"
    )


QUOTES = [(PAGE, stage_ab), (PAGE, exponents), (PAGE, main_job_ab)]

SETTINGS = [
    (PAGE, "within 2 % of the known answers"),  # tests/test_lyapunov.py's tolerance
]
