"""Quoted texts of the section "The Lyapunov stage's groups" of the sweep engine's internals page
(benchmarks/lyapunov_stage.py -> docs/bifurcation/lyapunov_stage.json; benchmarks/main_job_compile.py at the commits
before and after, alternating -> docs/performance/lyapunov_ab/), each computed from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

import statistics

from .files import _json, _runs_of

PAGE = "docs/internals/sweep-engine.md"
STAGE = "docs/bifurcation/lyapunov_stage.json"
AB = "docs/performance/lyapunov_ab/main_job_compile_{commit}_{i}.json"
AB_COMMITS = ("1f5895d", "0a4eddc")  # before; the groups dealt round-robin, 16 lanes per device


def stage_rows() -> str:
    """The layouts' table, one row per layout."""
    d = _json(STAGE)
    rows = []
    for name, r in d["layouts"].items():
        rows.append(
            f"| {name} | {r['groups']} | {r['padding_positions']} | {r['first_call_s']:.1f} | {r['warm_s']:.1f} | "
            f"{r['speedup_vs_contiguous']:.2f}× | {r['max_abs_lyapunov_difference_vs_contiguous']:.1e} |"
        )
    return " ".join(rows)  # a table's rows, its line breaks read as spaces (`_prose`)


def stage_setting() -> str:
    """What the stage ran on."""
    d = _json(STAGE)
    return (
        f"{d['successful_lanes']} of the {d['config']['n_freq']} lanes succeed, on {d['devices']} devices with the "
        f"pool's width of {d['pool_lanes_per_device']} lanes per device"
    )


def _mj(commit: str) -> list[dict]:
    return _runs_of(AB, commit, 2)


def main_job_ab(commits: tuple[str, str] = AB_COMMITS) -> str:
    """The main job, whole command, at the two commits (two fresh processes each, alternating), in words."""
    a, b = (_mj(c) for c in commits)

    def both(runs, f):
        return " and ".join(f"{f(d):.1f} s" for d in runs)

    first = lambda d: d["runs"][0]["command_s"]  # noqa: E731
    warm = lambda d: d["runs"][1]["command_s"]  # noqa: E731
    comp = lambda d: d["command_compile_overhead_s"]  # noqa: E731
    assert all(d["same_regimes"] for d in a + b)
    ratio = statistics.median(map(warm, a)) / statistics.median(map(warm, b))
    return (
        f"the first (compiling) run {both(b, first)} against {both(a, first)}, the second run {both(b, warm)} against "
        f"{both(a, warm)} ({ratio:.2f}× by the medians); what compilation adds, the difference of the two, "
        f"{both(b, comp)} against {both(a, comp)}"
    )


QUOTES = [(PAGE, stage_rows), (PAGE, stage_setting), (PAGE, main_job_ab)]


STAGE_AB = "docs/performance/lyapunov_ab/stage_{commit}_{i}.json"
STAGE_AB_COMMITS = ("008e79c", "c238b14")  # before; solve_to's Runge-Kutta stages in a plain loop (forward_only)


def _stage_rows(commit: str) -> list[dict]:
    return [d["layouts"]["round-robin 16"] for d in _runs_of(STAGE_AB, commit, 3)]


def stage_loop_ab() -> str:
    """The Lyapunov stage's program at the two commits (three fresh processes each, alternating), in words."""
    a, b = (_stage_rows(c) for c in STAGE_AB_COMMITS)

    def mr(rows, key):
        v = [r[key] for r in rows]
        return f"{statistics.median(v):.2f} s ({min(v):.2f}–{max(v):.2f} s)"

    warm = lambda rows: ", ".join(f"{x:.2f}" for r in rows for x in r["warm_each_s"])  # noqa: E731
    return (
        f"XLA compiled it in {mr(b, 'xla_compile_s')} against {mr(a, 'xla_compile_s')}; tracing and lowering took "
        f"{mr(b, 'trace_and_lower_s')} against {mr(a, 'trace_and_lower_s')}. Its warm calls took {warm(b)} s against "
        f"{warm(a)} s"
    )


QUOTES += [(PAGE, stage_loop_ab), (PAGE, lambda: main_job_ab(STAGE_AB_COMMITS))]
