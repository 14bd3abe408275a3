"""XLA compiler options of the programs jaxcelt compiles itself.

The lane pool (``jaxcelt.ensemble``): on a CPU, XLA's LLVM backend emits 256-bit vectors
(4 doubles) even where the CPU has 512-bit registers (AVX-512). ``xla_cpu_prefer_vector_width=512``
lets it use all eight lanes of a register: on this project's AVX-512 CPU the 400 x 300 sweep
stops at invalid states 1.18× as fast and integrates every lane on 1.12× as fast
(``benchmarks/vector_width.py`` -> ``docs/bifurcation/vector_width.json``). On a CPU without
AVX-512 the option changes nothing (LLVM caps the width at what the CPU has; checked with
``--xla_cpu_max_isa=AVX2``: the same program, the same steps). Wider vectors cost compilation
time, and a narrow pool gains nothing from them (the main job's pool of 30 slots per device ran
no faster with them and compiled longer), so only pools of at least `WIDE_VECTORS_MIN_SLOTS`
slots per device get them (the 400 x 300 sweep has 96), together with the contact law's
``wide_batch`` form (`jaxcelt.physics.contact.laws.AbstractContactLaw.wide_batch`: the vectorised logarithm,
which also costs compilation; `is_wide_pool`). The Lyapunov stage and the fit,
compiled with the loop emitters below, do not gain from them and go without.

The programs that hold a differentiated ODE solve:

On a CPU, XLA's older loop emitters (``xla_cpu_use_fusion_emitters=False``) compile a program
holding a diffrax solve and its forward-mode tangents in about 60 % of the time of the default
fusion emitters, and it runs as fast or faster (``benchmarks/fit_compile_parts.py`` ->
``docs/fit/compile_parts.json``; ``benchmarks/compile_options.py`` ->
``docs/performance/compile_options.json``). Results agree to rounding (another compiled
program). Other platforms get XLA's defaults.

The lane pool's first and last programs (`jaxcelt.ensemble.lane_programs.pool_start`, ``pool_outputs``) run once per
chunk of lanes, so their compile time is all they cost: on a CPU they get the loop emitters too (their step, the
stepper's initialisation, is the same arithmetic; see docs/internals/compilation.md for the main job's compile time
with and without). The pool's stepping program keeps the default emitters or the wide vectors above: it is where
the run time goes.

JAX takes compiler options only on a top-level ``jax.jit``. Programs never called inside another trace get them
directly: the fit's evaluation program and its optimisers' step programs (small programs with a host callback, which
gain nothing from the fusion emitters either), the sweep's Lyapunov stage (`jit_per_platform`). The programs of
periodic orbits and their continuation (`jaxcelt.periodic_orbit`, the arclength stepper's tangent, corrector and
multipliers, the curves' start) and of the Lyapunov spectrum hold a solve with its forward-mode tangents too, but are
public functions or their parts, which users may call inside their own ``jit``: `jit_anywhere` gives them the
options at top level and the plain program inside another trace (``benchmarks/orbit_compile.py``). Not
`jaxcelt.simulate`: a plain solve, whose run time the fusion emitters may serve better.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import equinox as eqx
import jax

LOOP_EMITTERS = {"xla_cpu_use_fusion_emitters": False}
WIDE_VECTORS = {"xla_cpu_prefer_vector_width": 512}
WIDE_VECTORS_MIN_SLOTS = 64


def compiler_options(platform: str) -> dict | None:
    """The options for a program compiled for ``platform`` (``"cpu"``, ``"gpu"``, ...) that holds a differentiated
    solve or runs once per job (the loop emitters on a CPU)."""
    return dict(LOOP_EMITTERS) if platform == "cpu" else None


def jit_per_platform(fn: Callable) -> Callable[[str], Callable]:
    """``fn`` as one ``equinox.filter_jit`` program per kind of platform, each compiled with `compiler_options` of
    its platform: ``jit_per_platform(fn)(platform)`` is the jitted ``fn`` to call on ``platform``. Only for programs
    called at top level (JAX takes compiler options there alone)."""
    jits = _jits_per_kind(fn, eqx.filter_jit)
    return lambda platform: jits["cpu" if platform == "cpu" else "other"]


def _jits_per_kind(fn: Callable, jit: Callable) -> dict[str, Callable]:
    """``jit(fn)`` with the `compiler_options` of each kind of platform ("cpu", "other")."""
    return {kind: jit(fn, compiler_options=compiler_options(kind)) for kind in ("cpu", "other")}


def jit_anywhere(fn: Callable, *, filter_jit: bool = True) -> Callable:
    """``fn`` jitted (``equinox.filter_jit``, or ``jax.jit`` with ``filter_jit=False``) with `compiler_options` of
    the default backend wherever JAX allows them, for programs that are also public functions or their parts.

    Called at top level (or under ``jax.vmap``), the program is compiled with the options; called inside another
    trace (a user's ``jax.jit``, a scan, ...), where JAX refuses compiler options on a nested jit, it is the plain
    jitted ``fn`` and the outer program's options apply. The same values either way, to rounding (another compiled
    program). Inside another trace the function is traced twice (the first attempt stops at JAX's refusal), once per
    compilation of the outer program. ``.lower`` lowers the top-level program."""
    jits = _jits_per_kind(fn, eqx.filter_jit if filter_jit else jax.jit)

    def top() -> Callable:
        return jits["cpu" if jax.default_backend() == "cpu" else "other"]

    @functools.wraps(fn)
    def call(*args: Any, **kwargs: Any) -> Any:
        program = top()
        if program is jits["other"]:  # no options: nothing to fall back from
            return program(*args, **kwargs)
        try:
            return program(*args, **kwargs)
        except ValueError as err:
            # JAX: "`compiler_options` can only be passed to top-level `jax.jit`" (raised while staging, before any
            # computation); inside another trace the options of the outermost program apply
            if "compiler_options" not in str(err) or "top-level" not in str(err):
                raise
            return jits["other"](*args, **kwargs)

    call.lower = lambda *args, **kwargs: top().lower(*args, **kwargs)  # type: ignore[attr-defined]
    return call


def is_wide_pool(platform: str, slots: int) -> bool:
    """Whether a lane pool of ``slots`` slots per device on ``platform`` gets wide vectors (and its
    contact law's `wide_batch` form: the vectorised logarithm, which costs compilation)."""
    return platform == "cpu" and slots >= WIDE_VECTORS_MIN_SLOTS


def pool_compiler_options(platform: str, slots: int) -> dict | None:
    """The options of the lane pool's program compiled for ``platform`` with ``slots`` slots per device."""
    return dict(WIDE_VECTORS) if is_wide_pool(platform, slots) else None
