"""Quotes of the lane kernel's GPU modes on one H200: mixed precision, the stiffness switch, the Lorenz
ensemble anchor (``benchmarks/gpu_map.py``, ``benchmarks/gpu_ensemble.py``)."""

from __future__ import annotations

from .files import _json, _sp

BIF = "docs/bifurcation/README.md"
PERF = "docs/performance.md"



def _maps() -> list[dict]:
    return [r for r in _json("docs/performance/gpu_map_h200.json")["runs"] if "grid" in r]


def _cmp() -> list[dict]:
    return [r["comparison"] for r in _json("docs/performance/gpu_map_h200.json")["runs"] if "comparison" in r]


def _map(field, rtol) -> dict:
    return next(r for r in _maps() if r["field_dtype"] == field and r["rtol"] == rtol)


def _stick(mode) -> dict:
    return next(r for r in _json("docs/performance/gpu_stiffness_h200.json")["runs"] if r["stiffness"] == mode)


def _lorenz(dtype) -> dict:
    return next(r for r in _json("docs/performance/gpu_ensemble.json")["runs"] if r["dtype"] == dtype)


def _row(r: dict, label: str, same: str) -> str:
    st = r["status_counts"]
    return (
        f"| {label} | {r['compile_s']:.1f} s | {r['run_s']:.1f} s | "
        f"{' / '.join(_sp(st.get(k, 0)) for k in '0123')} | {same} | {_sp(r['regime_counts'].get('period 3-16', 0))} |"
    )


def _pct(x: float) -> str:
    return f"{100 * x:.1f}"


def map_rows() -> str:
    f64, m6, m7 = _map(None, 1e-8), _map("float32", 1e-6), _map("float32", 1e-7)
    c6, c7 = _cmp()
    return "\n".join([
        "| 400 × 400 × 300 " + _row(f64, "float64, 1e-8", "—"),
        "| 400 × 400 × 300 " + _row(m6, "float32 field, float64 state, 1e-6", f"{_pct(c6['same_category_fraction'])} %"),
        "| 400 × 400 × 300 " + _row(m7, "float32 field, float64 state, 1e-7", f"{_pct(c7['same_category_fraction'])} %"),
    ])  # fmt: skip


def values() -> dict[str, str]:
    f64, m6, m7 = _map(None, 1e-8), _map("float32", 1e-6), _map("float32", 1e-7)
    c6, c7 = _cmp()
    off, auto = _stick("off"), _stick("auto")
    l32, l64 = _lorenz("float32"), _lorenz("float64")
    k32, d32 = l32["engines"]["kernel"], l32["engines"]["diffrax"]
    k64, d64 = l64["engines"]["kernel"], l64["engines"]["diffrax"]
    return {
        "MAPROWS": map_rows(),
        "FLOAT64RUN": f"{f64['run_s']:.1f}",
        "MIXSPEED": f"{f64['run_s'] / m6['run_s']:.2f}",
        "MIXSAME": _pct(c6["same_category_fraction"]),
        "MIXFIL": _sp(m6["regime_counts"]["period 3-16"]),
        "FILAMENTS": _sp(f64["regime_counts"]["period 3-16"]),
        "MIXSTEP": _sp(m6["status_counts"]["3"]),
        "MIX7MAX": _sp(m7["status_counts"]["1"]),
        "MIX7RUN": f"{m7['run_s']:.1f}",
        "MIX7SAME": _pct(c7["same_category_fraction"]),
        "STICKGRID": f"{off['grid'][0]} × {off['grid'][1]}",
        "STICKPERIODS": str(off["periods"]),
        "STICKOFFSTEPS": f"{off['steps_total'] / 1e6:.2f}",
        "STICKAUTOSTEPS": f"{auto['steps_total'] / 1e6:.2f}",
        "STICKOFFMAX": _sp(off["steps_max"]),
        "STICKAUTOMAX": _sp(auto["steps_max"]),
        "STICKOFFRUN": f"{off['run_s']:.1f}",
        "STICKAUTORUN": f"{auto['run_s']:.1f}",
        "STICKOFFCOMP": f"{off['compile_s']:.1f}",
        "STICKAUTOCOMP": f"{auto['compile_s']:.1f}",
        "LORENZN": _sp(l32["trajectories"]),
        "LORENZREP": str(l32["repeat"]),
        "K32": f"{k32['best_ms']:.1f}",
        "D32": _sp(round(d32["best_ms"])),
        "R32": f"{d32['best_ms'] / k32['best_ms']:.0f}",
        "C32K": f"{k32['compile_s']:.2f}",
        "C32D": f"{d32['compile_s']:.2f}",
        "S32K": f"{k32['steps_total'] / 1e6:.0f}",
        "S32D": f"{d32['steps_total'] / 1e6:.0f}",
        "S64K": _sp(k64["steps_total"]),
        "S64D": _sp(d64["steps_total"]),
        "DIFF64": f"{l64['max_final_difference_over_max_state']:.1e}",
        "K64": f"{k64['best_ms']:.1f}",
        "D64": _sp(round(d64["best_ms"])),
        "R64": f"{d64['best_ms'] / k64['best_ms']:.0f}",
    }


