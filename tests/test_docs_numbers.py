"""Numbers quoted in the README and the guides against the committed result files they come from.

Each check recomputes a quoted number from its JSON file (or from the test collection) and asserts
that the document contains it as written. A failure means a result file was regenerated (or a test
added) without updating the prose, or the prose was edited without a result behind it.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _text(rel: str) -> str:
    return (ROOT / rel).read_text(encoding="utf-8")


def _json(rel: str):
    return json.loads((ROOT / rel).read_text(encoding="utf-8"))


def _bench():
    return _json("docs/bifurcation/bench_sweep_400x300.json")


def _vector_width():
    return _json("docs/bifurcation/vector_width.json")["summary"]


def _processes():
    return _json("docs/bifurcation/processes.json")


def _runs(key: str) -> str:
    """A pool timing as the benchmark table gives it: median (each run; + compile)."""
    r = _bench()[key]
    each = ", ".join(f"{x:.1f}" for x in r["seconds_each_run"])
    return f"{r['seconds']:.1f} ({each}; + {r['compile_seconds']:.1f} compile)"


def _vs(ratio: float) -> str:
    """A wall-time ratio jaxcelt / other as the docs word it."""
    return f"{ratio:.2f}× slower" if ratio >= 1 else f"{1 / ratio:.2f}× faster"


def _first_branch() -> dict:
    return next(iter(_json("docs/orbits/branches.json")["branches"].values()))


def _bif(kind: str) -> dict:
    return next(b for b in _first_branch()["branch"]["bifurcations"] if b["kind"] == kind)


def _starts() -> set[str]:
    """Distinct initial conditions over the paper-reproduction study files (same start, one name)."""
    alias = {"rest psi0=0": "rest psi0=0deg", "rest psi0=pi/2": "rest psi0=90deg"}
    ics = set()
    for f in sorted((DOCS / "paper-reproduction").glob("study_*.json")):
        ics |= {alias.get(r["ic"], r["ic"]) for r in json.loads(f.read_text())["rows"]}
    return ics


def _lambda14() -> tuple[float, float]:
    lam = [
        r["lyapunov"]
        for f in (DOCS / "paper-reproduction").glob("study_*.json")
        for r in json.loads(f.read_text())["rows"]
        if r["omega_pi"] == 14.0 and r["lyapunov"] is not None
    ]
    return min(lam), max(lam)


def _long14() -> str:
    rows = {r["kind"]: r for r in _json("docs/orbits/census_long14/census.json")["results"]["14"]["attractors"]}
    c, i, q = rows["chaotic"], rows["invalid"], rows["quasi-periodic"]
    periodic = "none periodic" if "periodic" not in rows else "some periodic"
    return (
        f"chaotic {c['fraction']:.3f} (median λ₁ {c['lyapunov']:.3f} s⁻¹), invalid {i['fraction']:.3f}, "
        f"quasi-periodic {q['fraction']:.3f}, and {periodic}"
    )


def _per_step_512(mode: str) -> float:
    """512-bit over 256-bit vectors per step: the two programs' lanes may take different step counts."""
    r = _vector_width()[mode]
    return (r["256"]["run_s"] / r["256"]["steps"]) / (r["512"]["run_s"] / r["512"]["steps"])


def _main_job_time() -> str:
    """The README's main-job time and, once summary.json carries a provenance block, the machine it ran on."""
    d = _json("docs/bifurcation/summary.json")
    text = f"{d['wall_seconds_including_compile']:.1f} s including compilation"
    prov = d.get("provenance")
    if prov:
        m = prov["machine"]
        text += f" on {m['cpu']}, {m['cpu_cores_usable']} cores"
    return text


