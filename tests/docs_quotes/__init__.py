"""The quoted-number registry. Every module here defines ``QUOTES``, a list of (document, function returning the
quoted text computed from a committed result file), and may define ``SETTINGS``, a list of (document, phrase)
for numbers that are inputs rather than results (a phrase as written in the document, containing the number).
One module per group of pages, so that pages can be edited apart; ``QUOTES`` and ``SETTINGS`` below gather all
modules, in module order. ``scripts/results_index.py`` counts every measured number the site quotes against them."""

from __future__ import annotations

import importlib
import pkgutil

QUOTES: list = []
SETTINGS: list = []
for _m in sorted(m.name for m in pkgutil.iter_modules(__path__) if m.name != "files"):
    _mod = importlib.import_module(f"{__name__}.{_m}")
    QUOTES += _mod.QUOTES
    SETTINGS += getattr(_mod, "SETTINGS", [])
