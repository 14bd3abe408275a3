"""Contact laws: the friction force, spin-friction torque and rolling resistance per unit normal force.

* `laws` -- the contract (`AbstractContactLaw`: friction, rolling distortion, loads) and the closed-form laws:
  `GeneralisedPade` (the paper's eq. 13), `Pade`, `CoulombSpin`, `Coulomb`.
* `integral` -- the exact integral law over a pressure profile (`IntegralLaw`, `HertzProfile`, ...), the reference
  the approximants are calibrated against.
* `elliptic` -- complete elliptic integrals for the uniform-pressure limits.
* `calibrate` -- fitting an approximant's constants to the integral law.
* `registry` -- `CONTACT_LAWS`, the one table from a name to a law, and `get_contact_law`.

A new law: subclass `AbstractContactLaw` in a module here and add it to `CONTACT_LAWS`.
"""

from jaxcelt.physics.contact.elliptic import contact_integrals, ellipke
from jaxcelt.physics.contact.integral import (
    CustomProfile,
    HertzProfile,
    IntegralLaw,
    UniformProfile,
    patch_integrals,
    profile_moments,
)
from jaxcelt.physics.contact.laws import AbstractContactLaw, Coulomb, CoulombSpin, GeneralisedPade, Pade
from jaxcelt.physics.contact.registry import CONTACT_LAWS, get_contact_law, law_name

__all__ = [
    "AbstractContactLaw",
    "GeneralisedPade",
    "Pade",
    "CoulombSpin",
    "Coulomb",
    "IntegralLaw",
    "HertzProfile",
    "UniformProfile",
    "CustomProfile",
    "patch_integrals",
    "profile_moments",
    "contact_integrals",
    "ellipke",
    "CONTACT_LAWS",
    "get_contact_law",
    "law_name",
]
