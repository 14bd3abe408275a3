"""Periodic orbits of the wobblestone on the vibrating base, with its Floquet multipliers.

The state y (13,) = (v, omega, n, r_C, psi) lives on a manifold of dimension 8 plus two
cyclic directions (MODEL.md section 8):

* |n| = 1 and r_C3 = -rho(n) . n (the contact point on the base) fix two components;
* v_A . n = 0 (eq. 2) fixes one more;
* r_C1, r_C2 are cyclic: the vector field does not depend on them (translation invariance of
  the base plane), so they are left out of the periodicity condition and their change over
  k periods is reported as the drift;
* psi is NOT cyclic: the base vibrates along the global X1 axis, v_pi = q omega sin(omega t) E1
  (eq. 17) with E1 = E1(n, psi), so the field depends on psi; psi must return (mod 2 pi) too.

The chart z (8,) around a reference state y_ref with normal n0 and an orthonormal pair
e1, e2 normal to n0:

    n = (n0 + z6 e1 + z7 e2) / |...|,       (inverse: z6 = n.e1 / n.n0, z7 = n.e2 / n.n0)
    v_A = z0 e1 + z1 e2 + lam n0, lam such that v_A . n = 0   (inverse: z0 = v_A.e1, z1 = v_A.e2)
    omega = z2:5,  psi = z5 (wrapped to y_ref's psi +- pi on the way back),
    v = v_A - omega x rho(n),  r_C = R(n, psi)(-rho) + (X1_ref, X2_ref, 0).

The 8 multipliers of d(chart o P o embed)/dz are the physical ones. The 13 x 13 state-space
monodromy has 5 more, from the directions the chart leaves out: two exact 1s (translation of
r_C1, r_C2) and three from the constraints |n| = 1 (1: |n| is conserved by n_dot = -w x n),
r_C3 + rho . n (1: conserved) and v_A . n (exp(-kappa k T) with the Baumgarte gain kappa);
they are reported as ``trivial_multipliers``.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Unpack

import diffrax
import equinox as eqx
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import jit_anywhere
from jaxcelt._types import Array, ArrayLike, Scalar
from jaxcelt.orbits.branch import ArclengthBranch, continue_arclength
from jaxcelt.orbits.options import ShootingKeywords, ShootingOptions, resolve_options
from jaxcelt.orbits.points import BifurcationPoint, locate_bifurcation
from jaxcelt.orbits.shooting import ORBIT_STATUS, find_periodic_orbit, sort_multipliers, stroboscopic_map
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import CeltField, contact_geometry, horizontal_frame
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import check_state

GUESS_MANIFOLD_TOL = 1e-3
"""How far (|n| - 1, v_A . n, r_C3 + rho . n) a guess may be off the contact manifold."""

ORBIT_DEFAULTS = ShootingOptions(max_steps=200_000)
"""`periodic_orbit`'s options (the stone needs more solver steps per period than the generic default)."""

BRANCH_DEFAULTS = ShootingOptions(max_steps=200_000, newton_max_steps=8)
"""`continue_orbit`'s options (few Newton iterations per corrector step; a step that needs more is halved)."""

POINT_DEFAULTS = ShootingOptions(max_steps=200_000, newton_tol=1e-10)
"""`locate_orbit_bifurcation`'s options."""

__all__ = [
    "CeltOrbit",
    "periodic_orbit",
    "continue_orbit",
    "locate_orbit_bifurcation",
    "celt_chart",
    "celt_embed",
    "ORBIT_STATUS",
    "ORBIT_DEFAULTS",
    "BRANCH_DEFAULTS",
    "POINT_DEFAULTS",
]


def _basis(n0: Array) -> tuple[Array, Array]:
    """An orthonormal pair normal to n0 (smooth away from n0 = +-e1; the contact keeps n3 > 0)."""
    e1 = jnp.array([1.0, 0.0, 0.0], dtype=n0.dtype) - n0[0] * n0
    e1 = e1 / jnp.linalg.norm(e1)
    return e1, jnp.cross(n0, e1)


