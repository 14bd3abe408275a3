"""The lane kernel's stiffness switch: each lane steps explicitly until its steps are stability-limited,
then with Rodas4P (`jaxcelt.ensemble.rosenbrock`) until they are not.

A sticking lane is the GPU map's slowest (`jaxcelt.ensemble.kernel`): 32 lanes share a warp, and a
warp runs until its slowest lane is done, so one lane held at 10⁻⁴ s steps for 300 periods sets
the time of its block, and a few such blocks the time of the map. The switch, per lane:

* **explicit → stiff.** After each explicit step the lane estimates h ρ, ρ = |f(y₇) − f(y₆)| /
  |y₇ − y₆| from the last two stages (both at t + h), the estimate of the dominant eigenvalue
  along the step that Hairer & Wanner use to detect stiffness in DOPRI5 (*Solving ODEs II*,
  §IV.2). A step with h ρ above `STIFF_HRHO` (Tsit5's stability interval on the negative real axis
  ends near 3.5) counts one; one below `RELEASE_HRHO` resets the count; `SWITCH_AFTER` in a row
  switch the lane to the stiff step.
* **stiff → explicit.** Each Rodas4P step has the Jacobian J; where h ‖J‖∞ (an upper bound of h
  times the spectral radius) stays below `EXPLICIT_HNORM` for `SWITCH_AFTER` steps in a row, an
  explicit step of that size is stable and the lane switches back.

Both steps share the error control (diffrax's I-controller with the method's own exponent), the
section clipping, the validity monitor and the step budget (``max_steps`` counts both kinds).
A block runs the stiff step only while one of its lanes needs it (`jax.lax.cond` on the block),
so blocks without sticking lanes run the explicit kernel alone.
"""

from __future__ import annotations

import functools
from typing import Any

import jax
import jax.numpy as jnp

from jaxcelt._types import Array
from jaxcelt.ensemble.rosenbrock import RODAS4P, lu_factor, lu_solve

__all__ = ["EXPLICIT_HNORM", "RELEASE_HRHO", "STIFF_HRHO", "SWITCH_AFTER", "rosenbrock_step", "step_either"]

STIFF_HRHO = 3.0
"""an explicit step with h rho above this counts towards the switch to the stiff step"""
RELEASE_HRHO = 2.0
"""an explicit step with h rho below this resets the count"""
EXPLICIT_HNORM = 1.0
"""a stiff step with h ‖J‖∞ below this counts towards the switch back"""
SWITCH_AFTER = 15
"""steps in a row that switch a lane (Hairer & Wanner's DOPRI5 uses 15)"""


def _any(x: Array) -> Array:
    """Whether any lane of the block is set (a max: Triton lowers no boolean reductions)."""
    return jnp.max(x.astype(jnp.int32)) > 0


def _select(i: Array, col: Any, dtype: Any) -> Array:
    out = jnp.asarray(float(col[-1]), dtype)
    for r in range(len(col) - 2, -1, -1):
        out = jnp.where(i == r, jnp.asarray(float(col[r]), dtype), out)
    return out


