"""Module paths from before the topic packages, kept working for one release.

``import jaxcelt.sweep`` or ``from jaxcelt.data import load_csv`` still works: each old path is a stand-in module
whose attributes are looked up in the new place on first use, with a `DeprecationWarning` that names it. The stand-ins
are made when ``jaxcelt`` is imported (`install`); nothing else in the package uses them.
"""

from __future__ import annotations

import importlib
import sys
import types
import warnings
from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["MOVED", "RENAMED", "install"]

_MISSING = object()

MOVED: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        # old module (under jaxcelt.)  -> new modules searched in order for a name
        "params": ("jaxcelt.physics.params",),
        "state": ("jaxcelt.physics.state",),
        "model": ("jaxcelt.physics.model",),
        "diagnostics": ("jaxcelt.physics.diagnostics",),
        "contact": ("jaxcelt.physics.contact.laws", "jaxcelt.physics.contact.registry"),
        "integral_law": ("jaxcelt.physics.contact.integral",),
        "elliptic": ("jaxcelt.physics.contact.elliptic",),
        "calibrate": ("jaxcelt.physics.contact.calibrate",),
        "solve": ("jaxcelt.integrate.solve",),
        "noslip": ("jaxcelt.integrate.noslip",),
        "lyapunov": ("jaxcelt.integrate.lyapunov",),
        "io": ("jaxcelt.integrate.io",),
        "sweep": (
            "jaxcelt.sweeps.api",
            "jaxcelt.sweeps.result",
            "jaxcelt.sweeps.following",
            "jaxcelt.sweeps.dense",
            "jaxcelt.sweeps.options",
            "jaxcelt.ensemble.stroboscopic",
            "jaxcelt.ensemble",
            "jaxcelt.commands.args",
        ),
        "dataset": ("jaxcelt.sweeps.dataset", "jaxcelt.sweeps.result"),
        "regimes": ("jaxcelt.sweeps.regimes",),
        "attractors": ("jaxcelt.sweeps.census",),
        "periodic": ("jaxcelt.orbits.shooting", "jaxcelt.orbits.options"),
        "orbit_continuation": ("jaxcelt.orbits.branch", "jaxcelt.orbits.points", "jaxcelt.orbits.switching"),
        "bifurcation_point": ("jaxcelt.orbits.points",),
        "celt_orbit": ("jaxcelt.orbits.celt",),
        "data": ("jaxcelt.identify.observe", "jaxcelt.identify.records"),
        "fit": (
            "jaxcelt.identify.transforms",
            "jaxcelt.identify.options",
            "jaxcelt.physics.state",
            "jaxcelt.identify.problem",
            "jaxcelt.identify.result",
            "jaxcelt.identify.optimisers",
            "jaxcelt.identify.chaos",
            "jaxcelt.identify.strategies",
            "jaxcelt.identify.api",
        ),
        "ladder": ("jaxcelt.studies.ladder",),
        "benchmarking": ("jaxcelt.studies.benchmarking", "jaxcelt.integrate.solvers", "jaxcelt.plotting.results"),
    }
)
"""Old module name -> the modules that now hold its names (searched in order)."""

RENAMED: Mapping[str, Mapping[str, str]] = MappingProxyType(
    {
        "ladder": MappingProxyType({"OBSERVABLES": "jaxcelt.studies.ladder:QUANTITIES"}),
        "benchmarking": MappingProxyType({"Scene": "jaxcelt.studies.benchmarking:BenchmarkScene"}),
        "orbit_continuation": MappingProxyType(
            {
                "OrbitBranch": "jaxcelt.orbits.branch:NaturalBranch",
                "continue_periodic_orbit": "jaxcelt.orbits.branch:continue_natural",
                "continue_pseudo_arclength": "jaxcelt.orbits.branch:continue_arclength",
            }
        ),
        "sweep": MappingProxyType(
            {
                "orbit": "jaxcelt.sweeps.dense:dense_trajectory",
                "prepare_orbit": "jaxcelt.sweeps.dense:prepare_dense_trajectory",
                "continuation": "jaxcelt.sweeps.following:follow_attractor",
            }
        ),
    }
)
"""Old module name -> {old name: "new.module:new_name"} for names that were renamed as they moved."""


def _stand_in(package: str, old: str, targets: tuple[str, ...]) -> types.ModuleType:
    name = f"{package}.{old}"
    module = types.ModuleType(name, f"Deprecated: moved to {', '.join(targets)}.")

    def __getattr__(attr: str):
        if attr.startswith("__"):
            raise AttributeError(attr)
        renamed = RENAMED.get(old, {}).get(attr)
        found = [(renamed.partition(":")[0], renamed.partition(":")[2])] if renamed else []
        found += [(t, attr) for t in targets if not renamed]
        for target, new_attr in found:
            mod = importlib.import_module(target)
            with warnings.catch_warnings():  # a deprecated alias at the new place: this warning is the one
                warnings.simplefilter("ignore", DeprecationWarning)
                value = getattr(mod, new_attr, _MISSING)
            if value is not _MISSING:
                public = " (or jaxcelt." + new_attr + ")" if new_attr in getattr(sys.modules[package], "__all__", ()) else ""
                warnings.warn(
                    f"{name} is deprecated and will be removed in the next release; use {target}.{new_attr}{public}",
                    DeprecationWarning,
                    stacklevel=2,
                )
                return value
        raise AttributeError(f"module {name!r} has no attribute {attr!r} (it moved to {', '.join(targets)})")

    module.__getattr__ = __getattr__  # type: ignore[method-assign]
    return module


def install(package: types.ModuleType) -> None:
    """Register the stand-ins in `sys.modules`; set them as attributes where the package has no name of its own.

    ``jaxcelt.fit``, ``jaxcelt.attractors`` and ``jaxcelt.diagnostics`` stay the functions of those names, while
    ``from jaxcelt.fit import FitResult`` still finds the stand-in.
    """
    for old, targets in MOVED.items():
        name = f"{package.__name__}.{old}"
        module = sys.modules.setdefault(name, _stand_in(package.__name__, old, targets))
        if not hasattr(package, old):
            setattr(package, old, module)
