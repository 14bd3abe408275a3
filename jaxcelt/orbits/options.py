"""`ShootingOptions`: how one stroboscopic map is integrated and how Newton solves on it.

Every function of the orbits room that integrates the map (`jaxcelt.orbits.shooting`), follows a branch
(`jaxcelt.orbits.branch`) or locates a bifurcation point (`jaxcelt.orbits.points`) takes the same options: the
diffrax solver and its tolerances for one map evaluation, and the Newton tolerance and iteration limit. They are
one frozen, keyword-only object, documented here once.

Each public function also keeps its own keywords (``rtol=...``, ``newton_tol=...``) with its own defaults (a
continuation step needs fewer Newton iterations than a cold start; the wobblestone needs more solver steps than a
Duffing oscillator). `resolve_options` combines the two:

* neither given: the function's defaults;
* ``options=`` given: it replaces the function's defaults as a whole (fields left out take the defaults of
  `ShootingOptions`, not those of the function);
* keywords given as well: each keyword given overrides that one field of ``options``.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from typing import Any, TypedDict

import diffrax

from jaxcelt._options import with_keywords

__all__ = ["ShootingOptions", "ShootingKeywords", "resolve_options"]

_POSITIVE_FLOATS = ("rtol", "atol", "newton_tol")
_POSITIVE_INTS = ("max_steps", "newton_max_steps")


@dataclasses.dataclass(frozen=True, kw_only=True)
class ShootingOptions:
    """Solver and Newton settings of a shooting problem (frozen; keyword-only).

    ``dataclasses.replace(options, rtol=1e-9)`` gives a copy with one field changed.
    """

    solver: diffrax.AbstractSolver | None = None
    """diffrax solver of one map evaluation (None: `diffrax.Dopri8`)"""
    rtol: float = 1e-11
    """relative tolerance of the step-size controller"""
    atol: float = 1e-12
    """absolute tolerance of the step-size controller"""
    max_steps: int = 100_000
    """solver steps at most per map evaluation (over k periods)"""
    newton_tol: float = 1e-9
    """Newton tolerance (optimistix rtol = atol) in the unknowns; a root counts as converged when its
    residual is at most 10 x this"""
    newton_max_steps: int = 30
    """Newton iterations at most"""

    def __post_init__(self):
        for name in _POSITIVE_FLOATS:
            x = getattr(self, name)
            if isinstance(x, bool) or not isinstance(x, numbers.Real) or not (math.isfinite(x) and x > 0):
                raise ValueError(f"{name!r} must be a positive finite number, got {x!r}")
        for name in _POSITIVE_INTS:
            x = getattr(self, name)
            if isinstance(x, bool) or not isinstance(x, numbers.Integral) or x < 1:
                raise ValueError(f"{name!r} must be a positive int, got {x!r}")
        if self.solver is not None and not isinstance(self.solver, diffrax.AbstractSolver):
            raise ValueError(f"'solver' must be a diffrax solver or None, got {type(self.solver).__name__}")

    @property
    def ode(self) -> dict[str, Any]:
        """The solver settings as keywords of `jaxcelt.orbits.shooting.stroboscopic_map`."""
        return dict(solver=self.solver, rtol=self.rtol, atol=self.atol, max_steps=self.max_steps)


class ShootingKeywords(TypedDict, total=False):
    """The fields of `ShootingOptions` as single keywords (``**settings``) of the functions that take ``options=``."""

    solver: diffrax.AbstractSolver | None
    rtol: float
    atol: float
    max_steps: int
    newton_tol: float
    newton_max_steps: int


def resolve_options(
    options: ShootingOptions | None, defaults: ShootingOptions, *, caller: str = "shooting", **given: Any
) -> ShootingOptions:
    """The options a function runs with: ``options`` (or its ``defaults``), then each keyword not None on top.

    ``given`` are the keywords the caller passed (`ShootingKeywords`; None counts as not given); the rule is
    `jaxcelt._options.with_keywords` (an unknown keyword is a TypeError naming it).
    """
    changed = {name: value for name, value in given.items() if value is not None}
    return with_keywords(ShootingOptions, options, defaults, changed, caller=caller)
