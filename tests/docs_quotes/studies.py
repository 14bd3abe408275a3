"""Quoted texts of the numerical-studies pages (docs/internals/studies.md, docs/contact-laws.md and notebooks 03
and 05), each computed from the committed result file it comes from; SETTINGS lists the inputs they quote."""

from __future__ import annotations

from .files import _json

CL = "docs/contact-laws.md"
NB03 = "notebooks/03_contact_laws.ipynb"
ST = "docs/internals/studies.md"


def _contact() -> dict:
    return _json("docs/contact/summary.json")


def _ladder(scene: str) -> dict:
    """The ladder's results of one scene of scripts/contact_study.py, by rung."""
    return {r["rung"]: r for r in _contact()["ladder"]["results"][scene]}


def _ladder_row(rung: str) -> str:
    """A row of the scene table as jaxcelt.studies.ladder.results_table prints it."""
    cells = []
    for scene in _contact()["ladder"]["results"]:
        r = _ladder(scene)[rung]
        flag = "" if r["status"] == 0 and r["valid"] else " (invalid)" if r["status"] == 0 else f" (status {r['status']})"
        cells.append(f"{r['error']:.1e} / {r['run_s']:.2f} s / {r['steps']}{flag}")
    return f"| {rung} | " + " | ".join(cells) + " |"


def _kl(w3: str) -> dict:
    return _contact()["kane_levinson"][f"w3(0)={w3}"]


def _cal(name: str) -> dict:
    return _contact()["calibration"][name]


def _norr_range() -> tuple[float, float]:
    errs = [r["error"] for s in _contact()["ladder"]["results"] for n, r in _ladder(s).items() if n.endswith(":norr")]
    return 100 * min(errs), 100 * max(errs)


def _speedup_gp() -> tuple[float, float]:
    """Run time of the integral law over the generalised Padé law's, per scene: the smallest and the largest."""
    x = [_ladder(s)["integral"]["run_s"] / _ladder(s)["generalised_pade"]["run_s"] for s in _contact()["ladder"]["results"]]
    return min(x), max(x)


def _uncoupled_steps() -> tuple[float, float]:
    """Steps of Coulomb and Coulomb + spin over the generalised Padé law's on the fixed-table scenes."""
    x = [
        _ladder(s)[law]["steps"] / _ladder(s)["generalised_pade"]["steps"]
        for s in ("spin_reversal", "fast_spin")
        for law in ("coulomb", "coulomb_spin")
    ]
    return min(x), max(x)


QUOTES = [
    # docs/contact-laws.md (scripts/contact_study.py -> docs/contact/summary.json)
    (
        CL,
        lambda: (
            f"the generalisation beats Padé, {_cal('pade')['rms'] / _cal('generalised_pade')['rms']:.1f}× lower RMS with "
            f"the Hertz S_i ({_cal('pade+S')['rms'] / _cal('generalised_pade+S')['rms']:.1f}× when Padé may also bend the S_i"
        ),
    ),
    (CL, lambda: f"Energy drift over 20 s at rtol 1e-12: {_kl('-5.0')['energy_rel_drift_max']:.1e}"),
    (
        CL,
        lambda: (
            f"Then ω3(0) = −5 rad/s reverses (first at t ≈ {_kl('-5.0')['first_reversal_t']:.2f} s, ω3(20 s) = "
            f"{_kl('-5.0')['w3_final']:.2f}) while +5 rad/s never reverses in 20 s (ω3(20 s) = {_kl('5.0')['w3_final']:.2f})"
            if _kl("5.0")["first_reversal_t"] is None
            else "+5 rad/s reverses"
        ),
    ),
    *[(CL, lambda rung=rung: _ladder_row(rung)) for rung in
      ("integral", "generalised_pade", "pade", "coulomb_spin", "coulomb", "generalised_pade:norr", "coulomb:norr", "noslip")],
    (
        CL,
        lambda: (
            f"nothing cheaper than the integral law is within {100 * _contact()['ladder']['tol']:.0f} % for the fast spin "
            f"(generalised Padé {100 * _ladder('fast_spin')['generalised_pade']['errors']['tilt']:.0f} %, tilt amplitude)"
        ),
    ),
    (CL, lambda: f"and {100 * _ladder('fast_spin')['noslip']['error']:.0f} % off on the fast spin"),
    # notebooks/03_contact_laws.ipynb (the same summary.json)
    (
        NB03,
        lambda: (
            f"each step is far cheaper — {_speedup_gp()[0]:.0f}–{_speedup_gp()[1]:.0f}× faster here; it is within "
            f"{100 * _ladder('spin_reversal')['generalised_pade']['error']:.0f} % on the spin reversal and within "
            f"{100 * max(_ladder(s)['generalised_pade']['error'] for s in ('base14', 'base19')):.1f} % on the vibrating base"
        ),
    ),
    (
        NB03,
        lambda: (
            f"are within {100 * _contact()['ladder']['tol']:.0f} % and take the same number of steps"
            if all(_ladder("base19")[law]["error"] <= _contact()["ladder"]["tol"] for law in ("pade", "coulomb"))
            else "not within the tolerance"
        ),
    ),
    (
        NB03,
        lambda: (
            f"spin reversal (Padé {100 * _ladder('spin_reversal')['pade']['error']:.0f} %, Coulomb + spin "
            f"{100 * _ladder('spin_reversal')['coulomb_spin']['error']:.0f} %)"
        ),
    ),
    (
        NB03,
        lambda: (
            f"nothing cheaper is within {100 * _contact()['ladder']['tol']:.0f} % (generalised Padé "
            f"{100 * _ladder('fast_spin')['generalised_pade']['errors']['tilt']:.0f} %, in the tilt amplitude)"
        ),
    ),
    (NB03, lambda: f"rungs are {_norr_range()[0]:.0f}–{_norr_range()[1]:.0f} % off"),
    (
        NB03,
        lambda: (
            f"slower* than the generalised Padé law: {_uncoupled_steps()[0]:.0f}–{_uncoupled_steps()[1]:.0f}× more steps"
        ),
    ),
    (NB03, lambda: f"the stone reverses after about {_kl('-5.0')['first_reversal_t']:.0f} s"),
]

SETTINGS = [
    # the scenes' horizons (jaxcelt.studies.ladder.builtin_scenes) and the simulated span of the no-slip run
    (CL, "ω3(0) = −4 rad/s, 3 s"),
    (CL, "the paper's vibrating base from rest, 1.5 s"),
    (CL, "ω3(0) = +25 rad/s, 1 s"),
    # recommend's tie band (jaxcelt.studies.ladder.recommend)
    (NB03, "laws within 25 % of the fastest count as a tie"),
    (NB03, "over 1.5 s from rest"),
]
