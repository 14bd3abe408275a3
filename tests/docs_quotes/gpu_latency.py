"""Quotes of "One step's latency: what keeps the float64 map near a minute (one H200)" in the bifurcation page
(``benchmarks/gpu_kernel_latency.py`` -> docs/performance/gpu_kernel_latency.json, ``benchmarks/gpu_map.py`` ->
docs/performance/gpu_map_h200_rerun.json and gpu_map_noise_floor_h200.json), each computed from those files."""

from __future__ import annotations

from .files import _json, _sp

BIF = "docs/bifurcation/README.md"
LABELS = {
    "float64-loop": "float64, stages in a loop",
    "float64-unrolled": "float64, stages written out",
    "mixed-loop": "float32 field (mixed), stages in a loop",
}



def _lat(name: str) -> dict:
    return next(r for r in _json("docs/performance/gpu_kernel_latency.json")["runs"] if r["variant"] == name)


def _rerun() -> dict:
    return next(r for r in _json("docs/performance/gpu_map_h200_rerun.json")["runs"] if "grid" in r)


def _rerun_cmp() -> dict:
    return next(r for r in _json("docs/performance/gpu_map_h200_rerun.json")["runs"] if "comparison" in r)["comparison"]


def _floor_map() -> dict:
    return next(r for r in _json("docs/performance/gpu_map_noise_floor_h200.json")["runs"] if "grid" in r)


def _floor_cmp() -> dict:
    return next(r for r in _json("docs/performance/gpu_map_noise_floor_h200.json")["runs"] if "comparison" in r)[
        "comparison"
    ]


def _before(field: str | None) -> dict:
    return next(
        r
        for r in _json("docs/performance/gpu_map_h200.json")["runs"]
        if "grid" in r and r["field_dtype"] == field and r["rtol"] == (1e-8 if field is None else 1e-6)
    )


def _before_mixed_same() -> float:
    return [r["comparison"] for r in _json("docs/performance/gpu_map_h200.json")["runs"] if "comparison" in r][0][
        "same_category_fraction"
    ]


def rows() -> str:
    out = []
    for name, label in LABELS.items():
        r = _lat(name)
        out.append(
            f"| {label} | {r['compile_s']:.1f} s | {r['run_s']:.2f} s | {_sp(r['iterations'])} | "
            f"{r['us_per_iteration']:.1f} µs | {_sp(r['steps_total'])} |"
        )
    return "\n".join(out)


def values() -> dict[str, str]:
    f64, unr, mix = _lat("float64-loop"), _lat("float64-unrolled"), _lat("mixed-loop")
    rr, fl, b6 = _rerun(), _floor_map(), _before("float32")
    us = f64["us_per_iteration"]
    floor_s = rr["steps_max"] * us * 1e-6
    return {
        "F64": f"{us:.1f}",
        "MIX": f"{mix['us_per_iteration']:.1f}",
        "MIXX": f"{us / mix['us_per_iteration']:.1f}",
        "MIXMAX": _sp(mix["status_counts"]["1"]),
        "LANES": _sp(mix["grid"][0] * mix["grid"][1]),
        "STICK": _sp(rr["status_counts"]["1"]),
        "FLOOR": f"{floor_s:.1f}",
        "RERUN": f"{rr['run_s']:.1f}",
        "OVER": f"{rr['run_s'] / floor_s:.2f}",
        "STEPS": _sp(rr["steps_total"]),
        "CELLS": _sp(_rerun_cmp()["cells"]),
        "SAME": "all" if _rerun_cmp()["same_category_fraction"] == 1.0 == _rerun_cmp()["same_status_fraction"] else "not all",
        "BELOW": _sp(round(20.0 / (us * 1e-6), -3)),
        "UNR": f"{unr['us_per_iteration']:.1f}",
        "UNRX": f"{unr['us_per_iteration'] / us:.2f}",
        "UNRC": f"{unr['compile_s']:.1f}",
        "LOOPC": f"{f64['compile_s']:.1f}",
        "FLRUN": f"{fl['run_s']:.1f}",
        "B6RUN": f"{b6['run_s']:.1f}",
        "FLCOL": _sp(fl["status_counts"]["3"]),
        "B6COL": _sp(b6["status_counts"]["3"]),
        "FLSAME": f"{100 * _floor_cmp()['same_category_fraction']:.1f}",
        "B6SAME": f"{100 * _before_mixed_same():.1f}",
        "FACTOR": f"{fl['noise_factor']:.0f}",
    }


def _v(k: str) -> str:
    return values()[k]


QUOTES = [
    (BIF, lambda: " ".join(rows().split())),
    (BIF, lambda: f"**One float64 step of a lane costs {_v('F64')} µs**"),
    (BIF, lambda: f"with the field in float32 (mixed precision) {_v('MIX')} µs,"),
    (BIF, lambda: f"{_v('MIXX')}× less (at rtol 1e-8"),
    (BIF, lambda: f"sends {_v('MIXMAX')} of the {_v('LANES')} lanes to max_steps"),
    (BIF, lambda: f"Its {_v('STICK')} sticking lanes each take max_steps = 10⁶ steps"),
    (BIF, lambda: f"{_v('F64')} µs an iteration that is at least {_v('FLOOR')} s"),
    (BIF, lambda: f"again in {_v('RERUN')} s ({_v('OVER')}× the floor"),
    (BIF, lambda: f"with the same {_v('STEPS')} lane-steps and the same status and label in {_v('SAME')}"),
    (BIF, lambda: f"{_v('CELLS')} cells as the run in the table above"),
    (BIF, lambda: f"sequential steps below {_v('BELOW')} at this latency"),
    (BIF, lambda: f"{_v('UNR')} µs per iteration ({_v('UNRX')}× slower) and {_v('UNRC')} s of compilation against"),
    (BIF, lambda: f"{_v('LOOPC')} s. Dropped."),
    (BIF, lambda: f"compared with the tolerance plus {_v('FACTOR')}"),
    (BIF, lambda: f"the map took {_v('FLRUN')} s against {_v('B6RUN')} s without it"),
    (BIF, lambda: f"{_v('FLCOL')} lanes ended with a collapsed step ({_v('B6COL')} without)"),
    (BIF, lambda: f"{_v('FLSAME')} % of the cells got float64's label"),
    (BIF, lambda: f"({_v('B6SAME')} % without)"),
]

SETTINGS = [
    (BIF, "(32 × 8 lanes, ω_π 10–12.13 rad/s, q_π 0.02–0.0237 m, 10 periods from rest, rtol 1e-8: 8 blocks"),
    (BIF, "the code measured is that of\ncommits fbfc8ab and 4bfd0b4"),
    (BIF, "A float64 map in 20 s therefore needs"),
]
