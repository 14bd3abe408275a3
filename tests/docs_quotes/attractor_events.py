"""Quoted texts of the section "Every change of the attractor set" of the how-to page "Continue attractors over a
parameter" (scripts/attractor_events.py -> docs/orbits/attractor_events.json), each computed from that file.

Each entry is (document, function returning the quoted text); ``SETTINGS`` lists (document, phrase) for numbers
that are inputs.
"""

from __future__ import annotations

from .files import _json

PAGE = "docs/how-to/continue-attractors.md"
FILE = "docs/orbits/attractor_events.json"


def _d() -> dict:
    return _json(FILE)


def _kind(s: dict | None) -> str:
    if s is None:
        return "—"
    name = f"period-{s['period']}" if s["kind"] == "periodic" else s["kind"]
    return f"{name} {s['fraction']:.3f}"


def event_row(j: int) -> str:
    """One row of the table of changes."""
    e = _d()["events"][j]
    return (
        f"| {e['from']:g} → {e['to']:g} | #{e['id']} | {e['change']} | {_kind(e['before'])} → {_kind(e['after'])} "
        f"| {e['class']} | {e['explanation']} |"
    )


def spectrum_row(key: str) -> str:
    s = _d()["spectra"][key]
    w, a = key.split("/")
    return (
        f"| {w} | #{a} | {s['lambda1']:.3f} ± {s['lambda1_stderr']:.3f} | {s['lambda2']:.3f} ± {s['lambda2_stderr']:.3f} "
        f"| {s['label']} |"
    ).replace("-", "−")


def long_settings() -> str:
    d = _d()
    return (
        f"run on for {d['long_periods']} more periods (λ₁ over the last {d['long_lyapunov_periods']})"
    )


def counts() -> str:
    c = _d()["classes"]
    return ", ".join(f"{k} {v}" for k, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0])))


def rows() -> list[str]:
    """All rows of the table, in order (for writing the page)."""
    return [event_row(j) for j in range(len(_d()["events"]))]


def _n_events() -> int:
    try:
        return len(_d()["events"])
    except FileNotFoundError:
        return 0


def _spectra() -> list[str]:
    try:
        return sorted(_d()["spectra"])
    except FileNotFoundError:
        return []


QUOTES = [
    *[(PAGE, (lambda j=j: event_row(j))) for j in range(_n_events())],
    *[(PAGE, (lambda k=k: spectrum_row(k))) for k in _spectra()],
    (PAGE, long_settings),
    (PAGE, counts),
]
