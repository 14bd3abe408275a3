"""The lane kernel's stiff step: Rodas4P, a linearly implicit (Rosenbrock) method, on lane blocks.

While the stone sticks to the base, the smoothed friction law relaxes the slip velocity at about
μ g /(â √ε) ≈ 3.6·10⁴ s⁻¹ (ε = 10⁻⁴, docs/MODEL.md): an explicit step is then held at the edge
of its stability region (≈ 10⁻⁴ s) by the error controller, and a lane that sticks for 300
periods needs over 10⁶ steps. An L-stable Rosenbrock step is not limited that way: each step
solves linear systems with W = I/(γh) − J, J = ∂f/∂y, and its step size follows accuracy alone.

This module holds what that step needs on lane blocks (`jaxcelt.ensemble.soa`: one (B,) array per
scalar, one thread per lane in the GPU kernel), written out in plain arithmetic so that Pallas'
Triton backend lowers it:

* `RODAS4P`: Steinebach's Rodas4P (6 stages, order 4, stiffly accurate, L-stable, an order-3
  embedded error estimate), whose conditions keep order 4 on stiff Prothero–Robinson problems
  y' = λ(y − g(t)) + g'(t), where Hairer & Wanner's Rodas4 falls to first order at the
  tolerances of a map (the stiff components of a sticking lane are of that kind), in the
  W-transformed form of Hairer & Wanner's code RODAS (*Solving ODEs II*,
  §IV.7) — stage i solves
  W kᵢ = f(t + cᵢh, y + Σⱼ aᵢⱼ kⱼ) + dᵢ h ∂f/∂t + Σⱼ (Cᵢⱼ/h) kⱼ; the step is y + Σ bᵢ kᵢ and
  the error estimate is the last stage k₆;
* `lu_factor` / `lu_solve`: Gaussian elimination without pivoting on an n × n matrix of blocks.
  W = I/(γh) − J is the identity scaled by 1/(γh) minus the Jacobian; a pivot that vanishes gives
  inf/NaN, which the kernel's error estimate turns into a rejected step and a smaller h (where W
  tends to I/(γh), which needs no pivoting).

The switch between the explicit and this step, per lane, is `jaxcelt.ensemble.kernel`'s.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

__all__ = ["RODAS4P", "RosenbrockTableau", "lu_factor", "lu_solve"]


class RosenbrockTableau(NamedTuple):
    """A Rosenbrock method in the W-transformed form (module docstring); arrays over its s stages."""

    gamma: float
    a: np.ndarray
    """(s, s) strictly lower: stage i's state is y + Σⱼ a[i, j] kⱼ"""
    C: np.ndarray
    """(s, s) strictly lower: stage i's right-hand side adds Σⱼ (C[i, j]/h) kⱼ"""
    c: np.ndarray
    """(s,) stage times t + c[i] h"""
    d: np.ndarray
    """(s,) stage i's right-hand side adds d[i] h ∂f/∂t"""
    b: np.ndarray
    """(s,) the step: y + Σ b[i] kᵢ"""
    e: np.ndarray
    """(s,) the error estimate: Σ e[i] kᵢ"""
    order: int
    """order of the error estimate plus one (the step-size controller's exponent is 1/order)"""


def _rodas4p() -> RosenbrockTableau:
    # Steinebach's RODAS4P (1995), in the form of Hairer & Wanner's code RODAS
    a = np.zeros((6, 6))
    a[1, 0] = 3.0
    a[2, :2] = (1.831036793486759, 0.4955183967433795)
    a[3, :3] = (2.304376582692669, -0.05249275245743001, -1.176798761832782)
    a[4, :4] = (-7.170454962423024, -4.741636671481785, -16.31002631330971, -1.062004044111401)
    a[5, :5] = (*a[4, :4], 1.0)  # stage 6 starts from stage 5's state plus k5
    C = np.zeros((6, 6))
    C[1, 0] = -12.0
    C[2, :2] = (-8.791795173947035, -2.207865586973518)
    C[3, :3] = (10.81793056857153, 6.780270611428266, 19.53485944642410)
    C[4, :4] = (34.19095006749676, 15.49671153725963, 54.74760875964130, 14.16005392148534)
    C[5, :5] = (34.62605830930532, 15.30084976114473, 56.99955578662667, 18.40807009793095, -5.714285714285717)
    c = np.array([0.0, 0.75, 0.21, 0.63, 1.0, 1.0])
    d = np.array([0.25, -0.5, -0.023504, -0.0362, 0.0, 0.0])
    b = np.array([*a[4, :4], 1.0, 1.0])  # stiffly accurate: y1 = stage 6's state + k6
    e = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    return RosenbrockTableau(gamma=0.25, a=a, C=C, c=c, d=d, b=b, e=e, order=4)


RODAS4P = _rodas4p()
"""Rodas4P (module docstring)"""


def lu_factor(A: list[list[Any]]) -> list[list[Any]]:
    """LU factors of an n × n matrix of blocks (or numbers), in place of one matrix: L below the
    diagonal (unit diagonal implied), U on and above it. No pivoting (module docstring)."""
    n = len(A)
    A = [list(row) for row in A]
    for k in range(n):
        inv = 1.0 / A[k][k]
        for i in range(k + 1, n):
            li = A[i][k] * inv
            A[i][k] = li
            for j in range(k + 1, n):
                A[i][j] = A[i][j] - li * A[k][j]
    return A


def lu_solve(LU: list[list[Any]], rhs: list[Any]) -> list[Any]:
    """x with (L U) x = rhs, from `lu_factor`'s factors."""
    n = len(rhs)
    z = list(rhs)
    for i in range(n):
        for j in range(i):
            z[i] = z[i] - LU[i][j] * z[j]
    x = [None] * n
    for i in range(n - 1, -1, -1):
        acc = z[i]
        for j in range(i + 1, n):
            acc = acc - LU[i][j] * x[j]
        x[i] = acc / LU[i][i]
    return x
