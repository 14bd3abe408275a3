"""Integrating the model: one solve at a time, over diffrax.

* `solve` -- `simulate`, the one integration entry point (jit once, vmap over parameters and states, grad through
  the solver), returning a `Solution` with a status code (`STATUS`) and the validity monitors' findings
  (`INVALID_KINDS`) instead of raising inside a batch.
* `solvers` -- `SOLVERS`, the one table from a solver's name to a diffrax solver (`make_solver`).
* `lyapunov` -- the largest Lyapunov exponent of a forced ODE and of the wobblestone.
* `noslip` -- the rolling-without-slip reduction of the model and its solve.
* `io` -- saving and loading a computed trajectory.

Batches of many solves side by side live one floor up, in `jaxcelt.ensemble`.
"""

from jaxcelt.integrate.lyapunov import celt_lyapunov, largest_lyapunov
from jaxcelt.integrate.noslip import simulate_noslip
from jaxcelt.integrate.solve import INVALID_KINDS, STATUS, Solution, simulate
from jaxcelt.integrate.solvers import SOLVERS, make_solver

__all__ = [
    "simulate",
    "Solution",
    "STATUS",
    "INVALID_KINDS",
    "SOLVERS",
    "make_solver",
    "largest_lyapunov",
    "celt_lyapunov",
    "simulate_noslip",
]
