"""Quoted texts of the README and the guides, each computed from the result file it comes from.

Each entry is (document, function returning the quoted text). ``tests/test_docs_numbers.py`` asserts that the
document contains the text; ``scripts/results_index.py`` records which files each function reads.
"""

from __future__ import annotations

from .files import (  # noqa: F401
    _bench,
    _bif,
    _first_branch,
    _json,
    _lambda14,
    _long14,
    _machine,
    _main_job_time,
    _per_step_512,
    _processes,
    _runs,
    _starts,
    _text,
    _vector_width,
    _vs,
)

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
    ("docs/performance.md", lambda: f"(60 lanes) | {_machine('docs/bifurcation/summary.json')}, 2 JAX devices, cold compile cache |"),
    ("docs/performance.md", lambda: f"400 frequencies × 300 periods | {_machine('docs/bifurcation/summary_400x300.json')}, 2 JAX devices, cold compile cache |"),
    (
        "docs/bifurcation/README.md",
        lambda: "took {:.1f} s on {}, and the whole command {:.1f} s".format(
            _json("docs/bifurcation/summary.json")["wall_seconds_including_compile"],
            _machine("docs/bifurcation/summary.json"),
            _json("docs/bifurcation/summary.json")["command_seconds"],
        ),
    ),
    (
        "docs/bifurcation/README.md",
        lambda: "**{:.2f} s including compilation** on {}".format(
            _json("docs/bifurcation/summary_400x300.json")["wall_seconds_including_compile"],
            _machine("docs/bifurcation/summary_400x300.json"),
        ),
    ),
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
    ("docs/performance.md", lambda: "with its compilation the pool took {:.1f} s against the numba ensemble's {:.1f} s".format(
        _bench()["summary"]["total_with_compile_s"], _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"])),
    ("docs/performance.md", lambda: "the pool took {:.1f} s warm and {:.1f} s with compilation, against numba's {:.1f} s".format(
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
    ("docs/internals/sweep-engine.md", lambda: "the 400 × 300 sweep's pool compiled in {:.1f} s".format(_bench()["summary"]["compile_s"])),
    ("docs/internals/sweep-engine.md", lambda: "load average {:.1f} at the start, {:.1f} over 5 minutes".format(
        *_json("docs/bifurcation/step_parts.json")["load_average_at_start"][:2])),
    ("docs/internals/sweep-engine.md", lambda: "1-minute load average {:.1f} at the start), 96 lanes".format(
        _json("docs/bifurcation/roofline.json")["load_average_at_start"][0])),
    ("docs/bifurcation/README.md", lambda: "({} here: {} lanes over {} devices)".format(
        _json("docs/bifurcation/summary.json")["n_values"] // len(_json("docs/bifurcation/summary.json")["devices"]),
        _json("docs/bifurcation/summary.json")["n_values"], len(_json("docs/bifurcation/summary.json")["devices"]))),
]
