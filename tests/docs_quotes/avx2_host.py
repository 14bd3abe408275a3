"""Quoted texts of the performance page's paragraph on a CPU without AVX-512 (a 2-core AMD EPYC with AVX2): the
400 x 300 table against numba (benchmarks/numba_table.py -> docs/performance/numba_table_400x300_avx2.json), the
roofline (benchmarks/roofline.py -> docs/bifurcation/roofline_avx2.json) and the identification benchmark
(benchmarks/bench_fit.py -> docs/fit/bench_fit_avx2.json), each computed from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import _json
from .pool_programs import perf_latest

PAGE = "docs/performance.md"
TABLE = "docs/performance/numba_table_400x300_avx2.json"
ROOFLINE = "docs/bifurcation/roofline_avx2.json"
FIT = "docs/fit/bench_fit_avx2.json"


def table() -> str:
    """The table against numba on the AVX2 host, in words."""
    return perf_latest(TABLE, ratios=True)


def roofline() -> str:
    """The right-hand side's time and fraction of peak on the AVX2 host, against the AVX-512 host's file."""
    a, b = _json(ROOFLINE), _json("docs/bifurcation/roofline.json")
    assert a["cpu"]["isa"] == "AVX2" and b["cpu"]["isa"] == "AVX-512"
    return (
        f"{a['measured_us_per_lane_eval_one_core']:.3f} µs per lane-evaluation, {100 * a['fraction_of_peak']:.1f} % of "
        f"its peak, against {b['measured_us_per_lane_eval_one_core']:.3f} µs and {100 * b['fraction_of_peak']:.1f} % "
        f"with AVX-512"
    )


def fit() -> str:
    """The identification benchmark's cold fits (no noise) on the AVX2 host."""
    rows = {r["optimiser"]: r for r in _json(FIT)["rows"] if r["problem"] == "4p" and r["noise"] == 0.0}
    lm, lb = rows["lm"], rows["lbfgs"]
    return (
        f"Levenberg–Marquardt {lm['fit_total_s']:.1f} s cold ({lm['compile_s']:.1f} s of it compilation), optax "
        f"L-BFGS {lb['fit_total_s']:.1f} s ({lb['fit_total_s'] / lm['fit_total_s']:.2f}× LM)"
    )


QUOTES = [(PAGE, table), (PAGE, roofline), (PAGE, fit)]
