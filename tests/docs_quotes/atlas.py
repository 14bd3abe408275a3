"""Quoted texts of the how-to page "Draw the atlas over the forcing frequency" (``jaxcelt atlas`` at its default size
-> docs/atlas/atlas.json), each computed from that file.

Each entry is (document, function returning the quoted text); ``SETTINGS`` lists (document, phrase) for numbers
that are inputs.
"""

from __future__ import annotations

from .files import _json

PAGE = "docs/how-to/atlas.md"
FILE = "docs/atlas/atlas.json"
READ_OFF = ("14", "15.6", "17", "19")


def _d() -> dict:
    return _json(FILE)


def _m(x: float, fmt: str) -> str:
    """A number with a unicode minus."""
    return format(x, fmt).replace("-", "−")


def _att(a: dict) -> str:
    name = f"period-{a['period']}" if a["kind"] == "periodic" else a["kind"]
    parts = []
    if a["kind"] == "periodic" and a.get("multiplier_max") is not None:
        parts.append(f"\\|μ\\| {a['multiplier_max']:.4f}")
    if a.get("lyapunov") is not None:
        parts.append(f"λ₁ {_m(a['lyapunov'], '.2f')} ± {a['lyapunov_stderr']:.2f}")
    sp = a.get("spectrum") or [None, None]
    if sp[0] is not None and sp[1] is not None:
        parts.append(f"spectrum {_m(sp[0], '.2f')}, {_m(sp[1], '.2f')}")
    extra = f" ({'; '.join(parts)})" if parts else ""
    return f"#{a['id']} {name} {a['fraction']:.3f} ± {a['fraction_stderr']:.3f}{extra}"


def read_off_row(w: str) -> str:
    r = _d()["read_off"][w]
    atts = "; ".join(_att(a) for a in r["attractors"]) or "none"
    return f"| {w} | {atts} | {r['tipping_over']:.3f} ± {r['tipping_over_stderr']:.3f} |"


def branch_points() -> str:
    """The bifurcation points of the first branch (the mirror branch has the same ones)."""
    b = _d()["branches"][0]
    names = {"fold": "fold", "period-doubling": "period doubling", "Neimark-Sacker": "Neimark–Sacker point"}
    return " and a ".join(f"{names[x['kind']]} at {x['value']:.3f} rad/s" for x in b["bifurcations"])


def times() -> str:
    s = _d()["seconds"]
    return (
        f"{s['command']:.0f} s in all: continuation {s['continuation']:.0f} s, brute force {s['brute_force']:.0f} s, "
        f"branch {s['branches']:.0f} s, spectrum {s['spectrum']:.0f} s"
    )


def load() -> str:
    p = _d()["provenance"]
    return f"load average {p['load_average_at_start'][0]:.1f} at the start"


QUOTES = [
    *[(PAGE, (lambda w=w: read_off_row(w))) for w in READ_OFF],
    (PAGE, branch_points),
    (PAGE, times),
    (PAGE, load),
]

SETTINGS = [
    (PAGE, "tilts −0.1, 0, 0.1 rad"),
    (PAGE, "the spectrum over 20"),
    (PAGE, "from rest at ψ₀ = 157.5°"),
]


def _row(w: str) -> dict:
    return _d()["read_off"][w]


def floquet_rate() -> str:
    """log|mu_max| / T of the period-1 pair at 15.6 rad/s, beside the spectrum's lambda_1 there."""
    import math

    atts = [a for a in _row("15.6")["attractors"] if a["kind"] == "periodic"]
    rate = math.log(atts[0]["multiplier_max"]) * 15.6 / (2 * math.pi)
    lam = ", ".join(_m(a["spectrum"][0], ".2f") for a in atts)
    return f"log\\|μ_max\\|/T = {_m(rate, '.3f')} s⁻¹ of their orbits, where the spectrum over 20 periods gives {lam}"


def continued_orbit() -> str:
    """The largest |mu| of the pair's orbit continued by Newton at 17 and 19 rad/s."""
    out = []
    for w in ("17", "19"):
        mus = [a["orbit_multiplier_max"] for a in _row(w)["attractors"] if a.get("orbit_multiplier_max") is not None]
        out.append(f"{max(mus):.4f} at {w} rad/s")
    return "largest \\|μ\\| " + " and ".join(out)


def reference_branch() -> str:
    b = _json("docs/orbits/branches.json")["branches"]
    bif = next(iter(b.values()))["branch"]["bifurcations"]
    v = {x["kind"]: x["value"] for x in bif}
    return f"fold {v['fold']:.4f}, Neimark–Sacker {v['Neimark-Sacker']:.4f} rad/s there"


QUOTES += [(PAGE, floquet_rate), (PAGE, continued_orbit), (PAGE, reference_branch)]
