"""The Lyapunov spectrum (`jaxcelt.integrate.spectrum`): known answers.

* Lorenz (sigma = 10, rho = 28, beta = 8/3) over t = 1000 after a transient of 20: lambda_1 and lambda_3 within
  1 % of (0.9056, -14.5723) (Sprott 2003; the finite-time estimate's batch-means standard error is ~0.005 and
  ~0.004 here, 0.5 % and 0.03 %); |lambda_2| < 0.01 (the neutral exponent of the flow direction decays like 1/t:
  log of the speed's ratio at the window's ends over t = 1000); the sum equals the trace -(sigma + 1 + beta) to
  1e-7 relative (an identity: log|det| of the tangent flow over the window; only the integration error is left).
* A damped linear oscillator x'' + delta x' + x = 0 (complex eigenvalues): both exponents are -delta/2 exactly;
  over t = 2000 the finite-time split of the pair, bounded by log(condition of its eigenbasis) / t, is < 1e-3.
* The wobblestone's stable period-1 orbit at omega_pi = 15.6 rad/s (docs/orbits/orbit_check.json): from a start on
  the orbit the 8 exponents tend to log|mu_i| / T of its Floquet multipliers. Real multipliers and the sum converge
  exponentially fast (1e-6 after 30 + 10 periods), each exponent of a complex pair to within (a bounded log of the
  area distortion) / t: the slow test asks for 2 / t after 100 periods (measured 0.9 / t). The sum of all 13
  exponents equals the average divergence of the field over a period (Liouville; slow test).
"""

import importlib.util
import json
from pathlib import Path

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.integrate.spectrum import CELT_PHYSICAL_DIM, celt_lyapunov_spectrum, lyapunov_spectrum

ROOT = Path(__file__).resolve().parents[1]
LORENZ_ARGS = (10.0, 28.0, 8.0 / 3.0)


def lorenz(t, y, a):
    s, r, b = a
    return jnp.stack([s * (y[1] - y[0]), y[0] * (r - y[2]) - y[1], y[0] * y[1] - b * y[2]])


def damped(t, y, delta):
    return jnp.stack([y[1], -y[0] - delta * y[1]])


def _orbit_json():
    return json.loads((ROOT / "docs" / "orbits" / "orbit_check.json").read_text())


