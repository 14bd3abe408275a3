"""Argument types shared by the commands: each rejects bad input with a message naming what is wrong.

An ``argparse`` type raising `argparse.ArgumentTypeError` is reported by the parser as
``jaxcelt <command>: error: argument --name: <message>`` (one line, exit status 2, see `jaxcelt.cli`);
a `UsageError` (a `ValueError`) raised inside a command is reported the same way.
"""

from __future__ import annotations

import argparse
import math


class UsageError(ValueError):
    """Bad command-line input found by a command itself (the CLI prints it as one error line)."""


def _parse_number(s: str, kind=float):
    """``s`` as a finite float or an int; ValueError saying what was expected."""
    try:
        v = kind(s.strip())
    except ValueError:
        raise ValueError(f"expected {'an integer' if kind is int else 'a number'}, got {s!r}") from None
    if kind is float and not math.isfinite(v):
        raise ValueError(f"expected a finite number, got {s!r}")
    return v


def _number(s: str, kind=float):
    try:
        return _parse_number(s, kind)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def finite_float(s: str) -> float:
    """A finite number."""
    return _number(s)


def positive_float(s: str) -> float:
    """A finite number > 0."""
    v = _number(s)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {s!r}")
    return v


def nonnegative_int(s: str) -> int:
    """An integer >= 0."""
    v = _number(s, int)
    if v < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {s!r}")
    return v


def positive_int(s: str) -> int:
    """An integer >= 1."""
    v = _number(s, int)
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {s!r}")
    return v


def floats(n: int):
    """A type for ``n`` comma-separated finite numbers."""

    def parse(s: str) -> list[float]:
        vals = [_number(x) for x in s.split(",")]
        if len(vals) != n:
            raise argparse.ArgumentTypeError(f"expected {n} comma-separated numbers, got {s!r}")
        return vals

    parse.__name__ = f"{n} numbers"
    return parse


def parse_range(s: str):
    """``START:STOP:COUNT`` (COUNT evenly spaced values, ends included) or a list ``a,b,c``; ``''`` is empty.

    Returns a NumPy array of finite numbers; ValueError saying what is wrong otherwise. The one
    parser of value ranges (the commands' `value_range`; formerly also ``jaxcelt.sweep.parse_range``)."""
    import numpy as np

    if ":" in s:
        parts = s.split(":")
        if len(parts) != 3:
            raise ValueError(f"expected START:STOP:COUNT, got {s!r}")
        a, b, n = _parse_number(parts[0]), _parse_number(parts[1]), _parse_number(parts[2], int)
        if n < 1:
            raise ValueError(f"COUNT must be >= 1, got {s!r}")
        return np.linspace(a, b, n)
    return np.array([_parse_number(x) for x in s.split(",") if x.strip()], dtype=float)


def value_range(s: str):
    """`parse_range` as an argument type: ``START:STOP:COUNT`` or a list ``a,b,c`` -> a NumPy array."""
    try:
        return parse_range(s)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def override(s: str) -> tuple[str, float]:
    """``NAME=VALUE`` for ``--set`` (the name is checked by `jaxcelt.CeltParams`)."""
    if "=" not in s:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {s!r}")
    k, v = s.split("=", 1)
    if not k.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {s!r}")
    return k.strip(), _number(v)


def add_set_flag(p: argparse.ArgumentParser, help: str = "override any CeltParams field, repeatable") -> None:
    """The ``--set NAME=VALUE`` flag (repeatable; read it with `overrides`)."""
    p.add_argument("--set", action="append", type=override, default=[], metavar="NAME=VALUE", help=help)


def overrides(items: list[tuple[str, float]]) -> dict[str, float]:
    """The ``--set`` pairs as keyword arguments for `jaxcelt.CeltParams.paper` (the last one wins)."""
    return dict(items)
