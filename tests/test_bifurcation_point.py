"""Period-doubling point of the two-well forced Duffing oscillator, and its derivative in damping."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxcelt.orbits.points import locate_period_doubling
from jaxcelt.orbits.shooting import stroboscopic_map

OMEGA = 1.2
T = 2 * np.pi / OMEGA


def _duffing(t, y, a):
    F, delta = a
    return jnp.array([y[1], -delta * y[1] + y[0] - y[0] ** 3 + F * jnp.cos(OMEGA * t)])


@pytest.fixture(scope="module")
def guess():
    # period-1 orbit in the right well, by plain forward iteration at F = 0.26 (stable there)
    y = jnp.array([1.0, 0.0])
    for _ in range(60):
        y, _, _ = stroboscopic_map(_duffing, y, (0.26, 0.3), period=T, rtol=1e-9, atol=1e-10)
    return y


def _locate(y, delta):
    return locate_period_doubling(_duffing, y, 0.26, lambda F, d: (F, d), lambda a: T, delta, rtol=1e-10, atol=1e-11)


def test_duffing_period_doubling_point(guess):
    bp = _locate(guess, jnp.array(0.3))
    assert int(bp.status) == 0
    # literature value F_PD ~ 0.26558 (delta = 0.3, omega = 1.2); 5 digits quoted -> 1e-5
    assert abs(float(bp.value) - 0.26558) < 1e-5
    # the defining property, independent of the bordered test function: a multiplier at -1
    # (monodromy by forward-mode differentiation of a 1e-10-tolerance solve -> 1e-7)
    assert np.min(np.abs(np.asarray(bp.multipliers) + 1.0)) < 1e-7
    assert float(bp.residual) < 1e-9


@pytest.mark.slow
def test_period_doubling_gradient_matches_finite_differences(guess):
    g = float(jax.grad(lambda d: _locate(guess, d).value)(jnp.array(0.3)))
    h = 1e-4
    fd = (float(_locate(guess, jnp.array(0.3 + h)).value) - float(_locate(guess, jnp.array(0.3 - h)).value)) / (2 * h)
    # central FD truncation O(h^2) ~ 1e-8 plus Newton noise 1e-10/h ~ 1e-6 -> 1e-4 relative is safe
    assert abs(g - fd) <= 1e-4 * abs(fd)
