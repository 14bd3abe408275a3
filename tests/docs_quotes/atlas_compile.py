"""Quoted texts of the section "What compilation costs" of the how-to page "Draw the atlas over the forcing
frequency" (benchmarks/atlas_compile.py -> docs/atlas/atlas_compile.json), each computed from that file.

Each entry is (document, function returning the quoted text); ``SETTINGS`` lists (document, phrase) for numbers
that are inputs.
"""

from __future__ import annotations

from .files import _json

PAGE = "docs/how-to/atlas.md"
FILE = "docs/atlas/atlas_compile.json"
PARTS = (("continuation", "continuation"), ("brute_force", "brute force"), ("branches", "branches"),
         ("spectrum", "spectrum"), ("command", "the whole command"))  # fmt: skip


def _d() -> dict:
    return _json(FILE)


def part_row(key: str, name: str) -> str:
    p = _d()["parts"][key]
    return f"| {name} | {p['first_s']:.1f} | {p['second_s']:.1f} | {p['compile_s']:.1f} |"


def _first() -> dict:
    return _d()["runs"][0]["logged"]


def programs() -> str:
    g = _first()
    return (
        f"The first run compiles {g['programs_compiled']} programs (XLA {g['xla_s_all']:.1f} s, tracing "
        f"{g['tracing_s_all']:.1f} s, lowering {g['lowering_s_all']:.1f} s"
    )


def top() -> str:
    return ", ".join(f"`{n}` {v:.1f} s" for n, v in _first()["top5_xla"])


def second() -> str:
    g = _d()["runs"][1]["logged"]
    n, v = g["top5_xla"][0]
    return f"The second run compiles {g['programs_compiled']} small program again (`{n}`, {v:.1f} s)"


def load() -> str:
    return f"load average {_d()['load_average_at_start'][0]:.1f} at the start"


QUOTES = [
    *[(PAGE, (lambda k=k, n=n: part_row(k, n))) for k, n in PARTS],
    (PAGE, programs),
    (PAGE, top),
    (PAGE, second),
    (PAGE, load),
]
