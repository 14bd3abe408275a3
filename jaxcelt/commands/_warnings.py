"""Library warnings on the command line: one line each, ``jaxcelt <command>: warning: ...``."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator


@contextlib.contextmanager
def one_line_warnings(command: str) -> Iterator[None]:
    """Within the block, every warning prints as one line (no source line, no traceback)."""

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"jaxcelt {command}: warning: {message}", flush=True)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = show
        yield
