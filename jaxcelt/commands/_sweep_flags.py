"""The flags ``jaxcelt bifurcation`` and ``jaxcelt map`` share, and what they turn into.

`add_sweep_flags` adds the sampling, solver and execution flags (``--transient`` ..
``--stop-on-invalid``) in one place; each command gives its own defaults and help texts where
they differ. `lane_devices` turns ``--host-devices``/``--host-processes`` into a sweep's
``devices``, `run_settings` records the settings in the command's ``summary.json``.
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping

from jaxcelt.commands.args import (
    UsageError,
    add_set_flag,
    floats,
    nonnegative_int,
    positive_float,
    positive_int,
)

ENGINES = ("auto", "pool", "kernel")
"""`jaxcelt.ensemble.ENGINES`, written out: the CLI parses its arguments before it imports JAX"""
SWEEP_SOLVERS = ("Tsit5", "Dopri5", "Dopri8")  # names in jaxcelt.integrate.solvers.SOLVERS

_ENGINE_HELP = (
    "how lanes are stepped: auto (the lane kernel on a GPU, the pool elsewhere), pool, or kernel "
    "(off a GPU it runs interpreted: for tests, slow)"
)


def add_sweep_flags(
    p: argparse.ArgumentParser,
    *,
    lyapunov_default: int,
    chunk_size_default: int,
    dtype: bool,
    help: Mapping[str, str],
) -> None:
    """``--transient`` .. ``--stop-on-invalid`` (and ``--dtype`` if ``dtype``), in this order.

    ``help``: the command's own help texts of ``lyapunov``, ``set``, ``solver``, ``chunk-size``,
    ``width``, ``host-devices`` and ``stop-on-invalid``."""
    p.add_argument("--transient", type=nonnegative_int, default=100, help="transient forcing periods discarded")
    p.add_argument("--sample", type=positive_int, default=30, help="stroboscopic samples (periods) kept")
    p.add_argument("--lyapunov", type=nonnegative_int, default=lyapunov_default, help=help["lyapunov"])
    add_set_flag(p, help["set"])
    p.add_argument("--omega0", type=floats(3), default="0,0,0", help="initial omega (body) [rad/s]")
    p.add_argument("--solver", default="Tsit5", choices=SWEEP_SOLVERS, help=help["solver"])
    p.add_argument("--rtol", type=positive_float, default=1e-8)
    p.add_argument("--atol", type=positive_float, default=1e-10)
    p.add_argument("--max-steps", type=positive_int, default=1_000_000)
    if dtype:
        p.add_argument("--dtype", default="float64", choices=("float64", "float32"),
                       help="the pool's arithmetic (float32: faster on GPUs; use --rtol >= 1e-6)")  # fmt: skip
    p.add_argument("--chunk-size", type=positive_int, default=chunk_size_default, help=help["chunk-size"])
    p.add_argument("--width", type=positive_int, default=None, help=help["width"])
    p.add_argument("--engine", default="auto", choices=ENGINES, help=_ENGINE_HELP)
    p.add_argument("--host-devices", default="auto", help=help["host-devices"])
    add_host_processes(p)
    p.add_argument(
        "--stop-on-invalid", action=argparse.BooleanOptionalAction, default=True, help=help["stop-on-invalid"]
    )


def add_host_processes(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--host-processes",
        default=None,
        help="CPU only: run the lanes in this many worker processes, each pinned to a core with one JAX device "
        "('auto' = number of CPU cores; default: off, one process with --host-devices). The workers share no "
        "thread pool; each compiles its own programs. Replaces --host-devices",
    )


def lane_devices(args):
    """The sweep's ``devices``: a `jaxcelt.HostProcesses` with --host-processes (this process then keeps
    one JAX device), else None (all local devices, as --host-devices split the CPU)."""
    if args.host_processes is None:
        _set_host_devices(args.host_devices)
        return None
    spec = args.host_processes
    try:
        n = spec if spec == "auto" else int(spec)
    except ValueError:
        n = 0
    if n != "auto" and n < 1:
        raise UsageError(f"argument --host-processes: must be an integer >= 1 or 'auto', got {spec!r}")
    if getattr(args, "engine", "auto") == "kernel":
        raise UsageError("argument --engine: 'kernel' steps lanes on a GPU; --host-processes starts CPU workers")
    _set_host_devices("1")
    from jaxcelt.ensemble import HostProcesses

    return HostProcesses(n)


def _set_host_devices(spec: str) -> int:
    """Ask JAX for ``spec`` CPU devices (before the backend starts); returns the count asked for."""
    import os

    import jax

    try:
        n = (os.cpu_count() or 1) if spec == "auto" else int(spec)
    except ValueError:
        n = 0
    if n < 1:
        raise UsageError(f"argument --host-devices: must be an integer >= 1 or 'auto', got {spec!r}")
    try:
        jax.config.update("jax_num_cpu_devices", n)
    except RuntimeError:  # backend already started (e.g. called from Python after JAX work)
        pass
    return n


def run_settings(args, wall: float, devices=None) -> dict:
    """The settings and wall time of a sweep command (``bifurcation``, ``map``) for its summary.json."""
    import jax

    from jaxcelt.ensemble import DEFAULT_WIDTH

    return {
        "transient_periods": args.transient,
        "sample_periods": args.sample,
        "lyapunov_periods": args.lyapunov,
        "solver": args.solver,
        "rtol": args.rtol,
        "atol": args.atol,
        "stop_on_invalid": bool(args.stop_on_invalid),
        "devices": [str(d) for d in jax.local_devices()] if devices is None else repr(devices),
        "chunk_size": args.chunk_size,
        "width_per_device": args.width or DEFAULT_WIDTH,
        "engine": args.engine,
        "wall_seconds_including_compile": round(wall, 2),
    }