# (document, quoted text computed from the result file)
QUOTES = [
    # main job and the full-size CLI run (summary.json written by `jaxcelt bifurcation`)
    ("README.md", lambda: _main_job_time()),
    (
        "docs/bifurcation/README.md",
        lambda: f"took {_json('docs/bifurcation/summary.json')['wall_seconds_including_compile']:.1f} s",
    ),
    (
        "docs/bifurcation/README.md",
        lambda: (
            f"{_json('docs/bifurcation/summary.json')['lanes_invalid']} of {_json('docs/bifurcation/summary.json')['n_values']} lanes"
        ),
    ),
    (
        "docs/bifurcation/README.md",
        lambda: (
            f"**{_json('docs/bifurcation/summary_400x300.json')['wall_seconds_including_compile']:.2f} s including compilation**"
        ),
    ),
    (
        "docs/bifurcation/README.md",
        lambda: f"{_json('docs/bifurcation/summary_400x300.json')['lanes_invalid']} of the 400 lanes",
    ),
    # what compilation adds to the main job (benchmarks/main_job_compile.py)
    (
        "docs/internals/sweep-engine.md",
        lambda: (
            f"— {_json('docs/bifurcation/main_job_compile.json')['command_compile_overhead_s_median']:.1f} s for the "
            f"whole command, {_json('docs/bifurcation/main_job_compile.json')['sweep_compile_overhead_s_median']:.1f} s"
        ),
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: "medians of {} s for the sweep and {} s for the whole command".format(
            ", ".join(f"{x:.2f}" for x in _json("docs/bifurcation/main_job_compile.json")["sweep_compile_overhead_s_each"]),
            ", ".join(f"{x:.2f}" for x in _json("docs/bifurcation/main_job_compile.json")["command_compile_overhead_s_each"]),
        ),
    ),
    # XLA's loop emitters for the Lyapunov stage (benchmarks/compile_options.py)
    (
        "docs/internals/sweep-engine.md",
        lambda: "compile {:.2f} s → {:.2f} s, run {:.2f} s → {:.2f} s, exponents within {:.1e})".format(
            *(_json("docs/performance/compile_options.json")["runs"][v][k] for k in ("compile_s", "run_best_of_3_s") for v in ("default", "loop")),
            _json("docs/performance/compile_options.json")["lyapunov_max_abs_diff"],
        ).replace("e-09", "e-9"),
    ),
    # the 100 x 60 parameter map (scripts/map_study.py)
    (
        "docs/map/README.md",
        lambda: (
            f"**Time: {_json('docs/map/map_omega_q_100x60.json')['wall_seconds_including_compile']:.0f} s including "
            f"compilation ({_json('docs/map/map_omega_q_100x60.json')['whole_command_seconds']:.0f} s for the whole command)**"
        ),
    ),
    # the side-by-side sweep benchmark (benchmarks/bench_sweep.py)
    ("docs/internals/sweep-engine.md", lambda: f"**{_bench()['summary']['jaxcelt_stop_on_invalid_s']:.2f}**"),
    ("docs/internals/sweep-engine.md", lambda: f"**{_bench()['summary']['jaxcelt_dopri8_stop_on_invalid_s']:.2f}**"),
    # the numba loop's own method (Dopri5): equal work step for step
    ("docs/internals/sweep-engine.md", lambda: f"**{_bench()['jaxcelt_pool_stop_on_invalid_dopri5']['seconds']:.2f}**"),
    ("docs/internals/sweep-engine.md", lambda: _runs("jaxcelt_pool_dopri5")),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{1 / _bench()['summary']['wall_ratio_dopri5_vs_numba_ensemble_stop']:.2f}× faster stopping",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{_vs(_bench()['summary']['wall_ratio_dopri5_vs_numba_ensemble_integrate_on'])} integrating on, where",
    ),
    ("docs/internals/sweep-engine.md", lambda: _runs("jaxcelt_pool")),
    (
        "docs/internals/sweep-engine.md",
        lambda: "| {:.1f} ({}) | {:.1f} ({}) |".format(
            *(
                v
                for k in ("numba_dp5_ensemble_stop_on_invalid", "numba_dp5_ensemble")
                for v in (_bench()[k]["seconds"], ", ".join(f"{x:.1f}" for x in _bench()[k]["seconds_each_run"]))
            )
        ),
    ),
    # the lanes that run to max_steps integrating on (Tsit5), against numba and Dopri5
    (
        "docs/internals/sweep-engine.md",
        lambda: "{} lanes that run to max_steps set the critical path ({:.1f} M steps in all, numba's loop {:.1f} M; "
        "Dopri5 {:.1f} M".format(
            _bench()["jaxcelt_pool"]["status_counts"]["1"],
            _bench()["jaxcelt_pool"]["total_steps"] / 1e6,
            _bench()["numba_dp5_ensemble"]["total_steps"] / 1e6,
            _bench()["jaxcelt_pool_dopri5"]["total_steps"] / 1e6,
        ),
    ),
    (
        "docs/bifurcation/max-steps.md",
        lambda: "ends {} lanes with status 3 and still sends {} to max_steps: {:.1f} M steps in all".format(
            _bench()["jaxcelt_pool"]["status_counts"]["3"],
            _bench()["jaxcelt_pool"]["status_counts"]["1"],
            _bench()["jaxcelt_pool"]["total_steps"] / 1e6,
        ),
    ),
    ("docs/internals/sweep-engine.md", lambda: f"{_bench()['summary']['jaxcelt_stop_on_invalid_1dev_s']:.1f} (+"),
    (
        "docs/bifurcation/README.md",
        lambda: "lanes: {:.2f} s + {:.1f} s compile, `bench_sweep_400x300.json`".format(
            _bench()["summary"]["jaxcelt_stop_on_invalid_s"], _bench()["summary"]["compile_s"]
        ),
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"**{_bench()['scipy_dop853_numba_rhs_stop_on_invalid']['seconds']:.1f} (all 400 lanes, measured)**",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{_bench()['summary']['speedup_vs_scipy_loop_same_work_stop']:.1f}× (Tsit5)",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{_bench()['summary']['speedup_vs_scipy_loop_same_work_stop_dopri8']:.1f}× (Dopri8)",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: (
            f"Integrating every lane on: {_bench()['summary']['speedup_vs_scipy_loop_same_work_integrate_on']:.0f}×"
        ),
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{1 / _bench()['summary']['wall_ratio_vs_numba_ensemble_stop']:.2f}× faster than the numba",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{_vs(_bench()['summary']['wall_ratio_vs_numba_ensemble_integrate_on'])} integrating every lane on",
    ),
    # equal work against one simulate at a time: both integrate every lane on
    (
        "docs/internals/sweep-engine.md",
        lambda: (
            f"{_bench()['jaxcelt_lane_by_lane']['seconds'] / _bench()['jaxcelt_pool']['seconds']:.1f}× ({_bench()['jaxcelt_lane_by_lane']['seconds']:,.0f} s extrapolated against the pool's {_bench()['jaxcelt_pool']['seconds']:.1f} s)".replace(",", " ")
        ),
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{_bench()['summary']['total_with_compile_s']:.1f} s including compile in the benchmark",
    ),
    ("docs/performance.md", lambda: f"jaxcelt is {1 / _bench()['summary']['wall_ratio_vs_numba_ensemble_stop']:.2f}×"),
    # one process with a device per core against one pinned process per core (benchmarks/bench_processes.py)
    *[
        (
            "docs/internals/sweep-engine.md",
            lambda m=m: "| " + " | ".join(
                "{:.2f} ({})".format(
                    _processes()[m]["seconds"][k], ", ".join(f"{x:.2f}" for x in _processes()[m]["seconds_each_run"][k])
                )
                for k in ("devices", "processes", "numba")
            ) + " |",
        )
        for m in ("stop", "on")
    ],
    (
        "docs/internals/sweep-engine.md",
        lambda: f"{_processes()['on']['ratio_numba_over_processes']:.2f}× the numba loop's speed",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"loop ({_processes()['on']['ratio_numba_over_devices']:.2f}× and {_processes()['on']['ratio_numba_over_processes']:.2f}×",
    ),
    # 512-bit vectors against XLA's default 256 (benchmarks/vector_width.py)
    *[
        (
            "docs/internals/sweep-engine.md",
            lambda m=m, f=f: f.format(
                w=_vector_width()[m]["512"]["run_s"], d=_vector_width()[m]["256"]["run_s"], x=_vector_width()[m]["speedup_512"],
                p=_per_step_512(m),
            ).replace("17.9 s against 20.0 s", "{:.1f} s against {:.1f} s".format(
                _vector_width()["on"]["512"]["run_s"], _vector_width()["on"]["256"]["run_s"])),
        )
        for m, f in (
            ("stop", "stops at invalid states in {w:.2f} s against {d:.2f} s ({x:.2f}×, the same steps)"),
            ("on", "(17.9 s against 20.0 s) compare unequal work: per step the 512-bit program is {p:.2f}× faster"),
        )
    ],
    (
        "CHANGELOG.md",
        lambda: "The 512-bit vectors alone: {:.2f}× stopping (the same steps), {:.2f}× per step integrating on".format(
            _vector_width()["stop"]["speedup_512"], _per_step_512("on")
        ),
    ),
    # the roofline (benchmarks/roofline.py)
    (
        "docs/internals/sweep-engine.md",
        lambda: "takes {:.3f} µs per lane ({:.3f} µs with XLA's default 256-bit vectors and libm logarithms), against {:.3f} µs".format(
            *(
                _json("docs/bifurcation/roofline.json")[k]
                for k in (
                    "measured_us_per_lane_eval_one_core",
                    "measured_us_per_lane_eval_one_core_xla_defaults",
                    "ideal_us_per_lane_eval_one_core",
                )
            )
        ),
    ),
    ("docs/internals/sweep-engine.md", lambda: f"**{100 * _json('docs/bifurcation/roofline.json')['fraction_of_peak']:.1f} % of peak"),
    # per-step cost table (benchmarks/bench_step_parts.py)
    (
        "docs/internals/sweep-engine.md",
        lambda: f"**{_json('docs/bifurcation/step_parts.json')['us_per_lane']['fused step (pool)']:.2f}**",
    ),
    (
        "docs/internals/sweep-engine.md",
        lambda: f"| {_json('docs/bifurcation/step_parts.json')['us_per_lane']['diffrax tsit5 step + monitor']:.2f} |",
    ),
    # attractor census (scripts/attractor_census.py)
    (
        "docs/orbits/README.md",
        lambda: "at 14 rad/s {} s vs {} s".format(*_json("docs/orbits/census.json")["results"]["14"]["chunk_wall_s"]),
    ),
    (
        "docs/orbits/README.md",
        lambda: "load average {:.2f}–{:.2f}".format(
            min(r["load_average_start"][0] for r in _json("docs/orbits/census.json")["results"].values()),
            max(r["load_average_start"][0] for r in _json("docs/orbits/census.json")["results"].values()),
        ),
    ),
    ("docs/orbits/README.md", lambda: _long14()),
    # Duffing cascade (scripts/duffing_cascade.py)
    (
        "docs/orbits/README.md",
        lambda: "| 2 → 4 | {:.7f} |".format(_json("docs/orbits/duffing_cascade.json")["period_doublings"][1]["F_pd"]),
    ),
    (
        "docs/orbits/README.md",
        lambda: "intervals is {:.2f}".format(_json("docs/orbits/duffing_cascade.json")["ratios"][0]),
    ),
    # period-1 branches (scripts/orbit_branches.py)
    ("docs/orbits/README.md", lambda: f"| fold (saddle-node) | {_bif('fold')['value']:.4f} |"),
    ("docs/orbits/README.md", lambda: f"| Neimark–Sacker | {_bif('Neimark-Sacker')['value']:.4f} |"),
    (
        "docs/orbits/README.md",
        lambda: "| 17 | stable; saddle | {1:.4f}; {0:.4f} |".format(
            *(r["multipliers_abs"][0] for r in _json("docs/orbits/branches.json")["paper_frequencies"]["17.0"])
        ),
    ),
    (
        "docs/orbits/README.md",
        lambda: "the whole branch {:.1f} s".format(_first_branch()["seconds"]["branch_incl_compile"]),
    ),
    ("README.md", lambda: f"begins at a fold at {_bif('fold')['value']:.2f} rad/s"),
    (
        "docs/orbits/README.md",
        lambda: "diagram {:.1f} s with compilation".format(
            _json("docs/orbits/branches.json")["brute_force"]["seconds_incl_compile"]
        ),
    ),
    (
        "docs/orbits/README.md",
        lambda: "first call including compilation {:.1f} s, one Newton solve with the multipliers {:.2f} s".format(
            _first_branch()["seconds"]["newton_first_call_incl_compile"], _first_branch()["seconds"]["newton_solve"]
        ),
    ),
    ("docs/orbits/README.md", lambda: f"ω_fold = {_json('docs/orbits/celt_fold_grad.json')['omega_fold']:.6f} rad/s"),
    (
        "docs/orbits/README.md",
        lambda: "relative difference {:.1e}".format(_json("docs/orbits/celt_fold_grad.json")["relative_difference"]).replace("e-0", "e-"),
    ),
    # paper reproduction (scripts/paper_study.py, scripts/paper_figures.py)
    ("README.md", lambda: f"{len(_starts())} initial conditions"),
    ("docs/paper-reproduction.md", lambda: f"{len(_starts())} starts"),
    ("docs/paper-reproduction.md", lambda: "λ₁ = {:.2f}–{:.2f} s⁻¹ over all the study files".format(*_lambda14())),
    (
        "docs/paper-reproduction.md",
        lambda: (
            f"took {_json('docs/paper-reproduction/figures_psi157.5.json')['diagram_wall_s']:.0f} s, {_json('docs/paper-reproduction/figures_psi157.5.json')['wall_s']:.0f} s with"
        ),
    ),
    # the performance page: the README's jobs, and the 400 x 300 sweep against its peers (equal work, cores stated)
    ("docs/performance.md", lambda: f"| {_json('docs/bifurcation/summary.json')['wall_seconds_including_compile']:.1f} s for the sweep including compilation |"),
    ("docs/performance.md", lambda: f"| {_json('docs/bifurcation/main_job_compile.json')['command_compile_overhead_s_median']:.1f} s for the whole command (median of 3 processes) |"),
    ("docs/performance.md", lambda: f"| {_json('docs/bifurcation/summary_400x300.json')['wall_seconds_including_compile']:.2f} s for the sweep including compilation |"),
    ("docs/performance.md", lambda: "load average {:.1f} at the start (no CPU model recorded) | {:.2f} s + {:.1f} s compilation |".format(
        _bench()["load_average_at_start"][0], _bench()["summary"]["jaxcelt_stop_on_invalid_s"], _bench()["summary"]["compile_s"])),
    ("docs/performance.md", lambda: "| {:.1f} s, plus {:.1f} s compilation |".format(
        *(next(r for r in _json("docs/performance/gpu_map_kernel.json")["machine_2"] if r.get("dtype") == "float64")[k] for k in ("run_s", "compile_s")))),
    *[
        ("docs/performance.md", lambda k=k, e=e: "| {:.2f} | {:.1f} | {:.1e} |".format(
            _bench()[k]["seconds"], _bench()[k]["seconds"] + _bench()[k]["compile_seconds"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"][e]).replace("e-0", "e-0"))
        for k, e in (("jaxcelt_pool_stop_on_invalid", "jaxcelt"), ("jaxcelt_pool_stop_on_invalid_dopri8", "jaxcelt_dopri8"))
    ],
    ("docs/performance.md", lambda: "| 2 threads | {:.1f} |".format(_bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"])),
    ("docs/performance.md", lambda: "| 1 | {:.1f} | — |".format(_bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"])),
    ("docs/performance.md", lambda: "with its compilation the pool takes {:.1f} s against the numba ensemble's {:.1f} s".format(
        _bench()["summary"]["total_with_compile_s"], _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"])),
    ("docs/performance.md", lambda: "the pool takes {:.1f} s warm and {:.1f} s with compilation, against numba's {:.1f} s".format(
        _bench()["jaxcelt_pool"]["seconds"], _bench()["jaxcelt_pool"]["seconds"] + _bench()["jaxcelt_pool"]["compile_seconds"],
        _bench()["numba_dp5_ensemble"]["seconds"])),
    ("docs/performance.md", lambda: "2 cores is {:.1f}× faster in wall time, **{:.1f}× per core** (Tsit5; Dopri8,".format(
        _bench()["summary"]["speedup_vs_scipy_loop_same_work_stop"], _bench()["summary"]["speedup_vs_scipy_loop_same_work_stop"] / 2)),
    ("docs/performance.md", lambda: "as accurate here: {:.1f}× per core)".format(_bench()["summary"]["speedup_vs_scipy_loop_same_work_stop_dopri8"] / 2)),
    # the same comparison in the engine's internals
    ("docs/internals/sweep-engine.md", lambda: "per core {:.1f}× (Tsit5) and {:.1f}× (Dopri8)".format(
        _bench()["summary"]["speedup_vs_scipy_loop_same_work_stop"] / 2, _bench()["summary"]["speedup_vs_scipy_loop_same_work_stop_dopri8"] / 2)),
    ("docs/internals/sweep-engine.md", lambda: "with its {:.1f} s of compilation the stopping sweep takes {:.1f} s end to end, **slower than the numba ensemble's {:.1f} s**".format(
        _bench()["summary"]["compile_s"], _bench()["summary"]["total_with_compile_s"], _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"])),
    ("docs/internals/sweep-engine.md", lambda: "steps ({:.1f} M against {:.1f} M)".format(
        _vector_width()["on"]["512"]["steps"] / 1e6, _vector_width()["on"]["256"]["steps"] / 1e6)),
    ("docs/internals/sweep-engine.md", lambda: "critical path is the {} lanes that hit max_steps".format(_bench()["jaxcelt_pool"]["status_counts"]["1"])),
    ("docs/internals/sweep-engine.md", lambda: "the 400 × 300 sweep's pool compiles in {:.1f} s".format(_bench()["summary"]["compile_s"])),
    ("docs/internals/sweep-engine.md", lambda: "load average {:.1f} at the start, {:.1f} over 5 minutes".format(
        *_json("docs/bifurcation/step_parts.json")["load_average_at_start"][:2])),
    ("docs/internals/sweep-engine.md", lambda: "1-minute load average {:.1f} at the start), 96 lanes".format(
        _json("docs/bifurcation/roofline.json")["load_average_at_start"][0])),
    ("docs/bifurcation/README.md", lambda: "({} here: {} lanes over {} devices)".format(
        _json("docs/bifurcation/summary.json")["n_values"] // len(_json("docs/bifurcation/summary.json")["devices"]),
        _json("docs/bifurcation/summary.json")["n_values"], len(_json("docs/bifurcation/summary.json")["devices"]))),
]


@pytest.mark.parametrize("doc,quote", QUOTES, ids=[f"{d}:{i}" for i, (d, _) in enumerate(QUOTES)])
def test_quoted_number_matches_its_result_file(doc, quote):
    text = " ".join(_text(doc).split())  # line breaks in prose are spaces
    expected = quote()
    assert expected in text, f"{doc} should quote {expected!r} (from its result file)"


def test_attractor_census_table_from_census_json():
    import importlib.util

    spec = importlib.util.spec_from_file_location("attractor_census", ROOT / "scripts" / "attractor_census.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    text = _text("docs/orbits/README.md")
    for line in mod.markdown_table(_json("docs/orbits/census.json")).splitlines():
        assert line in text, f"docs/orbits/README.md should contain {line!r} (from census.json)"


def test_heading_study_has_sixteen_headings_and_a_roll():
    # "17 starts: rest at 16 headings and a 2° roll" (README, paper-reproduction.md)
    starts = _starts()
    assert sum(s.startswith("rest psi0=") for s in starts) == 16
    assert starts - {s for s in starts if s.startswith("rest psi0=")} == {"roll 2deg"}


def _paper_study():
    import importlib.util

    spec = importlib.util.spec_from_file_location("paper_study", ROOT / "scripts" / "paper_study.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_best_paper_score_by_the_readme_rule():
    """The paper score quoted in the README and docs/paper-reproduction.md: the README's labelling rule
    (period-k, else lambda_1 -+ 2 stderr against 0.02 1/s) re-applied to every stored row, strict score first.
    Rows with a standard error decide the headline; point-estimate-only files can score one more (the 17 rad/s
    lane the standard error makes uncertain), as the document says."""
    ps = _paper_study()
    best = {True: [0, 0], False: [0, 0]}  # has stderr -> [strict, allowed]
    for f in sorted((DOCS / "paper-reproduction").glob("study_*.json")):
        d = json.loads(f.read_text())
        assert d["labelling_rule"].startswith("README"), f.name
        rows = [dict(r) for r in d["rows"]]
        for r in rows:  # the stored labels are the rule's
            se = r.get("lyapunov_stderr")
            assert ps.relabel(r["strict"], r["lyapunov"], se) == r["strict"], (f.name, r)
            assert ps.relabel(r["allowed"], r["lyapunov"], se) == r["allowed"], (f.name, r)
        has_se = all("lyapunov_stderr" in r for r in rows)
        for t in ps.score_table(rows):
            best[has_se][0] = max(best[has_se][0], t["score_strict"])
            best[has_se][1] = max(best[has_se][1], t["score_allowed"])
    assert best[True] == [4, 5]
    assert best[False][0] <= 5
    for doc in ("README.md", "docs/paper-reproduction.md"):
        flat = " ".join(_text(doc).split())
        assert f"{best[True][0]} of 8" in flat and f"{best[True][1]} of 8" in flat, doc
    flat = " ".join(_text("docs/paper-reproduction.md").split())
    assert f"{best[True][0]} of 8 labels with the model's validity enforced" in flat


def test_repository_url_is_declared_once_and_used_by_the_notebooks():
    url = tomllib.loads(_text("pyproject.toml"))["project"]["urls"]["Repository"]
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        src = "".join("".join(c["source"]) for c in json.loads(nb.read_text())["cells"] if c["cell_type"] == "code")
        installs = re.findall(r"%pip install[^\n]*", src)
        assert installs and all(f"git+{url}" in line for line in installs), nb.name
    cff = _text("CITATION.cff")
    assert f'repository-code: "{url}"' in cff
    assert "10.5890/DNC.2014.06.002" in cff and "10.5890/DNC.2014.06.002" in _text("docs/MODEL.md")


def test_notebook_results_are_shipped_with_the_package():
    # every result file notebook 05 reads (jaxcelt.studies.benchmarking.RESULT_FILES) is committed and force-included
    from jaxcelt.plotting.results import RESULT_FILES

    forced = tomllib.loads(_text("pyproject.toml"))["tool"]["hatch"]["build"]["targets"]["wheel"]["force-include"]
    for name in RESULT_FILES:
        assert (DOCS / "performance" / name).is_file(), name
        assert forced[f"docs/performance/{name}"] == f"jaxcelt/_results/performance/{name}"


def test_readme_test_count():
    # "The second runs the default test suite (N tests, ...)": the number pytest collects with -m "not slow"
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-m", "not slow", "-p", "no:cacheprovider"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    m = re.search(r"(\d+)/\d+ tests collected", out) or re.search(r"(\d+) tests collected", out)
    assert m, out[-500:]
    quoted = re.search(r"default test suite \((\d+) tests", _text("README.md"))
    assert quoted and int(quoted[1]) == int(m[1]), f"README says {quoted and quoted[1]}, pytest collects {m[1]}"


def test_gpu_table_from_gpu_map_json():
    """Every GPU run in docs/performance/gpu_map.json appears in the engine's GPU table (times to 0.1 s,
    pool iterations with a space as thousands separator)."""
    text = _text("docs/internals/sweep-engine.md")
    runs = [r for r in _json("docs/performance/gpu_map.json")["runs"] if "run_s" in r]
    assert len(runs) == 5
    for r in runs:
        row = f"| {r['grid'][0]} × {r['grid'][1]} | {r['periods']} | {r['dtype']}"
        assert row in text, row
        for quote in (f"{r['compile_s']:.1f} s", f"{r['run_s']:.1f} s", f"{r['steps_max']:,}".replace(",", " ")):
            assert quote in text, quote


def test_sensor_study_numbers_from_json():
    """The sensor-axes study's summary in docs/identification.md against docs/fit/sensor_study.json."""
    text = " ".join(_text("docs/identification.md").split())
    d = _json("docs/fit/sensor_study.json")
    s = d["summary"]
    quotes = [f"Over {s['seeds']} noise seeds {s['converged']} fits converge"]
    quotes += [f"{n} {100 * s[n]['median_rel_err']:.2f} %" for n in ("mu", "k_r", "b_Ts", "m_Ts")]
    quotes += [f"{n} {100 * s[n]['coverage']:.0f} %" for n in ("mu", "k_r", "b_Ts", "m_Ts")]
    quotes += [f"components {100 * s['rotation']['coverage']:.0f} % and the offsets {100 * s['time_offset']['coverage']:.0f} %"]
    quotes += [f"s² = {d['whole_record_fit_seed0']['s2']:.0f}", f"compilation {s['run_s_median']:.1f} s"]
    for q in quotes:
        assert q in text, q


def test_fit_benchmark_table_from_json():
    """The optimiser x problem table in docs/identification.md is the one benchmarks/bench_fit.py
    prints from docs/fit/bench_fit.json, and the multi-start numbers come from docs/fit/multistart.json."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench_fit", Path(__file__).parents[1] / "benchmarks" / "bench_fit.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    text = _text("docs/identification.md")
    for line in bench.table(_json("docs/fit/bench_fit.json")["rows"]).splitlines():
        assert line in text, line
    ms = {r["mode"]: r for r in _json("docs/fit/multistart.json")["rows"]}
    flat = " ".join(text.split())
    for mode in ("vmapped", "sequential"):
        r = ms[mode]
        assert f"{mode}: compile {r['compile_s']:.1f} s, run {r['run_s']:.1f} s" in flat, mode
    assert f"{ms['vmapped']['n_at_best']} of {ms['vmapped']['n_starts']} starts" in flat


def test_gpu_projection_from_step_census_json():
    """The projection of the 400 x 400 map in the engine's GPU section against
    docs/performance/map_step_census.json (benchmarks/map_step_census.py), and the bounds against the step
    counts and the GPU rates they are made of (1e-3 relative: the JSON rounds to 0.1 s)."""
    text = " ".join(_text("docs/internals/sweep-engine.md").split())
    d = _json("docs/performance/map_step_census.json")
    p, q, r, sb = d["projection"], d["projection_without_stiff_lanes"], d["stiff_rerun"], d["stiff_box"]
    rate = d["rates"]["widest_pool_slot_steps_per_s"]
    gpu = [x for x in _json("docs/performance/gpu_map.json")["runs"] if "run_s" in x and x["width"] == 160000]
    assert rate == max(round(x["lanes"] * x["steps_max"] / x["run_s"]) for x in gpu if x["dtype"] == "float64")
    assert p["work_bound_s"] == pytest.approx(d["steps_mean"] * 160000 / rate, rel=1e-3)
    assert p["latency_bound_s"] == pytest.approx(
        d["steps_max"] * d["rates"]["narrowest_pool_us_per_iteration"] * 1e-6, rel=1e-3
    )

    def sp(n):
        return f"{n:,}".replace(",", " ")

    quotes = [
        f"{d['grid'][0]} × {d['grid'][1]} grid of the same box ({d['periods']} periods",
        f"{d['wall_s_including_compile']:.1f} s on the 2-core CPU",
        f"{sp(round(d['steps_mean']))} steps on average (median {sp(round(d['steps_quantiles']['q50']))})",
        f"at least {p['work_bound_s']:.1f} s, even with every slot busy",
        f"{p['slot_step_rate_needed_x']:.2f}× the measured slot-step rate",
        f"({d['stiff_lanes_at_max_steps']} of {d['lanes']})",
        f"least {p['latency_bound_s']:.1f} s.",
        f"{d['stiff_lanes']} of {d['lanes']} lanes, ω_π ≤ {sb['omega_pi'][1]:.1f} rad/s",
        f"q_π ≤ {sb['q_pi'][1]:.3f} m",
        f"carry {100 * d['stiff_share_of_steps']:.1f} % of the steps",
        f"bounds are {q['work_bound_s']:.1f} s and {q['latency_bound_s']:.1f} s",
        f"takes {sp(q['longest_lane_steps'])} steps",
        f"in at most {sp(r['steps_max'])} steps against {sp(r['tsit5_steps_max'])}",
        f"{r['steps_total'] / 1e6:.1f} M in all against {r['tsit5_steps_total'] / 1e6:.1f} M",
        f"took {r['wall_s_including_compile']:.0f} s with Kvaerno5",
        f"{q['slot_step_rate_needed_x']:.2f}× (without the sticking lanes) to {p['slot_step_rate_needed_x']:.2f}× (with them)",
    ]
    for quote in quotes:
        assert quote in text, quote


def test_map_window_check_from_json():
    """The window check in docs/map/README.md against docs/map/lyapunov_window_check.json
    (scripts/map_lyapunov_check.py)."""
    text = " ".join(_text("docs/map/README.md").split())
    d = _json("docs/map/lyapunov_window_check.json")
    s, runs = d["summary"], d["runs"]
    low = [i for i, lane in enumerate(d["lanes"]) if lane["group"] == "low"]
    per = [i for i in low if runs["long_transient"]["label"][i].startswith("period")]
    assert len(per) == s["low_periodic_after_long_transient"]

    def rng(run, idx):
        v = [runs[run]["lyapunov_per_s"][i] for i in idx if runs[run]["lyapunov_per_s"][i] is not None]
        return f"{min(v):.2f} to {max(v):.2f}".replace("-", "−")

    cm = s["chaotic_median_lyapunov_per_s"]
    fl = d["floquet"]["orbits"]
    fe = [o["floquet_exponent_per_s"] for o in fl]
    mu = [o["max_multiplier"] for o in fl]
    lo, lg = s["low_labels"], runs["long_lyapunov"]
    err_map = [runs["map"]["lyapunov_stderr_per_s"][i] for i in low]
    band = [i for i, lane in enumerate(d["lanes"]) if lane["group"] == "chaotic"]
    band_chaotic = [i for i in band if runs["map"]["label"][i] == "chaotic"]
    quotes = [
        f"runs {s['low_lanes']} lanes of the lower left",
        f"From the point estimate with the map's windows {s['low_chaotic_with_map_windows']} of the {s['low_lanes']} lanes are chaotic",
        f"After 300 transient periods {s['low_periodic_after_long_transient']} of the {s['low_lanes']} are period-1",
        f"({sum(runs['map']['label_point_estimate'][i] == 'chaotic' for i in per)} of these were chaotic",
        f"over 160 periods their λ₁ is {rng('long_lyapunov', per)} s⁻¹",
        f"converges for all {s['floquet_converged_stable']} to stable orbits with |μ_max| {min(mu):.3f}–{max(mu):.3f}",
        f"Floquet exponents {min(fe):.3f} to {max(fe):.3f} s⁻¹ ({d['floquet']['seconds']:.1f} s for the {len(fl)})".replace("-", "−"),
        f"for {s['floquet_within_2_stderr']} of {s['floquet_orbits']}",
        f"λ₁ over 10 periods is {rng('long_transient', per)} s⁻¹",
        f"({sum(runs['long_transient']['lyapunov_per_s'][i] > 0.02 for i in per)} of {len(per)} above",
        f"With the map's windows all {lo['map']['uncertain']} lanes are *uncertain*",
        f"(standard errors {min(err_map):.2f}–{max(err_map):.2f} s⁻¹)",
        f"over 160 periods {lo['long_lyapunov']['converging']} are *converging*, {lo['long_lyapunov']['uncertain']} "
        f"*uncertain* and {lo['long_lyapunov']['chaotic']} *chaotic*",
        f"All {s['chaotic_chaotic_with_both_windows']} lanes there are chaotic by the point estimate with both windows",
        f"from {cm['map']:.2f} s⁻¹ over 10 periods to {cm['lyapunov_40']:.2f} over 40 and {cm['long_lyapunov']:.3f} over 160",
        f"again {cm['long_transient']:.2f} s⁻¹",
        f"By the sweeps' rule {len(band_chaotic)} of the {len(band)} are still *chaotic* with the map's windows",
        " and ".join(f"{runs['map']['lyapunov_per_s'][i]:.2f} ± {runs['map']['lyapunov_stderr_per_s'][i]:.2f}" for i in band_chaotic),
        f"all {s['chaotic_labels']['long_lyapunov']['uncertain']} are *uncertain* over 40 and 160 periods",
        f"the 19 lanes take {runs['map']['seconds']:.1f} s with λ₁ over 10 periods and {lg['seconds']:.1f} s over",
    ]
    assert s["chaotic_labels"]["lyapunov_40"] == {"uncertain": len(band)}
    assert lo["lyapunov_40"] == {"uncertain": s["low_lanes"]}
    for quote in quotes:
        assert quote in text, quote


def test_gpu_kernel_table_from_json():
    """The lane kernel's GPU table and bullets in the engine's docs against docs/performance/gpu_map_kernel.json
    (benchmarks/gpu_map.py; times to 0.1 s, counts with a space as thousands separator)."""
    text = _text("docs/bifurcation/README.md")
    flat = " ".join(text.split())
    d = _json("docs/performance/gpu_map_kernel.json")

    def sp(n):
        return f"{n:,}".replace(",", " ")

    maps = [r for r in d["machine_2"] if "grid" in r]
    f64 = next(r for r in maps if r["dtype"] == "float64")
    f32 = next(r for r in maps if r["dtype"] == "float32")
    earlier = next(r for r in d["machine_1"] if "grid" in r and r["dtype"] == "float64")
    final = {r["dtype"]: r for r in d["machine_4"] if "grid" in r}
    for r in (f64, f32, earlier, final["float64"], final["float32"]):
        st = r["status_counts"]
        row = (f"{r['compile_s']:.1f} s", f"{r['run_s']:.1f} s", sp(round(r["lanes_per_s"])),
               f"{r['steps_total'] / 1e10:.3f} × 10¹⁰", sp(round(r["steps_median"])),
               f"{sp(st['0'])} / {sp(st['1'])} / {sp(st['2'])}")  # fmt: skip
        key = f"| {r['compile_s']:.1f} s | {r['run_s']:.1f} s |"
        rows = [ln.replace("**", "") for ln in text.splitlines()]  # bold run times
        line = next((ln for ln in rows if f"| {r['dtype']}, " in ln and key in ln), "")
        for q in row:
            assert q in line, (q, line)
    assert earlier["steps_total"] == f64["steps_total"] == final["float64"]["steps_total"]  # "the same number of lane-steps"
    chk32 = next(r["check"] for r in d["machine_4"] if "check" in r)["float32"]
    comp = next(r["comparison"] for r in d["machine_2"] if "comparison" in r)
    chk = next(r["check"] for r in d["machine_1"] if "check" in r)["float64"]
    quotes = [
        f"**Target met: {f64['run_s']:.1f} s, {earlier['run_s']:.1f} s and {final['float64']['run_s']:.1f} s**",
        f"64 of 64 the same status, step counts within {chk32['max_step_difference']} of each other, samples within "
        f"{chk32['max_sample_difference_rel']:.1e}".replace("e-0", "e-"),
        f"{sp(f64['status_counts']['1'])} sticking lanes stop at max_steps",
        f"all {chk['same_status']} lanes had the same status and the same step count",
        f"within {chk['max_sample_difference_rel']:.1e}",
        f"is {f64['run_s'] / f32['run_s']:.1f}× faster",
        f"status in {100 * comp['same_status_fraction']:.1f} % of the cells and its category in "
        f"{100 * comp['same_category_fraction']:.1f} %",
        f"{sp(f64['regime_counts']['period 3-16'])} cells in float64, {f32['regime_counts']['period 3-16']} in float32",
    ]
    side = {r["engine"]: r for r in d["machine_3"] if "grid" in r}  # equal work, one machine
    k, p = side["auto"], side["pool"]
    assert k["engine_used"] == "kernel" and p["engine_used"] == "pool" and k["periods"] == p["periods"]
    quotes += [
        f"the kernel {k['run_s']:.1f} s, the pool {p['run_s']:.1f} s (**{p['run_s'] / k['run_s']:.1f}×**)",
        f"({k['compile_s']:.1f} s and {p['compile_s']:.1f} s); {sp(k['steps_total'])} against {sp(p['steps_total'])} lane-steps",
    ]
    broken = next(r for r in d["machine_1"] if "grid" in r and r["dtype"] == "float32")  # times still float32
    quotes.append(f"collapsed the step of {sp(broken['status_counts']['3'])} of its {sp(broken['lanes'])} lanes")
    assert chk["same_steps"] == chk["same_status"] == 64
    for q in quotes:
        assert q in flat, q
    for path in ("README.md", "docs/map/README.md", "docs/performance.md"):  # the headline number elsewhere
        assert f"{f64['run_s']:.1f} s" in _text(path), path


def test_float32_periodic_check_from_json():
    """The float32-vs-float64 periodic-cell check quoted in the engine's GPU section against
    docs/performance/float32_periodic_check.json (scripts/float32_periodic_check.py)."""
    flat = " ".join(_text("docs/bifurcation/README.md").split())
    cells = _json("docs/performance/float32_periodic_check.json")["cells"]

    def span(run):
        g = [c[run]["gap_at_float64_period"] for c in cells]
        return f"{min(g):.1e}–{max(g):.1e}".replace("e-0", "e-")

    assert all(c["float64_rtol1e-8"]["regime"] == c["float64_rtol1e-6"]["regime"] == "periodic" for c in cells)
    assert all(c["float32_rtol1e-6"]["regime"] == "aperiodic" for c in cells)
    for q in (f"{len(cells)} such cells", f"to {span('float64_rtol1e-8')} in float64 at rtol 1e-8",
              f"to {span('float64_rtol1e-6')} at rtol 1e-6", f"only to {span('float32_rtol1e-6')} (aperiodic)"):
        assert q in flat, q
