"""Quoted texts of the "Neimark-Sacker curves" section of the periodic-orbit page (scripts/curves_omega_q.py →
docs/orbits/curves_omega_q.json), each computed from that file.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import ROOT, _json

ORBITS = "docs/orbits/README.md"
FILE = "docs/orbits/curves_omega_q.json"
ORDER = ("ns_a", "ns_a_lower", "ns_b", "ns_b_lower", "fold_a", "fold_a_upper", "fold_b", "fold_b_upper")
KIND = {"neimark-sacker": "Neimark–Sacker", "fold": "fold"}


def _f() -> dict:
    return _json(FILE)


def _e(x: float, digits: int = 1) -> str:
    """An error as the orbits page prints it: 7.9e-11 (no leading zero in the exponent)."""
    return format(x, f".{digits}e").replace("e-0", "e-").replace("e+0", "e+")


def _psi(branch: str) -> str:
    return branch.split("psi ")[1].replace(" deg", "°")


def _done() -> list[str]:
    if not (ROOT / FILE).exists():
        return []
    return [k for k in ORDER if k in _f()["curves"]]


def _curve(key: str):
    def text() -> str:
        c = _f()["curves"][key]
        (qlo, qhi), (wlo, whi) = c["q_range"], c["omega_range"]
        ends = " / ".join(c["stopped"])
        head = f"{KIND[c['kind']]}, ψ = {_psi(c['branch'])}"
        if c.get("continues"):
            end = "lower" if c["q_at_start"] >= qhi else "upper"
            head += f" (continues {c['continues']} from its {end} end)"
        out = f"{head}: {c['points']} points, q_π {qlo:.4f}–{qhi:.4f} m, ω_π {wlo:.4f}–{whi:.4f} rad/s (ends: {ends})"
        if not c.get("continues"):
            out += (
                f"; at q_π = 0.04 m ω_π = {c['curve_at_q_0_04']:.6f} rad/s, "
                f"{_e(abs(c['curve_minus_one_parameter']))} rad/s from the one-parameter point"
            )
        if c["kind"] == "neimark-sacker":
            t0, t1 = c["theta_range"]
            out += f"; θ = {t0:.3f}–{t1:.3f} rad, pair modulus 1 to {_e(c['max_abs_pair_modulus_minus_1'])}"
        else:
            out += f"; multiplier +1 to {_e(c['max_abs_multiplier_minus_1'])}"
        pts = ", ".join(f"{k} at ω_π = {w:.4f}, q_π = {q:.4f}" for k, w, q, _ in c["located_points"])
        return out + f"; codimension-two points: {pts or 'none'}"

    return text


def _linear() -> str:
    r = _f()["known_answers"]["linear_oscillator"]
    return (
        f"{r['points']} points with |ζ| ≤ {_e(r['max_abs_zeta'])} and |κ − cos(2π/ω)| ≤ "
        f"{_e(r['max_abs_kappa_minus_cos_2pi_over_w'])}; the 1:3 points at ω = 3/2 and 3 and the 1:4 points at "
        f"ω = 4/3 and 4 located to {_e(r['max_abs_resonance_error'])}"
    )


def _vdp() -> str:
    r = _f()["known_answers"]["forced_van_der_pol"]
    res = "; ".join(
        f"{p['kind']} at ω = {p['w']:.4f}, F = {p['F']:.4f} (scipy: θ − 2π/{p['kind'][2]} = "
        f"{_e(abs(p['theta_minus_2pi_over_k']))})"
        if p["kind"] != "1:1 resonance"
        else f"1:1 resonance at ω = {p['w']:.4f}, F = {p['F']:.4f} (scipy: a real pair, θ = {p['scipy_theta']:g})"
        for p in r["resonances"]
    )
    return (
        f"at all {r['ns_points_checked']} curve points with |κ| < 1 scipy returns to the state within "
        f"{_e(r['scipy_max_return_error'])}, the pair's modulus is 1 to {_e(r['scipy_max_abs_modulus_minus_1'])} and "
        f"its angle is arccos κ to {_e(r['scipy_max_angle_minus_arccos_kappa'])}; {res}"
    )


def _times() -> str:
    d = _f()
    parts = [
        f"{k} {d['curves'][k]['seconds']['to_first_step_incl_compile']:.0f} s to the first step (with compilation), "
        f"{d['curves'][k]['seconds']['total']:.0f} s in all"
        for k in _done()
    ]
    ka = d["known_answers"]
    parts.append(
        f"the known answers {ka['linear_oscillator']['seconds_incl_compile']:.0f} s and "
        f"{ka['forced_van_der_pol']['seconds_incl_compile']:.0f} s"
    )
    return "; ".join(parts)


def _mirror() -> str:
    c = _f()["curves"]
    a, b = c["ns_a"]["curve_at_q_0_04"], c["ns_b"]["curve_at_q_0_04"]
    fa, fb = c["fold_a"]["curve_at_q_0_04"], c["fold_b"]["curve_at_q_0_04"]
    return (
        f"the two mirror orbits' curves agree at q_π = 0.04 m to {_e(abs(a - b))} rad/s (Neimark–Sacker) and "
        f"{_e(abs(fa - fb))} rad/s (fold)"
    )


QUOTES = [(ORBITS, _curve(k)) for k in _done()]
if _done():
    QUOTES += [(ORBITS, _linear), (ORBITS, _vdp), (ORBITS, _times), (ORBITS, _mirror)]

# inputs, not results
SETTINGS = [
    (ORBITS, "x'' + 2ζx' + x = 0.3 cos(ωt)"),
    (ORBITS, "x'' − 0.5 (1 − x²) x' + x = F cos(ωt)"),
    (ORBITS, "from ω ≈ 1.27, F = 1"),
    (ORBITS, "arclength measured in the chart, κ, ω_π and q_π / 0.01"),
]
