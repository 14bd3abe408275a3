"""Quoted texts of the page "The smoothing taken to zero" (scripts/eps_limit.py → docs/orbits/eps_limit.json), each
computed from that file.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import ROOT, _json

PAGE = "docs/orbits/eps-limit.md"
FILE = "docs/orbits/eps_limit.json"
KINDS = ("fold", "neimark-sacker")
WP_ROWS = [
    (kind, eps, name, rtol)
    for kind in ("fold",)
    for eps in (1e-4, 1e-8, 1e-12)
    for name, rtol in (
        ("Dopri8", 1e-8),
        ("Dopri8", 1e-10),
        ("Dopri8", 1e-12),
        ("Tsit5", 1e-8),
        ("Tsit5", 1e-10),
        ("Kvaerno5", 1e-6),
        ("Kvaerno5", 1e-8),
        ("Kvaerno5", 1e-10),
    )
]
"""(orbit, eps, solver, rtol) of the work-precision tables"""


def _f() -> dict:
    return _json(FILE)


def _e(x: float, digits: int = 1) -> str:
    """1.2e-11 (no leading zero in the exponent)."""
    return format(x, f".{digits}e").replace("e-0", "e-").replace("e+0", "e+")


def _same(a: float, b: float) -> bool:
    """eps values equal up to the round-off of 10**log10(eps) (the located points store the latter)."""
    return abs(a - b) <= 1e-9 * abs(b)


def _point(kind: str, eps: float) -> dict | None:
    return next((r for r in _f()["points"][kind] if _same(r["eps"], eps) and "omega" in r), None)


def _orbit(kind: str, eps: float) -> dict | None:
    return next((r for r in _f()["orbits"][kind] if _same(r["eps"], eps)), None)


def _solver(o: dict, name: str, rtol: float) -> dict:
    return next(s for s in o["work"]["solvers"] if s["solver"] == name and s["rtol"] == rtol)


def row(eps: float) -> str:
    """One row of the eps table: omega_fold, omega_NS, min V^2 - eps (fold / NS orbit), Dopri8 rtol 1e-10 steps per
    period and time, the locating time, and the fold minus the arclength curve of fold_curves.json."""
    cells = [_e(eps, 0)]
    pts = [_point(k, eps) for k in KINDS]
    orbs = [_orbit(k, eps) for k in KINDS]
    cells += [f"{p['omega']:.10f}" if p else "—" for p in pts]
    cells.append(" / ".join(f"{o['work']['min_V2_minus_eps']:.2f}" if o else "—" for o in orbs))
    cells.append(" / ".join(str(_solver(o, "Dopri8", 1e-10)["steps"]) if o else "—" for o in orbs))
    cells.append(" / ".join(f"{1e3 * _solver(o, 'Dopri8', 1e-10)['seconds']:.1f}" if o else "—" for o in orbs))
    cells.append(" / ".join(f"{p['seconds']:.0f}" if p else "—" for p in pts))
    chk = pts[0].get("fold_curves_minus_this") if pts[0] else None
    cells.append(_e(chk) if chk is not None else "—")
    return "| " + " | ".join(cells) + " |"


def wp_row(kind: str, eps: float, name: str, rtol: float) -> str:
    s = _solver(_orbit(kind, eps), name, rtol)
    ok = "" if s["status"] == 0 else f" (status {s['status']})"
    return (
        f"| {name} rtol {_e(rtol, 0)} | {s['steps']}{ok} | {s['rejected']} | {1e3 * s['seconds']:.1f} | "
        f"{_e(s['error_vs_reference'])} |"
    )


def fit_text(kind: str) -> str:
    f = _f()["fits"][kind]
    p = f.get("power_law", {})
    if "alpha" not in p:
        return f"power law: not fitted ({p.get('failed', 'too few points')})"
    return (
        f"ω₀ = {p['omega_0']:.10f} ± {_e(p['omega_0_err'])} rad/s, c = {p['c']:.4g} ± {_e(p['c_err'])}, "
        f"α = {p['alpha']:.5f} ± {_e(p['alpha_err'])}"
    )


def linear_text(kind: str) -> str:
    f = _f()["fits"][kind]["linear"]
    return (
        f"ω₀ = {f['omega_0']:.10f} ± {_e(f['omega_0_err'])} rad/s, c = {f['c']:.5f} ± {_e(f['c_err'])} rad/s per s⁻² "
        f"(largest residual {_e(f['max_abs_residual'])} rad/s)"
    )


def change_text(kind: str) -> str:
    f = _f()["fits"][kind]
    return (
        f"{_e(abs(f['change_1e-3_to_smallest']))} rad/s from ε = 1e-3 to {_e(f['eps_range'][0], 0)}, "
        f"{_e(f['change_over_last_two_decades'])} rad/s over ε ≤ 1e-6"
    )


def linear_small_text(kind: str) -> str:
    f = _f()["fits"][kind]["linear_eps_le_1e-5"]
    return (
        f"ω₀ = {f['omega_0']:.11f} ± {_e(f['omega_0_err'])} rad/s, c = {f['c']:.5f} ± {_e(f['c_err'])} "
        f"(largest residual {_e(f['max_abs_residual'])} rad/s)"
    )


def multipliers_text() -> str:
    d = _f()["points"]
    fm = max(r["min_abs_multiplier_minus_1"] for r in d["fold"] if "omega" in r)
    nm = max(r["pair_abs_minus_1"] for r in d["neimark-sacker"] if "omega" in r)
    return f"a multiplier within {_e(fm)} of +1, every Neimark–Sacker point a complex pair within {_e(nm)}"


def agreement_text() -> str:
    v = [
        abs(r["fold_curves_minus_this"]) for r in _f()["points"]["fold"] if r.get("fold_curves_minus_this") is not None
    ]
    return f"to {_e(max(v))} rad/s ({len(v)} values of ε)"


def margins_text() -> str:
    o = _f()["orbits"]
    v2 = [min(r["work"]["min_V2_minus_eps"] for r in o[k]) for k in KINDS]
    dr = [min(r["work"]["min_DR2_minus_epsR"] for r in o[k]) for k in KINDS]
    ws = o["fold"][0]["work"]["omega_s_sign_changes"]
    return (
        f"smallest |v_s|² over a period is {v2[0]:.2f} / {v2[1]:.1f} s⁻² (fold / Neimark–Sacker orbit) and the "
        f"smallest D_R² − ε_R is {dr[0]:.2f} / {dr[1]:.1f} s⁻²; ω_s changes sign {ws} times per period"
    )


def explicit_text() -> str:
    lim = _f()["explicit_limit"]

    def steps(key: str) -> str:
        lo, hi = lim[key]["steps_range"]
        return str(lo) if lo == hi else f"{lo}–{hi}"

    parts = [
        f"{lab}: Dopri8 {steps(k + '/Dopri8')}, Tsit5 {steps(k + '/Tsit5')} steps per period"
        for k, lab in (("fold", "fold orbit"), ("neimark-sacker", "Neimark–Sacker orbit"))
    ]
    smallest = min(v["smallest_eps"] for v in lim.values())
    stops = [v["stops_at_eps"] for v in lim.values() if v["stops_at_eps"] is not None]
    end = f"first stop at ε = {_e(max(stops), 0)}" if stops else "no stop"
    return f"{'; '.join(parts)} at every ε down to {_e(smallest, 0)}, {end}"


def answer_text() -> str:
    d = _f()
    out = []
    for kind, lab in (("fold", "fold"), ("neimark-sacker", "Neimark–Sacker point")):
        f = d["fits"][kind]["linear_eps_le_1e-5"]
        p = _point(kind, 1e-4)
        out.append(
            f"the {lab} to {f['omega_0']:.9f} rad/s, {_e(f['omega_0'] - p['omega'])} rad/s above its value at ε = 1e-4"
        )
    return "; ".join(out)


def _quotes() -> list:
    if not (ROOT / FILE).exists():
        return []
    d = _f()
    out = [(PAGE, lambda e=e: row(e)) for e in d["eps_values"]]
    for kind in KINDS:
        if "linear" in d["fits"][kind]:
            out += [(PAGE, lambda k=kind: fit_text(k)), (PAGE, lambda k=kind: linear_text(k))]
            out += [(PAGE, lambda k=kind: change_text(k)), (PAGE, lambda k=kind: linear_small_text(k))]
    out += [(PAGE, multipliers_text), (PAGE, agreement_text), (PAGE, margins_text), (PAGE, explicit_text)]
    out += [(PAGE, answer_text)]
    out += [(PAGE, lambda a=a: wp_row(*a)) for a in WP_ROWS]
    return out


QUOTES = _quotes()
SETTINGS = [
    (PAGE, "ε = ε_R = 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8"),
    (PAGE, "14.8798 rad/s at q_π = 0.04 m"),
    (PAGE, "its Neimark–Sacker point (17.7475 rad/s)"),
    (PAGE, "exceed 2× its steps"),
    (PAGE, "(ω_π = 17 rad/s, q_π = 0.01 m, from rest)"),
]
