"""jaxcelt: a differentiable, vmappable JAX simulator of the rattleback (Celtic stone) on a
horizontally vibrating base, with the coupled dry-friction / rolling-resistance contact model
of Awrejcewicz & Kudra (2014). See MODEL.md for the equations.

Importing jaxcelt enables float64 in JAX (``jax_enable_x64``).
"""

import sys

from jaxcelt import (
    _config,  # noqa: F401  (float64 on)
    _moved,
)
from jaxcelt.ensemble import HostProcesses
from jaxcelt.identify.api import fit  # noqa: F811  (jaxcelt.fit is the function)
from jaxcelt.identify.options import FitOptions
from jaxcelt.identify.records import MeasuredData, Trajectory, generate_data, load_data, save_data
from jaxcelt.identify.result import FitResult
from jaxcelt.integrate.lyapunov import celt_lyapunov, largest_lyapunov
from jaxcelt.integrate.noslip import simulate_noslip
from jaxcelt.integrate.solve import INVALID_KINDS, STATUS, Solution, simulate
from jaxcelt.integrate.spectrum import SpectrumResult
from jaxcelt.integrate.spectrum import celt_lyapunov_spectrum as lyapunov_spectrum
from jaxcelt.orbits.celt import CeltOrbit, continue_orbit, periodic_orbit
from jaxcelt.orbits.celt_curves import continue_orbit_bifurcation
from jaxcelt.orbits.curves import BifurcationCurve, continue_bifurcation
from jaxcelt.orbits.options import ShootingOptions
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
from jaxcelt.physics.contact.registry import CONTACT_LAWS, get_contact_law
from jaxcelt.physics.diagnostics import Diagnostics, centre_position, diagnostics, energy, tilt
from jaxcelt.physics.model import STATE_NAMES, kinematics, normal_force, vector_field
from jaxcelt.physics.params import PARAM_NAMES, CeltParams
from jaxcelt.physics.state import check_state, constraint_residual, initial_state, project_state
from jaxcelt.studies.ladder import Scene, hertz_params, run_ladder
from jaxcelt.sweeps.api import bifurcation, parameter_map, sweep_lanes
from jaxcelt.sweeps.atlas import AtlasOptions, AtlasResult, atlas
from jaxcelt.sweeps.census import AttractorCensus, AttractorStarts, attractor_starts, attractors
from jaxcelt.sweeps.continuation import continue_attractors
from jaxcelt.sweeps.continuation_options import ContinuationOptions
from jaxcelt.sweeps.following import continuation
from jaxcelt.sweeps.following import follow_attractor as follow_attractor  # new name of continuation
from jaxcelt.sweeps.options import SweepOptions
from jaxcelt.sweeps.result import SweepResult
from jaxcelt.sweeps.zero_one import zero_one_test

__version__ = "0.1.0"

_moved.install(sys.modules[__name__])

__all__ = [
    "AttractorCensus",
    "AttractorStarts",
    "attractor_starts",
    "attractors",
    "continue_attractors",
    "zero_one_test",
    "atlas",
    "AtlasOptions",
    "AtlasResult",
    "ContinuationOptions",
    "CeltOrbit",
    "periodic_orbit",
    "continue_orbit",
    "continue_bifurcation",
    "continue_orbit_bifurcation",
    "BifurcationCurve",
    "ShootingOptions",
    "FitResult",
    "FitOptions",
    "MeasuredData",
    "Trajectory",
    "fit",
    "generate_data",
    "load_data",
    "project_state",
    "save_data",
    "AbstractContactLaw",
    "SweepResult",
    "HostProcesses",
    "bifurcation",
    "celt_lyapunov",
    "continuation",
    "follow_attractor",
    "SweepOptions",
    "parameter_map",
    "sweep_lanes",
    "largest_lyapunov",
    "lyapunov_spectrum",
    "SpectrumResult",
    "CONTACT_LAWS",
    "CeltParams",
    "Diagnostics",
    "GeneralisedPade",
    "Pade",
    "Coulomb",
    "CoulombSpin",
    "IntegralLaw",
    "HertzProfile",
    "UniformProfile",
    "CustomProfile",
    "patch_integrals",
    "Scene",
    "hertz_params",
    "run_ladder",
    "simulate_noslip",
    "profile_moments",
    "INVALID_KINDS",
    "PARAM_NAMES",
    "STATE_NAMES",
    "STATUS",
    "Solution",
    "centre_position",
    "check_state",
    "constraint_residual",
    "contact_integrals",
    "diagnostics",
    "ellipke",
    "energy",
    "get_contact_law",
    "initial_state",
    "kinematics",
    "normal_force",
    "simulate",
    "tilt",
    "vector_field",
]
