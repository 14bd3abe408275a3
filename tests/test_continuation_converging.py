"""A set that closes in on a stable orbit too slowly to settle is that orbit's attractor ("converging").

Known answers:

* `contraction_onto` on a linear focus x_{j+1} = r R(theta) x_j (every sample's distance to the fixed point
  shrinks by exactly r): the ratio of the last quarter's mean distance to the first quarter's is r^(3S/4)
  (to rounding, 1e-12); on a circle around the point (a torus-like set) it is exactly 1; for a period-2 orbit
  the phase that ends nearest the given point is the one compared (the same r^12).
* Through the continuation core, a forced linear oscillator x'' + c x' + x = cos(w t) continued in c: its only
  attractor is the harmonic response, a period-1 orbit with Floquet multipliers of modulus exp(-c T / 2). At
  c = 0.5 the lanes settle (periodic); at c = 0.03 and 0.01 they close in by exp(-c T / 2) per period only, are not
  periodic within the transient, and must be labelled ``converging`` with the continued orbit beside them, not
  counted as a new set (c is lowered in steps, so that each value's set lies near the previous one's).
"""

from __future__ import annotations

import numpy as np

from jaxcelt.sweeps.continuation_core import continue_section_attractors
from jaxcelt.sweeps.continuation_match import contraction_onto
from jaxcelt.sweeps.continuation_ode import forced_ode_model


def _focus(r: float, theta: float, S: int, x0=(1.0, 0.0)) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    x = [np.asarray(x0, float)]
    for _ in range(S - 1):
        x.append(r * np.array([c * x[-1][0] - s * x[-1][1], s * x[-1][0] + c * x[-1][1]]))
    return np.asarray(x)


def test_contraction_of_a_linear_focus_is_exact():
    S, r = 16, 0.98
    lanes = np.stack([_focus(r, 0.7, S, (1.0, 0.0)), _focus(r, 0.7, S, (0.0, 0.5))])
    ratio, last = contraction_onto(lanes, np.zeros(2), 1)
    assert abs(ratio - r**12) < 1e-12  # quarters of 4 samples: every distance of the last is r^12 times one of the first
    assert last < 1.0
    circle = np.stack([np.cos(np.arange(S) * 0.9), np.sin(np.arange(S) * 0.9)], axis=-1)[None]
    assert abs(contraction_onto(circle, np.zeros(2), 1)[0] - 1.0) < 1e-12


def test_contraction_onto_a_period_two_orbit():
    S, r = 16, 0.9
    a, b = np.array([1.0, 0.0]), np.array([-1.0, 0.0])
    dev = _focus(r, 0.3, S, (0.2, 0.0))  # deviations shrinking by r per sample
    pts = np.where((np.arange(S) % 2 == 0)[:, None], a + dev, b + dev)[None]
    ratio, _ = contraction_onto(pts, b, 2)
    assert abs(ratio - r**12) < 1e-12  # the odd phase: samples 13, 15 against 1, 3 (12 samples later)


def _oscillator(t, y, a):
    import jax.numpy as jnp

    c, w = a
    return jnp.stack([y[1], -c * y[1] - y[0] + jnp.cos(w * t)])


def test_slowly_attracting_orbit_is_converging_not_new():
    w = 1.3
    T = 2 * np.pi / w
    model = forced_ode_model(_oscillator, lambda c: (c, w), lambda c: T, key=f"linear oscillator w={w}")
    starts = np.array([[0.3, 0.0], [-0.4, 0.2], [0.1, -0.3], [0.5, 0.5]])
    values = [0.5, 0.3, 0.1, 0.03, 0.01]
    ds = continue_section_attractors(model, "c", values, starts, transient_periods=40, sample_periods=16,
                                     seeds_per_attractor=1)  # fmt: skip
    assert ds.sizes["attractor"] == 1 and np.all(ds.outcome.values == 0)  # one attractor id throughout
    kinds = [str(k) for k in ds.kind.values[0]]
    assert kinds[0] == "periodic"  # |mu| = 0.30: settled within 40 periods
    assert kinds[3:] == ["converging", "converging"]  # |mu| = 0.93, 0.98: not settled, closing in
    # the orbit beside it: Floquet multipliers of x'' + c x' + x are exp((-c/2 +- i sqrt(1 - c^2/4)) T)
    mu = np.exp(-np.asarray(values) * T / 2)
    assert np.all(ds.orbit_period.values[0] == 1)
    assert np.max(np.abs(ds.orbit_multiplier_max.values[0] - mu)) < 1e-6  # Newton + variational solve at 1e-9
