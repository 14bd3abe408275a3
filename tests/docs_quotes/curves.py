"""Quoted texts of the two-parameter-curves section of the periodic-orbit page (scripts/bifurcation_curves_check.py
→ docs/orbits/curves_known_answers.json), each computed from that file.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import _json

ORBITS = "docs/orbits/README.md"


def _c() -> dict:
    return _json("docs/orbits/curves_known_answers.json")


def _e(x: float, digits: int = 1) -> str:
    """An error as the orbits page prints it: 7.9e-11 (no leading zero in the exponent)."""
    return format(x, f".{digits}e").replace("e-0", "e-").replace("e+0", "e+")


def _mathieu() -> str:
    m = _c()["mathieu"]
    lo, hi = m["q_range"]
    return (
        f"followed from q = {m['start_q']:g} until q leaves [{lo:g}, 5.2] ({m['points']} points, "
        f"{m['points_compared']} of them with q in [{lo:g}, {hi:g}]): a deviates from `scipy.special.mathieu_b(1, q)` "
        f"by at most {_e(m['max_abs_deviation_at_points'])} at the curve points and by at most "
        f"{_e(m['max_abs_deviation_interpolated'])} between them (cubic interpolation along the curve at 101 values "
        f"of q). Both multipliers stay within {_e(m['max_multiplier_distance_from_minus_1'])} of −1"
    )


def _cusp() -> str:
    d = _c()["duffing"]
    c = d["cusp"][0]
    mu = sorted(c["multipliers"], reverse=True)
    return (
        f"from the upper fold at F = {d['start']['F']:g} ({d['points']} points) passes its cusp at "
        f"ω = {c['omega']:.5f}, F = {c['F']:.5f} (multipliers {mu[0]:.6f} and {mu[1]:.4f}; normal-form coefficient "
        f"{_e(c['test'])} there)"
    )


def _census() -> str:
    cs = _c()["duffing"]["census"]
    rows = cs["rows"]
    inside = [r for r in rows if r["where"] == "inside"]
    outside = [r for r in rows if r["where"] == "outside"]
    return (
        f"{sorted(set(r['orbits'] for r in inside))[0]} stable period-1 orbits at each of the {len(inside)} points "
        f"in the middle of the wedge (F = {', '.join(format(r['F'], 'g') for r in inside)}), "
        f"{sorted(set(r['orbits'] for r in outside))[0]} at each of the {len(outside)} points outside it"
    )


def _times() -> str:
    c = _c()
    m, d = c["mathieu"], c["duffing"]
    load = c["provenance"]["load_average_at_start"][0]
    return (
        f"Mathieu curve {m['time_first_s']:.1f} s with compilation and {m['time_compiled_s']:.2f} s on a repeat "
        f"call, the Duffing curve {d['time_first_s']:.1f} s and {d['time_compiled_s']:.2f} s, the scipy census "
        f"{d['census']['time_s']:.1f} s (1-minute load average {load:.1f} at the start)"
    )


QUOTES = [
    (ORBITS, _mathieu),
    (ORBITS, _cusp),
    (ORBITS, _census),
    (ORBITS, _times),
]

# inputs, not results
SETTINGS = [
    (ORBITS, "x'' + 0.2x' + x + x³ = F cos ωt"),
    (ORBITS, "below the cusp at F = 0.8 F_cusp"),
    (ORBITS, "at ω = ω_cusp ± 0.05"),
]
