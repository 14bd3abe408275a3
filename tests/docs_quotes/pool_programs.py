"""Quoted texts of the section "The main job at scale against numba, compilation included" of the sweep engine's
internals page (benchmarks/numba_table.py -> docs/performance/numba_table_400x300.json, the engine as it is, and
docs/performance/numba_table_400x300_one_program.json, commit 8d5565a: the pool as one program), each computed
from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

import statistics

from .files import _json, _median_range, _runs_of, _sp

PAGE = "docs/internals/sweep-engine.md"
AFTER = "docs/performance/numba_table_400x300.json"
BEFORE = "docs/performance/numba_table_400x300_one_program.json"
MODES = (("stop", "stop at invalid"), ("on", "integrate on"))


def _statuses(c: dict) -> str:
    return ", ".join(f"{v} × {k}" for k, v in sorted(c.items()))


def row(path: str, label: str, mode: str, name: str) -> str:
    m = _json(path)["modes"][mode]
    j, n = m["jaxcelt"], m["numba"]
    return (
        f"| {label} | {name} | {j['warm_s']:.1f} | {n['warm_s']:.1f} | {m['warm_speedup_vs_numba']:.2f}× | "
        f"{j['first_call_s']:.1f} | {n['first_call_s']:.1f} | {m['first_call_speedup_vs_numba']:.2f}× | "
        f"{m['first_call_minus_warm_jaxcelt_s']:.1f} | {j['lane_steps'] / 1e6:.1f} M / {n['lane_steps'] / 1e6:.1f} M |"
    )


def xla(path: str, mode: str) -> str:
    """The first call's XLA compilation per pool program, in the order JAX logged them."""
    log = _json(path)["modes"][mode]["jaxcelt"]["first_call_compile_log"]
    parts = [(n.split("jit(")[1].rstrip(")"), t) for n, t in log if n.startswith("XLA compilation") and "_pool" in n]
    return ", ".join(f"`{n}` {t:.1f} s" for n, t in parts)


def statuses(mode: str) -> str:
    m = _json(AFTER)["modes"][mode]
    return f"jaxcelt {_statuses(m['jaxcelt']['status_counts'])}; numba {_statuses(m['numba']['status_counts'])}"


def load() -> str:
    a, b = (_json(p)["provenance"]["load_average_at_start"][0] for p in (BEFORE, AFTER))
    return f"1-minute load average {a:.1f} and {b:.1f} at the starts"


def scipy() -> str:
    s = _json(AFTER)["scipy_stop"]
    return f"{s['one_core_s']:.0f} s on one core ({s['all_cores_s']:.0f} s spread over {s['cores']} cores"


def prose() -> list[str]:
    """The section's sentences that repeat the table's numbers."""
    b, a = (_json(p)["modes"] for p in (BEFORE, AFTER))
    return [
        f"a first call costs {a['stop']['first_call_minus_warm_jaxcelt_s']:.1f} s more than a warm one stopping at invalid "
        f"states ({b['stop']['first_call_minus_warm_jaxcelt_s']:.1f} s before)",
        f"({a['stop']['jaxcelt']['warm_s']:.1f} s against {b['stop']['jaxcelt']['warm_s']:.1f} s)",
        f"(numba's own first call: {b['stop']['numba']['first_call_s']:.1f} s and {a['stop']['numba']['first_call_s']:.1f} s",
    ]


def first_calls() -> str:
    m = _json(AFTER)["modes"]
    return (
        f"{m['stop']['jaxcelt']['first_call_s']:.1f} s against {m['stop']['numba']['first_call_s']:.1f} s stopping at "
        f"invalid states, {m['on']['jaxcelt']['first_call_s']:.1f} s against {m['on']['numba']['first_call_s']:.1f} s "
        f"integrating every lane on"
    )


QUOTES = [
    ("docs/performance.md", first_calls),
    *[(PAGE, (lambda i=i: prose()[i])) for i in range(3)],
    *[(PAGE, (lambda p=p, lab=lab, m=m, n=n: row(p, lab, m, n)))
      for p, lab in ((BEFORE, "one program (8d5565a)"), (AFTER, "separate programs"))
      for m, n in MODES],  # fmt: skip
    *[(PAGE, (lambda p=p, m=m: xla(p, m))) for p in (BEFORE, AFTER) for m in ("stop", "on")],
    *[(PAGE, (lambda m=m: statuses(m))) for m in ("stop", "on")],
    (PAGE, load),
    (PAGE, scipy),
]

