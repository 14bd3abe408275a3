"""The solvers the CLI and the studies name: one table from a name to a diffrax solver.

`SOLVERS` maps a name (``--solver Tsit5``, ``solver="Kvaerno5-Newton"``) to a factory and a kind (explicit,
implicit, fixed); `make_solver` builds one and rejects unknown names. `RK4` and `FixedStep` fill two gaps of
diffrax: the classical 4th-order Runge-Kutta method, and a wrapper that makes any Runge-Kutta method take constant
steps in `jaxcelt.simulate`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar

import diffrax
import numpy as np
import optimistix as optx

from jaxcelt._diffrax_adapter import use_stepsize_tol

__all__ = ["SOLVERS", "make_solver", "RK4", "FixedStep"]


_rk4_tableau = diffrax.ButcherTableau(
    a_lower=(np.array([0.5]), np.array([0.0, 0.5]), np.array([0.0, 0.0, 1.0])),
    b_sol=np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6]),
    # embedded error: difference to the 2nd-order midpoint method (unused with constant steps)
    b_error=np.array([1 / 6, 1 / 3 - 1, 1 / 3, 1 / 6]),
    c=np.array([0.5, 0.5, 1.0]),
)


class RK4(diffrax.AbstractERK):
    """The classical 4th-order Runge-Kutta method (4 stages), for use with constant steps."""

    tableau: ClassVar[diffrax.ButcherTableau] = _rk4_tableau
    interpolation_cls: ClassVar[Callable[..., Any]] = diffrax.ThirdOrderHermitePolynomialInterpolation.from_k

    def order(self, terms):
        return 4


class FixedStep(diffrax.AbstractSolver):
    """Runs a diffrax solver with constant steps in `jaxcelt.simulate`.

    Deliberately *not* an ``AbstractWrappedSolver`` (those forward ``isinstance`` checks), so
    `simulate` sees a solver without error estimate and uses ``ConstantStepSize``.
    """

    solver: diffrax.AbstractSolver

    @property
    def term_structure(self):
        return self.solver.term_structure

    @property
    def interpolation_cls(self):  # pyright: ignore
        return self.solver.interpolation_cls

    def order(self, terms):
        return self.solver.order(terms)

    def init(self, terms, t0, t1, y0, args):
        return self.solver.init(terms, t0, t1, y0, args)

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        y1, _, dense, state, result = self.solver.step(terms, t0, t1, y0, args, solver_state, made_jump)
        return y1, None, dense, state, result

    def func(self, terms, t0, y0, args):
        return self.solver.func(terms, t0, y0, args)


def _newton():
    return optx.Newton(rtol=use_stepsize_tol, atol=use_stepsize_tol, norm=optx.rms_norm)


SOLVERS: dict[str, tuple[Callable[[], diffrax.AbstractSolver], str]] = {
    "Tsit5": (diffrax.Tsit5, "explicit"),
    "Dopri5": (diffrax.Dopri5, "explicit"),
    "Dopri8": (diffrax.Dopri8, "explicit"),
    "Kvaerno3": (diffrax.Kvaerno3, "implicit"),
    "Kvaerno5": (diffrax.Kvaerno5, "implicit"),
    "Kvaerno3-Newton": (lambda: diffrax.Kvaerno3(root_finder=_newton()), "implicit"),
    "Kvaerno5-Newton": (lambda: diffrax.Kvaerno5(root_finder=_newton()), "implicit"),
    "RK4-fixed": (lambda: FixedStep(RK4()), "fixed"),
    "Heun-fixed": (lambda: FixedStep(diffrax.Heun()), "fixed"),
    "Midpoint-fixed": (lambda: FixedStep(diffrax.Midpoint()), "fixed"),
    "Euler-fixed": (diffrax.Euler, "fixed"),
}
"""name -> (factory, kind) with kind in explicit | implicit | fixed."""


def make_solver(name: str) -> diffrax.AbstractSolver:
    """A fresh solver by `SOLVERS` name.

    ``*-Newton`` variants replace diffrax's default root finder (`diffrax.VeryChord`: one
    Jacobian per step, reused by every stage and iteration) by full Newton (`optimistix.Newton`,
    a fresh Jacobian per iteration); tolerances are the step controller's in both cases.
    KenCarp3/4/5 are IMEX methods that need a ``MultiTerm(explicit, implicit)``, which
    `jaxcelt.simulate` does not build (the wobblestone field has no natural split), so they are
    not in the table.
    """
    if name not in SOLVERS:
        raise ValueError(f"unknown solver {name!r}; known: {sorted(SOLVERS)}")
    return SOLVERS[name][0]()
