"""Two-parameter continuation of bifurcation points (`jaxcelt.continue_bifurcation`), on known answers.

* Mathieu x'' + (a - 2 q cos 2t) x = 0 (period pi): the period-doubling curve of the trivial orbit x = 0 (a
  multiplier -1 of the pi-map) is the lower edge a = b1(q) of the first instability tongue. Continued in (a, q)
  from q = 0.1 until q leaves [0.02, 5.2], a at every curve point with q in [0.02, 5] must match
  `scipy.special.mathieu_b(1, q)` to 1e-7 absolute (|b1| > 0.9 for q < 0.1 and up to 5.8 at q = 5, so at most
  1e-7 relative except near b1 = 0, q ~ 1.9): the corrector's Newton tolerance is 1e-9 on the unknowns and the
  ODE tolerances rtol 1e-10, atol 1e-11, so 1e-7 leaves a factor 100 (measured: 8e-11). The area-preserving
  map has a double multiplier -1 on this curve (a Jordan block): both multipliers lie within 1e-3 of -1
  (eigenvalues of a Jordan block move by the square root of the matrix error, about 1e-5 here).
* Forced Duffing x'' + 0.2 x' + x + x^3 = F cos(w t): the fold curve of period-1 orbits in (w, F), from the upper
  fold at F = 0.3 through its cusp and up the other fold branch. The cusp (zero of the fold's normal-form
  coefficient) must be found once, converged, with both multipliers real (1 and exp(-0.2 T) ~ 0.35), and be the
  lowest point of the curve in F: the curve's F has its minimum at a cusp, so no curve point lies below it
  (1e-9: the Newton tolerance) and the nearest lies at most 1e-3 above (F - F_cusp grows like s^2 with the
  arclength s from the cusp; steps of at most 0.2 put a point within 0.1 of it, 1e-3 allows a curvature of 0.1).
  Slow: the two fold values of the one-parameter branch at F = 0.3 (`continue_arclength`, folds interpolated in
  the tangent over steps up to 0.3) match the curve at F = 0.3: the upper one to 1e-3 (the curve's start point),
  the lower one, linearly interpolated between curve points up to 0.2 apart on a curved stretch, to 1e-2, and a scipy-only census (DOP853, 8 starts, 500 periods, every start settled to
  1e-6) finds two stable period-1 orbits in the middle of the wedge at F = 0.3 and one on
  either side of it.
"""

import importlib.util
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import mathieu_b

import jaxcelt as jc
from jaxcelt.orbits.branch import continue_arclength
from jaxcelt.orbits.curves import CODIM2_TESTS, codim2_tests


