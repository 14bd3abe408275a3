"""Largest Lyapunov exponent: checked on systems with answers we did not compute.

* Lorenz (sigma, rho, beta) = (10, 28, 8/3): lambda_1 = 0.9056 (Sprott, "Chaos and Time-Series
  Analysis", 2003, table A.?; Wolf et al. 1985 give 0.90). Finite-time estimates over t = 1000
  scatter by ~1 %; the mean of 4 orbits is asked to be within 2 %.
* Weakly forced damped Duffing x'' + d x' + x + 0.1 x^3 = 0.2 cos(1.2 t): a stable periodic
  orbit whose Floquet multipliers are a complex pair, so by Liouville's formula both
  exponents equal half the divergence, -d/2 (exact); asked within 2 %.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.integrate.lyapunov import celt_lyapunov, celt_tangent_projection, largest_lyapunov


def lorenz(t, y, args):
    s, r, b = 10.0, 28.0, 8.0 / 3.0
    return jnp.stack([s * (y[1] - y[0]), y[0] * (r - y[2]) - y[1], y[0] * y[1] - b * y[2]])


def duffing(t, y, d):
    return jnp.stack([y[1], -d * y[1] - y[0] - 0.1 * y[0] ** 3 + 0.2 * jnp.cos(1.2 * t)])


# the step-size control measuring the state alone (default) or the state and the tangent vector; the tangent's
# derivative by a forward difference of the field (default) or by forward-mode differentiation: each within 2 %
SETTINGS = [("state", "difference"), ("all", "difference"), ("state", "jvp")]


@pytest.mark.parametrize(("error_control", "tangent"), SETTINGS)
def test_lorenz_largest_exponent(error_control, tangent):
    y0s = jnp.array([[1.0, 1.0, 20.0], [-3.0, 2.0, 25.0], [5.0, -5.0, 10.0], [0.5, 0.1, 30.0]])
    f = jax.jit(
        jax.vmap(
            lambda y0: largest_lyapunov(
                lorenz, y0, None, segment=1.0, n_segments=1000, n_transient_segments=20, error_control=error_control,
                tangent=tangent,
            )
        )
    )  # fmt: skip
    r = f(y0s)
    assert bool(np.all(r.success))
    lam = float(np.mean(r.exponent))
    assert abs(lam - 0.9056) / 0.9056 < 0.02, np.asarray(r.exponent)


@pytest.mark.parametrize(("error_control", "tangent"), SETTINGS)
@pytest.mark.parametrize("d", [0.3, 0.1])
def test_duffing_periodic_orbit_negative(d, error_control, tangent):
    T = 2 * np.pi / 1.2
    r = jax.jit(
        lambda y0: largest_lyapunov(
            duffing, y0, d, segment=T, n_segments=150, n_transient_segments=100, error_control=error_control,
            tangent=tangent,
        )
    )(jnp.array([0.1, 0.0]))  # fmt: skip
    lam = float(r.exponent)
    assert lam < 0
    assert abs(lam - (-d / 2)) / (d / 2) < 0.02, lam


def test_error_control_bad_input(paper_params):
    with pytest.raises(ValueError, match="error_control"):
        largest_lyapunov(lorenz, jnp.ones(3), None, segment=1.0, n_segments=2, error_control="tangent")
    from jaxcelt.ensemble import SweepConfig

    with pytest.raises(ValueError, match="lyapunov_error_control"):
        SweepConfig(lyapunov_error_control="none")
    # recorded in the dataset's settings (and so its fingerprint) only where a Lyapunov stage runs
    assert SweepConfig(lyapunov_periods=5).attrs()["lyapunov_error_control"] == "state"
    assert "lyapunov_error_control" not in SweepConfig().attrs()


def test_tangent_bad_input_and_settings():
    with pytest.raises(ValueError, match="tangent"):
        largest_lyapunov(lorenz, jnp.ones(3), None, segment=1.0, n_segments=2, tangent="fd")
    from jaxcelt.ensemble import SweepConfig

    with pytest.raises(ValueError, match="lyapunov_tangent"):
        SweepConfig(lyapunov_tangent="complex")
    assert SweepConfig(lyapunov_periods=5).attrs()["lyapunov_tangent"] == "difference"
    assert "lyapunov_tangent" not in SweepConfig().attrs()
    assert jc.SweepOptions(lyapunov_periods=5, lyapunov_tangent="jvp").config().lyapunov_tangent == "jvp"


def test_celt_tangents_agree(paper_params):
    # The two tangents differentiate the same discretised flow (the steps are the state's alone with the default
    # error control), so the exponents differ only by the difference quotient's error (about sqrt(eps) = 1.5e-8
    # relative per evaluation) grown by the flow: over 150 periods the main job's 27 chaotic and periodic lanes
    # differed by at most 2e-4 1/s. Here a chaotic lane (omega_pi = 17) over 20 periods, asked within 1e-5 1/s.
    p = paper_params.replace(omega_pi=17.0)
    y0 = jc.initial_state(p)
    r = {t: jax.jit(lambda y, t=t: celt_lyapunov(p, y, periods=20, transient_periods=5, tangent=t))(y0)
         for t in ("difference", "jvp")}  # fmt: skip
    assert bool(r["difference"].success) and bool(r["jvp"].success)
    # the steps are the state's in both (two compiled programs: their rounding may differ, so not asked equal)
    assert abs(int(r["difference"].num_steps) - int(r["jvp"].num_steps)) <= 0.01 * int(r["jvp"].num_steps)
    assert abs(float(r["difference"].exponent) - float(r["jvp"].exponent)) < 1e-5


def test_celt_projection_keeps_manifold(paper_params):
    # The projected tangent vector leaves |n| and c = v_A . n unchanged to first order (checked
    # by finite differences of the core's constraint_residual, which this module did not write).
    y = jc.initial_state(paper_params, omega=(0.3, -0.2, 1.5), n=(0.1, 0.05, np.sqrt(1 - 0.0125)))
    dy = jax.random.normal(jax.random.PRNGKey(0), (13,))
    dyp = celt_tangent_projection(y, dy, paper_params)
    h = 1e-6
    r_plus = jc.constraint_residual(y + h * dyp, paper_params)
    r_minus = jc.constraint_residual(y - h * dyp, paper_params)
    for k in (0, 1):  # |n|-1 and v_A . n: second order in h only
        assert abs(float(r_plus[k]) + float(r_minus[k])) / 2 < 1e-10
        assert abs(float(r_plus[k]) - float(r_minus[k])) / (2 * h) < 1e-8
    assert np.all(np.asarray(dyp[9:12]) == 0)


@pytest.mark.slow
@pytest.mark.parametrize(("tangent", "tol"), [("jvp", 1e-10), ("difference", 1e-6)])
def test_celt_vmapped_matches_single(paper_params, tangent, tol):
    # two compiled programs: their rounding differs. The forward difference divides it by its step h ~ sqrt(eps), so
    # its exponents agree to about sqrt(eps) (3.5e-8 seen over these 3 periods), the forward-mode tangent's to ~1e-12
    y0 = jc.initial_state(paper_params)
    from jaxcelt.ensemble import lanes_params

    pb = lanes_params(paper_params, "omega_pi", jnp.array([14.0, 17.0]))
    f = jax.jit(jax.vmap(lambda p, y: celt_lyapunov(p, y, periods=3, tangent=tangent)))
    rb = f(pb, jnp.stack([y0, y0]))
    r1 = jax.jit(lambda p, y: celt_lyapunov(p, y, periods=3, tangent=tangent))(paper_params.replace(omega_pi=17.0), y0)
    assert abs(float(rb.exponent[1]) - float(r1.exponent)) < tol
