"""Quoted texts of the sweep pages: the sweep engine's internals, the bifurcation docs, max-steps, the performance
page and the README's prose, each computed from the result file it comes from.

Each entry is (document, function returning the quoted text). ``tests/test_docs_numbers.py`` asserts that the
document contains the text; ``scripts/results_index.py`` records which files each function reads.
"""

from __future__ import annotations

import json

from .files import DOCS, _bench, _json, _processes, _vector_width  # noqa: F401

ENGINE = "docs/internals/sweep-engine.md"
BIF = "docs/bifurcation/README.md"
MAXSTEPS = "docs/bifurcation/max-steps.md"
PERF = "docs/performance.md"


def _sp(n) -> str:
    """A count with a space as thousands separator."""
    return f"{round(n):,}".replace(",", " ")


def _minus(s: str) -> str:
    return s.replace("-", "−")


# --- peers, one trajectory at a time (benchmarks/peers.py --out docs/performance) -------------------------------


def _peer_ratios(*names: str) -> list[float]:
    """Wall time of each named peer over jaxcelt Tsit5's, at equal accuracy, over both accuracy targets."""
    eq = _json("docs/performance/peers_idle.json")["equal_accuracy"]
    return [r["ratio_vs_jaxcelt"] for rows in eq.values() for r in rows if r["name"] in names]


def _peers_sentence() -> str:
    level = _peer_ratios("scipy LSODA + numba RHS", "CVODE Adams + numba RHS", "CVODE BDF + numba RHS")
    python = _peer_ratios("scipy DOP853 + Python RHS (interpreted)")
    numba = [1 / r for r in _peer_ratios("numba DP5 (hand-written)")]
    return (
        f"jaxcelt Tsit5 is level with scipy LSODA and SUNDIALS CVODE driving a numba right-hand side "
        f"({min(level):.1f}–{max(level):.1f}×), {min(python):.0f}–{max(python):.0f}× faster than scipy with an "
        f"interpreted Python right-hand side, and {min(numba):.0f}–{max(numba):.0f}× slower than a hand-written numba loop"
    )


def _study_loads() -> list[float]:
    """1-minute load averages recorded by the work-precision ladders (per run) and the stability maps (start, end)."""
    wp = _json("docs/performance/work_precision.json")
    loads = [r["loadavg_1min"] for s in wp["scenes"] for r in s["runs"] if r.get("loadavg_1min") is not None]
    for f in sorted((DOCS / "performance").glob("stability_*.json")):
        d = json.loads(f.read_text(encoding="utf-8"))
        for la in (d.get("versions", {}).get("loadavg_at_start"), d.get("loadavg_at_end")):
            if la:
                loads.append(float(la[0]))
    return loads


def _main_job_lanes(lo: float, hi: float) -> dict[str, list[float]]:
    """The main job's lanes with lo <= ω_π < hi by regime (`regimes` of summary.json: runs of equal labels)."""
    d = _json("docs/bifurcation/summary.json")
    omegas = [10 + 10 * i / (d["n_values"] - 1) for i in range(d["n_values"])]
    out: dict[str, list[float]] = {}
    for r in d["regimes"]:
        if "label" not in r:
            continue
        for w in omegas:
            if r["from"] - 1e-9 <= w <= r["to"] + 1e-9 and lo <= w < hi:
                out.setdefault(r["label"].split(",")[0], []).append(w)
    return out


def _main_job_window_sentence() -> str:
    lanes = _main_job_lanes(12.8, 15.1)
    ch = [f"{w:.1f}" for w in lanes["chaotic"]]
    p8, p6 = lanes["period-8"], lanes["period-6"]
    return (
        f"The main job labels its lanes there *chaotic* at {', '.join(ch[:-1])} and {ch[-1]} rad/s, period-8 and period-6 "
        f"at {p8[0]:.1f} and {p6[0]:.1f}, *invalid* at {', '.join(f'{w:.1f}' for w in lanes['invalid'])} and *uncertain* "
        f"at the other {['zero', 'one', 'two', 'three', 'four', 'five', 'six', 'seven', 'eight'][len(lanes['uncertain'])]}"
    )


# --- the lane kernel's 400 x 400 map on one H100 (benchmarks/gpu_map.py) ----------------------------------------


def _kernel_maps(machine: str) -> dict:
    return {r["dtype"]: r for r in _json("docs/performance/gpu_map_kernel.json")[machine] if "grid" in r}


def _kernel_row(machine: str, dtype: str, label: str, bold: bool = False, longest_note: str = "") -> str:
    r = _kernel_maps(machine)[dtype]
    st = r["status_counts"]
    run = f"**{r['run_s']:.1f} s**" if bold else f"{r['run_s']:.1f} s"
    return (
        f"| {r['grid']} | {label} | {r['compile_s']:.1f} s | {run} | {_sp(r['lanes_per_s'])} | "
        f"{r['steps_total'] / 1e10:.3f} × 10¹⁰ | {_sp(r['steps_max'])}{longest_note} | {_sp(r['steps_median'])} | "
        f"{_sp(st.get('0', 0))} / {_sp(st.get('1', 0))} / {_sp(st.get('2', 0))} |"
    ).replace("| [400, 400] |", f"| 400 × 400 × {r['periods']} |")


def _float64_maps() -> list[dict]:
    return [_kernel_maps(m)["float64"] for m in ("machine_2", "machine_1", "machine_4")]


def _kernel_check(machine: str, key: str) -> dict:
    return next(r[key] for r in _json("docs/performance/gpu_map_kernel.json")[machine] if key in r)


def _kernel_maps_engine(engine: str) -> dict:
    """The kernel and the pool side by side on equal work (machine_3: the map over 3 periods)."""
    return next(r for r in _json("docs/performance/gpu_map_kernel.json")["machine_3"] if r.get("engine") == engine)


# --- the side-by-side CPU benchmark (benchmarks/bench_sweep.py) and its companions -------------------------------


def _each(r: dict, fmt: str = "{:.2f}") -> str:
    return ", ".join(fmt.format(x) for x in r["seconds_each_run"])


