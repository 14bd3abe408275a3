"""The defining system of a Neimark-Sacker curve (two-bordered, minimally augmented, for maps).

A period-k orbit of a forced ODE has a Neimark-Sacker (torus) point where a complex pair of Floquet multipliers
e^{+-i theta} lies on the unit circle. With kappa = cos(theta) as an extra unknown, the pair are the roots of
mu^2 - 2 kappa mu + 1, so B = M^2 - 2 kappa M + I (M the monodromy in local coordinates z) has a two-dimensional
null space there (the real invariant plane of the pair). Bordered with two n x 2 matrices V, W,

    [ B    W ] [ Q ]   [ 0  ]
    [ V^T  0 ] [ G ] = [ I2 ],

the 2 x 2 block G(z, kappa, p1, p2) vanishes exactly where B has rank n - 2, and is smooth there (Govaerts,
*Numerical methods for bifurcations of dynamical equilibria*, SIAM 2000; Kuznetsov, *Elements of applied
bifurcation theory*, 3rd ed., sec. 10.3.3; the system MatCont uses for maps). Two of G's four entries are
independent: a point of the curve is a regular root of

    F(z, kappa, p1, p2) = [ chart(P(embed(z))) - z ; g_a ; g_b ] = 0      (n + 2 equations, n + 3 unknowns)

with (g_a, g_b) the pair of G's entries whose gradients, restricted to the null space of the orbit equations'
Jacobian, are furthest from dependent (largest smallest singular value), chosen afresh at every accepted point
with the borders (V, W: orthonormal bases of the solutions Q and of the transposed system's, rotated to the
closest bases to the previous ones, so that G changes continuously). The fixed choice g11 = g22 = 0 is not
regular where M acts on the plane as a rotation in the bordering basis (the two equations coincide to first
order), hence the choice per point.

A root of the two chosen entries is accepted only where the other two vanish too (`G_TOL`). Past kappa = +-1
the same system continues smoothly as a neutral-saddle curve (a real pair mu, 1/mu), which is
not a bifurcation: the 1:1 and 1:2 points (kappa = 1, -1) separate the two. Where M is a multiple of I (a
two-dimensional map that is the square of another, e.g. a forced oscillator with the symmetry x -> -x, t -> t + T/2,
whose monodromy is A^2 with A's eigenvalues +-i s) B vanishes too: such a curve can meet a Neimark-Sacker curve at
a 1:2 point and the continuation may follow it (|kappa| > 1 there as well). `NSSystem` follows
`jaxcelt.orbits.curve_fold.FoldSystem`'s interface (``residual``, ``start``, ``recentre``, ``observe``,
``tests``) for the driver `jaxcelt.orbits.curves.continue_bifurcation`; unknowns u = (z, kappa, p1 / s1,
p2 / s2), reference (y_ref, V, W, entries).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array
from jaxcelt.orbits.curve_fold import curve_map_and_monodromy
from jaxcelt.orbits.options import ShootingOptions
from jaxcelt.orbits.shooting import Chart, sort_multipliers

__all__ = ["G_TOL", "NS_TESTS", "NSSystem", "ns_tests", "bordered_pair"]

NS_TESTS = ("1:1 resonance", "1:2 resonance", "1:3 resonance", "1:4 resonance", "fold-NS", "flip-NS")
"""codimension-two points detected on a Neimark-Sacker curve (`ns_tests`)"""

G_TOL = 1e-5
"""a corrector's point is accepted only where all four entries of G are below this (the two entries it solves
reach the Newton tolerance; the other two vanish with them on the curve, but not on the spurious curves where only
the chosen two vanish, which cross the Neimark-Sacker curve where that choice degenerates, e.g. near a 1:2 point
of a two-dimensional map whose monodromy is close to -I)"""

_PAIRS = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
"""candidate pairs of G's entries (row-major: g11, g12, g21, g22)"""


def bordered_pair(B: Array, V: Array, W: Array) -> tuple[Array, Array, Array]:
    """(Q, P, G) of the two-bordered system [[B, W], [V^T, 0]] [Q; G] = [0; I2] and its transpose
    [[B^T, V], [W^T, 0]] [P; G^T] = [0; I2]: Q, P (n, 2) span near-null spaces of B and B^T, G (2, 2)."""
    n = B.shape[0]
    border = jnp.block([[B, W], [V.T, jnp.zeros((2, 2))]])
    rhs = jnp.concatenate([jnp.zeros((n, 2)), jnp.eye(2)])
    sol = jnp.linalg.solve(border, rhs)
    sol_t = jnp.linalg.solve(border.T, rhs)
    return sol[:n], sol_t[:n], sol[n:]


def _closest_basis(Q: Array, V_old: Array) -> Array:
    """The orthonormal basis of span(Q) closest to V_old (orthogonal Procrustes)."""
    Qo, _ = jnp.linalg.qr(Q)
    U, _, Vt = jnp.linalg.svd(Qo.T @ V_old)
    return Qo @ U @ Vt


