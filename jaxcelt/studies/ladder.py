"""Model no more than a scene needs: run a ladder of contact laws on a scene and pick the cheapest
one that is good enough.

A `Scene` is (parameters, initial state, forcing, horizon, observed quantities). `run_ladder`
simulates it with the reference (the integral law, eqs. 7-9, with a physical pressure profile:
Hertz) and with each rung of the ladder (approximants with constants calibrated to the same
Hertz profile, simpler laws, rolling resistance off, rolling without slip), and reports for each
rung its error on the observed quantities against the reference over the horizon and its cost
(run wall time after compilation, accepted steps). `recommend` picks the cheapest rung within a
tolerance. `needed_state` decides from the Jacobian structure of the vector field which state
components a scene's observations depend on (e.g. r_C only for global-path plots).

What is compared: approximants calibrated to Hertz against the Hertz integral law, so the
error measures the approximation of the law, not a mismatch of constants (the paper's S_i
belong to no physical sigma0; MODEL.md section 9 A10). All rungs share the smoothing eps,
eps_R of the scene's parameters.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt.integrate.noslip import simulate_noslip
from jaxcelt.integrate.solve import simulate
from jaxcelt.physics.contact.integral import HERTZ_S, IntegralLaw
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law, law_name
from jaxcelt.physics.diagnostics import centre_position, energy, tilt
from jaxcelt.physics.model import STATE_NAMES, vector_field
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import initial_state

__all__ = [
    "Scene",
    "Rung",
    "RungResult",
    "QUANTITIES",
    "HERTZ_CALIBRATED",
    "default_ladder",
    "builtin_scenes",
    "run_ladder",
    "recommend",
    "needed_state",
    "hertz_params",
]

HERTZ_S_PARAMS = {"S0": HERTZ_S["S0"], "S2": HERTZ_S["S2"], "S3": HERTZ_S["S3"]}

HERTZ_CALIBRATED = {
    "generalised_pade": {"b_Ts": 0.070424, "b_Ms": 0.291419, "m_Ts": 0.672929, "m_Ms": 0.646714},
    "pade": {"b_Ts": 0.035863, "b_Ms": 0.113412},
}
"""Constants fitted by `jaxcelt.physics.contact.calibrate.calibrate` to the Hertz integral law at b = 0.1813
with S_i fixed at the Hertz moments (regenerate with ``scripts/contact_study.py``)."""


def hertz_params(p: CeltParams) -> CeltParams:
    """p with S0, S2, S3 set to the Hertz moments (MODEL.md section 7)."""
    return p.replace(**HERTZ_S_PARAMS)


QUANTITIES: dict[str, tuple[Callable, tuple[int, ...]]] = {
    "omega": (lambda ts, ys, p: ys[:, 3:6], (3, 4, 5)),
    "omega3": (lambda ts, ys, p: ys[:, 5], (5,)),
    "spin": (lambda ts, ys, p: jnp.sum(ys[:, 3:6] * ys[:, 6:9], axis=1), (3, 4, 5, 6, 7, 8)),
    "n": (lambda ts, ys, p: ys[:, 6:9], (6, 7, 8)),
    "tilt": (lambda ts, ys, p: jax.vmap(tilt)(ys), (8,)),
    "energy": (lambda ts, ys, p: jax.vmap(energy, in_axes=(0, None))(ys, p), tuple(range(9))),
    "r_O": (lambda ts, ys, p: jax.vmap(centre_position, in_axes=(0, None))(ys, p)[:, :2], tuple(range(6, 13))),
}
"""The quantities a scene compares between rungs: name -> (function (ts, ys, params) -> values over time, state
components it reads). (Not the sensor observables of identification, `jaxcelt.identify.observe.OBSERVABLES`.)"""


@dataclasses.dataclass(frozen=True)
class Scene:
    """What a user wants to simulate and look at.

    ``params`` (with S_i as the pressure profile's), ``y0`` (13,), ``forcing`` (overrides of
    q_pi, omega_pi applied to params), ``t1`` horizon [s], ``observed`` names in `QUANTITIES`,
    ``n_save`` saved samples.
    """

    name: str
    params: CeltParams
    y0: np.ndarray
    t1: float
    observed: tuple[str, ...] = ("omega", "tilt")
    forcing: dict = dataclasses.field(default_factory=dict)
    n_save: int = 201
    description: str = ""

    def __post_init__(self):
        unknown = set(self.observed) - set(QUANTITIES)
        if unknown:
            raise ValueError(f"Scene {self.name!r}: unknown observed {sorted(unknown)}; known {sorted(QUANTITIES)}")
        if not self.t1 > 0:
            raise ValueError(f"Scene {self.name!r}: t1 must be > 0, got {self.t1}")

    @property
    def full_params(self) -> CeltParams:
        return self.params.replace(**self.forcing) if self.forcing else self.params

    @property
    def ts(self) -> np.ndarray:
        return np.linspace(0.0, self.t1, self.n_save)


@dataclasses.dataclass(frozen=True)
class Rung:
    """One law of the ladder: a contact law (or ``"noslip"``) and constants it overrides."""

    name: str
    law: AbstractContactLaw | str
    overrides: dict = dataclasses.field(default_factory=dict)


def default_ladder() -> tuple[Rung, ...]:
    """Integral (reference) first, then approximants calibrated to Hertz, simpler laws, no-slip."""
    gp, pd = HERTZ_CALIBRATED["generalised_pade"], HERTZ_CALIBRATED["pade"]
    return (
        Rung("integral", IntegralLaw()),
        Rung("generalised_pade", get_contact_law("generalised_pade"), gp),
        Rung("pade", get_contact_law("pade"), pd),
        Rung("coulomb_spin", get_contact_law("coulomb_spin")),
        Rung("coulomb", get_contact_law("coulomb")),
        Rung("generalised_pade:norr", get_contact_law("generalised_pade:norr"), gp),
        Rung("coulomb:norr", get_contact_law("coulomb:norr")),
        Rung("noslip", "noslip"),
    )


@dataclasses.dataclass
class RungResult:
    """Error of one rung on a scene (max over observables of max_t |x - x_ref| / max_t |x_ref|),
    per-observable errors, run wall time [s] (second call, compiled), compile+run time of the
    first call [s], accepted steps, solver status and validity."""

    rung: str
    error: float
    errors: dict
    run_s: float
    first_call_s: float
    steps: int
    status: int
    valid: bool

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def _simulate(scene: Scene, rung: Rung, rtol: float, atol: float):
    p = scene.full_params.replace(**rung.overrides) if rung.overrides else scene.full_params
    ts = jnp.asarray(scene.ts)
    if isinstance(rung.law, str) and rung.law == "noslip":
        run = lambda: simulate_noslip(p, scene.y0, scene.t1, ts=ts, rtol=rtol, atol=atol)
    else:
        run = lambda: simulate(p, scene.y0, scene.t1, ts=ts, rtol=rtol, atol=atol, contact_law=rung.law)
    t0 = time.perf_counter()
    sol = run()
    jax.block_until_ready(sol.ys)
    t1 = time.perf_counter()
    sol = run()
    jax.block_until_ready(sol.ys)
    t2 = time.perf_counter()
    return sol, p, t2 - t1, t1 - t0


def _observe(scene: Scene, ts, ys, p) -> dict:
    return {k: np.asarray(QUANTITIES[k][0](ts, ys, p)) for k in scene.observed}


def run_ladder(
    scene: Scene,
    ladder: tuple[Rung, ...] | None = None,
    *,
    rtol: float = 1e-8,
    atol: float = 1e-10,
) -> list[RungResult]:
    """Simulate the scene with every rung; the first rung is the reference (error 0)."""
    ladder = ladder or default_ladder()
    out, ref_obs = [], None
    for rung in ladder:
        sol, p, run_s, first_s = _simulate(scene, rung, rtol, atol)
        obs = _observe(scene, sol.ts, sol.ys, p)
        if ref_obs is None:
            ref_obs = obs
        errors = {}
        for k in scene.observed:
            scale = float(np.max(np.abs(ref_obs[k]))) or 1.0
            d = np.abs(obs[k] - ref_obs[k])
            errors[k] = float(np.max(d) / scale) if np.all(np.isfinite(d)) else float("inf")
        out.append(
            RungResult(
                rung=rung.name,
                error=max(errors.values()),
                errors=errors,
                run_s=run_s,
                first_call_s=first_s,
                steps=int(sol.num_accepted_steps),
                status=int(sol.status),
                valid=bool(sol.valid),
            )
        )
    return out


def recommend(results: list[RungResult], tol: float) -> str:
    """Cheapest rung (run wall time) with error <= tol, a successful solve and a valid model;
    the reference (first rung) if none qualifies.

    Wall times of laws with the same step count differ only by timing noise, so rungs within
    25 % of the fastest are treated as a tie, broken by fewer accepted steps, then by ladder
    order (the simpler law comes later in the default ladder, so prefer the later one).
    """
    ok = [(i, r) for i, r in enumerate(results) if i > 0 and r.error <= tol and r.status == 0 and r.valid]
    if not ok:
        return results[0].rung
    fastest = min(r.run_s for _, r in ok)
    near = [(i, r) for i, r in ok if r.run_s <= 1.25 * fastest]
    return min(near, key=lambda ir: (ir[1].steps, -ir[0]))[1].rung


def needed_state(scene: Scene, law: AbstractContactLaw | str | None = None, n_points: int = 5) -> dict:
    """Which state components the scene's observations need (Jacobian-structure closure).

    Component j is needed if an observed quantity reads it, or if dy_i/dt depends on y_j for a
    needed i (checked with ``jax.jacfwd`` of `vector_field` at ``n_points`` states of a short
    trajectory of the scene; a structural zero is zero at all of them). Returns
    ``{"needed": [...names], "droppable": [...names], "reads": {...}}``.
    """
    p = scene.full_params
    law = get_contact_law(law)
    ts = np.linspace(0, scene.t1, n_points)
    sol = simulate(p, scene.y0, scene.t1, ts=jnp.asarray(ts), contact_law=law)
    J = jax.vmap(jax.jacfwd(vector_field, argnums=1), in_axes=(0, 0, None, None))(sol.ts, sol.ys, p, law)
    dep = np.any(np.abs(np.asarray(J)) > 0, axis=0)  # dep[i, j]: y_i' depends on y_j
    needed = set()
    for k in scene.observed:
        needed |= set(QUANTITIES[k][1])
    while True:
        new = needed | {j for i in needed for j in np.nonzero(dep[i])[0]}
        if new == needed:
            break
        needed = new
    names = [STATE_NAMES[i] for i in sorted(needed)]
    return {
        "needed": names,
        "droppable": [n for i, n in enumerate(STATE_NAMES) if i not in needed],
        "reads": {k: [STATE_NAMES[i] for i in QUANTITIES[k][1]] for k in scene.observed},
    }


def _tilted(n1: float, n2: float) -> np.ndarray:
    n = np.array([n1, n2, 1.0])
    return n / np.linalg.norm(n)


def builtin_scenes(short: bool = False) -> dict[str, Scene]:
    """The scenes of the study (docs/contact-laws.md); ``short`` halves the horizons."""
    f = 0.5 if short else 1.0
    base = hertz_params(CeltParams.paper())
    table = base.replace(q_pi=0.0, a_hat=1e-3, k_r=0.05, eps=1e-2, eps_R=1e-2)
    scenes = {
        "spin_reversal": Scene(
            "spin_reversal",
            table,
            np.asarray(initial_state(table, omega=(0, 0, -4.0), n=_tilted(0.0, 0.03))),
            3.0 * f,
            ("omega3", "tilt"),
            description="fixed table, spin -4 rad/s in the unstable direction, small roll tilt; small patch, weak rolling resistance",
        ),
        "base14": Scene(
            "base14",
            base,
            np.asarray(initial_state(base)),
            1.5 * f,
            ("omega", "tilt"),
            {"q_pi": 0.04, "omega_pi": 14.0},
            description="vibrating base q = 0.04 m, omega_pi = 14 rad/s, from rest",
        ),
        "base19": Scene(
            "base19",
            base,
            np.asarray(initial_state(base)),
            1.5 * f,
            ("omega", "tilt"),
            {"q_pi": 0.04, "omega_pi": 19.0},
            description="vibrating base q = 0.04 m, omega_pi = 19 rad/s, from rest",
        ),
        "fast_spin": Scene(
            "fast_spin",
            base.replace(q_pi=0.0),
            np.asarray(initial_state(base, omega=(0, 0, 25.0), n=_tilted(0.01, 0.01))),
            1.0 * f,
            ("omega3", "tilt"),
            description="fixed table, fast spin +25 rad/s",
        ),
    }
    return scenes


def results_table(results: dict[str, list[RungResult]], tol: float) -> str:
    """Markdown table law x scene -> error / run time / steps, with the recommendation per scene."""
    scenes = list(results)
    rungs = [r.rung for r in results[scenes[0]]]
    head = "| law | " + " | ".join(scenes) + " |\n|---|" + "---|" * len(scenes) + "\n"
    rows = []
    for i, name in enumerate(rungs):
        cells = []
        for s in scenes:
            r = results[s][i]
            flag = "" if r.status == 0 and r.valid else " (invalid)" if r.status == 0 else f" (status {r.status})"
            cells.append(f"{r.error:.1e} / {r.run_s:.2f} s / {r.steps}{flag}")
        rows.append(f"| {name} | " + " | ".join(cells) + " |")
    rec = "| **recommended** (tol " + f"{tol:g}) | " + " | ".join(recommend(results[s], tol) for s in scenes) + " |"
    return head + "\n".join(rows) + "\n" + rec + "\n"


__all__ += ["results_table", "law_name"]
