"""Quoted texts of "The 14 rad/s question, answered by fold curves" (docs/paper-reproduction.md) and the README's
answer paragraph (scripts/paper_14.py -> docs/orbits/paper_14.json; the (omega_pi, q_pi) and (omega_pi, mu) curves
of docs/orbits/fold_curves.json), each computed from those files.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import ROOT, _json

PAGE = "docs/paper-reproduction.md"
README = "README.md"
FILE = "docs/orbits/paper_14.json"
FOLDS = "docs/orbits/fold_curves.json"
B12_PAPER = 1.728e-4
LABEL = {"q_pi": "q_π", "B12": "B12", "derivative_exact": "derivative_exact", "k_r": "k_r"}
UNIT = {"q_pi": " m", "B12": " kg m²", "derivative_exact": "", "k_r": ""}


def _f() -> dict:
    return _json(FILE)


def _g(x: float, d: int = 4) -> str:
    return format(x, f".{d}g").replace("e-0", "e-").replace("e+0", "e+")


def _curve(key: str) -> tuple[list, list]:
    c = _f()["curves"][key]
    return c["curve"]["omega_pi"], c["curve"][c["parameter"]]


def _b12() -> str:
    d = _f()["curves"]
    c = d["B12"]
    (x,) = c["crossings_of_14"]
    w = [*d["B12"]["curve"]["omega_pi"], *d.get("B12_to_0", d["B12"])["curve"]["omega_pi"]]
    p = [*d["B12"]["curve"]["B12"], *d.get("B12_to_0", d["B12"])["curve"]["B12"]]
    j = min(range(len(p)), key=lambda i: p[i])
    return (
        f"dω_fold/dB12 = {c['domega_dp_at_start'] * 1e-4:.3f} rad/s per 1e-4 kg m² at the paper's value (secant "
        f"through the start's neighbours); the fold crosses 14 rad/s at B12 = {_g(x['p'])} kg m² "
        f"({100 * x['p'] / B12_PAPER:.0f} % of the paper's value) and lies at {w[j]:.4f} rad/s at B12 = {_g(p[j])} kg m²"
    )


def _de() -> str:
    c = _f()["curves"]["derivative_exact"]
    w, p = c["curve"]["omega_pi"], c["curve"]["derivative_exact"]
    k = next(i for i in range(len(p) - 1) if p[i] <= 1.0 <= p[i + 1])
    w1 = w[k] + (1.0 - p[k]) / (p[k + 1] - p[k]) * (w[k + 1] - w[k])
    return (
        f"the fold moves from {w[p.index(0.0)]:.4f} rad/s (derivative_exact = 0) to {w1:.4f} rad/s at "
        f"derivative_exact = 1 (interpolated between the curve's points); dω_fold/d(derivative_exact) = "
        f"{_g(c['domega_dp_at_start'], 3)} rad/s"
    )


def _kr() -> str:
    c = _f()["curves"]["k_r"]
    lo, hi = c["range_reached"]
    return (
        f"k_r from {_g(lo)} to {_g(hi)}: the fold moves between {c['omega_range'][0]:.4f} and "
        f"{c['omega_range'][1]:.4f} rad/s, dω_fold/dk_r = {_g(c['domega_dp_at_start'], 3)} rad/s at the paper's 0.4345"
    )


def _q_crossing() -> str:
    c = _json(FOLDS)["curves"]["q_pi_upper2"]["curve"]
    w, q = c["omega_pi"], c["q_pi"]
    for i in range(len(w) - 1):
        if (w[i] - 14.0) * (w[i + 1] - 14.0) < 0:
            x = q[i] + (14.0 - w[i]) / (w[i + 1] - w[i]) * (q[i + 1] - q[i])
            return f"q_π = {x:.5f} m"
    raise AssertionError("the (omega_pi, q_pi) curve no longer crosses 14 rad/s")


def _mu_low() -> str:
    c = _json(FOLDS)["curves"]["mu"]
    return f"{c['lowest_fold']['omega_pi']:.4f} rad/s"


def _sheet_rows() -> list[str]:
    rows = []
    for a in _f()["at_14"].values():
        name = a["parameter"]
        for s in a["sheets_at_14"]:
            m = s.get("motion", {})
            rows.append(
                f"| {LABEL[name]} = {_g(a[name])}{UNIT[name]} | {a['fold_omega']:.4f} | "
                f"{'stable' if s['stable'] else 'saddle'} | {s['multipliers_abs'][0]:.4f} | "
                f"{_g(m.get('net_drift_m', float('nan')), 2)} m | {m.get('global_motion', '—')} | "
                f"{m.get('left_orbit_at_period') if m.get('left_orbit_at_period') is not None else 'never'} |"
            )
    return rows


def _row(i: int):
    return lambda: _sheet_rows()[i]


def _rows156() -> list[str]:
    rows = []
    moves = list(_f()["at_15_6"].values())
    pairs = [("paper's values", moves[0]["default"])]
    pairs += [(f"{LABEL[a['parameter']]} = {_g(a['end_value'])}{UNIT[a['parameter']]}", a["end"]) for a in moves]
    for lab, r in pairs:
        m = r.get("motion", {})
        rows.append(
            f"| {lab} | {'stable' if r['stable'] else 'unstable'} | {r['multipliers_abs'][0]:.4f} | "
            f"{_g(m.get('net_drift_m', float('nan')), 2)} m | {m.get('global_motion', '—')} |"
        )
    return rows


def _row156(i: int):
    return lambda: _rows156()[i]


def _n_rows(fn) -> int:
    return len(fn()) if (ROOT / FILE).exists() else 0


QUOTES = [
    (PAGE, lambda: f"{_f()['located_fold_omega']:.4f} rad/s"),
    (PAGE, _b12),
    (PAGE, _de),
    (PAGE, _kr),
    (PAGE, _q_crossing),
    (PAGE, _mu_low),
    *[(PAGE, _row(i)) for i in range(_n_rows(_sheet_rows))],
    *[(PAGE, _row156(i)) for i in range(_n_rows(_rows156))],
    (README, _q_crossing),
]


def _grad() -> str:
    d = _f()
    g = d["gradient_at_paper_values"]["domega_fold_d"]
    c = d["curves"]
    return (
        f"B12: {g['B12'] * 1e-4:.3f} (curve secant {c['B12']['domega_dp_at_start'] * 1e-4:.3f}) rad/s per 1e-4 kg m²; "
        f"derivative_exact: {g['derivative_exact']:.4e} ({c['derivative_exact']['domega_dp_at_start']:.4e}) rad/s; "
        f"k_r: {g['k_r']:.4f} ({c['k_r']['domega_dp_at_start']:.4f}) rad/s; q_π: {g['q_pi']:.2f} rad/s per m; "
        f"μ: {g['mu']:.4f} rad/s"
    ).replace("e-0", "e-")


def _walk(i: int):
    return lambda: _walk_text(_f()["walks_at_14"][i])


def _walk_text(w: dict) -> str:
    ok = [p["B12"] for p in w["path"] if p["status"] == 0 and p["stable"]]
    last = w["path"][-1]

    def e(x: float) -> str:
        return format(x, ".3e").replace("e-0", "e-")

    return (
        f"stable at every step up to B12 = {e(max(ok))} kg m² (largest multiplier "
        f"{max(p['multipliers_abs'][0] for p in w['path'] if p['status'] == 0):.4f})"
        + (f", Newton fails at the next, B12 = {e(last['B12'])} kg m²" if last["status"] != 0 else "")
    )


QUOTES += [(PAGE, _grad)]
QUOTES += [(PAGE, _walk(i)) for i in range(len(_f().get("walks_at_14", [])) if (ROOT / FILE).exists() else 0)]