def _problems():
    """The test problems, defined once in scripts/bifurcation_curves_check.py (which writes the committed results)."""
    spec = importlib.util.spec_from_file_location(
        "bifurcation_curves_check", Path(__file__).resolve().parents[1] / "scripts" / "bifurcation_curves_check.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


_P = _problems()
DELTA, mathieu, duffing, mathieu_args, duffing_args, pi_period, duffing_period = (
    _P.DELTA, _P.mathieu, _P.duffing, _P.mathieu_args, _P.duffing_args, _P.pi_period, _P.duffing_period
)


def test_codim2_test_functions():
    # fold curve: multipliers (1, 0.5) -> 1:1 test 0.5 - 1, fold-flip 0.5 + 1; PD curve (-1, -0.5)
    assert codim2_tests(np.array([1.0, 0.5]), "fold") == {"1:1 resonance": -0.5, "fold-flip": 1.5}
    assert codim2_tests(np.array([-0.5, -1.0]), "period-doubling") == {"1:2 resonance": 0.5, "fold-flip": -1.5}
    assert CODIM2_TESTS["fold"][0] == "cusp"
    with pytest.raises(ValueError, match="not detected"):
        jc.continue_bifurcation(mathieu, jnp.zeros(2), mathieu_args, pi_period, (0.9, 0.1), ((0, 2), (0, 1)),
                                kind="period-doubling", detect=("cusp",))  # fmt: skip


def test_mathieu_period_doubling_curve_matches_mathieu_b_up_to_q5():
    q0 = 0.1
    c = jc.continue_bifurcation(
        mathieu, jnp.zeros(2), mathieu_args, pi_period, (1 - q0 - q0**2 / 8, q0), ((-10.0, 2.0), (0.02, 5.2)),
        kind="period-doubling", detect=("fold-flip",), ds=0.05, ds_max=0.2,
    )  # fmt: skip
    assert c.stopped == ("left the bounds", "left the bounds")
    assert c.status[0] == 2 and c.status[-1] == 2 and np.all(c.status[1:-1] <= 1)
    inside = (c.p2 >= 0.02) & (c.p2 <= 5.0)
    assert c.p2[inside].min() < 0.07 and c.p2[inside].max() > 4.8  # the whole range is covered
    np.testing.assert_array_less(np.abs(c.p1 - mathieu_b(1, c.p2))[inside], 1e-7)
    np.testing.assert_array_less(np.abs(c.multipliers + 1.0), 1e-3)
    assert c.points == []  # the other multiplier stays at -1: no fold-flip


def _hb_upper_fold(F):
    """The upper fold of the period-1 response by harmonic balance (x = a cos wt + b sin wt): a start guess."""
    A = np.linspace(0.3, 3.0, 200001)
    K = 1 + 0.75 * A**2
    disc = (2 * K - DELTA**2) ** 2 - 4 * (K**2 - F**2 / A**2)
    w = np.where(disc > 0, np.sqrt(((2 * K - DELTA**2) + np.sqrt(np.maximum(disc, 0.0))) / 2), np.nan)
    i = int(np.nanargmax(w))
    r = 1 - w[i] ** 2 + 0.75 * A[i] ** 2
    a, b = np.linalg.solve([[r, DELTA * w[i]], [-DELTA * w[i], r]], [F, 0.0])
    return float(w[i]), np.array([a, w[i] * b])


@pytest.fixture(scope="module")
def duffing_fold_curve():
    w0, y0 = _hb_upper_fold(0.3)
    return jc.continue_bifurcation(
        duffing, jnp.asarray(y0), duffing_args, duffing_period, (w0, 0.3), ((0.5, 3.0), (0.02, 0.5)),
        kind="fold", ds=0.05, ds_max=0.2,
    )  # fmt: skip


def test_duffing_fold_curve_passes_its_cusp(duffing_fold_curve):
    c = duffing_fold_curve
    cusps = [p for p in c.points if p.kind == "cusp"]
    assert len(cusps) == 1 and cusps[0].converged
    cusp = cusps[0]
    np.testing.assert_allclose(np.sort(cusp.multipliers.real), [np.exp(-DELTA * 2 * np.pi / cusp.p1), 1.0], atol=1e-6)
    assert np.all(c.p2 >= cusp.p2 - 1e-9) and c.p2.min() - cusp.p2 < 1e-3
    # the fold branches on either side of the cusp: one at lower w than the other at the same F
    i = cusp.bracket[1]
    assert 0 < i < len(c.p1) - 1 and c.tests["cusp"][i - 1] * c.tests["cusp"][i] < 0
    np.testing.assert_array_less(np.min(np.abs(c.multipliers - 1.0), axis=1), 1e-6)
    assert not [p for p in c.points if p.kind != "cusp"]  # second multiplier ~0.35: no 1:1 or fold-flip


def _census(w, F, periods=500):
    starts = [(x, v) for x in (-1.5, -0.5, 0.5, 1.5) for v in (-1.0, 1.0)]
    n, T = len(starts), 2 * np.pi / w

    def rhs(t, Y):
        x, v = Y[:n], Y[n:]
        return np.concatenate([v, -DELTA * v - x - x**3 + F * np.cos(w * t)])

    y0 = np.array([s[0] for s in starts] + [s[1] for s in starts])
    sol = solve_ivp(
        rhs, (0, periods * T), y0, method="DOP853", rtol=1e-10, atol=1e-11, t_eval=T * np.array([periods - 1, periods])
    )
    last, prev = sol.y[:, -1].reshape(2, n).T, sol.y[:, -2].reshape(2, n).T
    assert np.all(np.max(np.abs(last - prev), axis=1) < 1e-6)  # every start settled on a period-1 orbit
    orbits = []
    for y in last:
        if not any(np.max(np.abs(y - o)) < 1e-4 for o in orbits):
            orbits.append(y)
    return len(orbits)


@pytest.mark.slow
def test_duffing_fold_curve_against_one_parameter_folds_and_scipy_census(duffing_fold_curve):
    c = duffing_fold_curve
    br = continue_arclength(duffing, jnp.array([0.5, 0.0]), lambda w: (w, 0.3), duffing_period, 1.0, (0.8, 2.5),
                            ds=0.05, ds_max=0.3, rtol=1e-10, atol=1e-11)  # fmt: skip
    folds = sorted(b.value for b in br.bifurcations if b.kind == "fold")
    assert len(folds) == 2
    # the curve at F = 0.3 on each branch (linear interpolation between points <= 0.2 apart: 2e-3)
    i = [p for p in c.points if p.kind == "cusp"][0].bracket[1]
    w_a = np.interp(0.3, c.p2[:i][::-1], c.p1[:i][::-1])
    w_b = np.interp(0.3, c.p2[i:], c.p1[i:])
    # folds on the one-parameter branch are interpolated in the tangent (~ step^2 ~ 1e-3); curve: 2e-3
    # upper fold: the curve's start point lies at F = 0.3 exactly, only the branch's tangent interpolation errs
    # (measured 8e-5); lower fold: both sides interpolate linearly over a curved stretch (measured 5.3e-3)
    np.testing.assert_allclose(max(w_a, w_b), folds[1], atol=1e-3)
    np.testing.assert_allclose(min(w_a, w_b), folds[0], atol=1e-2)
    w1, w2 = sorted((w_a, w_b))
    F = 0.3
    assert _census(0.5 * (w1 + w2), F) == 2
    assert _census(w1 - 0.5 * (w2 - w1), F) == 1
    assert _census(w2 + 0.5 * (w2 - w1), F) == 1