def celt_embed(z: Array, y_ref: Array, params: CeltParams) -> Array:
    """State y (13,) on the contact manifold from chart coordinates z (8,) around ``y_ref``."""
    n0 = y_ref[6:9] / jnp.linalg.norm(y_ref[6:9])
    e1, e2 = _basis(n0)
    n = n0 + z[6] * e1 + z[7] * e2
    n = n / jnp.linalg.norm(n)
    u = z[0] * e1 + z[1] * e2
    v_A = u - jnp.dot(u, n) / jnp.dot(n0, n) * n0
    omega, psi = z[2:5], z[5]
    rho = contact_geometry(n, omega, params).rho
    v = v_A - jnp.cross(omega, rho)
    r_C = horizontal_frame(n, psi).to_global(-rho, n)
    # the contact point's horizontal position is taken from y_ref (cyclic coordinates)
    x_A = horizontal_frame(y_ref[6:9], y_ref[12]).to_global(
        -contact_geometry(y_ref[6:9], y_ref[3:6], params).rho, y_ref[6:9]
    )
    r_C = r_C + jnp.concatenate([y_ref[9:11] - x_A[0:2], jnp.zeros(1, z.dtype)])
    return jnp.concatenate([v, omega, n, r_C, psi[None]])


def celt_chart(y: Array, y_ref: Array, params: CeltParams) -> Array:
    """Chart coordinates z (8,) = (v_A.e1, v_A.e2, omega, psi, n.e1/n.n0, n.e2/n.n0) of a state.

    psi is wrapped into (psi_ref - pi, psi_ref + pi], so that a whole turn counts as periodic.
    """
    n0 = y_ref[6:9] / jnp.linalg.norm(y_ref[6:9])
    e1, e2 = _basis(n0)
    v, omega, n = y[0:3], y[3:6], y[6:9]
    v_A = v + jnp.cross(omega, contact_geometry(n, omega, params).rho)
    psi = y_ref[12] + jnp.remainder(y[12] - y_ref[12] + jnp.pi, 2 * jnp.pi) - jnp.pi
    nn = jnp.dot(n, n0)
    return jnp.concatenate(
        [jnp.stack([jnp.dot(v_A, e1), jnp.dot(v_A, e2)]), omega, psi[None], jnp.stack([n @ e1 / nn, n @ e2 / nn])]
    )


class CeltOrbit(eqx.Module):
    """A period-k orbit of the wobblestone (`periodic_orbit`); leading batch axes under vmap."""

    y: Array
    """state (13,) at the section time t0 (on the contact manifold)"""
    k: int = eqx.field(static=True)
    """forcing periods per return"""
    period: Scalar
    """k T = 2 pi k / omega_pi [s]"""
    residual: Scalar
    """max-norm of the periodicity defect in chart coordinates (m/s, rad/s, rad, 1)"""
    multipliers: Array
    """the 8 physical Floquet multipliers (complex), by decreasing modulus"""
    trivial_multipliers: Array
    """the 5 of the 13 x 13 monodromy from translations and constraints (see module doc)"""
    monodromy: Array
    """(8, 8) in chart coordinates"""
    monodromy_full: Array
    """(13, 13) in state coordinates"""
    drift: Array
    """change of the global position (r_C1, r_C2) over k periods [m]"""
    psi_turns: Array
    """whole turns of psi over k periods (psi(kT) - psi(0) = 2 pi psi_turns on the orbit)"""
    status: Array
    """`ORBIT_STATUS`: 0 converged, 1 not converged, 2 ODE solver failed"""
    newton_steps: Array
    ode_steps: Array

    @property
    def stable(self) -> Array:
        """All physical multipliers strictly inside the unit circle."""
        return jnp.all(jnp.abs(self.multipliers) < 1.0, axis=-1)

    @property
    def max_multiplier(self) -> Array:
        """|mu| of the largest physical multiplier."""
        return jnp.abs(self.multipliers[..., 0])

    @property
    def floquet_exponent(self) -> Array:
        """log|mu_max| / (k T) [1/s]: the largest Lyapunov exponent of the orbit."""
        return jnp.log(self.max_multiplier) / self.period


