"""Quoted texts of the how-to page "Continue attractors over a parameter" (scripts/attractor_continuation.py →
docs/orbits/attractor_continuation.json; the census comparison from docs/orbits/census.json), each computed from
those files.

Each entry is (document, function returning the quoted text); ``SETTINGS`` lists (document, phrase) for numbers
that are inputs.
"""

from __future__ import annotations

from .files import _json

PAGE = "docs/how-to/continue-attractors.md"
FILE = "docs/orbits/attractor_continuation.json"
READ_OFF = ("14", "15.6", "17", "19")


def _d() -> dict:
    return _json(FILE)


def _census(w: str) -> dict:
    return _json("docs/orbits/census.json")["results"][w]


def _m(x: float, fmt: str) -> str:
    """A number with a unicode minus."""
    return format(x, fmt).replace("-", "−")


def duffing_row(j: int) -> str:
    r = _d()["duffing"]["values"][j]
    xs = ", ".join(f"{_m(a['x'], '.3f')}" for a in sorted(r["attractors"], key=lambda a: a["x"]))
    kinds = " and ".join(sorted({f"period-{a['period']}" for a in r["attractors"]}))
    dos = "—" if r["diff_over_sigma"] is None else f"{r['diff_over_sigma']:.2f}"
    return (
        f"| {r['F']:g} | {len(r['attractors'])} × {kinds} (x = {xs}) | {r['left_fraction']:.3f} ± "
        f"{r['left_fraction_stderr']:.3f} | {r['scipy_left_fraction']:.3f} | {dos} | {r['lane_agreement']:.3f} |"
    )


def duffing_multipliers() -> str:
    d = _d()["duffing"]
    mu = [a["multiplier_max"] for r in d["values"] for a in r["attractors"]]
    dev = max(abs(x - d["multiplier_analytic"]) for x in mu)
    return (
        f"every orbit's largest \\|μ\\| is {d['multiplier_analytic']:.6f} = exp(−δπ) "
        f"(largest difference {dev:.1e}".replace("e-0", "e-")
        + ")"
    )


def duffing_times() -> str:
    d = _d()["duffing"]
    return (
        f"the continuation took {d['wall_s']:.1f} s (compilation included), the scipy census {d['scipy_wall_s']:.1f} s"
    )


def _att(a: dict) -> str:
    if a["kind"] == "periodic":
        extra = f"\\|μ\\| {a['multiplier_max']:.4f}" if a.get("multiplier_max") is not None else a["refine_status"]
        name = f"period-{a['period']}"
    else:
        ly, se = a.get("lyapunov"), a.get("lyapunov_stderr")
        extra = "λ₁ not computed" if ly is None else f"λ₁ {_m(ly, '.3f')} ± {se:.3f} s⁻¹"
        name = a["kind"]
    return f"#{a['id']} {name} {a['fraction']:.3f} ± {a['fraction_stderr']:.3f} ({extra})"


def read_off_row(w: str) -> str:
    r = _d()["read_off"][w]
    atts = "; ".join(_att(a) for a in r["attractors"]) or "none"
    c = _census(w)
    cen = {a["name"]: a["fraction"] for a in c["attractors"] if a["kind"] != "periodic"}
    per = [a["fraction"] for a in c["attractors"] if a["kind"] == "periodic"]
    cen_text = ", ".join([f"period-1 {x:.3f}" for x in per] + [f"aperiodic {cen.get('aperiodic', 0.0):.3f}"])
    return (
        f"| {w} | {atts} | {r['tipping_over']:.3f} ± {r['tipping_over_stderr']:.3f} | {cen_text}; "
        f"invalid {cen.get('invalid', 0.0):.3f} |"
    )


def _row(w: float) -> dict:
    return next(r for r in _d()["summary"]["values"] if abs(r["value"] - w) < 1e-9)


def _pair_orbit_mu(w: float) -> float:
    """The mirror pair's orbit continued by Newton at w rad/s (the largest orbit_multiplier_max of the pair)."""
    return max(a["orbit_multiplier_max"] for a in _row(w)["attractors"] if a.get("orbit_multiplier_max") is not None)


def orbit_sentence() -> str:
    return f"largest \\|μ\\| {_pair_orbit_mu(17.0):.4f} at 17 rad/s"


def orbit_sentence_19() -> str:
    return f"unstable ({_pair_orbit_mu(19.0):.4f} at 19 rad/s)"


def wobblestone_times() -> str:
    d = _d()
    return f"{d['wall_s']:.0f} s for the {d['settings']['n_values']} values"


def _periodic_range() -> str:
    vals = [r["value"] for r in _d()["summary"]["values"] if any(a["kind"] == "periodic" for a in r["attractors"])]
    return f"Periodic attractors are found from {min(vals):g} to {max(vals):g} rad/s"


def _unsettled() -> str:
    """The first value after the periodic range where the pair is no longer periodic."""
    rows = _d()["summary"]["values"]
    last = max(j for j, r in enumerate(rows) if any(a["kind"] == "periodic" for a in r["attractors"]))
    return f"From {rows[last + 1]['value']:g} rad/s its lanes no longer"


def _tipping_below() -> str:
    """The first value where fewer than half of the starts tip over."""
    first = next(r["value"] for r in _d()["summary"]["values"] if r["tipping_over"] < 0.5)
    return f"Below {first:g} rad/s almost every start tips over"


QUOTES = [
    *[(PAGE, (lambda j=j: duffing_row(j))) for j in range(4)],
    (PAGE, duffing_multipliers),
    (PAGE, duffing_times),
    *[(PAGE, (lambda w=w: read_off_row(w))) for w in READ_OFF],
    (PAGE, orbit_sentence),
    (PAGE, orbit_sentence_19),
    (PAGE, wobblestone_times),
    (PAGE, _periodic_range),
    (PAGE, _unsettled),
    (PAGE, _tipping_below),
]

SETTINGS = [
    (PAGE, "x'' + 0.25 x' − x + x³ = F cos t"),
    (PAGE, "F = 0.1, 0.15, 0.2, 0.25"),
    (PAGE, "ω_π = 10, 10.5, …, 20 rad/s and 15.6"),
    (PAGE, "`match_tol` (default 0.25)"),
    (PAGE, "tilt ±0.1 rad"),
    (PAGE, "λ₁ threshold 0.02 s⁻¹"),
    (PAGE, "at least 95 % of the starts in the same well"),
]
