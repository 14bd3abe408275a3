"""Quoted texts of the section "The first call: small programs, and which program is traced first" of the compilation
page: benchmarks/numba_table.py (stop at invalid states, jaxcelt only) and benchmarks/main_job_compile.py at the commits
before and after, alternating, three fresh processes each (docs/performance/first_call_ab/), each computed from those
files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

import statistics

from .files import _runs_of

PAGE = "docs/internals/compilation.md"
STOP = "docs/performance/first_call_ab/numba_table_stop_{commit}_{i}.json"
STOP_COMMITS = ("8100b62", "4e4d9f4")  # before, after (the drain's decision on the host)
MAIN = "docs/performance/first_call_ab/main_job_compile_{commit}_{i}.json"
MAIN_COMMITS = ("4e4d9f4", "06005b9")  # before, after (the Lyapunov stage traced first)


def _stop(commit: str) -> list[dict]:
    return [d["modes"]["stop"]["jaxcelt"] for d in _runs_of(STOP, commit, 3)]


def _small(r: dict) -> list[float]:
    """The first call's XLA compilations (of at least 0.05 s, as logged) other than the pool's three programs and the
    start's projection onto the manifold."""
    return [
        s for k, s in r["first_call_compile_log"]
        if k.startswith("XLA compilation") and not any(x in k for x in ("pool_", "_state_on_manifold"))
    ]  # fmt: skip


def stop_ab() -> str:
    """The 400 x 300 stop-at-invalid sweep's first calls, warm calls and small programs before and after, in words."""
    before, after = _stop(STOP_COMMITS[0]), _stop(STOP_COMMITS[1])
    assert all(r["lane_steps"] == before[0]["lane_steps"] and r["status_counts"] == before[0]["status_counts"]
               for r in before + after)  # fmt: skip

    def each(rs, f):
        return ", ".join(f"{f(r):.2f}" for r in rs)

    n_b = {len(_small(r)) for r in before}
    assert len(n_b) == 1
    sums = [sum(_small(r)) for r in before]
    return (
        f"the first call took {each(after, lambda r: r['first_call_s'])} s against "
        f"{each(before, lambda r: r['first_call_s'])} s, {each(after, lambda r: r['first_call_s'] - r['warm_s'])} s "
        f"against {each(before, lambda r: r['first_call_s'] - r['warm_s'])} s more than the warm call (the median of "
        f"three). Before, the first call compiled {n_b.pop()} such programs of at least 0.05 s (the log's threshold), "
        f"{min(sums):.2f}–{max(sums):.2f} s in all; after, at most {max(len(_small(r)) for r in after)}, "
        f"{max(sum(_small(r)) for r in after):.2f} s"
    )


def main_job_ab() -> str:
    """The main job's first sweep, its compile overhead and the Lyapunov stage's tracing and XLA times, in words."""
    before, after = (_runs_of(MAIN, c, 3) for c in MAIN_COMMITS)

    def each(runs, f):
        return ", ".join(f"{f(d):.1f}" for d in runs)

    def logged(d, key):
        return next(s for k, s in d["runs"][0]["logged_over_0_2_s"] if k == key)

    def med(runs, key):
        return statistics.median(logged(d, key) for d in runs)

    assert all(d["same_regimes"] for d in before + after)
    return (
        f"the sweep's first (compiling) run took {each(after, lambda d: d['runs'][0]['sweep_s'])} s against "
        f"{each(before, lambda d: d['runs'][0]['sweep_s'])} s, what compilation adds to it "
        f"{each(after, lambda d: d['sweep_compile_overhead_s'])} s against "
        f"{each(before, lambda d: d['sweep_compile_overhead_s'])} s; the stage's program was traced in "
        f"{med(after, 'tracing _lyap_chunk_impl for jit'):.1f} s against {med(before, 'tracing _lyap_chunk_impl for jit'):.1f} s "
        f"and compiled by XLA in {med(after, 'XLA compilation of jit(_lyap_chunk_impl)'):.1f} s against "
        f"{med(before, 'XLA compilation of jit(_lyap_chunk_impl)'):.1f} s (medians)"
    )


QUOTES = [(PAGE, stop_ab), (PAGE, main_job_ab)]
