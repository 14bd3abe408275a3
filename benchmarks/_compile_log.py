"""What the compile-time benchmarks share (``main_job_compile.py``, ``atlas_compile.py``): the heavy modules a
command imports on its first run (loaded before it, so that only compilation is counted) and the loggers through
which JAX reports its tracing, lowering and XLA compilation times (``jax_log_compiles``)."""

from __future__ import annotations

import importlib
import logging
import time

COMMON_IMPORTS = ("matplotlib.pyplot", "xarray", "h5py", "h5netcdf", "tqdm.auto", "PIL.Image")
"""modules every jaxcelt command with figures and datasets imports"""
JAX_COMPILE_LOGGERS = ("jax._src.dispatch", "jax._src.interpreters.pxla", "jax._src.compiler")


def pre_import(modules) -> float:
    """Import ``modules``; the seconds it took."""
    t = time.perf_counter()
    for mod in modules:
        importlib.import_module(mod)
    return time.perf_counter() - t


def log_compiles(handler: logging.Handler) -> None:
    """Turn on ``jax_log_compiles`` and send JAX's compile messages to ``handler`` only."""
    import jax

    jax.config.update("jax_log_compiles", True)
    for name in JAX_COMPILE_LOGGERS:
        lg = logging.getLogger(name)
        lg.addHandler(handler)
        lg.setLevel(logging.DEBUG)
        lg.propagate = False