RERUN = "docs/performance/numba_table_400x300_rerun.json"
LOOP = "docs/performance/numba_table_400x300_stage_loop.json"


def rerun(path: str = RERUN) -> str:
    """The final code's table again, in words."""
    m = _json(path)["modes"]
    s, o = m["stop"], m["on"]
    return (
        f"stopping, jaxcelt warm {s['jaxcelt']['warm_s']:.1f} s against numba {s['numba']['warm_s']:.1f} s "
        f"({s['warm_speedup_vs_numba']:.2f}×), first call {s['jaxcelt']['first_call_s']:.1f} s against "
        f"{s['numba']['first_call_s']:.1f} s ({s['first_call_speedup_vs_numba']:.2f}×), a first call "
        f"{s['first_call_minus_warm_jaxcelt_s']:.1f} s above a warm one; integrating on, warm {o['jaxcelt']['warm_s']:.1f} s "
        f"against {o['numba']['warm_s']:.1f} s ({o['warm_speedup_vs_numba']:.2f}×), first call "
        f"{o['jaxcelt']['first_call_s']:.1f} s against {o['numba']['first_call_s']:.1f} s "
        f"({o['first_call_speedup_vs_numba']:.2f}×), {o['first_call_minus_warm_jaxcelt_s']:.1f} s above warm."
    )


def _advance_compile(path: str, mode: str) -> float:
    log = _json(path)["modes"][mode]["jaxcelt"]["first_call_compile_log"]
    return next(t for n, t in log if n == "XLA compilation of jit(pool_advance)")


def stage_loop() -> str:
    """The stages-in-a-loop run against the rerun, in words."""
    a, b = _json(LOOP)["modes"], _json(RERUN)["modes"]
    j = lambda m, k: (a[m]["jaxcelt"][k], b[m]["jaxcelt"][k])  # noqa: E731
    return (
        f"Stopping, it compiled `pool_advance` in {_advance_compile(LOOP, 'stop'):.1f} s against "
        f"{_advance_compile(RERUN, 'stop'):.1f} s, but the first call was no faster ({j('stop', 'first_call_s')[0]:.1f} s "
        f"against {j('stop', 'first_call_s')[1]:.1f} s; integrating on {j('on', 'first_call_s')[0]:.1f} s against "
        f"{j('on', 'first_call_s')[1]:.1f} s) and the warm calls were slower ({j('stop', 'warm_s')[0]:.1f} s against "
        f"{j('stop', 'warm_s')[1]:.1f} s; {j('on', 'warm_s')[0]:.1f} s against {j('on', 'warm_s')[1]:.1f} s). Its lanes "
        f"agree to rounding (another program: {_sp(j('stop', 'lane_steps')[0])} against {_sp(j('stop', 'lane_steps')[1])} "
        f"lane-steps stopping)."
    )



RERUN2 = "docs/performance/numba_table_400x300_rerun2.json"


def rerun2_host() -> str:
    """How the host of the second rerun compares (numba's warm call) and what its pool_start compiled in."""
    a, b = _json(RERUN2)["modes"]["stop"], _json(RERUN)["modes"]["stop"]
    start = [next(t for n, t in f["jaxcelt"]["first_call_compile_log"] if n == "XLA compilation of jit(pool_start)") for f in (a, b)]
    return (
        f"numba's warm call {a['numba']['warm_s']:.1f} s against {b['numba']['warm_s']:.1f} s in the final-code table; the pool's first and "
        f"last programs now compiled with the loop emitters, `pool_start` {start[0]:.1f} s against {start[1]:.1f} s of XLA time"
    )


QUOTES += [(PAGE, rerun), (PAGE, stage_loop), (PAGE, lambda: rerun(RERUN2)), (PAGE, rerun2_host)]


