"""Quoted texts of the "fold in two parameters" section of the periodic-orbit page (scripts/fold_curves.py →
docs/orbits/fold_curves.json), each computed from that file.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import ROOT, _json

ORBITS = "docs/orbits/README.md"
FILE = "docs/orbits/fold_curves.json"
ORDER = ("q_pi", "q_pi_upper", "q_pi_upper2", "eps", "mu", "k_r")
LABEL = {"q_pi": "q_π", "eps=eps_R": "ε = ε_R", "mu": "μ", "k_r": "k_r"}
UNIT = {"q_pi": " m", "eps=eps_R": " s⁻²", "mu": "", "k_r": ""}
PER = {"q_pi": " rad/s per m", "eps=eps_R": " rad/s per s⁻²", "mu": " rad/s", "k_r": " rad/s"}


def _f() -> dict:
    return _json(FILE)


def _e(x: float, digits: int = 1) -> str:
    """An error as the orbits page prints it: 7.9e-11 (no leading zero in the exponent)."""
    return format(x, f".{digits}e").replace("e-0", "e-").replace("e+0", "e+")


def _g(x: float) -> str:
    return format(x, ".4g").replace("e-0", "e-").replace("e+0", "e+")


def _done() -> list[str]:
    if not (ROOT / FILE).exists():
        return []
    return [k for k in ORDER if k in _f()["curves"]]


def _curve(key: str):
    def text() -> str:
        c = _f()["curves"][key]
        name, cd = c["parameter"], c["curve"]
        lab, unit = LABEL[name], UNIT[name]
        lo, hi = c["range_reached"]
        om_lo, om_hi = c["omega_range"]
        ends = " / ".join(cd["stopped"])
        pv = cd[name]
        turns = [pv[i] for i in range(1, len(pv) - 1) if (pv[i] - pv[i - 1]) * (pv[i + 1] - pv[i]) < 0]
        turn = f"; it turns back in {lab} at {', '.join(_g(v) for v in turns)}" if turns else ""
        pts = ", ".join(f"{p['kind']} at ω_π = {p['omega_pi']:.4f}, {lab} = {_g(p[name])}" for p in cd["points"])
        if "continues" in c:
            return (
                f"(ω_π, q_π) continued from that end (q_π = {_g(cd[name][0])}{unit}): {c['points']} more points, "
                f"{lab} to {_g(hi)}{unit} (end: {cd['stopped'][1]}); the fold lies between ω_π = {om_lo:.6f} and "
                f"{om_hi:.6f} rad/s, lowest at {lab} = {_g(c['lowest_fold'][name])}{unit}; its start is "
                f"{_e(abs(c['start_minus_end_of_continued_curve']))} rad/s from the end point it continues{turn}; "
                f"codimension-two points: {pts or 'none'}"
            )
        return (
            f"({key_label(key)}): {c['points']} points, {lab} from {_g(lo)} to {_g(hi)}{unit} (ends: {ends}); "
            f"the fold lies between ω_π = {om_lo:.6f} and {om_hi:.6f} rad/s, lowest at {lab} = "
            f"{_g(c['lowest_fold'][name])}{unit}; dω_fold/d{lab.split(' ')[0]} = {_g(c['domega_dp_at_start'])}"
            f"{PER[name]} at the paper's value; start {c['start_omega']:.6f} rad/s ({_e(abs(c['start_minus_located_fold']))} from the "
            f"located fold){turn}; codimension-two points: {pts or 'none'}"
        )

    return text


def key_label(key: str) -> str:
    return {
        "q_pi": "ω_π, q_π",
        "q_pi_upper": "ω_π, q_π",
        "q_pi_upper2": "ω_π, q_π",
        "eps": "ω_π, ε = ε_R",
        "mu": "ω_π, μ",
        "k_r": "ω_π, k_r",
    }[key]


def _answer_text() -> str:
    d = _f()
    low = min((d["curves"][k] for k in _done()), key=lambda c: c["lowest_fold"]["omega_pi"])
    name = low["parameter"]
    head = (
        "A fold at or below 14 rad/s is reached"
        if d["fold_below_14_anywhere"]
        else "No fold on the computed curves lies at or below 14 rad/s"
    )
    cd = low["curve"]
    i = cd["omega_pi"].index(low["lowest_fold"]["omega_pi"])
    second = sorted((abs(complex(*m)) for m in cd["multipliers"][i]), reverse=True)[1]
    text = (
        f"{head}: the lowest fold on any curve is ω_π = {low['lowest_fold']['omega_pi']:.4f} rad/s, at "
        f"{LABEL[name]} = {_g(low['lowest_fold'][name])}{UNIT[name]}, where all the other multipliers lie inside the "
        f"unit circle (the next largest modulus {second:.3f}): a stable orbit and a saddle meet there"
    )
    cross = []
    for k in _done():
        c = d["curves"][k]
        w, pv = c["curve"]["omega_pi"], c["curve"][c["parameter"]]
        for i in range(len(w) - 1):
            if (w[i] - 14.0) * (w[i + 1] - 14.0) < 0:
                f = (14.0 - w[i]) / (w[i + 1] - w[i])
                cross.append(f"{LABEL[c['parameter']]} = {_g(pv[i] + f * (pv[i + 1] - pv[i]))}{UNIT[c['parameter']]}")
    if cross:
        text += f"; the curve crosses ω_π = 14 rad/s at {', '.join(cross)} (linear interpolation between its points)"
    if "mu" in d["curves"]:
        g = _json("docs/orbits/celt_fold_grad.json")["domega_fold_dmu_grad"]
        text += (
            f"; along the (ω_π, μ) curve dω_fold/dμ = {_g(d['curves']['mu']['domega_dp_at_start'])} rad/s at "
            f"μ = 0.2241 (secant through the start's neighbours) against {g:.4f} from the implicit function theorem"
        )
    cusps = [
        f"ω_π = {pt['omega_pi']:.4f} rad/s, {LABEL[d['curves'][k]['parameter']]} = {_g(pt[d['curves'][k]['parameter']])}"
        for k in _done()
        for pt in d["curves"][k]["curve"]["points"]
        if pt["kind"] == "cusp"
    ]
    if cusps:
        text += ". Cusps, where two folds meet and the curve turns back in its second parameter: " + "; ".join(cusps)
    mu_cusps = [pt for pt in d["curves"].get("mu", {}).get("curve", {}).get("points", []) if pt["kind"] == "cusp"]
    if mu_cusps:
        pt = mu_cusps[-1]
        text += (
            f". For μ above {_g(pt['mu'])} this family has no fold near ω_π = {pt['omega_pi']:.2f} rad/s, so its lower "
            "end there is not a fold and whether it reaches 14 rad/s is not decided by these curves"
        )
    return text


def _stability() -> str:
    s = _f()["stability_past_fold"]
    mu = s["multipliers_abs"]
    return (
        f"at ω_π = {s['omega_pi']:.4f} rad/s ({s['omega_minus_fold']:.3f} rad/s past the fold) `periodic_orbit` "
        f"converges (residual {_e(s['residual'])}) to a {'stable' if s['stable'] else 'unstable'} orbit, largest "
        f"multiplier modulus {mu[0]:.4f}"
    )


def _at14() -> str:
    o = _f()["orbits_near_the_q_curve_at_14"]["orbits"]
    parts = [
        f"ω_π = {r['omega_pi']:g} rad/s, q_π = {r['q_pi']:g} m: largest multiplier modulus {r['multipliers_abs'][0]:.4f}"
        for r in o
    ]
    return "; ".join(parts)


def _times() -> str:
    d = _f()
    parts = []
    for k in _done():
        s = d["curves"][k]["seconds"]
        parts.append(
            f"{key_label(k).split(', ')[1]}{' (continued)' if k.startswith('q_pi_upper') else ''} {s['to_first_step_incl_compile']:.0f} s to the first step (with "
            f"compilation), then {s['continuation_after_first_step']:.0f} s"
        )
    load = d["provenance"]["load_average_at_start"][0]
    return "; ".join(parts) + f" (1-minute load average {load:.1f} at the start)"


QUOTES = [(ORBITS, _curve(k)) for k in _done()]
if _done():
    QUOTES += [(ORBITS, _answer_text), (ORBITS, _times)]
    if "orbits_near_the_q_curve_at_14" in _f():
        QUOTES.append((ORBITS, _at14))
    if "stability_past_fold" in _f():
        QUOTES.append((ORBITS, _stability))

# inputs, not results
SETTINGS = [
    (ORBITS, "q_π ∈ [0.02, 0.06]"),
    (ORBITS, "(q_π = 0.04, ε = ε_R = 1e-4, μ = 0.2241, k_r = 0.4345)"),
    (ORBITS, "μ ∈ [0.1, 0.4] or k_r ∈ [0.2, 0.8]"),
    (ORBITS, "divided by 0.01, 1e-4, 0.02 and 0.04"),
]