def _pool_cell(key: str, bold: bool) -> str:
    """A pool timing of the benchmark table: median (each run; + compile)."""
    r = _bench()[key]
    fmt = "{:.2f}" if bold else "{:.1f}"
    head = f"**{r['seconds']:.2f}**" if bold else f"{r['seconds']:.1f}"
    return f"{head} ({_each(r, fmt)}; + {r['compile_seconds']:.1f} compile)"


def _gpu_pool_row(i: int, label: str, longest_unit: str = "") -> str:
    r = _json("docs/performance/gpu_map.json")["runs"][i]
    us = r["microseconds_per_pool_iteration"]
    per = f"{us:.0f} µs" if us < 1000 else f"{us / 1000:.2f} ms"
    rate = f"{r['lane_steps_per_s']:.1e}".replace("e+0", "e")
    return (
        f"| {r['grid'][0]} × {r['grid'][1]} | {r['periods']} | {label} | {r['compile_s']:.1f} s | {r['run_s']:.1f} s | "
        f"{_sp(r['steps_max'])}{longest_unit} | {per} | {rate} |"
    )


def _gpu_pool(i: int) -> dict:
    return _json("docs/performance/gpu_map.json")["runs"][i]


def _vector_width_rows() -> list[dict]:
    return _json("docs/bifurcation/vector_width.json")["rows"]


def _census() -> dict:
    return _json("docs/performance/map_step_census.json")


# --- max-steps study (benchmarks/max_steps_study.py) -------------------------------------------------------------


def _max_steps_row(key: str, label: str) -> str:
    lanes = _json("docs/bifurcation/max_steps_study.json")["lanes"]
    st = [lane[key][1] for lane in lanes]
    steps = sum(lane[key][0] for lane in lanes)
    return f"| {label} | {st.count(0)} | {st.count(1)} | {st.count(3)} | {steps / 1e6:.1f} M |"


def _max_steps_lane(omega: float) -> dict:
    return next(x for x in _json("docs/bifurcation/max_steps_study.json")["lanes"] if abs(x["omega_pi"] - omega) < 5e-5)


# --- the full-size diagram's regimes (summary_400x300.json: runs of equal labels) and the float32 check ------------


def _full_runs() -> list[dict]:
    return _json("docs/bifurcation/summary_400x300.json")["regimes"]


def _invalid_bands() -> list[tuple[float, float]]:
    """The invalid stretches of the 400 x 300 diagram (runs of at least 10 invalid lanes)."""
    return [(r["from"], r["to"]) for r in _full_runs() if r["label"].startswith("invalid") and r["n"] >= 10]


def _long_valid_run() -> dict:
    return max((r for r in _full_runs() if not r["label"].startswith("invalid")), key=lambda r: r["n"])


def _full_bands_sentences() -> list[str]:
    b = _invalid_bands()
    f = "{:.1f}".format
    band = [f"{f(lo)}–{f(hi)}" for lo, hi in b]
    between = [r for r in _full_runs() if b[2][1] < r["from"] and r["to"] < b[3][0]]  # valid lanes between the last two
    long = _long_valid_run()
    return [
        f"**{band[0]} rad/s, {', '.join(band[1:-1])} and {band[-1]}: invalid**",
        f"**{f(b[0][1])}–{f(b[1][0])} rad/s: aperiodic with periodic windows**, among them a period-doubling structure: {_full_windows()}",
        f"**{f(b[1][1])}–{f(long['from'])} rad/s: aperiodic, bounded and unbounded lanes interleaved**",
        f"**{f(long['from'])}–{f(long['to'])}: a narrow band of ω₂**",
        f"**{f(between[0]['from'])}–{f(between[-1]['to'])}: a few valid lanes",
    ]


def _full_windows() -> str:
    """The periodic windows of the 400 x 300 diagram, adjacent lanes of one period merged, grouped by period."""
    step = 10 / (_json("docs/bifurcation/summary_400x300.json")["n_values"] - 1)
    wins: list[list] = []
    for r in _full_runs():
        k = r["label"].split(",")[0]
        if not k.startswith("period-"):
            continue
        if wins and wins[-1][0] == k and r["from"] - wins[-1][2] < 1.5 * step:
            wins[-1][2] = r["to"]
        else:
            wins.append([k, r["from"], r["to"]])
    groups: dict[str, list[str]] = {}
    for k, lo, hi in wins:
        groups.setdefault(k, []).append(f"{lo:.2f}" if lo == hi else f"{lo:.2f}–{hi:.2f}")
    items = list(groups.items())
    head = [f"{k} at {' and '.join(w)}" for k, w in items[:-1]]
    k, w = items[-1]
    return ", ".join(head) + f", and a {k} window at {' and '.join(w)}"


def _e(x: float) -> str:
    """1.5e-9 as the docs write it (no leading zero in the exponent)."""
    m, e = f"{x:.1e}".split("e")
    return f"{m}e{int(e)}"


def _float32_check_sentence() -> str:
    cells = _json("docs/performance/float32_periodic_check.json")["cells"]

    def span(key: str) -> str:
        g = [c[key]["gap_at_float64_period"] for c in cells]
        return f"{_e(min(g))}–{_e(max(g))}"

    def regime(key: str) -> str:
        (r,) = {c[key]["regime"] for c in cells}
        return r

    assert regime("float64_rtol1e-8") == regime("float64_rtol1e-6") == "periodic"
    return (
        f"{len(cells)} such cells run again on a CPU (`scripts/float32_periodic_check.py` → "
        f"`docs/performance/float32_periodic_check.json`) repeat at the float64 period to {span('float64_rtol1e-8')} in "
        f"float64 at rtol 1e-8 and to {span('float64_rtol1e-6')} at rtol 1e-6 (periodic both times: the test's tolerance "
        f"is 1e-4), but in float32 at rtol 1e-6 only to {span('float32_rtol1e-6')} ({regime('float32_rtol1e-6')})"
    )