def _v(key: str) -> str:
    return values()[key]


QUOTES = [
    (BIF, lambda: " ".join(map_rows().split())),
    (BIF, lambda: f"**The float64 map took {_v('FLOAT64RUN')} s on the H200**"),
    (BIF, lambda: f"**Mixed precision at rtol 1e-6 is {_v('MIXSPEED')}× faster than float64**"),
    (
        BIF,
        lambda: (
            f"label in {_v('MIXSAME')} % of the cells; it keeps {_v('MIXFIL')} of the {_v('FILAMENTS')} period 3–16 cells"
        ),
    ),
    (BIF, lambda: f"but {_v('MIXSTEP')} lanes end with a collapsed step"),
    (
        BIF,
        lambda: (
            f"{_v('MIX7MAX')} lanes run to max_steps and the map is slower than float64's ({_v('MIX7RUN')} s, {_v('MIX7SAME')} % of the labels)"
        ),
    ),
    (
        BIF,
        lambda: (
            f"({_v('STICKGRID')} lanes, ω_π 10–12.13 rad/s, q_π 0.02–0.0237 m, {_v('STICKPERIODS')} periods from rest)"
        ),
    ),
    (
        BIF,
        lambda: (
            f"from {_v('STICKOFFSTEPS')} to {_v('STICKAUTOSTEPS')} million (the longest lane from {_v('STICKOFFMAX')} to {_v('STICKAUTOMAX')})"
        ),
    ),
    (
        BIF,
        lambda: (
            f"the run from {_v('STICKOFFRUN')} s to {_v('STICKAUTORUN')} s and the compilation from {_v('STICKOFFCOMP')} s to {_v('STICKAUTOCOMP')} s"
        ),
    ),
    (BIF, lambda: f"N = {_v('LORENZN')}, t ∈ [0, 1]"),
    (
        BIF,
        lambda: (
            f"(warm, best of {_v('LORENZREP')}): **the kernel {_v('K32')} ms, diffrax's `jax.vmap` {_v('D32')} ms ({_v('R32')}×)**"
        ),
    ),
    (BIF, lambda: f"compilation {_v('C32K')} s and {_v('C32D')} s apart"),
    (BIF, lambda: f"({_v('S32K')} and {_v('S32D')} million lane-steps)"),
    (BIF, lambda: f"({_v('S64K')} against {_v('S64D')} lane-steps), end within {_v('DIFF64')} of the largest state"),
    (BIF, lambda: f"take {_v('K64')} ms against {_v('D64')} ms ({_v('R64')}×)"),
    (
        PERF,
        lambda: (
            "| Lorenz GPU ensemble benchmark, {} trajectories | one NVIDIA H200 | {} ms (diffrax `vmap`: {} ms) |".format(
                _v("LORENZN"), _v("K32"), _v("D32")
            )
        ),
    ),
]

SETTINGS = [
    (BIF, "Published for the same problem on a Tesla V100"),
    (BIF, "DiffEqGPU's kernel 69.5 ms, MPGOS 48.8 ms, diffrax `vmap` 2 611 ms"),
    (BIF, "ρ = linspace(0, 21, N)"),
    (BIF, "adaptive Tsit5 at rtol = atol = 1e-8, dt0 = 10⁻³, float32"),
    (BIF, "| map | arithmetic, rtol |"),
    (BIF, "At rtol 1e-7 the float32"),
    (BIF, "a float32 state kept 6"),
    (BIF, "resolving that rocking to rtol 1e-8"),
    (BIF, "the 13 × 13 Jacobian (14 tangents of the field)"),
    (BIF, "factors it and solves six\n  systems"),
    (BIF, "The 400 × 400 map's time stays set by its 760 sticking lanes"),
    (BIF, "Neither\n  reaches 98 % of the labels at twice the speed"),
]

# the heading's singularity (status 4): the angle that HEADING_GAP = 1e-6 on 1 - n2^2 leaves, a consequence of the
# setting (arcsin(sqrt(1e-6)) = 0.057°), checked here against the constant
STATUS_PAGE = "docs/explanation/status-codes.md"


SETTINGS += [(STATUS_PAGE, "(on its side to within about 0.06°)")]  # tests/test_heading_singularity.py checks it

QUOTES += [
    (
        "README.md",
        lambda: "the published Lorenz GPU ensemble benchmark, {} trajectories, in {} ms on one H200 against {} ms for "
        "diffrax's vmap on the same card".format(_v("LORENZN"), _v("K32"), _v("D32")),
    )
]