def _trivial(mu_all: Array, mu_phys: Array) -> Array:
    """The 5 eigenvalues of the full monodromy left after removing the 8 physical ones (greedy)."""
    rest = mu_all
    for i in range(mu_phys.shape[0]):
        j = jnp.argmin(jnp.abs(rest - mu_phys[i]))
        rest = rest.at[j].set(jnp.inf)
    keep = jnp.argsort(jnp.isinf(rest.real), stable=True)[: mu_all.shape[0] - mu_phys.shape[0]]
    return sort_multipliers(rest[keep])


def _check_params(params) -> None:
    if not isinstance(params, CeltParams):
        raise TypeError(f"params must be a CeltParams, got {type(params).__name__}")


def _period(params: CeltParams) -> Array:
    return 2 * jnp.pi / params.omega_pi


@jit_anywhere
def _orbit(params, y_guess, t0, *, k, law, options):
    T = _period(params)
    field = CeltField(law)
    orb = find_periodic_orbit(
        field, y_guess, params, period=T, k=k, t0=t0, embed=celt_embed, chart=celt_chart, options=options
    )
    # one more plain pass for the drift and psi's winding (cheap next to the variational solve)
    y1, _, _ = stroboscopic_map(field, orb.y, params, period=T, k=k, t0=t0, options=options)
    mu_all = jnp.linalg.eigvals(jnp.where(jnp.isfinite(orb.monodromy_full), orb.monodromy_full, 0.0))
    return CeltOrbit(
        y=orb.y,
        k=k,
        period=k * T,
        residual=orb.residual,
        multipliers=orb.multipliers,
        trivial_multipliers=_trivial(mu_all, orb.multipliers),
        monodromy=orb.monodromy,
        monodromy_full=orb.monodromy_full,
        drift=y1[9:11] - orb.y[9:11],
        psi_turns=jnp.round((y1[12] - orb.y[12]) / (2 * jnp.pi)),
        status=orb.status,
        newton_steps=orb.newton_steps,
        ode_steps=orb.ode_steps,
    )


