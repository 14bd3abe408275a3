"""Quoted texts of the contact-law pages (docs/contact-laws.md and notebook 03's text), each computed from
docs/contact/summary.json (``scripts/contact_study.py``); more entries of the same pages are in ``studies.py``.

Each entry is (document, function returning the quoted text); ``SETTINGS`` lists (document, phrase) for numbers
that are inputs, not results.
"""

from __future__ import annotations

from .files import _json

CL = "docs/contact-laws.md"
NB03 = "notebooks/03_contact_laws.ipynb"


def _s() -> dict:
    return _json("docs/contact/summary.json")


def _e(x: float, digits: int = 1) -> str:
    """6.6e-11 as the docs write it (no leading zero in the exponent)."""
    m, e = f"{x:.{digits}e}".split("e")
    return f"{m}e{int(e)}"


def _limit(prefix: str) -> float:
    """The largest deviation from an exact limit over the study's spins (limits in summary.json)."""
    return max(abs(v) for k, v in _s()["limits"].items() if k.startswith(prefix))


def _cal_row(name: str, label: str, keys: tuple[str, ...]) -> str:
    c = _s()["calibration"][name]
    fmt = {"b_Ts": ".4f", "b_Ms": ".4f", "m_Ts": ".3f", "m_Ms": ".3f", "S0": ".3f", "S2": ".4f", "S3": ".4f"}
    fitted = ", ".join(f"{k} {format(c['values'][k], fmt[k])}" for k in keys)
    return f"| {label} | {fitted} | {c['rms']:.4f} | {c['max_err']:.3f} |"


def _map_max(law: str) -> list[float]:
    """The largest error of a law over the two error maps (no rolling, rolling)."""
    return [m[law]["max"] for m in _s()["error_maps"].values()]


def _norr() -> list[float]:
    return [r["error"] for rows in _s()["ladder"]["results"].values() for r in rows if r["rung"].endswith(":norr")]


def _g(x: float, nd: int) -> str:
    return f"{round(x, nd):g}"


QUOTES = [
    # ---------------------------------------------------------------- docs/contact-laws.md
    (
        CL,
        lambda: "pure spin |M_s − 4E S2 sign ω_s| = {}; pure sliding |T − v_s/|v_s|| = {}; slopes at v_s = 0 "
        "|∂T_sx/∂v_sx − 4G S0/|ω_s|| ≤ {}, |∂T_sy/∂v_sy − 4H S0/|ω_s|| ≤ {}".format(
            _e(_limit("pure spin")), _e(_limit("pure sliding")), _e(_limit("dT_sx")), _e(_limit("dT_sy"), 0)
        ),
    ),
    (CL, lambda: _cal_row("generalised_pade", "generalised Padé (S_i Hertz)", ("b_Ts", "b_Ms", "m_Ts", "m_Ms"))),
    (CL, lambda: _cal_row("generalised_pade+S", "generalised Padé (+ S_i fitted)", ("S0", "S2", "S3"))),
    (CL, lambda: _cal_row("pade", "Padé (S_i Hertz)", ("b_Ts", "b_Ms"))),
    (CL, lambda: _cal_row("pade+S", "Padé (+ S_i fitted)", ("S0", "S2", "S3"))),
    (
        CL,
        lambda: "constants (with the paper's S_i) are {:.2f} RMS from the Hertz law (error maps, last panel)".format(
            _s()["error_maps"]["d0"]["gen. Pade (paper constants)"]["rms"]
        ),
    ),
    (CL, lambda: f"Rolling resistance matters everywhere (:norr errors {_g(min(_norr()), 2)}–{_g(max(_norr()), 2)})"),
    (CL, lambda: "(our b_Ts = {:.4f} is far from the paper's 0.5305)".format(_s()["calibration"]["generalised_pade"]["values"]["b_Ts"])),
    # ---------------------------------------------------------------- notebooks/03_contact_laws.ipynb
    (
        NB03,
        lambda: "a maximum error of about {}–{} (in units of $\\mu N$), Padé about {}. Coulomb + spin ignores the Contensou "
        "coupling and is off by up to ~{}–{} where".format(
            f"{min(_map_max('gen. Pade (Hertz-cal.)')):.2f}",
            f"{max(_map_max('gen. Pade (Hertz-cal.)')):.2f}",
            "{:.1f}".format(*{round(x, 1) for x in _map_max("Pade (Hertz-cal.)")}),
            _g(min(_map_max("Coulomb + spin")), 1),
            _g(max(_map_max("Coulomb + spin")), 1),
        ),
    ),
    (
        NB03,
        lambda: "stays within ~{:.2f} $\\mu N$ of the integral law".format(_s()["calibration"]["generalised_pade"]["max_err"]),
    ),
]

SETTINGS = [
    # Kane & Levinson's rattleback (their data, our sign conventions), the spin-reversal scene's inputs and the
    # ladder's tolerance
    (CL, "h = 0.01 m puts C *between O and the flat top* (our k3 = +0.01"),
    (CL, "D = −2e-5 is the inertia-*tensor* entry (our B12 = +2e-5"),
    (CL, "With C *below* O (k3 = −0.01)"),
    (CL, "small patch â = 1 mm, k_r = 0.05"),
    (CL, "| **recommended** (tol 0.05) |"),
    (
        NB03,
        "Kane & Levinson's data: semi-axes 0.20, 0.03, 0.02 m, centre of mass $h = 0.01$ m off the geometric centre, "
        "per-unit-mass inertia $A = 2\\cdot10^{-4}$, $B = 1.6\\cdot10^{-3}$, $C = 1.7\\cdot10^{-3}$",
    ),
]