def ns_tests(mu: np.ndarray, kappa: float) -> dict[str, float]:
    """The test functions of a Neimark-Sacker curve point (`NS_TESTS`): kappa - 1, kappa + 1, kappa + 1/2, kappa
    (1:1, 1:2, 1:3, 1:4 resonances) and Re prod (mu - 1), Re prod (mu + 1) over the multipliers other than the
    pair (fold-NS, flip-NS: a third multiplier through +1 or -1)."""
    mu = np.asarray(mu, dtype=complex)
    root = complex(kappa) + np.sqrt(complex(kappa) ** 2 - 1)
    others = list(mu)
    for r in (root, 1 / root):
        others.pop(int(np.argmin(np.abs(np.asarray(others) - r))))
    others = np.asarray(others)
    return {
        "1:1 resonance": float(kappa - 1.0),
        "1:2 resonance": float(kappa + 1.0),
        "1:3 resonance": float(kappa + 0.5),
        "1:4 resonance": float(kappa),
        "fold-NS": float(np.prod(others - 1.0).real),
        "flip-NS": float(np.prod(others + 1.0).real),
    }


class NSSystem(NamedTuple):
    """The augmented system of a Neimark-Sacker curve and what is observed at its points (pure, jittable
    methods; hashable)."""

    vector_field: Callable[[Any, Array, Any], Array]
    args_of: Callable[[Array, Array], Any]
    period_of: Callable[[Any], Array]
    scale: tuple[float, float]
    k: int
    t0: float
    embed: Chart
    chart: Chart
    options: ShootingOptions

    extra = 3
    """unknowns after the chart coordinates z: (kappa, p1 / s1, p2 / s2)"""

    def args(self, u):
        return self.args_of(u[-2] * self.scale[0], u[-1] * self.scale[1])

    def map_and_monodromy(self, z, args, y_ref):
        return curve_map_and_monodromy(self, z, args, y_ref)

    def _parts(self, u, y_ref, V, W):
        z, kappa = u[:-3], u[-3]
        w1, M, ok = self.map_and_monodromy(z, self.args(u), y_ref)
        B = M @ M - 2.0 * kappa * M + jnp.eye(z.shape[0])
        Q, P, G = bordered_pair(B, V, W)
        return w1 - z, G, Q, P, M, ok

    def residual(self, u, ref):
        """(the n + 2 equations, ok): ok also requires all four entries of G below `G_TOL` (a root of the two
        chosen entries where the other two do not vanish is not a Neimark-Sacker point)."""
        y_ref, V, W, entries = ref
        r, G, _, _, _, ok = self._parts(u, y_ref, V, W)
        return jnp.concatenate([r, G.ravel()[entries]]), ok & (jnp.max(jnp.abs(G)) < G_TOL)

    def _entries(self, u, y_ref, V, W):
        """The pair of G's entries with the most independent gradients on the null space of the orbit equations."""
        J = jax.jacfwd(lambda v: jnp.concatenate([x.ravel() for x in self._parts(v, y_ref, V, W)[:2]]))(u)
        n = u.shape[0] - 3
        _, _, vt = jnp.linalg.svd(J[:n])
        Jg = J[n:] @ vt[n:].T  # (4, 3): G's gradients along the orbit equations' null space
        smallest = jax.vmap(lambda ij: jnp.linalg.svd(Jg[ij], compute_uv=False)[-1])(jnp.asarray(_PAIRS))
        return jnp.asarray(_PAIRS)[jnp.argmax(smallest)]

    def _borders(self, u, y_ref, V_old, W_old):
        _, _, Q, P, _, _ = self._parts(u, y_ref, V_old, W_old)
        V, W = _closest_basis(Q, V_old), _closest_basis(P, W_old)
        return V, W, self._entries(u, y_ref, V, W)

    def start(self, z0, p, y_guess):
        """(u, ref) of the start: kappa = cos(arg mu) of the complex multiplier nearest the unit circle at the
        guess, borders from the two smallest singular values of B there."""
        _, M, _ = self.map_and_monodromy(z0, self.args_of(p[0] * self.scale[0], p[1] * self.scale[1]), y_guess)
        mu = jnp.linalg.eigvals(M)
        score = jnp.abs(jnp.abs(mu) - 1.0) + jnp.where(jnp.abs(mu.imag) > 1e-12, 0.0, 1e3)
        kappa = jnp.cos(jnp.angle(mu[jnp.argmin(score)]))
        B = M @ M - 2.0 * kappa * M + jnp.eye(M.shape[0])
        U, _, Vt = jnp.linalg.svd(B)
        u = jnp.concatenate([z0, kappa[None], p])
        return u, (y_guess, *self._borders(u, y_guess, Vt[-2:].T, U[:, -2:]))

    def recentre(self, u, t, ref):
        y_ref, V, W, _ = ref
        y = self.embed(u[:-3], y_ref, self.args(u))

        def to_new(v):
            a = self.args(v)
            return jnp.concatenate([self.chart(self.embed(v[:-3], y_ref, a), y, a), v[-3:]])

        u_new, t_new = jax.jvp(to_new, (u,), (t,))
        return u_new, t_new / jnp.linalg.norm(t_new), (y, *self._borders(u_new, y, V, W))

    def observe(self, u, ref):
        y_ref = ref[0]
        z, args = u[:-3], self.args(u)
        _, M, _ = self.map_and_monodromy(z, args, y_ref)
        return dict(multipliers=sort_multipliers(jnp.linalg.eigvals(M)), y=self.embed(z, y_ref, args), kappa=u[-3])

    def tests(self, obs: dict, kind: str) -> dict[str, float]:
        """All test functions of a point from its (host) observation."""
        return ns_tests(obs["multipliers"], float(obs["kappa"]))
