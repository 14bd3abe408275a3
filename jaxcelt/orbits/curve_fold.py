"""The defining system of a fold or period-doubling curve (one-bordered, minimally augmented).

A point of a fold (period-doubling) curve of a period-k orbit of a forced ODE is a regular root of

    G(z, p1, p2) = [ chart(P(embed(z))) - z ; g(z, p1, p2) ] = 0      (n + 1 equations, n + 2 unknowns)

with P the k-period stroboscopic map in local coordinates z and g the bordered test function of A = M + s I
(`jaxcelt.orbits.points.bordered_test_function`; s = -1 fold, +1 period doubling; M the monodromy in the chart).
`FoldSystem` holds this system and what is observed at a point (multipliers, the cusp coefficient); the driver
`jaxcelt.orbits.curves.continue_bifurcation` follows it. Unknowns u = (z, p1 / s1, p2 / s2); the reference a point
is measured from is (y_ref, b, c): the chart's centre and the bordering vectors, refreshed at every accepted point
(the near-null vectors of A there, `jaxcelt.orbits.points.bordering_vectors`, signs kept continuous).

`curve_map_and_monodromy` (the map and its monodromy from the variational equations, in forward mode so that
Newton's ``jax.jacfwd`` goes through the solve) is shared with the Neimark-Sacker system
(`jaxcelt.orbits.ns_system`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array
from jaxcelt.orbits.options import ShootingOptions
from jaxcelt.orbits.points import BIFURCATION_POINT_KINDS, bordered_test_function, bordering_vectors
from jaxcelt.orbits.shooting import Chart, chart_monodromy, sort_multipliers, variational_map

__all__ = ["FoldSystem", "codim2_tests", "curve_map_and_monodromy"]


def codim2_tests(mu: np.ndarray, kind: str) -> dict[str, float]:
    """The multiplier test functions of a fold or period-doubling curve point (all of
    `jaxcelt.orbits.curves.CODIM2_TESTS` but the cusp)."""
    s0 = -BIFURCATION_POINT_KINDS[kind]  # the critical multiplier: +1 fold, -1 period doubling
    mu = np.asarray(mu)
    others = np.delete(mu, int(np.argmin(np.abs(mu - s0))))
    same, opposite = float(np.prod(others - s0).real), float(np.prod(others + s0).real)
    if kind == "fold":
        return {"1:1 resonance": same, "fold-flip": opposite}
    return {"1:2 resonance": same, "fold-flip": opposite}


def curve_map_and_monodromy(system, z: Array, args: Any, y_ref: Array) -> tuple[Array, Array, Array]:
    """(chart(P(embed(z))), monodromy in the chart, solver success) of a curve system (fields ``vector_field``,
    ``period_of``, ``k``, ``t0``, ``embed``, ``chart``, ``options``)."""
    y = system.embed(z, y_ref, args)
    y1, Phi, ok, _ = variational_map(
        system.vector_field, y, args, period=system.period_of(args), k=system.k, t0=system.t0, forward_mode=True,
        options=system.options,
    )  # fmt: skip
    M = chart_monodromy(system.embed, system.chart, z, y1, y_ref, args, Phi)
    return system.chart(y1, y_ref, args), M, ok


class FoldSystem(NamedTuple):
    """The augmented system of a fold or period-doubling curve and what is observed at its points (pure, jittable
    methods; hashable, so that a jitted stepper can be kept per system)."""

    vector_field: Callable[[Any, Array, Any], Array]
    args_of: Callable[[Array, Array], Any]
    period_of: Callable[[Any], Array]
    shift: float
    scale: tuple[float, float]
    k: int
    t0: float
    embed: Chart
    chart: Chart
    options: ShootingOptions
    cusp: bool

    extra = 2
    """unknowns after the chart coordinates z: (p1 / s1, p2 / s2)"""

    def args(self, u):
        return self.args_of(u[-2] * self.scale[0], u[-1] * self.scale[1])

    def map_and_monodromy(self, z, args, y_ref):
        return curve_map_and_monodromy(self, z, args, y_ref)

    def residual(self, u, ref):
        y_ref, b, c = ref
        z = u[:-2]
        w1, M, ok = self.map_and_monodromy(z, self.args(u), y_ref)
        g = bordered_test_function(M + self.shift * jnp.eye(z.shape[0]), b, c)
        return jnp.concatenate([w1 - z, g[None]]), ok

    def bordering(self, u, y_ref, b_old, c_old):
        _, M, _ = self.map_and_monodromy(u[:-2], self.args(u), y_ref)
        b, c = bordering_vectors(M + self.shift * jnp.eye(M.shape[0]))
        return b * jnp.sign(jnp.dot(b, b_old) + 1e-300), c * jnp.sign(jnp.dot(c, c_old) + 1e-300)

    def start(self, z0, p, y_guess):
        """(u, ref) of the start: the chart around ``y_guess``, bordering vectors there."""
        u = jnp.concatenate([z0, p])
        ones = jnp.ones(z0.shape[0]) / np.sqrt(z0.shape[0])
        return u, (y_guess, *self.bordering(u, y_guess, ones, ones))

    def recentre(self, u, t, ref):
        y_ref, b, c = ref
        y = self.embed(u[:-2], y_ref, self.args(u))

        def to_new(v):
            a = self.args(v)
            return jnp.concatenate([self.chart(self.embed(v[:-2], y_ref, a), y, a), v[-2:]])

        u_new, t_new = jax.jvp(to_new, (u,), (t,))
        # b, c: carried into the new chart only through their signs (they are re-computed there)
        b_new, c_new = self.bordering(u_new, y, b, c)
        return u_new, t_new / jnp.linalg.norm(t_new), (y, b_new, c_new)

    def observe(self, u, ref):
        y_ref, b, c = ref
        z, args = u[:-2], self.args(u)
        _, M, _ = self.map_and_monodromy(z, args, y_ref)
        n = z.shape[0]
        A = M + self.shift * jnp.eye(n)
        border = jnp.block([[A, b[:, None]], [c[None, :], jnp.zeros((1, 1))]])
        e = jnp.zeros(n + 1).at[n].set(1.0)
        q = jnp.linalg.solve(border, e)[:n]  # A q ~ 0, c.q = 1: oriented like c
        p = jnp.linalg.solve(border.T, e)[:n]  # A^T p ~ 0, b.p = 1
        out = dict(multipliers=sort_multipliers(jnp.linalg.eigvals(M)), y=self.embed(z, y_ref, args))
        if self.cusp:
            # B(q, q) = d/de M(z + e q) q at e = 0; a = 1/2 <p, B(q, q)> with |q| = 1, <p, q> = 1
            Bqq = jax.jvp(lambda zz: self.map_and_monodromy(zz, args, y_ref)[1] @ q, (z,), (q,))[1]
            out["cusp"] = 0.5 * jnp.dot(p, Bqq) / (jnp.dot(p, q) * jnp.linalg.norm(q))
        return out

    def tests(self, obs: dict, kind: str) -> dict[str, float]:
        """All test functions of a point from its (host) observation."""
        out = codim2_tests(obs["multipliers"], kind)
        if self.cusp:
            out["cusp"] = float(obs["cusp"])
        return out
