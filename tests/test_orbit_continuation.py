"""Natural continuation of forced-ODE orbits with bifurcation detection (`jaxcelt.orbits.branch`).

Double-well Duffing x'' + 0.3 x' - x + x^3 = F cos(1.2 t), right-well period-1 orbit continued in
F: its multiplier passes -1 (period doubling). Checked by brute force with scipy DOP853 (an
independent integrator, no Newton): 2 % below the located F the attractor reached from the
orbit's neighbourhood is period-1 (section points repeat to 1e-6 after 800 periods), 2 % above
it is period-2 (points alternate by more than 1e-3 and repeat every second period to 1e-6).
Below, the period-1 multiplier is about -0.86 (0.86^800 ~ 1e-52); above, the orbit is near
the bifurcation and its period-2 neighbour attracts slowly, so 800 periods is the margin.
"""

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jaxcelt.orbits.branch import continue_natural

W = 1.2
T = 2 * np.pi / W
BASE = np.array([0.3, -1.0, 0.0, 1.0, 0.2, W])  # d, a, c, b, F, w


def oscillator(t, y, p):
    d, a, c, b, F, w = p
    x, v = y
    return jnp.stack([v, -d * v - (a + c * jnp.cos(w * t)) * x - b * x**3 + F * jnp.cos(w * t)])


def sections(F, y0, periods=800, last=4):
    f = lambda t, y: [y[1], -0.3 * y[1] + y[0] - y[0] ** 3 + F * np.cos(W * t)]  # noqa: E731
    ts = T * np.arange(periods - last, periods + 1)
    s = solve_ivp(f, (0, periods * T), y0, method="DOP853", rtol=1e-11, atol=1e-12, t_eval=ts)
    return s.y.T


@pytest.mark.slow
def test_duffing_period_doubling_located_by_continuation_matches_brute_force():
    y0 = sections(0.24, [1.0, 0.0], periods=100, last=0)[-1]
    br = continue_natural(
        oscillator,
        y0,
        lambda F: jnp.asarray(BASE).at[4].set(F),
        lambda a: 2 * jnp.pi / a[5],
        np.linspace(0.24, 0.30, 13),
        bisections=30,
        rtol=1e-12,
        atol=1e-13,
    )
    assert br.stopped_at is None
    pd = [b for b in br.bifurcations if b.kind == "period-doubling"]
    assert len(pd) == 1 and not [b for b in br.bifurcations if b.kind == "fold"]
    F_pd = pd[0].value
    assert 0.24 < F_pd < 0.30
    assert np.min(np.abs(pd[0].multipliers + 1)) < 1e-6
    below = sections(0.98 * F_pd, br.y[0])
    assert np.max(np.abs(np.diff(below, axis=0))) < 1e-6
    above = sections(1.02 * F_pd, br.y[0])
    assert np.min(np.abs(above[1:] - above[:-1])) > 1e-3
    assert np.max(np.abs(above[2:] - above[:-2])) < 1e-6