QUOTES = [
    # ---------------------------------------------------------------- docs/performance.md
    (PERF, lambda: _peers_sentence()),
    (PERF, lambda: f"timed on a shared 2-core machine (load average {min(_study_loads()):.0f}–{max(_study_loads()):.0f})"),
    (
        PERF,
        lambda: "| 400 × 400 × 300-period ω_π × q_π map | one NVIDIA H100 | {:.1f} s, plus {:.1f} s compilation |".format(
            _kernel_maps("machine_2")["float64"]["run_s"], _kernel_maps("machine_2")["float64"]["compile_s"]
        ),
    ),
    # ---------------------------------------------------------------- README.md
    (
        "README.md",
        lambda: "a 400 × 400 ω_π × q_π map of {} periods in {:.1f} s on one H100, compilation apart".format(
            _kernel_maps("machine_2")["float64"]["periods"], _kernel_maps("machine_2")["float64"]["run_s"]
        ),
    ),
    (
        "README.md",
        lambda: "λ₁ over {} periods differs from λ₁ over {} periods by up to {:.1f} s⁻¹".format(
            _json("docs/map/lyapunov_window_check.json")["runs"]["map"]["lyapunov_periods"],
            _json("docs/map/lyapunov_window_check.json")["runs"]["long_lyapunov"]["lyapunov_periods"],
            max(
                abs(a - b)
                for a, b in zip(
                    _json("docs/map/lyapunov_window_check.json")["runs"]["map"]["lyapunov_per_s"],
                    _json("docs/map/lyapunov_window_check.json")["runs"]["long_lyapunov"]["lyapunov_per_s"],
                )
                if a is not None and b is not None
            ),
        ),
    ),
    # ---------------------------------------------------------------- docs/internals/sweep-engine.md
    # the benchmark table (bench_sweep_400x300.json)
    (
        ENGINE,
        lambda: "| {} | {} | {:.1f} % / {:.0f} % of the slots idle; integrate on: {:.1f} M steps, {} lanes hit max_steps, {} end at a collapsed step (status 3) |".format(
            _pool_cell("jaxcelt_pool_stop_on_invalid", True),
            _pool_cell("jaxcelt_pool", False),
            100 * _bench()["jaxcelt_pool_stop_on_invalid"]["wasted_slot_fraction"],
            100 * _bench()["jaxcelt_pool"]["wasted_slot_fraction"],
            _bench()["jaxcelt_pool"]["total_steps"] / 1e6,
            _bench()["jaxcelt_pool"]["status_counts"]["1"],
            _bench()["jaxcelt_pool"]["status_counts"]["3"],
        ),
    ),
    (
        ENGINE,
        lambda: "| {} | {} | the same tableau and controller: stopping, {:.1f} M steps (numba {:.1f} M) and {} / {} lanes to the end / stopped (numba {} / {}); integrate on: {:.1f} M steps (numba {:.1f} M), {} hit max_steps, {} end at a collapsed step |".format(
            _pool_cell("jaxcelt_pool_stop_on_invalid_dopri5", True),
            _pool_cell("jaxcelt_pool_dopri5", False),
            _bench()["jaxcelt_pool_stop_on_invalid_dopri5"]["total_steps"] / 1e6,
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["total_steps"] / 1e6,
            _bench()["jaxcelt_pool_stop_on_invalid_dopri5"]["status_counts"]["0"],
            _bench()["jaxcelt_pool_stop_on_invalid_dopri5"]["status_counts"]["2"],
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["status_counts"]["0"],
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["status_counts"]["2"],
            _bench()["jaxcelt_pool_dopri5"]["total_steps"] / 1e6,
            _bench()["numba_dp5_ensemble"]["total_steps"] / 1e6,
            _bench()["jaxcelt_pool_dopri5"]["status_counts"].get("1", 0),
            _bench()["jaxcelt_pool_dopri5"]["status_counts"]["3"],
        ),
    ),
    (
        ENGINE,
        lambda: "| {} | — | {:.1f} M steps × {} RHS (Tsit5: {:.1f} M × {}); {:.0f} % idle |".format(
            _pool_cell("jaxcelt_pool_stop_on_invalid_dopri8", True),
            _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["total_steps"] / 1e6,
            _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["rhs_per_step"],
            _bench()["jaxcelt_pool_stop_on_invalid"]["total_steps"] / 1e6,
            _bench()["jaxcelt_pool_stop_on_invalid"]["rhs_per_step"],
            100 * _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["wasted_slot_fraction"],
        ),
    ),
    (
        ENGINE,
        lambda: "| jaxcelt lane pool, Tsit5, 1 device | {:.1f} (+ {:.1f} compile) | — | {:.0f} % idle; 2 devices = {:.2f}× faster |".format(
            _bench()["jaxcelt_pool_stop_on_invalid_1dev"]["seconds"],
            _bench()["jaxcelt_pool_stop_on_invalid_1dev"]["compile_seconds"],
            100 * _bench()["jaxcelt_pool_stop_on_invalid_1dev"]["wasted_slot_fraction"],
            _bench()["jaxcelt_pool_stop_on_invalid_1dev"]["seconds"] / _bench()["jaxcelt_pool_stop_on_invalid"]["seconds"],
        ),
    ),
    (
        ENGINE,
        lambda: "| {:.1f} ({}) | {:.1f} ({}) | integrate on: {:.1f} M steps; {} lanes end at a NaN error or a collapsed step, {} hit max_steps |".format(
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"],
            _each(_bench()["numba_dp5_ensemble_stop_on_invalid"], "{:.1f}"),
            _bench()["numba_dp5_ensemble"]["seconds"],
            _each(_bench()["numba_dp5_ensemble"], "{:.1f}"),
            _bench()["numba_dp5_ensemble"]["total_steps"] / 1e6,
            _bench()["numba_dp5_ensemble"]["status_counts"]["3"],
            _bench()["numba_dp5_ensemble"]["status_counts"].get("1", 0),
        ),
    ),
    (
        ENGINE,
        lambda: "| jaxcelt `simulate`, one lane at a time | — | {:.0f} (extrapolated) | {} evenly spread lanes, full length, cost-weighted; compile {:.1f} s |".format(
            _bench()["jaxcelt_lane_by_lane"]["seconds"],
            _bench()["jaxcelt_lane_by_lane"]["lanes"],
            _bench()["jaxcelt_lane_by_lane"]["compile_seconds"],
        ),
    ),
    (
        ENGINE,
        lambda: "| **{:.1f} (all {} lanes, measured)** | {} (extrapolated) | {:.1f} M RHS evaluations when stopping; integrate on: {} lanes, cost-weighted |".format(
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"],
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["lanes"],
            _sp(_bench()["scipy_dop853_numba_rhs"]["seconds"]),
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["rhs_evals"] / 1e6,
            _bench()["scipy_dop853_numba_rhs"]["lanes"],
        ),
    ),
    (
        ENGINE,
        lambda: "jaxcelt Tsit5 {:.1e}, jaxcelt Dopri5 {:.1e}, jaxcelt Dopri8 {:.1e}, numba DP5 {:.1e}, scipy DOP853 {:.1e}".format(
            *(_bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"][k] for k in ("jaxcelt", "jaxcelt_dopri5", "jaxcelt_dopri8", "numba_dp5", "scipy_dop853"))
        ),
    ),
    (
        ENGINE,
        lambda: "**Integrating every lane on is a race of a few pathological lanes.** {:.0f} % of that work is in lanes past the model's validity".format(
            100 * _bench()["jaxcelt_pool"]["steps_in_invalid_lanes_fraction"]
        ),
    ),
    (ENGINE, lambda: "(deterministic lanes, one compiled program) and took {} s".format(_each(_bench()["jaxcelt_pool"], "{:.1f}"))),
    # one process with a device per core against one pinned process per core (processes.json)
    (
        ENGINE,
        lambda: "Stopping at invalid states, the processes change little ({:.2f} s against {:.2f} s)".format(
            _processes()["stop"]["seconds"]["processes"], _processes()["stop"]["seconds"]["devices"]
        ),
    ),
    (
        ENGINE,
        lambda: "Integrating on, one process is now the faster ({:.1f} s against {:.1f} s)".format(
            _processes()["on"]["seconds"]["devices"], _processes()["on"]["seconds"]["processes"]
        ),
    ),
    (
        ENGINE,
        lambda: "{:.1f} M steps against {:.1f} M, {} lanes at max_steps against {} (stopping: {} / {} lanes to the end / stopped against {} / {}, {:.2f} M steps against {:.2f} M)".format(
            _processes()["on"]["total_steps_processes"] / 1e6,
            _processes()["on"]["total_steps_devices"] / 1e6,
            _processes()["on"]["status_counts_processes"]["1"],
            _processes()["on"]["status_counts_devices"]["1"],
            _processes()["stop"]["status_counts_processes"]["0"],
            _processes()["stop"]["status_counts_processes"]["2"],
            _processes()["stop"]["status_counts_devices"]["0"],
            _processes()["stop"]["status_counts_devices"]["2"],
            _processes()["stop"]["total_steps_processes"] / 1e6,
            _processes()["stop"]["total_steps_devices"] / 1e6,
        ),
    ),
    (
        ENGINE,
        lambda: "each on its one core: {:.1f} s, against {:.1f} s of compilation in one process".format(
            _processes()["on"]["worker_start_and_compile_seconds"], _processes()["on"]["compile_seconds_devices"]
        ),
    ),
    # how the loops are extrapolated (bench_sweep_400x300.json)
    (
        ENGINE,
        lambda: "(its status counts, {} to the end and {} stopped, match jaxcelt's {} / {}). From the same per-lane timings the {}-lane subset would have said {:.0f} s by lane count and {:.0f} s weighted by cost".format(
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["solver_status_counts"]["0"],
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["solver_status_counts"]["1"],
            _bench()["jaxcelt_pool_stop_on_invalid"]["status_counts"]["0"],
            _bench()["jaxcelt_pool_stop_on_invalid"]["status_counts"]["2"],
            _bench()["scipy_dop853_numba_rhs"]["lanes"],
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["subset_extrapolated_by_lane_count"],
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["subset_extrapolated_cost_weighted"],
        ),
    ),
    (
        ENGINE,
        lambda: "the cost-weighted estimate is within {:.0f} % of the measured {:.0f} s".format(
            100 * abs(_bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["subset_extrapolated_cost_weighted"] / _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"] - 1),
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"],
        ),
    ),
    # against the performance targets
    (
        ENGINE,
        lambda: "{:.1f} s including compile in the benchmark (Dopri8: {:.1f} s)".format(
            _bench()["summary"]["total_with_compile_s"],
            _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["seconds"] + _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["compile_seconds"],
        ),
    ),
    (
        ENGINE,
        lambda: "met — {:.2f}×** (Tsit5; Dopri8 {:.2f}×)".format(
            _bench()["summary"]["per_rhs_ratio_jaxcelt_vs_numba"], _bench()["summary"]["per_rhs_ratio_jaxcelt_dopri8_vs_numba"]
        ),
    ),
    (
        ENGINE,
        lambda: "jaxcelt {:.3f} (Dopri8 {:.3f}), numba {:.3f}".format(
            _bench()["summary"]["core_us_per_rhs_jaxcelt"],
            _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["core_us_per_rhs"],
            _bench()["summary"]["core_us_per_rhs_numba"],
        ),
    ),
    (
        ENGINE,
        lambda: "Dopri8 stops in {:.2f} s, {:.2f}× the numba loop's speed, at {:.0f}× its accuracy".format(
            _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["seconds"],
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"] / _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["seconds"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["numba_dp5"] / _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["jaxcelt_dopri8"],
        ),
    ),
    (
        ENGINE,
        lambda: "as accurate at rtol 1e-8: {:.1e} vs {:.1e}); Tsit5 is {:.0f}× less accurate at that tolerance ({:.1e})".format(
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["jaxcelt_dopri8"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["scipy_dop853"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["jaxcelt"] / _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["scipy_dop853"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["jaxcelt"],
        ),
    ),
    (
        ENGINE,
        lambda: "(default Tsit5, which compiles {:.0f} s faster)".format(
            _bench()["jaxcelt_pool_stop_on_invalid_dopri8"]["compile_seconds"] - _bench()["jaxcelt_pool_stop_on_invalid"]["compile_seconds"]
        ),
    ),
    (
        ENGINE,
        lambda: "(matplotlib, xarray, h5py, …: {:.1f} s)".format(_json("docs/bifurcation/main_job_compile.json")["imports_s_median"]),
    ),
    # what limits it
    (
        ENGINE,
        lambda: "the scipy loop (1 core) is {:.0f}× slower in wall time than the hand-written numba ensemble (2 threads; {:.1f} s vs {:.1f} s), the practical CPU floor; jaxcelt's pool (2 cores) is below it in warm wall time ({:.2f} s)".format(
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"] / _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"],
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"],
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"],
            _bench()["jaxcelt_pool_stop_on_invalid"]["seconds"],
        ),
    ),
    (
        ENGINE,
        lambda: "RHS {:.3f} µs per lane, the fused Tsit5 step with its 6 evaluations {:.2f} µs at {} slots".format(
            _bench()["per_lane_eval_cost"]["rhs_us_per_lane"],
            _bench()["per_lane_eval_cost"]["fused_step_us_per_lane"],
            _bench()["per_lane_eval_cost"]["width"],
        ),
    ),
    # the drain (drain.json)
    (
        ENGINE,
        lambda: "costs {:.1f} µs at 6 and {:.1f} µs at 16 slots per device".format(
            *(_json("docs/bifurcation/drain.json")["lone_lanes"]["widths"][w]["us_per_iteration"] for w in ("6", "16"))
        ),
    ),
    (
        ENGINE,
        lambda: "{:.1f} µs per iteration at 3 and {:.1f} µs at 4 slots per device, against {:.1f} µs at 6".format(
            *(_json("docs/bifurcation/drain.json")["lone_lanes"]["widths"][w]["us_per_iteration"] for w in ("3", "4", "6"))
        ),
    ),
    (
        ENGINE,
        lambda: "took {:.1f} s against {:.1f} s integrating every lane on, and {:.2f} s against {:.2f} s stopping at invalid states".format(
            *(
                _json("docs/bifurcation/drain.json")["schedules"][s][m]["run_s"]
                for m in ("integrate_on", "stop_on_invalid")
                for s in ("quarter_to_4", "quarter_to_6")
            )
        ),
    ),
    (
        ENGINE,
        lambda: "the stopping sweep takes about {} iterations".format(
            _sp(round(next(r for r in _vector_width_rows() if r["variant"] == "512" and r["mode"] == "stop")["iterations"], -3))
        ),
    ),
    (
        ENGINE,
        lambda: "What is left: {:.1f} % idle slots when stopping, {:.0f} % integrating on".format(
            100 * _bench()["jaxcelt_pool_stop_on_invalid"]["wasted_slot_fraction"], 100 * _bench()["jaxcelt_pool"]["wasted_slot_fraction"]
        ),
    ),
    (
        ENGINE,
        lambda: "and shards lanes over them: {:.2f}× here".format(
            _bench()["jaxcelt_pool_stop_on_invalid_1dev"]["seconds"] / _bench()["jaxcelt_pool_stop_on_invalid"]["seconds"]
        ),
    ),
    # per-step cost table (step_parts.json)
    (ENGINE, lambda: "| one vectorised RHS evaluation | {:.2f} |".format(_json("docs/bifurcation/step_parts.json")["us_per_lane"]["rhs"])),
    (
        ENGINE,
        lambda: "| the pool's fused Tsit5 step, without stage boundaries | {:.2f} |".format(
            _json("docs/bifurcation/step_parts.json")["us_per_lane"]["fused step, no stage boundaries"]
        ),
    ),
    (
        ENGINE,
        lambda: "({:.2f} → {:.2f} µs, the table above)".format(
            _json("docs/bifurcation/step_parts.json")["us_per_lane"]["fused step, no stage boundaries"],
            _json("docs/bifurcation/step_parts.json")["us_per_lane"]["fused step (pool)"],
        ),
    ),
    # the roofline (roofline.json)
    (
        ENGINE,
        lambda: "an evaluation costs {} flops and {:.0f} transcendental functions per lane ({} flops counting each at {}".format(
            _sp(_json("docs/bifurcation/roofline.json")["xla_cost_per_lane_eval"]["flops"]),
            _json("docs/bifurcation/roofline.json")["xla_cost_per_lane_eval"]["transcendentals"],
            _sp(_json("docs/bifurcation/roofline.json")["effective_flops_per_lane_eval"]),
            _json("docs/bifurcation/roofline.json")["flops_per_transcendental_assumed"],
        ),
    ),
    (
        ENGINE,
        lambda: "{} doubles × 2 pipes × 2 flops × {:.2f} GHz = {:.0f} GFLOP/s per core, turbo not counted): **{:.1f} % of peak, {:.1f}× from it**".format(
            _json("docs/bifurcation/roofline.json")["cpu"]["doubles_per_vector"],
            _json("docs/bifurcation/roofline.json")["cpu"]["ghz"],
            _json("docs/bifurcation/roofline.json")["cpu"]["peak_gflops_per_core"],
            100 * _json("docs/bifurcation/roofline.json")["fraction_of_peak"],
            1 / _json("docs/bifurcation/roofline.json")["fraction_of_peak"],
        ),
    ),
    (
        ENGINE,
        lambda: "start from AVX-512's estimate, {} `rsqrt14` call sites)".format(
            _json("docs/bifurcation/roofline.json")["intrinsic_and_function_calls_in_optimised_ir"]["llvm.x86.avx512.rsqrt14.pd.512"]
        )
        if "llvm.sqrt.v8f64" not in _json("docs/bifurcation/roofline.json")["intrinsic_and_function_calls_in_optimised_ir"]
        else "",
    ),
    # pool width (pool_width.json) and compilation
    (
        ENGINE,
        lambda: "{} slots per device cost {} µs per slot-step and compile in {} s".format(
            " / ".join(str(r["width_per_device"]) for r in _json("docs/bifurcation/pool_width.json")["rows"]),
            " / ".join(f"{r['us_per_slot']:.2f}" for r in _json("docs/bifurcation/pool_width.json")["rows"]),
            " / ".join(f"{r['compile_s']:.0f}" for r in _json("docs/bifurcation/pool_width.json")["rows"]),
        ),
    ),
    (
        ENGINE,
        lambda: "the main job adds {:.1f} s of compilation (above)".format(
            _json("docs/bifurcation/main_job_compile.json")["command_compile_overhead_s_median"]
        ),
    ),
    # the lane pool on a GPU (gpu_map.json)
    (ENGINE, lambda: _gpu_pool_row(0, "float64, 1e-8 (with per-stage kernel boundaries)", " steps")),
    (ENGINE, lambda: _gpu_pool_row(4, "float64, 1e-8")),
    (ENGINE, lambda: _gpu_pool_row(1, "float64, 1e-8")),
    (ENGINE, lambda: _gpu_pool_row(2, "float32, 1e-6")),
    (ENGINE, lambda: _gpu_pool_row(5, "float64, 1e-8, XLA command buffers for while/conditional")),
    (
        ENGINE,
        lambda: "one iteration of the {}-slot pool costs ≈ {:.2f} ms, ≈ {:.1f} µs per slot against ≈ {:.0f} ns per slot at {} slots".format(
            _gpu_pool(4)["width"],
            _gpu_pool(4)["microseconds_per_pool_iteration"] / 1000,
            _gpu_pool(4)["microseconds_per_pool_iteration"] / _gpu_pool(4)["width"],
            1000 * _gpu_pool(1)["microseconds_per_pool_iteration"] / _gpu_pool(1)["width"],
            _sp(_gpu_pool(1)["width"]),
        ),
    ),
    (
        ENGINE,
        lambda: "takes {} steps in {} periods, ≈ {} per period, against ≈ {} for the median lane of the 400 × 400 map".format(
            _sp(_gpu_pool(0)["steps_max"]),
            _gpu_pool(0)["periods"],
            _sp(round(_gpu_pool(0)["steps_max"] / _gpu_pool(0)["periods"], -3)),
            round(_gpu_pool(1)["steps_median"] / _gpu_pool(1)["periods"] / 10) * 10,
        ),
    ),
    (
        ENGINE,
        lambda: "At that rate 300 periods are ≈ {:.1f} M sequential steps, ≥ {} min of iterations at {:.2f} ms".format(
            300 * _gpu_pool(0)["steps_max"] / _gpu_pool(0)["periods"] / 1e6,
            int(300 * _gpu_pool(0)["steps_max"] / _gpu_pool(0)["periods"] * _gpu_pool(4)["microseconds_per_pool_iteration"] * 1e-6 / 60),
            _gpu_pool(4)["microseconds_per_pool_iteration"] / 1000,
        ),
    ),
    (
        ENGINE,
        lambda: "{} slots step ≈ {:.0f}× more lane-steps per second than {} slots".format(
            _sp(_gpu_pool(1)["width"]), _gpu_pool(1)["lane_steps_per_s"] / _gpu_pool(4)["lane_steps_per_s"], _gpu_pool(4)["width"]
        ),
    ),
    (
        ENGINE,
        lambda: "computes all {} slots for all {} iterations although the median lane is done after {:.0f}".format(
            _sp(_gpu_pool(1)["width"]), _sp(_gpu_pool(1)["steps_max"]), _gpu_pool(1)["steps_median"]
        ),
    ),
    (
        ENGINE,
        lambda: "({} against {} in the longest".format(_sp(_gpu_pool(2)["steps_max"]), _sp(_gpu_pool(1)["steps_max"])),
    ),
    (
        ENGINE,
        lambda: "changed nothing measurable ({:.1f} s against {:.1f} s)".format(_gpu_pool(5)["run_s"], _gpu_pool(1)["run_s"]),
    ),
    (ENGINE, lambda: "with them, {:.0f} µs per iteration".format(_gpu_pool(0)["microseconds_per_pool_iteration"])),
    # the projection (map_step_census.json)
    (ENGINE, lambda: "{:.1f} s on the 2-core CPU) and".format(_census()["wall_s_including_compile"])),
    (
        ENGINE,
        lambda: "At the widest pool's {:.2f} × 10⁷ slot-steps/s that is at least {:.1f} s, even with every slot busy in every iteration: the target needs {:.2f}× the measured slot-step rate".format(
            _census()["rates"]["widest_pool_slot_steps_per_s"] / 1e7,
            _census()["projection"]["work_bound_s"],
            _census()["projection"]["slot_step_rate_needed_x"],
        ),
    ),
    (
        ENGINE,
        lambda: "at least the {:.1f} µs measured for the narrowest pool ({} slots), that is at least {:.1f} s".format(
            _census()["rates"]["narrowest_pool_us_per_iteration"],
            _census()["rates"]["narrowest_pool_slots"],
            _census()["projection"]["latency_bound_s"],
        ),
    ),
    (
        ENGINE,
        lambda: "base accelerations q_π ω_π² ≤ {:.1f} m/s²) carry {:.1f} % of the steps. Without them the bounds are {:.1f} s and {:.1f} s: long lanes are a continuum (the longest of the others takes {} steps)".format(
            _census()["stiff_box"]["q_omega2_max"],
            100 * _census()["stiff_share_of_steps"],
            _census()["projection_without_stiff_lanes"]["work_bound_s"],
            _census()["projection_without_stiff_lanes"]["latency_bound_s"],
            _sp(_census()["projection_without_stiff_lanes"]["longest_lane_steps"]),
        ),
    ),
    (
        ENGINE,
        lambda: "all {} finish (status 0; with Tsit5 {} ended at max_steps), in at most {} steps against {}, {:.1f} M in all against {:.1f} M. On the CPU these {} lanes took {:.0f} s with Kvaerno5 (including compilation), against {:.1f} s for the whole {}-lane map".format(
            _census()["stiff_rerun"]["status_counts"]["0"],
            _census()["stiff_lanes_at_max_steps"],
            _sp(_census()["stiff_rerun"]["steps_max"]),
            _sp(_census()["stiff_rerun"]["tsit5_steps_max"]),
            _census()["stiff_rerun"]["steps_total"] / 1e6,
            _census()["stiff_rerun"]["tsit5_steps_total"] / 1e6,
            _census()["stiff_lanes"],
            _census()["stiff_rerun"]["wall_s_including_compile"],
            _census()["wall_s_including_compile"],
            _census()["lanes"],
        ),
    ),
    (
        ENGINE,
        lambda: "{:.2f}× (without the sticking lanes) to {:.2f}× (with them) the measured slot-steps per second at full width, where an iteration of {} slots costs {:.1f}–{:.1f} ms".format(
            _census()["projection_without_stiff_lanes"]["slot_step_rate_needed_x"],
            _census()["projection"]["slot_step_rate_needed_x"],
            _sp(_gpu_pool(1)["width"]),
            min(_gpu_pool(i)["microseconds_per_pool_iteration"] for i in (1, 5)) / 1000,
            max(_gpu_pool(i)["microseconds_per_pool_iteration"] for i in (1, 5)) / 1000,
        ),
    ),
    (
        ENGINE,
        lambda: "one kernel for all of a section's steps, and the map then took {:.1f} s".format(_kernel_maps("machine_2")["float64"]["run_s"]),
    ),
    # ---------------------------------------------------------------- docs/bifurcation/README.md
    (BIF, lambda: _main_job_window_sentence()),
    (
        BIF,
        lambda: "(in the main job {} lanes *chaotic* and {} *uncertain*)".format(
            len(_main_job_lanes(16.2, 17.2)["chaotic"]), len(_main_job_lanes(16.2, 17.2)["uncertain"])
        ),
    ),
    (
        BIF,
        lambda: "range over the whole sweep: {} over {} periods)".format(
            _minus("{:.2f} to {:.2f} s⁻¹".format(*_json("docs/bifurcation/summary.json")["regimes"][-1]["lyapunov_range_per_s"])),
            _json("docs/bifurcation/summary.json")["lyapunov_periods"],
        ),
    ),
    (
        BIF,
        lambda: "exponents over {} periods differ from those over {} periods by up to {:.1f} s⁻¹".format(
            _json("docs/map/lyapunov_window_check.json")["runs"]["map"]["lyapunov_periods"],
            _json("docs/map/lyapunov_window_check.json")["runs"]["long_lyapunov"]["lyapunov_periods"],
            max(
                abs(a - b)
                for a, b in zip(
                    _json("docs/map/lyapunov_window_check.json")["runs"]["map"]["lyapunov_per_s"],
                    _json("docs/map/lyapunov_window_check.json")["runs"]["long_lyapunov"]["lyapunov_per_s"],
                )
                if a is not None and b is not None
            ),
        ),
    ),
    # the lane kernel's table (gpu_map_kernel.json: machine_2 unmarked, machine_1 and machine_4 marked)
    (BIF, lambda: _kernel_row("machine_2", "float64", "float64, 1e-8", bold=True, longest_note=" (max_steps)")),
    (BIF, lambda: _kernel_row("machine_1", "float64", "float64, 1e-8 (machine 1)")),
    (BIF, lambda: _kernel_row("machine_4", "float64", "float64, 1e-8 (machine 4)")),
    (BIF, lambda: _kernel_row("machine_2", "float32", "float32, 1e-6")),
    (BIF, lambda: _kernel_row("machine_4", "float32", "float32, 1e-6 (machine 4)")),
    (
        BIF,
        lambda: "**The float64 map in {}** (within a minute) (three runs, each on its own H100), with {:.1f}–{:.1f} s of compilation apart".format(
            " and ".join([", ".join(f"{r['run_s']:.1f} s" for r in _float64_maps()[:2]), f"{_float64_maps()[2]['run_s']:.1f} s"]),
            min(r["compile_s"] for r in _float64_maps()),
            max(r["compile_s"] for r in _float64_maps()),
        ),
    ),
    (
        BIF,
        lambda: "the kernel {:.1f} s, the pool {:.1f} s (**{:.1f}×**), compilation apart ({:.1f} s and {:.1f} s); {} against {} lane-steps".format(
            _kernel_maps_engine("auto")["run_s"],
            _kernel_maps_engine("pool")["run_s"],
            _kernel_maps_engine("pool")["run_s"] / _kernel_maps_engine("auto")["run_s"],
            _kernel_maps_engine("auto")["compile_s"],
            _kernel_maps_engine("pool")["compile_s"],
            _sp(_kernel_maps_engine("auto")["steps_total"]),
            _sp(_kernel_maps_engine("pool")["steps_total"]),
        ),
    ),
    (
        BIF,
        lambda: "{} sticking lanes stop at max_steps".format(_sp(_kernel_maps("machine_2")["float64"]["status_counts"]["1"])),
    ),
    (
        BIF,
        lambda: "**float32** at rtol 1e-6 is {:.1f}× faster. It gives the float64 map's status in {:.1f} % of the cells and its category in {:.1f} %".format(
            _kernel_maps("machine_2")["float64"]["run_s"] / _kernel_maps("machine_2")["float32"]["run_s"],
            100 * _kernel_check("machine_2", "comparison")["same_status_fraction"],
            100 * _kernel_check("machine_2", "comparison")["same_category_fraction"],
        ),
    ),
    (
        BIF,
        lambda: "{} cells in float64, {} in float32".format(
            _sp(_kernel_maps("machine_2")["float64"]["regime_counts"]["period 3-16"]),
            _sp(_kernel_maps("machine_2")["float32"]["regime_counts"]["period 3-16"]),
        ),
    ),
    (
        BIF,
        lambda: "collapsed the step of {} of its {} lanes".format(
            _sp(_kernel_maps("machine_1")["float32"]["status_counts"]["3"]), _sp(_kernel_maps("machine_1")["float32"]["lanes"])
        ),
    ),
    (
        BIF,
        lambda: "In float64 all {} lanes had the same status and the same step count, with samples within {}".format(
            _kernel_check("machine_1", "check")["float64"]["same_status"],
            f"{_kernel_check('machine_1', 'check')['float64']['max_sample_difference_rel']:.1e}",
        ),
    ),
    (
        BIF,
        lambda: "{0} of {0} the same status, step counts within {1} of each other, samples within {2}".format(
            _kernel_check("machine_4", "check")["float32"]["same_status"],
            _kernel_check("machine_4", "check")["float32"]["max_step_difference"],
            f"{_kernel_check('machine_4', 'check')['float32']['max_sample_difference_rel']:.1e}".replace("e-0", "e-"),
        ),
    ),
    # ---------------------------------------------------------------- docs/bifurcation/max-steps.md
    (MAXSTEPS, lambda: _max_steps_row("numba_dp5", "numba loop, Dormand–Prince 5(4)")),
    (MAXSTEPS, lambda: _max_steps_row("numba_tsit5", "numba loop, Tsitouras 5(4)")),
    (MAXSTEPS, lambda: _max_steps_row("jaxcelt_dopri5", "jaxcelt pool, `diffrax.Dopri5`")),
    (MAXSTEPS, lambda: _max_steps_row("jaxcelt_tsit5", "jaxcelt pool, `diffrax.Tsit5` (default)")),
    (
        MAXSTEPS,
        lambda: "run to max_steps where the numba Dormand–Prince loop finishes in {} steps".format(
            _sp(_max_steps_lane(10.8271)["numba_dp5"][0])
        ),
    ),
    (
        MAXSTEPS,
        lambda: "jaxcelt's Tsit5 ends at a collapsed step after {} steps while the numba Tsit5 loop finishes in {}".format(
            _sp(_max_steps_lane(10.7268)["jaxcelt_tsit5"][0]), _sp(_max_steps_lane(10.7268)["numba_tsit5"][0])
        ),
    ),
    (
        MAXSTEPS,
        lambda: "ω_π = 10.0: {} against {} steps".format(
            _sp(_max_steps_lane(10.0)["numba_tsit5"][0]), _sp(_max_steps_lane(10.0)["numba_dp5"][0])
        ),
    ),
    (
        MAXSTEPS,
        lambda: "M steps in all, against the numba loop's {:.1f} M ({} lanes at status 3)".format(
            _bench()["numba_dp5_ensemble"]["total_steps"] / 1e6, _bench()["numba_dp5_ensemble"]["status_counts"]["3"]
        ),
    ),
    # ---------------------------------------------------------------- docs/performance.md: the sweep table's other rows
    (
        PERF,
        lambda: "| 2 threads | {:.1f} | not recorded (numba caches its compiled loop on disk) | {:.1e} |".format(
            _bench()["numba_dp5_ensemble_stop_on_invalid"]["seconds"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["numba_dp5"],
        ),
    ),
    (
        PERF,
        lambda: "| 1 | {:.1f} | — | {:.1e} |".format(
            _bench()["scipy_dop853_numba_rhs_stop_on_invalid"]["seconds"],
            _bench()["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"]["scipy_dop853"],
        ),
    ),
    # the fixed-step stability limit 2.785/rho (RK4) in the stick-slip scene at eps = 1e-4, scaled by sqrt(eps)
    (
        PERF,
        lambda: "only with dt below the sticking limit ≈ {}·√ε s (RK4)".format(
            "{:.1e}".format(
                next(
                    r for r in _json("docs/performance/stability_b.json")["rows"] if r.get("scene") == "stick-slip eps 1e-4"
                )["dt_limit_RK4"]
                / 1e-4**0.5
            ).replace("e-0", "e-")
        ),
    ),
    # ---------------------------------------------------------------- docs/internals/sweep-engine.md: more
    (
        ENGINE,
        lambda: "1-minute load average {:.1f} at the start, `load_average_at_start`".format(_bench()["load_average_at_start"][0]),
    ),
    (
        ENGINE,
        lambda: "The grid's lanes take {} steps on average (median {}), so the full map is {:.2f} × 10¹⁰ lane-steps".format(
            _sp(_census()["steps_mean"]),
            _sp(_census()["steps_quantiles"]["q50"]),
            _census()["projection"]["lane_steps"] / 1e10,
        ),
    ),
    # ---------------------------------------------------------------- docs/bifurcation/README.md: more
    *[(BIF, lambda i=i: _full_bands_sentences()[i]) for i in range(5)],
    (BIF, lambda: _float32_check_sentence()),
]

SETTINGS = [
    # inputs: the README's example start, the controller's constants, the map's box, a threshold, a constant,
    # the supported versions, the reference's DOI
    ("README.md", "at rest at heading ψ0 = 157.5° (long axis turned 22.5° from the vibration"),
    (MAXSTEPS, "I-control, safety 0.9, step factor in [0.2, 10]"),
    (MAXSTEPS, "at ω_π = 10.8271 both Tsitouras 5(4) integrators"),
    (MAXSTEPS, "at 10.7268 jaxcelt's Tsit5"),
    (ENGINE, "(Hairer's 0.4/0.3 and others)"),
    (ENGINE, "q_π 0.02–0.06 m"),
    ("docs/how-to/regime-labels.md", "O drifts more than 0.05 m over the samples"),
    ("docs/explanation/lane-engine.md", "(`PILOT_FRACTION` = 0.1)"),
    ("docs/install.md", "| 3.11 | 0.10 (the newest for 3.11) | 0.6.2 – 0.10 | | ≥ 3.12 | 0.12 | 0.6.2 – 0.12 |"),
    ("docs/install.md", "JAX 0.11 and 0.12 need Python ≥ 3.12"),
    ("docs/citing.md", "doi:10.5890/DNC.2014.06.002"),
    # targets the engine is measured against, and the census' definition of a sticking lane (stiff_factor)
    (ENGINE, "Per-RHS-evaluation cost within 1.5× of the numba ensemble"),
    (ENGINE, "(target 2×: **met**)"),
    (ENGINE, "more than 10× the median steps"),
    # the tolerances the tests assert (tests/test_kernel.py, tests/test_lyapunov.py)
    (BIF, "step counts within 1 % (equal in the test's 16 lanes)"),
    # the GPU map's box and periods, the kernel-against-pool check's grid, and the literature's Lorenz exponent
    (BIF, "q_π 0.02–0.06 m, 270 + 30 periods"),
    (BIF, "8 × 8 lanes of ω_π 15–20, q_π 0.04–0.06 over 10 periods"),
    (BIF, "Lorenz against its published λ₁ = 0.9056"),
]