RERUN3 = "docs/performance/numba_table_400x300_rerun3.json"
DRAIN_AB = "docs/performance/drain_ab/numba_on_{commit}_{i}.json"
DRAIN_COMMITS = ("c22b69e", "264599e", "b8f0b6b")  # before; drain compiled from the start; its width's law form


def _drain_rows(commit: str) -> list[dict]:
    return [d["modes"]["on"]["jaxcelt"] for d in _runs_of(DRAIN_AB, commit, 4)]


def _ab_per_commit(rows: list[list[dict]]) -> dict[str, list]:
    """An A/B's jaxcelt rows (one list per commit) summarised per commit: median (range) of the warm and first calls
    and of the first call above the warm one; the lane-steps and statuses, each checked to be one per commit (every
    process of a commit ran the same program on the same lanes)."""
    steps = [{r["lane_steps"] for r in rs} for rs in rows]
    status = [{tuple(sorted(r["status_counts"].items())) for r in rs} for rs in rows]
    assert all(len(x) == 1 for x in steps + status), (steps, status)
    return {
        "warm": [_median_range(r["warm_s"] for r in rs) for rs in rows],
        "first": [_median_range(r["first_call_s"] for r in rs) for rs in rows],
        "above": [_median_range(r["first_call_s"] - r["warm_s"] for r in rs) for rs in rows],
        "steps": [_sp(x.pop()) for x in steps],
        "status": [dict(x.pop()) for x in status],
    }


def drain_ab() -> str:
    """The drain A/B (integrating on, jaxcelt only, three commits in turn), in words."""
    ab = _ab_per_commit([_drain_rows(c) for c in DRAIN_COMMITS])
    above, first, warm, steps = ab["above"], ab["first"], ab["warm"], ab["steps"]
    assert all(st == ab["status"][0] for st in ab["status"])  # the same statuses at every commit
    return (
        f"A first call {above[0]} above a warm one before, {above[1]} with the drain compiled from the start, "
        f"{above[2]} with its width's form of the law; first calls {first[0]}, {first[1]} and {first[2]}; warm calls "
        f"{warm[0]}, {warm[1]} and {warm[2]}. The same statuses in every process; lane-steps {steps[0]}, "
        f"{steps[1]} and {steps[2]}"
    )


def rerun3_compile() -> str:
    """What the final table's first calls logged for the pool's stepping programs."""
    m = _json(RERUN3)["modes"]
    adv = {k: [round(t, 1) for n, t in m[k]["jaxcelt"]["first_call_compile_log"] if n == "XLA compilation of jit(pool_advance)"] for k in m}
    return (
        f"XLA compiled `pool_advance` in {adv['stop'][0]:.1f} s stopping; integrating on, the full-width program and the "
        f"drain at the same time, in {adv['on'][0]:.1f} s and {adv['on'][1]:.1f} s (in the order they finished)"
    )


QUOTES += [(PAGE, drain_ab), (PAGE, lambda: rerun(RERUN3)), (PAGE, rerun3_compile)]


def perf_latest(path: str | None = None, ratios: bool = False) -> str:
    """A table against numba on the performance page (default `RERUN5`), in words (``ratios``: with the warm ratios)."""
    m = _json(path or RERUN5)["modes"]
    s, o = m["stop"], m["on"]
    r = (lambda row: f" ({row['warm_speedup_vs_numba']:.2f}×)") if ratios else (lambda row: "")  # noqa: E731
    return (
        f"stopping, warm {s['jaxcelt']['warm_s']:.1f} s against numba's {s['numba']['warm_s']:.1f} s{r(s)}, a first call "
        f"{s['jaxcelt']['first_call_s']:.1f} s against {s['numba']['first_call_s']:.1f} s; integrating on, warm "
        f"{o['jaxcelt']['warm_s']:.1f} s against {o['numba']['warm_s']:.1f} s{r(o)}, a first call {o['jaxcelt']['first_call_s']:.1f} s "
        f"against {o['numba']['first_call_s']:.1f} s"
    )


QUOTES += [("docs/performance.md", perf_latest)]


def changelog_drain() -> str:
    """The drain A/B's medians as the changelog gives them."""
    med = [statistics.median(r["first_call_s"] - r["warm_s"] for r in _drain_rows(c)) for c in DRAIN_COMMITS]
    return f"{med[0]:.2f} s -> {med[2]:.2f} s above a warm one"


