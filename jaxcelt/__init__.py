"""jaxcelt: a differentiable, vmappable JAX simulator of the rattleback (Celtic stone) on a
horizontally vibrating base, with the coupled dry-friction / rolling-resistance contact model
of Awrejcewicz & Kudra (2014). See MODEL.md for the equations.

Importing jaxcelt enables float64 in JAX (``jax_enable_x64``).
"""

from . import _config  # noqa: F401  (float64 on)
from .attractors import AttractorCensus, AttractorStarts, attractor_starts, attractors
from .celt_orbit import CeltOrbit, continue_orbit, periodic_orbit
from .contact import CONTACT_LAWS, AbstractContactLaw, Coulomb, CoulombSpin, GeneralisedPade, Pade, get_contact_law
from .data import MeasuredData, Trajectory, generate_data, load_data, save_data
from .diagnostics import Diagnostics, centre_position, diagnostics, energy, tilt
from .elliptic import contact_integrals, ellipke
from .ensemble import HostProcesses
from .fit import FitResult, fit, project_state  # noqa: F811  (jaxcelt.fit is the function)
from .integral_law import CustomProfile, HertzProfile, IntegralLaw, UniformProfile, patch_integrals, profile_moments
from .ladder import Scene, hertz_params, run_ladder
from .lyapunov import celt_lyapunov, largest_lyapunov
from .model import STATE_NAMES, kinematics, normal_force, vector_field
from .noslip import simulate_noslip
from .params import PARAM_NAMES, CeltParams
from .solve import INVALID_KINDS, STATUS, Solution, simulate
from .state import check_state, constraint_residual, initial_state
from .sweep import SweepResult, bifurcation, continuation, parameter_map, sweep_lanes

__version__ = "0.1.0"

__all__ = [
    "AttractorCensus",
    "AttractorStarts",
    "attractor_starts",
    "attractors",
    "CeltOrbit",
    "periodic_orbit",
    "continue_orbit",
    "FitResult",
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
    "parameter_map",
    "sweep_lanes",
    "largest_lyapunov",
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
