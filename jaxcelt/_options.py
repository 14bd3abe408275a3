"""How a function combines its options object with single keywords: the one rule of every options object
(`jaxcelt.SweepOptions`, `jaxcelt.ShootingOptions`, `jaxcelt.FitOptions`).

``options=`` (or the function's own defaults) is the base; each keyword given replaces that one field. A keyword
that is no field is a TypeError naming it (as Python reports an unknown keyword argument); an ``options`` of another
type is a ValueError.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, TypeVar

__all__ = ["with_keywords"]

T = TypeVar("T")


def with_keywords(cls: type[T], options: T | None, defaults: T, keywords: Mapping[str, Any], *, caller: str) -> T:
    """``options`` (``defaults`` when None) with each of ``keywords`` replacing its field; ``caller`` names the
    function in errors."""
    fields = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    unknown = sorted(set(keywords) - fields)
    if unknown:
        raise TypeError(f"{caller}() got unexpected keyword argument(s) {', '.join(map(repr, unknown))}")
    if options is None:
        options = defaults
    elif not isinstance(options, cls):
        raise ValueError(f"'options' must be a {cls.__name__}, got {type(options).__name__}")
    return dataclasses.replace(options, **keywords) if keywords else options  # type: ignore[type-var]