def periodic_orbit(
    params: CeltParams,
    y_guess: ArrayLike,
    *,
    k: int = 1,
    t0: float = 0.0,
    contact_law: AbstractContactLaw | str | None = None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> CeltOrbit:
    """Period-k orbit of the wobblestone near ``y_guess`` (a state at the section time t0).

    Newton (optimistix) on the stroboscopic map over k T = 2 pi k / omega_pi in the 8 chart
    coordinates of the contact manifold (`celt_chart`; r_C1, r_C2 excluded as cyclic, psi
    included); Floquet multipliers from the variational equations (`jaxcelt.orbits.shooting`).
    A good guess is the state after a long transient at t0 = m T (e.g. ``simulate`` with
    ``ts`` on the section). Vmappable over params / guesses (jit inside; lanes that fail get
    ``status`` 1 or 2, never an exception).

    Args:
        params: the stone and the base (omega_pi sets T).
        y_guess: (13,) state near the orbit at time t0, within `GUESS_MANIFOLD_TOL` of the
            contact manifold (it is projected onto it through the chart).
        k: forcing periods per return (2 for a period-doubled orbit).
        t0: section time [s] (the base's phase omega_pi t0).
        contact_law: the model's law (default: the registry's).
        options: `jaxcelt.orbits.options.ShootingOptions` (default `ORBIT_DEFAULTS`: Dopri8, rtol 1e-11,
            atol 1e-12, max_steps 200 000, newton_tol 1e-9 on the periodicity defect in chart
            coordinates, newton_max_steps 30).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``;
            each one given overrides it.
    """
    _check_params(params)
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise ValueError(f"periodic_orbit: 'k' must be a positive int, got {k!r}")
    # a guess need only be near the manifold: its chart coordinates are embedded back exactly
    # (a long default-tolerance `simulate` drifts ~1e-6 off it); garbage is still rejected
    check_state(y_guess, params, name="y_guess", tol=GUESS_MANIFOLD_TOL)
    y_guess = jnp.asarray(y_guess, dtype=float)
    if y_guess.shape != (13,):
        raise ValueError(f"periodic_orbit: 'y_guess' must have shape (13,), got {y_guess.shape}")
    opts = resolve_options(options, ORBIT_DEFAULTS, caller="periodic_orbit", **settings)
    opts = dataclasses.replace(opts, solver=opts.solver or diffrax.Dopri8())
    return _orbit(params, y_guess, jnp.asarray(t0, float), k=k, law=get_contact_law(contact_law), options=opts)


def continue_orbit(
    params: CeltParams,
    orbit: CeltOrbit,
    name: str,
    stop: float | tuple[float, float],
    *,
    ds: float = 0.05,
    ds_min: float = 1e-4,
    ds_max: float = 0.3,
    max_points: int = 300,
    contact_law: AbstractContactLaw | str | None = None,
    bisections: int = 30,
    callback=None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> ArclengthBranch:
    """Follow ``orbit`` (found at ``params``) in the parameter ``name`` to ``stop``.

    Pseudo-arclength continuation in the 8 chart coordinates of the contact manifold plus the
    parameter (`jaxcelt.orbits.branch.continue_arclength`, the chart re-centred on
    every point), so the branch passes folds; folds, period doublings (bisected) and
    Neimark-Sacker points are reported in ``bifurcations``. The section is t0 = 0 (the field
    depends on t only through the base's phase omega_pi t, so an orbit found at t0 = m T is the
    same section point).

    Args:
        params: parameters of ``orbit`` (its value of ``name`` is the start).
        orbit: a converged `CeltOrbit` (`periodic_orbit`).
        name: a scalar `CeltParams` field (omega_pi, q_pi, mu, ...).
        stop: the branch ends once it passes this value of ``name``; or a window ``(lo, hi)``
            around the start: the branch is followed both ways until each end leaves it (it
            may turn at a fold and come back on another sheet).
        ds, ds_min, ds_max, max_points: arclength step control (coordinates: m/s, rad/s, rad,
            and the parameter's own unit).
        contact_law: the model's law.
        options: `jaxcelt.orbits.options.ShootingOptions` (default `BRANCH_DEFAULTS`: rtol 1e-11,
            atol 1e-12, max_steps 200 000, newton_tol 1e-9, newton_max_steps 8 per corrector step).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``;
            each one given overrides it.
        bisections: halvings of the bracket of each period doubling and Neimark-Sacker point.
        callback: ``callback(n_points, value, accepted)`` after every corrector attempt.

    Returns:
        `jaxcelt.orbits.branch.ArclengthBranch` (``y``: states at the section t0 = 0).
    """
    _check_params(params)
    if name not in CeltParams.__dataclass_fields__ or np.ndim(getattr(params, name)) != 0:
        raise ValueError(f"continue_orbit: 'name' must be a scalar CeltParams field, got {name!r}")
    if int(np.max(np.asarray(orbit.status))) != 0 or np.ndim(orbit.status) != 0:
        raise ValueError("continue_orbit: 'orbit' must be one converged orbit (status 0)")
    lam0 = float(getattr(params, name))
    st = np.asarray(stop, dtype=float)
    if st.ndim == 1 and st.shape == (2,) and np.all(np.isfinite(st)):
        if not st[0] < lam0 < st[1]:
            raise ValueError(f"continue_orbit: 'stop' window must contain {name} = {lam0}, got {stop!r}")
        stop = (float(st[0]), float(st[1]))
    elif st.ndim != 0 or not np.isfinite(st) or float(st) == lam0:
        raise ValueError(
            f"continue_orbit: 'stop' must be a finite value other than {name} = {lam0} or a window, got {stop!r}"
        )
    else:
        stop = float(st)
    opts = resolve_options(options, BRANCH_DEFAULTS, caller="continue_orbit", **settings)

    return continue_arclength(
        CeltField(get_contact_law(contact_law)),
        orbit.y,
        _field_setter(params, name),
        _period,
        lam0,
        stop,
        ds=ds,
        ds_min=ds_min,
        ds_max=ds_max,
        max_points=max_points,
        k=orbit.k,
        embed=celt_embed,
        chart=celt_chart,
        options=dataclasses.replace(opts, solver=opts.solver or diffrax.Dopri8()),
        bisections=bisections,
        callback=callback,
    )


def _field_setter(params: CeltParams, name: str) -> Callable:
    """``lam -> params`` with the field ``name`` set to lam. The same function object comes back for the same stone
    (equal values of the other fields), so that the branch's compiled programs, keyed on it
    (`jaxcelt.orbits.branch`), serve the next branch of this stone instead of being compiled again."""
    others = tuple(
        (f.name, np.asarray(getattr(params, f.name)).tobytes()) for f in dataclasses.fields(params) if f.name != name
    )
    fn, stone = _field_setter_cached(others, name)
    stone.setdefault("params", params)  # any stone of this key: they differ only in the field fn sets
    return fn


@functools.lru_cache(maxsize=16)
def _field_setter_cached(key: tuple, name: str) -> tuple[Callable, dict]:
    """A cache of `_field_setter`'s functions, keyed on the other fields' values (bytes): 16 stones at most."""
    stone: dict = {}

    def args_of(lam):
        return eqx.tree_at(lambda p: getattr(p, name), stone["params"], jnp.asarray(lam, float))

    return args_of, stone


def locate_orbit_bifurcation(
    params: CeltParams,
    y_guess: ArrayLike,
    name: str,
    value_guess: float,
    *,
    kind: str = "fold",
    wrt: tuple[str, ...] = ("mu", "k_r", "b_Ts", "m_Ts"),
    k: int = 1,
    contact_law: AbstractContactLaw | str | None = None,
    options: ShootingOptions | None = None,
    **settings: Unpack[ShootingKeywords],
) -> BifurcationPoint:
    """Refine a fold or period doubling of a wobblestone orbit in ``name``; differentiable in ``wrt``.

    `jaxcelt.orbits.points.locate_bifurcation` in the chart of the contact manifold
    (`celt_chart`, section t0 = 0): Newton on (periodicity, bordered det(M -+ I) = 0) for the
    orbit state and the value of ``name``. ``jax.grad`` of the result's ``value`` (or ``y``)
    with respect to the fields ``wrt`` of ``params`` is the implicit-function-theorem derivative
    of the located point, e.g. ``jax.grad(lambda mu: locate_orbit_bifurcation(
    eqx.tree_at(lambda p: p.mu, params, mu), y, "omega_pi", 14.88).value)(params.mu)``.

    Args:
        params: the stone; its ``name`` field is replaced by the located value.
        y_guess, value_guess: a nearby orbit state at t0 = 0 and value of ``name`` (e.g. a
            ``Bifurcation`` of `continue_orbit`: ``b.y``, ``b.value``).
        name: the bifurcation parameter (a scalar `CeltParams` field).
        kind: ``"fold"`` (a multiplier at +1) or ``"period-doubling"`` (-1).
        wrt: the fields derivatives are carried for (the others are constants).
        k, contact_law: periods per return; the model's law.
        options: `jaxcelt.orbits.options.ShootingOptions` (default `POINT_DEFAULTS`: max_steps 200 000,
            newton_tol 1e-10, the others `ShootingOptions`' defaults).
        solver, rtol, atol, max_steps, newton_tol, newton_max_steps: single fields of ``options``;
            each one given overrides it.
    """
    _check_params(params)
    for n in (name, *wrt):
        if n not in CeltParams.__dataclass_fields__:
            raise ValueError(f"locate_orbit_bifurcation: {n!r} is not a CeltParams field")
    if name in wrt:
        raise ValueError(f"locate_orbit_bifurcation: 'wrt' must not contain the bifurcation parameter {name!r}")
    check_state(y_guess, params, name="y_guess", tol=GUESS_MANIFOLD_TOL)
    opts = resolve_options(options, POINT_DEFAULTS, caller="locate_orbit_bifurcation", **settings)
    theta = {n: jnp.asarray(getattr(params, n), float) for n in wrt}

    def args_of(lam, th):
        names = (name, *th)
        return eqx.tree_at(lambda p: [getattr(p, n) for n in names], params, [lam, *th.values()])

    return locate_bifurcation(
        CeltField(get_contact_law(contact_law)),
        jnp.asarray(y_guess, float),
        value_guess,
        args_of,
        _period,
        theta,
        kind=kind,
        k=k,
        embed=celt_embed,
        chart=celt_chart,
        options=dataclasses.replace(opts, solver=opts.solver or diffrax.Dopri8()),
    )
