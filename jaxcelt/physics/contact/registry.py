"""The contact laws by name: the one table that turns a name (CLI, configuration files, ``contact_law="pade"``)
into a law object, and back.

Every law jaxcelt ships is listed here explicitly; a new law is added to `CONTACT_LAWS`.
"""

from __future__ import annotations

from jaxcelt.physics.contact.integral import IntegralLaw
from jaxcelt.physics.contact.laws import AbstractContactLaw, Coulomb, CoulombSpin, GeneralisedPade, Pade

__all__ = ["CONTACT_LAWS", "get_contact_law", "law_name"]


CONTACT_LAWS: dict[str, type[AbstractContactLaw]] = {
    "generalised_pade": GeneralisedPade,
    "pade": Pade,
    "coulomb_spin": CoulombSpin,
    "coulomb": Coulomb,
    "integral": IntegralLaw,
}
"""Name -> law class: every law jaxcelt ships, listed here in one place."""


def get_contact_law(law: str | AbstractContactLaw | None = None) -> AbstractContactLaw:
    """Resolve a law given by object or by name (``None`` -> the paper's `GeneralisedPade`)."""
    if law is None:
        return GeneralisedPade()
    if isinstance(law, AbstractContactLaw):
        return law
    if isinstance(law, str):
        # "name" or "name:norr" (rolling resistance off).
        name = law.lower().replace("-", "_")
        name, _, opt = name.partition(":")
        if name not in CONTACT_LAWS or opt not in ("", "rr", "norr"):
            raise ValueError(f"unknown contact law {law!r}; known: {sorted(CONTACT_LAWS)} (optionally ':norr')")
        return CONTACT_LAWS[name](rolling_resistance=opt != "norr")
    raise TypeError(f"contact_law must be a name or an AbstractContactLaw, got {type(law).__name__}")


def law_name(law: AbstractContactLaw) -> str:
    """Short name of a law object, ``"name"`` or ``"name:norr"`` (inverse of `get_contact_law`)."""
    for name, cls in CONTACT_LAWS.items():
        if type(law) is cls:
            return name if law.rolling_resistance else f"{name}:norr"
    return type(law).__name__
