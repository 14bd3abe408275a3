"""Quoted texts of the Lyapunov-spectrum section of the periodic-orbit page (scripts/lyapunov_spectrum_check.py →
docs/orbits/lyapunov_spectrum.json), each computed from that file.

Each entry is (document, function returning the quoted text).
"""

from __future__ import annotations

from .files import _json

ORBITS = "docs/orbits/README.md"


def _s() -> dict:
    return _json("docs/orbits/lyapunov_spectrum.json")


def _lz() -> dict:
    return _s()["lorenz"]


def _ob() -> dict:
    return _s()["orbit_15_6"]


def _m(x: float, fmt: str) -> str:
    """A number as the docs print it: a unicode minus."""
    return format(x, fmt).replace("-", "−")


def _e(x: float, digits: int = 1) -> str:
    """An error as the orbits page prints it: −1.8e-7 (a unicode minus in front, none in the exponent's)."""
    return ("−" if x < 0 else "") + format(abs(x), f".{digits}e").replace("e-0", "e-").replace("e+0", "e+")


def _row(values: list[float]) -> str:
    return " | ".join(_m(v, ".4f") for v in values)


def _lorenz_row() -> str:
    r = _lz()
    lam, se = r["exponents"], r["stderr"]
    cells = " | ".join(f"{_m(x, '.4f')} ± {s:.4f}" for x, s in zip(lam, se))
    return f"| `lyapunov_spectrum`, t = 1000 | {cells} | {_m(r['sum'], '.7f')} |"


def _lorenz_reference_row() -> str:
    r = _lz()
    ref = r["reference"]
    return "| Sprott (2003); trace −(σ + 1 + β) | {} | {:g} | {} | {} |".format(
        _m(ref[0], ".4f"), ref[1], _m(ref[2], ".4f"), _m(r["trace"], ".7f")
    )


def _close_pairs() -> str:
    mu = _ob()["multipliers_abs"]
    return f"the second and third pairs (\\|μ\\| {mu[2]:.4f} and {mu[4]:.4f})"


def _lorenz_diffs() -> str:
    r = _lz()
    return "λ₁ is {:.2f} % and λ₃ {:.3f} % from the reference values; the sum differs from the trace by {}".format(
        100 * r["rel_diff_lambda1"], 100 * r["rel_diff_lambda3"], _e(r["sum_minus_trace"])
    )


def _orbit_rows() -> list[str]:
    r = _ob()
    return [
        f"| log\\|μᵢ\\|/T (`periodic_orbit`) | {_row(r['floquet_exponents'])} |",
        f"| `lyapunov_spectrum`, {r['periods']} periods | {_row(r['exponents'])} |",
    ]


def _orbit_diffs() -> str:
    r = _ob()
    return (
        "the two real multipliers' exponents to {} and {}, the sum of the 8 to {}; the leading complex pair's sum to {}; "
        "each exponent to {:.3f} s⁻¹ at most ({:.1f} / t for t = {:.1f} s)"
    ).format(
        _e(abs(r["real_abs_diff"][0])),
        _e(abs(r["real_abs_diff"][1])),
        _e(abs(r["sum_physical"] - r["sum_floquet"])),
        _e(abs(r["pair_sum_abs_diff"][0])),
        r["max_abs_diff"],
        r["max_abs_diff_times_time"],
        r["time"],
    )


def _liouville() -> str:
    r = _ob()
    return "mean divergence {} s⁻¹ over a period; the sum of the 13 exponents differs from it by {}".format(
        _m(r["mean_divergence"], ".6f"), _e(abs(r["sum_all_13_minus_divergence"]))
    )


def _times() -> str:
    lz, ob = _lz()["seconds"], _ob()["seconds"]
    return (
        "Lorenz {:.1f} s on the first call (compilation included) and {:.1f} s compiled; the orbit's {} + {} periods "
        "{:.1f} s and {:.1f} s"
    ).format(
        lz["first_call_incl_compile"],
        lz["compiled"],
        _ob()["transient_periods"],
        _ob()["periods"],
        ob["first_call_incl_compile"],
        ob["compiled"],
    )


def _load() -> str:
    p = _s()["provenance"]
    return "({}, {} cores, 1-minute load average {:.1f} at the start)".format(
        p["machine"]["cpu"], p["machine"]["cpu_cores"], p["load_average_at_start"][0]
    )


QUOTES = [
    (ORBITS, _lorenz_row),
    (ORBITS, _lorenz_reference_row),
    (ORBITS, _lorenz_diffs),
    (ORBITS, _close_pairs),
    *[(ORBITS, (lambda i=i: _orbit_rows()[i])) for i in range(2)],
    (ORBITS, _orbit_diffs),
    (ORBITS, _liouville),
    (ORBITS, _times),
    (ORBITS, _load),
]
