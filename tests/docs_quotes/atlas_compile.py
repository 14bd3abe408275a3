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
    """A part's medians over the fresh processes."""
    p = _d()["medians"][key]
    return f"| {name} | {p['first_s']:.1f} | {p['second_s']:.1f} | {p['compile_s']:.1f} |"


def reps() -> str:
    return f"medians over {len(_d()['reps'])} fresh processes"


def programs() -> str:
    g = _d()["medians"]["logged_first_run"]
    return (
        f"The first run compiles {g['programs_compiled']:.0f} programs (medians: XLA {g['xla_s_all']:.1f} s, tracing "
        f"{g['tracing_s_all']:.1f} s, lowering {g['lowering_s_all']:.1f} s"
    )


def top() -> str:
    return ", ".join(f"`{n}` {v:.1f} s" for n, v in _d()["reps"][0]["runs"][0]["logged"]["top5_xla"])


def second() -> str:
    g = _d()["reps"][0]["runs"][1]["logged"]
    n, v = g["top5_xla"][0]
    return f"The second run compiles {g['programs_compiled']} small program again (`{n}`, {v:.1f} s)"


def load() -> str:
    return f"load average {_d()['reps'][0]['load_average_at_start'][0]:.1f} at the start"


QUOTES = [
    *[(PAGE, (lambda k=k, n=n: part_row(k, n))) for k, n in PARTS],
    (PAGE, reps),
    (PAGE, programs),
    (PAGE, top),
    (PAGE, second),
    (PAGE, load),
]
