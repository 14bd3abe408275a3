"""Periodic orbits of forced ODEs, their branches and bifurcation points; the wobblestone's orbits.

Entry points for the wobblestone (`jaxcelt.orbits.celt`, also at ``jaxcelt.``): `periodic_orbit` (a period-k
orbit and its Floquet multipliers, `CeltOrbit`), `continue_orbit` (its branch in one `CeltParams` field, through
folds) and `locate_orbit_bifurcation` (a fold or period doubling, differentiable in other parameters).

The model-agnostic layer they are built on, module by module:

* `jaxcelt.orbits.shooting` -- shooting on the stroboscopic map of any periodically forced ODE:
  `find_periodic_orbit`, `stroboscopic_map`, `variational_map`, `PeriodicOrbit`, and `OrbitFamily` (orbits as one
  parameter varies: what a branch continues).
* `jaxcelt.orbits.branch` -- continuation algorithms, apart from what they continue: `continue_arclength`
  (pseudo-arclength, passes folds), `continue_natural` (a fixed grid), the reusable stepper `ArclengthStepper` /
  `trace_arclength`, and `branch_to_dict`.
* `jaxcelt.orbits.points` -- bifurcation points on a branch: detection (test functions), location (bisection),
  and refinement with implicit-function-theorem derivatives (`locate_bifurcation`, bordered test functions).
* `jaxcelt.orbits.curves` -- `continue_bifurcation`: a fold, period-doubling or Neimark-Sacker point continued in
  two parameters (its curve, with cusps, fold-flip, fold-NS and 1:1 / 1:2 / 1:3 / 1:4 resonance points located on
  it); the defining systems in `jaxcelt.orbits.curve_fold` (fold, period doubling) and `jaxcelt.orbits.ns_system`
  (Neimark-Sacker).
* `jaxcelt.orbits.switching` -- `switch_at_period_doubling`: the period-2k orbit that starts a new branch.
* `jaxcelt.orbits.celt` -- the wobblestone's chart of the contact manifold (`celt_chart`, `celt_embed`) and the
  entry points above.
* `jaxcelt.orbits.options` -- `ShootingOptions`, the solver and Newton settings all of them take (``options=``).
"""

from jaxcelt.orbits.branch import (
    ArclengthBranch,
    ArclengthStepper,
    NaturalBranch,
    branch_to_dict,
    continue_arclength,
    continue_natural,
    trace_arclength,
)
from jaxcelt.orbits.celt import (
    CeltOrbit,
    celt_chart,
    celt_embed,
    continue_orbit,
    locate_orbit_bifurcation,
    periodic_orbit,
)
from jaxcelt.orbits.celt_curves import continue_orbit_bifurcation
from jaxcelt.orbits.curves import (
    CODIM2_TESTS,
    CURVE_STATUS,
    BifurcationCurve,
    CurvePoint,
    continue_bifurcation,
    curve_to_dict,
)
from jaxcelt.orbits.options import ShootingOptions
from jaxcelt.orbits.points import (
    BIFURCATION_KINDS,
    Bifurcation,
    BifurcationPoint,
    locate_bifurcation,
    locate_fold,
    locate_period_doubling,
)
from jaxcelt.orbits.shooting import (
    ORBIT_STATUS,
    OrbitFamily,
    PeriodicOrbit,
    find_periodic_orbit,
    stroboscopic_map,
    variational_map,
)
from jaxcelt.orbits.switching import switch_at_period_doubling

__all__ = [
    "periodic_orbit",
    "continue_orbit",
    "locate_orbit_bifurcation",
    "continue_orbit_bifurcation",
    "CeltOrbit",
    "celt_chart",
    "celt_embed",
    "ShootingOptions",
    "find_periodic_orbit",
    "stroboscopic_map",
    "variational_map",
    "PeriodicOrbit",
    "OrbitFamily",
    "ORBIT_STATUS",
    "continue_arclength",
    "continue_natural",
    "ArclengthBranch",
    "NaturalBranch",
    "ArclengthStepper",
    "trace_arclength",
    "branch_to_dict",
    "Bifurcation",
    "BIFURCATION_KINDS",
    "BifurcationPoint",
    "locate_bifurcation",
    "locate_period_doubling",
    "locate_fold",
    "switch_at_period_doubling",
    "continue_bifurcation",
    "BifurcationCurve",
    "CurvePoint",
    "CURVE_STATUS",
    "CODIM2_TESTS",
    "curve_to_dict",
]
