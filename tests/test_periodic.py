"""Periodic orbits and Floquet multipliers of forced ODEs (`jaxcelt.orbits.shooting`), on known answers.

* Linear damped forced oscillator x'' + d x' + w0^2 x = F cos(w t): the periodic orbit is the
  analytic steady state and the multipliers are exp((-d/2 +- i w_d) T), w_d = sqrt(w0^2 - d^2/4)
  (exact). Asked to 1e-9: Dopri8 at rtol 1e-12 has a global error ~1e-11 over one period of an
  O(1) solution, and the monodromy is the derivative of that same discrete flow.
* Mathieu x'' + (a - 2 q cos 2t) x = 0 (period pi): the boundaries of the first instability
  tongue, where tr M = -2 (a multiplier at -1), located by bisection in a, against the
  Ince-Strutt series (Abramowitz & Stegun 20.2.25) b1(q), a1(q) truncated after q^5; the
  tolerance is twice the first omitted term (49 q^6 / 589824) plus the bisection tolerance.
* Forced Duffing x'' + d x' + a x + b x^3 = F cos(w t): the period-1 orbit equals the section
  point of a long scipy DOP853 integration (independent integrator, transient decayed by
  |mu|^400 < 1e-20), and det M = exp(-d T) (Liouville: det M = exp of the integral of tr J, exact).
"""

import jax
import jax.numpy as jnp
import numpy as np
from scipy.integrate import solve_ivp

from jaxcelt.orbits.shooting import find_periodic_orbit

TIGHT = dict(rtol=1e-12, atol=1e-13)
LANES = 6  # every test runs the same compiled program: a batch of 6 lanes


def oscillator(t, y, p):
    """x'' + d x' + (a + c cos(w t)) x + b x^3 = F cos(w t); p = (d, a, c, b, F, w)."""
    d, a, c, b, F, w = p
    x, v = y
    return jnp.stack([v, -d * v - (a + c * jnp.cos(w * t)) * x - b * x**3 + F * jnp.cos(w * t)])


@jax.jit
@jax.vmap
def _orbit(y, p):
    return find_periodic_orbit(oscillator, y, p, period=2 * jnp.pi / p[5], **TIGHT)


def orbits(guesses, params):
    """Pad to LANES lanes (repeating the last) and run the shared program."""
    guesses, params = np.atleast_2d(guesses), np.atleast_2d(params)
    n = max(len(guesses), len(params))
    g = np.broadcast_to(guesses, (n, 2)) if len(guesses) == 1 else guesses
    p = np.broadcast_to(params, (n, 6)) if len(params) == 1 else params
    pad = LANES - n
    g = np.concatenate([g, np.repeat(g[-1:], pad, 0)])
    p = np.concatenate([p, np.repeat(p[-1:], pad, 0)])
    out = _orbit(jnp.asarray(g, float), jnp.asarray(p, float))
    return jax.tree_util.tree_map(lambda x: np.asarray(x)[:n], out)


def test_linear_oscillator_steady_state_and_multipliers():
    d, w0, F, w = 0.3, 1.5, 0.7, 2.1
    T = 2 * np.pi / w
    orb = orbits([1.0, -1.0], [d, w0**2, 0.0, 0.0, F, w])
    assert orb.status.tolist() == [0]
    X = F / (w0**2 - w**2 + 1j * d * w)  # x(t) = Re(X exp(i w t))
    np.testing.assert_allclose(orb.y[0], [X.real, -w * X.imag], rtol=0, atol=1e-9)
    wd = np.sqrt(w0**2 - d**2 / 4)
    expected = np.exp((-d / 2 + np.array([1j, -1j]) * wd) * T)
    np.testing.assert_allclose(np.sort_complex(orb.multipliers[0]), np.sort_complex(expected), rtol=0, atol=1e-9)
    assert bool(orb.stable[0])
    assert orb.residual[0] < 1e-10


