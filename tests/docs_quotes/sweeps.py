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


# --- max-steps study (benchmarks/max_steps_study.py) -------------------------------------------------------------


def _max_steps_row(key: str, label: str) -> str:
    lanes = _json("docs/bifurcation/max_steps_study.json")["lanes"]
    st = [lane[key][1] for lane in lanes]
    steps = sum(lane[key][0] for lane in lanes)
    return f"| {label} | {st.count(0)} | {st.count(1)} | {st.count(3)} | {steps / 1e6:.1f} M |"


def _max_steps_lane(omega: float) -> dict:
    return next(x for x in _json("docs/bifurcation/max_steps_study.json")["lanes"] if abs(x["omega_pi"] - omega) < 5e-5)


QUOTES = [
    # ---------------------------------------------------------------- docs/performance.md
    (PERF, lambda: _peers_sentence()),
    (PERF, lambda: "timed on a shared 2-core machine (load average {:.0f}–{:.0f})".format(min(_study_loads()), max(_study_loads()))),
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
        lambda: "**Target met: {}** for the float64 map (three runs, each on its own H100), with {:.1f}–{:.1f} s of compilation apart".format(
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
]

SETTINGS = [
    # the tolerances the tests assert (tests/test_kernel.py, tests/test_lyapunov.py)
    (BIF, "step counts within 1 % (equal in the test's 16 lanes)"),
]