def rosenbrock_step(seg: Any, s: dict, pv: tuple[Array, ...]) -> tuple[list, list, list, Array, Array, Array]:
    """One Rodas4P step from every lane's state: (y1, f(y1), the error, N, den at y1, h ‖J‖∞)."""
    T = RODAS4P
    n, dt_ = seg.n, seg.dtype
    y0, t0 = s["y"], s["tprev"]
    dt = s["tnext"] - t0
    dts = dt.astype(dt_)
    zero = jnp.zeros(t0.shape, dt_)
    one = jnp.ones(t0.shape, dt_)

    def column(k, carry):  # column k of J (k < n) or df/dt (k = n): one copy of the field's derivative
        J, ft = carry
        ty = [jnp.where(k == m, one, zero) for m in range(n)]
        _, df = seg.field_tangent(t0, y0, pv, jnp.where(k == n, one, zero), ty)
        J = [[jnp.where(k == j, df[i], J[i][j]) for j in range(n)] for i in range(n)]
        ft = [jnp.where(k == n, df[i], ft[i]) for i in range(n)]
        return J, ft

    J, ft = jax.lax.fori_loop(0, n + 1, column, ([[zero] * n for _ in range(n)], [zero] * n))
    hnorm = jnp.abs(dts) * functools.reduce(jnp.maximum, [sum(jnp.abs(x) for x in row) for row in J])
    inv_gh = 1.0 / (T.gamma * dts)
    LU = lu_factor([[(inv_gh if i == j else zero) - J[i][j] for j in range(n)] for i in range(n)])
    ns = len(T.c)
    cols = [j for j in range(ns) if T.a[:, j].any() or T.C[:, j].any()]

    def stage(i, ks):
        a = {j: _select(i, T.a[:, j], dt_) for j in cols}
        C = {j: _select(i, T.C[:, j], dt_) for j in cols}
        u = [y0[m] + sum(a[j] * ks[j][m] for j in cols) for m in range(n)]
        fi, _, _ = seg.field(t0 + _select(i, T.c, jnp.float64) * dt, u, pv)
        di = _select(i, T.d, dt_) * dts
        rhs = [fi[m] + di * ft[m] + sum(C[j] * ks[j][m] for j in cols) / dts for m in range(n)]
        k = lu_solve(LU, rhs)
        return [[jnp.where(i == j, k[m], ks[j][m]) for m in range(n)] for j in range(ns)]

    ks = jax.lax.fori_loop(0, ns, stage, [[zero] * n for _ in range(ns)])
    y1 = [y0[m] + sum(float(T.b[j]) * ks[j][m] for j in range(ns) if T.b[j] != 0) for m in range(n)]
    err = [sum(float(T.e[j]) * ks[j][m] for j in range(ns) if T.e[j] != 0) for m in range(n)]
    f1, N, den = seg.field(t0 + dt, y1, pv)
    return y1, f1, err, N, den, hnorm


def step_either(seg: Any, s: dict, pv: tuple[Array, ...], act: Array) -> tuple:
    """Every lane's step by its mode (module docstring): (y1, f(y1), error, N, den, the controller's
    exponent order per lane, the new mode, the new count)."""
    n, dt_ = seg.n, seg.dtype
    stiff = s["stiff"] > 0
    shape = s["tprev"].shape

    def zeros():
        z = jnp.zeros(shape, dt_)
        return [z] * n, [z] * n, [z] * n, z, z, z

    ex = jax.lax.cond(_any(act & ~stiff), lambda: seg.explicit(s, pv), zeros)
    ro = jax.lax.cond(_any(act & stiff), lambda: rosenbrock_step(seg, s, pv), zeros)
    pick = lambda a, b: jnp.where(stiff, b, a)  # noqa: E731
    y1 = [pick(a, b) for a, b in zip(ex[0], ro[0])]
    f1 = [pick(a, b) for a, b in zip(ex[1], ro[1])]
    err = [pick(a, b) for a, b in zip(ex[2], ro[2])]
    N, den = pick(ex[3], ro[3]), pick(ex[4], ro[4])
    q = jnp.where(stiff, float(RODAS4P.order), seg.q).astype(dt_)
    hrho, hnorm = ex[5], ro[5]
    count = s["stiff_count"]
    up = jnp.where(hrho > STIFF_HRHO, count + 1, jnp.where(hrho < RELEASE_HRHO, 0, count))
    down = jnp.where(hnorm < EXPLICIT_HNORM, count + 1, 0)
    count = jnp.where(stiff, down, up)
    switch = count >= SWITCH_AFTER
    mode = jnp.where(switch, 1 - s["stiff"], s["stiff"]).astype(jnp.int32)
    return y1, f1, err, N, den, q, mode, jnp.where(switch, 0, count).astype(jnp.int32)
