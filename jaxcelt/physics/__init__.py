"""The wobblestone's physics: pure JAX functions of one state, no solver, no I/O.

The ground floor of the package; it imports nothing above it (an import contract checks this).

* `params` -- `CeltParams`, every number of the model (geometry, inertia, contact, base forcing), validated.
* `state` -- states on the contact manifold: `initial_state`, `check_state`, `constraint_residual`.
* `model` -- the vector field ``f(t, y, params)`` (eqs. 1-17 of MODEL.md) as a chain of pure stages: contact
  geometry -> kinematics -> contact law -> normal force -> Newton-Euler.
* `contact` -- the contact laws (generalised Padé of the paper, Padé, Coulomb, the exact integral law) and the
  registry that names them.
* `diagnostics` -- energy, tilt, the path of the centre, the validity monitors' quantities.
"""

from jaxcelt.physics.contact import CONTACT_LAWS, AbstractContactLaw, get_contact_law
from jaxcelt.physics.diagnostics import Diagnostics, centre_position, diagnostics, energy, tilt
from jaxcelt.physics.model import STATE_NAMES, kinematics, normal_force, vector_field
from jaxcelt.physics.params import PARAM_NAMES, CeltParams
from jaxcelt.physics.state import check_state, constraint_residual, initial_state

__all__ = [
    "CeltParams",
    "PARAM_NAMES",
    "initial_state",
    "check_state",
    "constraint_residual",
    "STATE_NAMES",
    "vector_field",
    "normal_force",
    "kinematics",
    "Diagnostics",
    "diagnostics",
    "energy",
    "tilt",
    "centre_position",
    "AbstractContactLaw",
    "CONTACT_LAWS",
    "get_contact_law",
]
