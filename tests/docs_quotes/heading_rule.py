"""Quotes of the heading rule (status 4) on the max-steps study's lanes (``benchmarks/max_steps_study.py
--lanes-from docs/bifurcation/max_steps_study.json --name heading_rule_study.json``)."""

from __future__ import annotations

from .files import _json

MAXSTEPS = "docs/bifurcation/max-steps.md"
NAMES = {
    "numba_dp5": "numba loop, Dormand–Prince 5(4)",
    "numba_tsit5": "numba loop, Tsitouras 5(4)",
    "jaxcelt_dopri5": "jaxcelt pool, `diffrax.Dopri5`",
    "jaxcelt_tsit5": "jaxcelt pool, `diffrax.Tsit5` (default)",
}


def _counts(file: str, key: str) -> tuple[dict[int, int], float]:
    lanes = _json(f"docs/bifurcation/{file}")["lanes"]
    st = [ln[key][1] for ln in lanes]
    return {s: st.count(s) for s in range(5)}, sum(ln[key][0] for ln in lanes) / 1e6


def rows() -> str:
    out = []
    for key, name in NAMES.items():
        c, steps = _counts("heading_rule_study.json", key)
        out.append(f"| {name} | {c[0]} | {c[4]} | {c[3]} | {c[1]} | {steps:.2f} M |")
    return " ".join(out)


def _lanes() -> int:
    return len(_json("docs/bifurcation/heading_rule_study.json")["lanes"])


QUOTES = [
    (MAXSTEPS, rows),
    (MAXSTEPS, lambda: f"The same {_lanes()} lanes again"),
    (MAXSTEPS, lambda: "jaxcelt's Tsit5 takes {:.2f} M steps on them in all, against {:.1f} M before the rule".format(
        _counts("heading_rule_study.json", "jaxcelt_tsit5")[1], _counts("max_steps_study.json", "jaxcelt_tsit5")[1])),
]
SETTINGS = [(MAXSTEPS, "1 − n2² below 10⁻⁶")]