def test_mathieu_period_doubling_boundaries_match_ince_strutt():
    # x'' + (a - 2 q cos 2t) x = 0; the zero solution is the orbit, tr M + 2 changes sign at
    # the tongue's edges b1(q) < a < a1(q). Six bisections (3 q x 2 edges) run as six lanes.
    qs = np.array([0.1, 0.2, 0.4])
    q = np.repeat(qs, 2)
    mid = 1 - q**2 / 8  # inside the tongue (tr M < -2)
    lo = np.where(np.arange(6) % 2 == 0, mid - q - 0.1, mid)
    hi = np.where(np.arange(6) % 2 == 0, mid, mid + q + 0.1)
    sign_lo = None
    for _ in range(45):  # bracket 0.2..0.5 wide -> < 1e-14
        a = 0.5 * (lo + hi)
        p = np.stack([np.zeros(6), a, -2 * q, np.zeros(6), np.zeros(6), 2 * np.ones(6)], axis=1)
        orb = orbits(np.zeros((6, 2)), p)
        assert orb.status.tolist() == [0] * 6
        g = np.trace(orb.monodromy, axis1=1, axis2=2) + 2.0
        if sign_lo is None:  # outside the tongue tr M > -2: at the lower edge g(lo) > 0, upper edge g(hi) > 0
            sign_lo = np.where(np.arange(6) % 2 == 0, 1.0, -1.0)
        move_lo = np.sign(g) == sign_lo
        lo, hi = np.where(move_lo, a, lo), np.where(move_lo, hi, a)
    a = 0.5 * (lo + hi)
    b1 = 1 - qs - qs**2 / 8 + qs**3 / 64 - qs**4 / 1536 - 11 * qs**5 / 36864
    a1 = 1 + qs - qs**2 / 8 - qs**3 / 64 - qs**4 / 1536 + 11 * qs**5 / 36864
    tol = 2 * 49 * qs**6 / 589824 + 1e-10
    np.testing.assert_array_less(np.abs(a[0::2] - b1), tol)
    np.testing.assert_array_less(np.abs(a[1::2] - a1), tol)


DUFF = (0.25, 1.0, 0.0, 0.5, 0.3, 1.3)  # d, alpha, c = 0, beta, F, w


def test_duffing_orbit_matches_brute_force_and_liouville():
    d, al, _, be, F, w = DUFF
    T = 2 * np.pi / w
    # the complex pair contracts by exp(-d T / 2) = 0.55 per period: 80 periods -> 1e-21
    ref = solve_ivp(
        lambda t, y: [y[1], -d * y[1] - al * y[0] - be * y[0] ** 3 + F * np.cos(w * t)],
        (0, 80 * T),
        [0.0, 0.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-13,
        t_eval=[80 * T],
    ).y[:, -1]
    # a bad lane (NaN guess) in the batch must not poison the others
    orb = orbits([[0.0, 0.0], [0.5, 0.2], [np.nan, 0.0]], DUFF)
    assert orb.status.tolist() == [0, 0, 2]
    assert np.all(np.isnan(orb.multipliers[2]))
    for i in (0, 1):
        np.testing.assert_allclose(orb.y[i], ref, rtol=0, atol=1e-8)
        assert abs(np.prod(orb.multipliers[i]).real - np.exp(-d * T)) < 1e-9
        assert abs(np.linalg.det(orb.monodromy[i]) - np.exp(-d * T)) < 1e-9
        assert bool(orb.stable[i])


def test_not_converged_is_flagged():
    # a far guess with a 1-step Newton budget cannot meet the tolerance (another program)
    p = jnp.asarray(DUFF)
    f = jax.jit(lambda y: find_periodic_orbit(oscillator, y, p, period=2 * jnp.pi / p[5], newton_max_steps=1, **TIGHT))
    orb = f(jnp.array([2.0, -1.0]))
    assert int(orb.status) == 1
    assert not bool(orb.converged)
    assert float(orb.residual) > 1e-6
