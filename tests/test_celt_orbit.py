"""`jaxcelt.periodic_orbit` on the wobblestone.

Fast: the chart of the contact manifold (round trip, states on the manifold, psi wrapping),
input validation. Slow: the period-1 orbit at omega_pi = 15.6 rad/s reached from rest at
psi0 = 157.5 deg (scripts/orbit_check.py), checked against things computed independently:

* its 8 multipliers against a central-difference monodromy of the numpy/scipy reference model
  (DOP853, rtol 1e-12, h = 1e-5): 1e-5 (FD truncation ~h^2 and integrator noise ~1e-12/h ~1e-7);
* log|mu_max| / T against `celt_lyapunov` over 1000 periods: 2 % (finite-time average of a
  complex pair's growth, bias ~ log(condition of its eigenbasis) / (1000 T));
* the trivial multipliers (translations, |n|, r_C3, v_A . n with kappa = 0) are 1 (1e-6);
* the orbit does not drift (period-1 bounded regime; drift < 1e-8 m per period).
"""

import importlib.util
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.orbits.celt import celt_chart, celt_embed

ROOT = Path(__file__).resolve().parents[1]


def test_chart_round_trip_stays_on_manifold(paper_params):
    p = paper_params
    y_ref = jc.initial_state(
        p, omega=(0.3, -0.2, 1.1), n=(0.1, -0.2, np.sqrt(0.95)), psi=2.9, v_A=(0.05, 0.025, 0.0), position=(0.3, -0.1)
    )
    z0 = celt_chart(y_ref, y_ref, p)
    np.testing.assert_allclose(np.asarray(celt_embed(z0, y_ref, p)), np.asarray(y_ref), atol=1e-15)
    rng = np.random.default_rng(0)
    for _ in range(5):
        z = z0 + 0.05 * rng.standard_normal(8)
        y = celt_embed(jnp.asarray(z), y_ref, p)
        np.testing.assert_allclose(np.asarray(celt_chart(y, y_ref, p)), z, atol=1e-14)
        dn, c, h = (float(x) for x in jc.constraint_residual(y, p))
        assert abs(dn) < 1e-15 and abs(c) < 1e-15 and abs(h) < 1e-15
    # a whole turn of psi is the same chart point
    y2 = y_ref.at[12].add(2 * np.pi)
    np.testing.assert_allclose(np.asarray(celt_chart(y2, y_ref, p)), np.asarray(z0), atol=1e-14)


def test_bad_input(paper_params):
    y = jc.initial_state(paper_params)
    with pytest.raises(ValueError, match="'k'"):
        jc.periodic_orbit(paper_params, y, k=0)
    with pytest.raises(ValueError, match="off the contact manifold"):
        jc.periodic_orbit(paper_params, y.at[2].add(0.1))
    with pytest.raises(ValueError, match="newton_tol"):
        jc.periodic_orbit(paper_params, y, newton_tol=-1.0)


@pytest.mark.slow
def test_period_one_orbit_at_15_6_against_scipy_fd_and_lyapunov():
    spec = importlib.util.spec_from_file_location("orbit_check", ROOT / "scripts" / "orbit_check.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    r = mod.check(periods=1000)
    assert r["status"] == 0 and r["residual"] < 1e-9
    assert r["stable"]
    assert r["reference_fd_defect"] < 1e-7  # the orbit is periodic in the reference model too
    assert r["multiplier_max_abs_diff_vs_scipy_fd"] < 1e-5, r
    assert r["lyapunov_rel_diff"] < 0.02, r
    np.testing.assert_allclose(r["trivial_multipliers_abs"], 1.0, atol=1e-6)
    assert np.max(np.abs(r["drift_m"])) < 1e-8


@pytest.mark.slow
def test_continue_orbit_in_omega_pi_is_smooth():
    # a short stretch of the 15.6 rad/s orbit in omega_pi: the branch reaches 15.9, multipliers
    # move continuously (|mu| changes < 0.05 between points at most 0.3 apart in arclength) and
    # nothing crosses the unit circle; the branch's orbit at a point is a periodic orbit by an
    # independent Newton solve (periodic_orbit from that point at that omega_pi, 1e-8)
    spec = importlib.util.spec_from_file_location("orbit_check", ROOT / "scripts" / "orbit_check.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    p = jc.CeltParams.paper(omega_pi=15.6)
    yg, t0 = mod.guess(p)
    orb = jc.periodic_orbit(p, yg, t0=t0)
    br = jc.continue_orbit(p, orb, "omega_pi", 15.9)
    assert br.stopped == "end value reached" and br.values[-1] >= 15.9
    assert np.all(np.diff(br.values) > 0)
    np.testing.assert_allclose(np.abs(br.multipliers[0]), np.abs(np.asarray(orb.multipliers)), atol=1e-8)
    assert np.max(np.abs(np.diff(np.abs(br.multipliers), axis=0))) < 0.05
    assert br.bifurcations == [] and bool(np.all(br.stable))
    i = len(br.values) // 2
    again = jc.periodic_orbit(jc.CeltParams.paper(omega_pi=float(br.values[i])), br.y[i], t0=0.0)
    assert int(again.status) == 0
    np.testing.assert_allclose(np.asarray(again.y), br.y[i], atol=1e-8)
    with pytest.raises(ValueError, match="'name'"):
        jc.continue_orbit(p, orb, "nope", 15.9)
    with pytest.raises(ValueError, match="'stop'"):
        jc.continue_orbit(p, orb, "omega_pi", (16.0, 20.0))