QUOTES += [("CHANGELOG.md", changelog_drain)]


FIELD_COMMITS = ("1adaa3d", "5c549db")  # before; the field with fewer divisions (4aa02e0, benchmark script 5c549db)
FIELD_AB = "docs/performance/field_ab/numba_stop_{commit}_{i}.json"
POOL_OPS = "docs/performance/field_ab/pool_ops_{commit}.json"
RERUN4 = "docs/performance/numba_table_400x300_rerun4.json"


def _field_rows(commit: str) -> list[dict]:
    return [d["modes"]["stop"]["jaxcelt"] for d in _runs_of(FIELD_AB, commit, 3)]


def field_ab(commits: tuple[str, str] = FIELD_COMMITS) -> str:
    """A field A/B (stopping, jaxcelt only, the two commits in turn), in words."""
    rows = [_field_rows(c) for c in commits]
    ab = _ab_per_commit(rows)
    warm, first, steps, status = ab["warm"], ab["first"], ab["steps"], ab["status"]
    ratio = statistics.median(r["warm_s"] for r in rows[0]) / statistics.median(r["warm_s"] for r in rows[1])
    return (
        f"warm calls {warm[1]} against {warm[0]} ({ratio:.2f}×), first calls {first[1]} against {first[0]}; "
        f"lane-steps {steps[1]} against {steps[0]}, statuses {_statuses(status[1])} against {_statuses(status[0])}"
    )


def field_ops(commits: tuple[str, str] = FIELD_COMMITS) -> str:
    """Operations per lane in the optimised `pool_advance` of the two commits."""
    before, after = (_json(POOL_OPS.format(commit=c)) for c in commits)
    for d, c in zip((before, after), commits):
        assert d["provenance"]["commit"].startswith(c) and not d["provenance"]["dirty"], c
    o, n = before["programs"][0]["ops_per_lane"], after["programs"][0]["ops_per_lane"]
    f = lambda k: f"{_sp(round(o[k]))} → {_sp(round(n[k]))}"  # noqa: E731
    roots = lambda d: _sp(round(d["sqrt"] + d["rsqrt"]))  # noqa: E731
    return (
        f"divisions {f('divide')}, square roots {roots(o)} → {roots(n)}, exponentials {f('exponential')}, "
        f"multiplications {f('multiply')}, selects {f('select')}"
    )


QUOTES += [(PAGE, field_ab), (PAGE, field_ops), (PAGE, lambda: rerun(RERUN4))]


def rerun4_statuses() -> str:
    """Integrating on, the statuses of the last two tables."""
    a, b = (_json(p)["modes"]["on"]["jaxcelt"]["status_counts"] for p in (RERUN4, RERUN3))
    return f"{a['0']} lanes end their run, {a['4']} past validity ({b['0']} and {b['4']} at b8f0b6b)"


QUOTES += [(PAGE, rerun4_statuses)]


LOG_COMMITS = ("2791e40", "135b478")  # before (the code of 5c549db); the Pade denominators with one logarithm fewer
RERUN5 = "docs/performance/numba_table_400x300_rerun5.json"
QUOTES += [(PAGE, lambda: field_ab(LOG_COMMITS)), (PAGE, lambda: field_ops(("5c549db", "135b478"))), (PAGE, lambda: rerun(RERUN5))]


def main_job_compile_ab() -> str:
    """The main job's compile overhead (whole command) at the three commits, two fresh processes each."""
    pat = "docs/performance/field_ab/main_job_compile_{commit}_{i}.json"
    runs = [[d["command_compile_overhead_s"] for d in _runs_of(pat, c, 2)] for c in ("1adaa3d", "5c549db", "135b478")]
    return ", ".join(" and ".join(f"{x:.1f} s" for x in r) for r in runs)


QUOTES += [(PAGE, main_job_compile_ab)]


QUADRANT_COMMITS = ("ecdf62f", "f109721")  # before (the code of 135b478); sincos's quadrant from integer bits
QUOTES += [(PAGE, lambda: field_ab(QUADRANT_COMMITS)), (PAGE, lambda: field_ops(("135b478", "f109721")))]
