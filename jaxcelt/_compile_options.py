"""XLA compiler options of the programs that hold a differentiated ODE solve.

On a CPU, XLA's older loop emitters (``xla_cpu_use_fusion_emitters=False``) compile a program
holding a diffrax solve and its forward-mode tangents in about 60 % of the time of the default
fusion emitters, and it runs as fast or faster (``benchmarks/fit_compile_parts.py`` ->
``docs/fit/compile_parts.json``; ``benchmarks/compile_options.py`` ->
``docs/performance/compile_options.json``). Results agree to rounding (another compiled
program). Other platforms get XLA's defaults.

JAX takes compiler options only on a top-level ``jax.jit``, so they are given to programs that
are never called inside another trace: the fit's evaluation program and the sweep's Lyapunov
stage (not `jaxcelt.simulate`, which users call inside their own ``jit``, ``vmap`` and ``grad``).
"""

from __future__ import annotations

LOOP_EMITTERS = {"xla_cpu_use_fusion_emitters": False}


def compiler_options(platform: str) -> dict | None:
    """The options for a program compiled for ``platform`` (``"cpu"``, ``"gpu"``, ...)."""
    return dict(LOOP_EMITTERS) if platform == "cpu" else None