def _script():
    spec = importlib.util.spec_from_file_location(
        "lyapunov_spectrum_check", ROOT / "scripts" / "lyapunov_spectrum_check.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_lorenz_spectrum_known_answer():
    r = jax.jit(
        lambda y0: lyapunov_spectrum(
            lorenz, y0, LORENZ_ARGS, segment=1.0, n_segments=1000, n_transient_segments=20, rtol=1e-10, atol=1e-10
        )
    )(jnp.array([1.0, 1.0, 1.0]))
    lam = np.asarray(r.exponents)
    assert int(r.status) == 0 and int(r.n_reorth) == 1000 and float(r.time) == 1000.0
    assert abs(lam[0] - 0.9056) < 0.01 * 0.9056, lam
    assert abs(lam[1]) < 0.01, lam
    assert abs(lam[2] + 14.5723) < 0.01 * 14.5723, lam
    trace = -(10.0 + 1.0 + 8.0 / 3.0)
    assert abs(lam.sum() - trace) < 1e-7 * abs(trace), lam.sum() - trace
    assert np.all(np.diff(lam) < 0)
    assert np.all(np.asarray(r.stderr) > 0) and np.all(np.asarray(r.stderr) < 0.02)
    assert r.log_growth.shape == (1000, 3) and r.trivial.shape == (0,)


def test_damped_oscillator_pair_is_half_the_damping():
    delta = 0.3
    r = lyapunov_spectrum(damped, jnp.array([1.0, 0.0]), delta, segment=1.0, n_segments=2000, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(np.asarray(r.exponents), -delta / 2, atol=1e-3)
    assert abs(float(np.sum(r.exponents)) + delta) < 1e-8


def test_vmap_and_k_below_dim():
    def run(y0, rho):
        return lyapunov_spectrum(lorenz, y0, (10.0, rho, 8.0 / 3.0), segment=0.5, n_segments=40, k=2)

    ys = jnp.array([[1.0, 1.0, 1.0], [-2.0, 3.0, 20.0]])
    rhos = jnp.array([28.0, 0.5])
    rb = jax.vmap(run)(ys, rhos)
    assert rb.exponents.shape == (2, 2) and rb.stderr.shape == (2, 2) and rb.y_final.shape == (2, 3)
    for i in range(2):
        ri = run(ys[i], rhos[i])
        np.testing.assert_allclose(np.asarray(rb.exponents[i]), np.asarray(ri.exponents), rtol=1e-10)
    assert np.all(np.asarray(rb.exponents[1]) < 0)  # rho = 0.5 < 1: the origin is a stable node


def test_bad_input():
    y = jnp.array([1.0, 1.0, 1.0])
    kw = dict(segment=1.0, n_segments=10)
    with pytest.raises(ValueError, match="'n_segments'"):
        lyapunov_spectrum(lorenz, y, LORENZ_ARGS, segment=1.0, n_segments=0)
    with pytest.raises(ValueError, match="'segment'"):
        lyapunov_spectrum(lorenz, y, LORENZ_ARGS, segment=-1.0, n_segments=10)
    with pytest.raises(ValueError, match="'k'"):
        lyapunov_spectrum(lorenz, y, LORENZ_ARGS, k=4, **kw)
    with pytest.raises(ValueError, match="'Q0'"):
        lyapunov_spectrum(lorenz, y, LORENZ_ARGS, Q0=jnp.eye(3)[:, :2], **kw)
    with pytest.raises(ValueError, match="'rtol'"):
        lyapunov_spectrum(lorenz, y, LORENZ_ARGS, rtol=0.0, **kw)
    with pytest.raises(ValueError, match="'y0'"):
        lyapunov_spectrum(lorenz, jnp.ones((2, 3)), LORENZ_ARGS, **kw)
    p = jc.CeltParams.paper()
    y0 = jc.initial_state(p)
    with pytest.raises(ValueError, match="'params'"):
        jc.lyapunov_spectrum(None, y0)
    with pytest.raises(ValueError, match="'y0'"):
        jc.lyapunov_spectrum(p, y0[:12])
    with pytest.raises(ValueError, match="'periods'"):
        jc.lyapunov_spectrum(p, y0, periods=0)
    with pytest.raises(ValueError, match="'transient_periods'"):
        jc.lyapunov_spectrum(p, y0, transient_periods=-1)
    with pytest.raises(ValueError, match="'reorth_per_period'"):
        jc.lyapunov_spectrum(p, y0, reorth_per_period=1.5)
    with pytest.raises(ValueError, match="'solver'"):
        jc.lyapunov_spectrum(p, y0, solver="tsit5")
    with pytest.raises(ValueError, match="'atol'"):
        jc.lyapunov_spectrum(p, y0, atol=float("nan"))


def test_wobblestone_orbit_real_exponents_and_sum():
    # the committed orbit at 15.6 rad/s (scripts/orbit_check.py); 30 + 10 periods from it (the frame aligns with
    # the most contracting directions like exp(-(lambda_6 - lambda_7) t) = 0.4 per period)
    d = _orbit_json()
    p = jc.CeltParams.paper(omega_pi=d["omega_pi"])
    T = 2 * np.pi / d["omega_pi"]
    floquet = np.log(np.asarray(d["multipliers_abs"])) / T
    r = jc.lyapunov_spectrum(p, jnp.asarray(d["y"]), periods=10, transient_periods=30, t0=d["t0"])
    lam = np.asarray(r.exponents)
    assert jc.lyapunov_spectrum is celt_lyapunov_spectrum
    assert int(r.status) == 0 and lam.shape == (CELT_PHYSICAL_DIM,) and int(r.n_reorth) == 10
    np.testing.assert_allclose(float(r.time), 10 * T, rtol=1e-14)
    np.testing.assert_array_equal(np.asarray(r.trivial), [0.0, 0.0, 0.0, 0.0, -0.0])  # kappa = 0
    np.testing.assert_allclose(lam[6:], floquet[6:], atol=1e-6)  # the real multipliers
    assert abs(lam.sum() - floquet.sum()) < 1e-6
    assert abs(lam[0] + lam[1] - floquet[0] - floquet[1]) < 1e-3  # the leading complex pair's sum
    assert np.all(np.diff(lam) <= 0)


@pytest.mark.slow
def test_wobblestone_orbit_spectrum_equals_floquet_exponents():
    d = _orbit_json()
    p = jc.CeltParams.paper(omega_pi=d["omega_pi"])
    orb = jc.periodic_orbit(p, jnp.asarray(d["y"]), t0=d["t0"])
    assert int(orb.status) == 0
    T = float(orb.period)
    floquet = np.log(np.abs(np.asarray(orb.multipliers))) / T
    r = jc.lyapunov_spectrum(p, orb.y, periods=100, transient_periods=20, t0=d["t0"], solver=diffrax.Tsit5())
    lam, t = np.asarray(r.exponents), float(r.time)
    assert int(r.status) == 0
    assert np.max(np.abs(lam - floquet)) < 2.0 / t, (lam - floquet) * t
    np.testing.assert_allclose(lam[6:], floquet[6:], atol=1e-6)
    assert abs(lam[0] + lam[1] - floquet[0] - floquet[1]) < 1e-4
    assert abs(lam.sum() - floquet.sum()) < 1e-6
    # Liouville: all 13 exponents (8 physical + 5 trivial) sum to the mean divergence over a period
    div = _script().mean_divergence(p, orb.y, d["t0"], T)
    assert abs(lam.sum() + float(np.sum(r.trivial)) - div) < 1e-6 * abs(div), (lam.sum(), div)
