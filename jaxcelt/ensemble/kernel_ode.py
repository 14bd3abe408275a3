"""Any ODE's lanes through the lane kernel: `solve_lanes`, every lane from t0 to t1, final states.

The lane kernel (`jaxcelt.ensemble.kernel`) steps the wobblestone's field by default; its step,
controller and loop are model-agnostic: a per-lane field ``f(t, y, args) -> dy/dt`` made of the
elementwise operations that `jaxcelt.ensemble.soa.blockwise` re-expresses on lane blocks runs the
same way, one GPU thread per lane (off a GPU, in Pallas' interpreter). This is the ensemble
problem of GPU ODE benchmarks (many parameter sets, one final state each) and what
``benchmarks/gpu_ensemble.py`` times against diffrax's `jax.vmap` of `diffrax.diffeqsolve`.

The step size starts from Hairer's initial-step heuristic (*Solving ODEs I*, §II.4), the step is
diffrax's controller (`diffrax.PIDController`'s I-control at the given tolerances) as in the
kernel. Status per lane as `jaxcelt.STATUS`: 0 reached t1, 1 max_steps, 3 step size collapsed.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._diffrax_adapter import t1_clip_floor
from jaxcelt._types import Array
from jaxcelt.ensemble.kernel import BLOCK, KERNEL_FIELDS, Segment, flatten_state, kernel_supported, unflatten_state

__all__ = ["solve_lanes"]


def _initial_step(f0: Array, y0: Array, rtol: float, atol: float, span: Array) -> Array:
    scale = atol + jnp.abs(y0) * rtol
    d0 = jnp.sqrt(jnp.mean((y0 / scale) ** 2, axis=-1))
    d1 = jnp.sqrt(jnp.mean((f0 / scale) ** 2, axis=-1))
    h = jnp.where((d0 < 1e-5) | (d1 < 1e-5), 1e-6, 0.01 * d0 / d1)
    return jnp.minimum(h, span)


def solve_lanes(
    field: Callable[[Any, Any, tuple], Any],
    y0: Any,
    args: tuple,
    t0: float,
    t1: float,
    *,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-8,
    max_steps: int = 1_000_000,
    dt0: float | None = None,
    dtype: Any = jnp.float64,
    interpret: bool | None = None,
) -> dict[str, Array]:
    """Every lane of ``y0`` (L, n) from ``t0`` to ``t1`` under ``field(t, y, args)``, where ``args``
    is a tuple of (L,) arrays (one value per lane each) and ``field`` is written for one lane.

    Returns ``y1`` (L, n), ``status`` (L,), ``num_steps`` (L,). ``solver``: an explicit FSAL
    Runge-Kutta solver (default `diffrax.Tsit5`); ``dt0``: the first step (default: Hairer's
    heuristic); ``interpret``: Pallas' interpreter (default: off a
    GPU). Traceable: call it under `jax.jit`."""
    solver = diffrax.Tsit5() if solver is None else solver
    if not kernel_supported(solver):
        raise ValueError(
            f"solver: the lane kernel needs an explicit FSAL Runge-Kutta solver, got {type(solver).__name__}"
        )
    if not (t1 > t0):
        raise ValueError(f"t1 must be after t0, got t0={t0!r}, t1={t1!r}")
    for name, v in (("rtol", rtol), ("atol", atol)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a positive finite number, got {v!r}")
    if interpret is None:
        interpret = jax.default_backend() not in ("gpu", "cuda", "rocm")
    y0 = jnp.asarray(y0, dtype)
    if y0.ndim != 2:
        raise ValueError(f"y0 must be (lanes, n), got shape {y0.shape}")
    L, n = y0.shape
    args = tuple(jnp.broadcast_to(jnp.asarray(a, dtype), (L,)) for a in args)
    Lp = -(-L // BLOCK) * BLOCK
    pad = lambda x: jnp.concatenate([x, jnp.repeat(x[-1:], Lp - L, axis=0)]) if Lp > L else x  # noqa: E731
    y0, args = pad(y0), tuple(pad(a) for a in args)
    cfg = types.SimpleNamespace(solver=solver, rtol=rtol, atol=atol, max_steps=max_steps, stop_on_invalid=False,
                                contact_law=None, stiffness="off")  # fmt: skip
    seg = Segment(cfg, None, len(args), dtype, field=lambda t, y, pv: (field(t, y, pv), (1.0, 1.0)), n=n,
                   omega_of=None, n3_index=None)  # fmt: skip
    t0a = jnp.full((Lp,), t0, jnp.float64)
    t1a = jnp.full((Lp,), t1, jnp.float64)
    f0 = jax.vmap(lambda y, *a: field(jnp.asarray(t0, dtype), y, a))(y0, *args).astype(dtype)
    if dt0 is None:
        h0 = _initial_step(f0, y0, rtol, atol, jnp.asarray(t1 - t0, dtype)).astype(jnp.float64)
    else:
        h0 = jnp.full((Lp,), min(float(dt0), t1 - t0), jnp.float64)
    ints = {"num_steps", "code", "first_invalid_kind", "stiff", "stiff_count", "stiff_steps"}
    s = {k: (jnp.zeros((Lp,), jnp.int32) if k in ints else jnp.zeros((Lp,), dtype)) for k in KERNEL_FIELDS}
    s.update(y=[y0[:, m] for m in range(n)], f=[f0[:, m] for m in range(n)], tprev=t0a, tnext=t0a + h0,
             first_invalid_t=jnp.full((Lp,), jnp.inf, jnp.float64), min_N=jnp.full((Lp,), jnp.inf, dtype),
             min_n3=jnp.full((Lp,), jnp.inf, dtype))  # fmt: skip
    floor = jax.vmap(t1_clip_floor)(t1a)
    flat, _ = seg(flatten_state(s), t1a, t1a, floor, args, interpret)
    s = unflatten_state(flat, n)
    done = s["tprev"] >= t1a
    status = jnp.where(s["code"] != 0, s["code"], jnp.where(done, 0, 1)).astype(jnp.int32)
    return dict(y1=jnp.stack(s["y"], axis=-1)[:L], status=status[:L], num_steps=s["num_steps"][:L])
