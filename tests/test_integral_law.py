"""Integral law (eqs. 7-9): against scipy dblquad, exact limits (MODEL.md section 7), convergence."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import dblquad

import jaxcelt as jc
from jaxcelt.physics.contact.integral import (
    HERTZ_S,
    CustomProfile,
    HertzProfile,
    UniformProfile,
    patch_integrals,
    profile_moments,
)
from jaxcelt.physics.contact.laws import ContactKinematics

B = 0.1813
_pi = jax.jit(patch_integrals, static_argnames=("profile", "n_angle", "n_radial"))
K, E, G, H = (float(x) for x in jc.contact_integrals(B))


def _scipy(vx, vy, w, dc=0.0, ds=0.0, b=B):
    # Cartesian adaptive quadrature of eq. 8 with Hertz pressure: independent of our polar scheme.
    def sig(x, y):
        return 3 / (2 * np.pi) / b * np.sqrt(max(1 - x * x - y * y / b / b, 0.0)) * (1 + dc * x + ds * y / b)

    out = []
    for k in range(3):

        def fn(y, x, k=k):
            ux, uy = vx - w * y, vy + w * x
            return sig(x, y) * (ux, uy, x * uy - y * ux)[k] / np.hypot(ux, uy)

        lim = lambda x: b * np.sqrt(max(1 - x * x, 0.0))
        out.append(dblquad(fn, -1, 1, lambda x, lim=lim: -lim(x), lim, epsabs=1e-11, epsrel=1e-11)[0])
    return np.array(out)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
@pytest.mark.parametrize(
    "args",
    [
        (0.9, 0.1, 1.0, 0.1, -0.2),
        pytest.param((0.05, 0.02, 1.0, 0.0, 0.0), marks=pytest.mark.slow),
        pytest.param((0.3, -0.2, -1.0, 0.2, 0.3), marks=pytest.mark.slow),
    ],
    ids=["ICS-outside", "ICS-inside", "ICS-outside-near-rim-rolling"],
)
def test_against_scipy_dblquad(args):
    # dblquad resolves the discontinuity at the ICS adaptively (to ~1e-9); our scheme at
    # 48 x 20 nodes per arc/ray is converged to < 1e-10 (see test_convergence).
    got = np.array(_pi(*args[:3], B, *args[3:], n_angle=48, n_radial=20))
    np.testing.assert_allclose(got, _scipy(*args), atol=2e-8)


@pytest.mark.parametrize("w", [0.5, 2.0, -3.0])
def test_exact_limits_spin_and_slopes(w):
    f = lambda *a: _pi(*a, n_angle=24, n_radial=12)  # the law's default size
    # pure spin: M_s = 4 E S2 sign(w), T = 0
    Tx, Ty, M = f(0.0, 0.0, w, B)
    assert abs(float(M) - 4 * E * HERTZ_S["S2"] * np.sign(w)) < 1e-6
    assert abs(float(Tx)) < 1e-12 and abs(float(Ty)) < 1e-12
    # slopes at v_s = 0: dT_sx/dv_sx = 4 G S0/|w|, dT_sy/dv_sy = 4 H S0/|w| (autodiff through the quadrature)
    gx = jax.grad(lambda v: f(v, 0.0, w, B)[0])(0.0)
    gy = jax.grad(lambda v: f(0.0, v, w, B)[1])(0.0)
    assert abs(float(gx) - 4 * G * HERTZ_S["S0"] / abs(w)) < 1e-6
    assert abs(float(gy) - 4 * H * HERTZ_S["S0"] / abs(w)) < 1e-6


@pytest.mark.parametrize("beta", [0.0, 1.0, 2.5, -2.0])
def test_exact_limit_pure_sliding(beta):
    T = _pi(2 * np.cos(beta), 2 * np.sin(beta), 0.0, B)
    assert np.hypot(float(T[0]) - np.cos(beta), float(T[1]) - np.sin(beta)) < 1e-6
    assert abs(float(T[2])) < 1e-12  # no spin torque from symmetric pressure


def test_convergence_near_ics():
    # ICS inside the patch near its rim (eta_c = 0.94): error decreases with nodes to < 1e-9.
    args = (0.17, 0.0, 1.0)
    ref = np.array(_pi(*args, B, n_angle=96, n_radial=40))
    errs = [np.abs(np.array(_pi(*args, B, n_angle=a, n_radial=r)) - ref).max() for a, r in [(8, 6), (16, 10), (32, 16)]]
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-9


def test_profiles_moments_and_custom():
    m = profile_moments(HertzProfile())
    for k in ("S0", "S1", "S2", "S3"):
        assert abs(float(m[k]) - HERTZ_S[k]) < 1e-10
    u = profile_moments(UniformProfile())
    for i in range(4):
        assert abs(float(u[f"S{i}"]) - 1 / (np.pi * (i + 1))) < 1e-12
    # an unnormalised user profile of Hertz shape is normalised and reproduces Hertz
    cp = CustomProfile(fn=_hertz_shape)
    a = np.array(_pi(0.3, 0.1, 1.2, B, 0.1, 0.2, profile=cp))
    h = np.array(_pi(0.3, 0.1, 1.2, B, 0.1, 0.2))
    np.testing.assert_allclose(a, h, atol=1e-10)
    # uniform pure spin: M = 4 E S2 with S2 = 1/(3 pi)
    M = float(_pi(0.0, 0.0, 1.0, B, profile=UniformProfile())[2])
    assert abs(M - 4 * E / (3 * np.pi)) < 1e-6


def _hertz_shape(rho):
    return 7.0 * jnp.sqrt(jnp.maximum(1 - rho**2, 0.0))


def test_gradients_finite_difference_and_vmap():
    f = jax.jit(lambda x: jnp.stack(patch_integrals(x[0], x[1], x[2], B, x[3], x[4], n_angle=32, n_radial=16)))
    x0 = jnp.array([0.2, -0.05, 0.8, 0.1, 0.2])  # ICS inside the patch
    J = jax.jacfwd(f)(x0)
    h = 1e-6
    Jfd = np.stack([(f(x0 + h * e) - f(x0 - h * e)) / (2 * h) for e in np.eye(5)], axis=1)
    np.testing.assert_allclose(np.asarray(J), Jfd, atol=1e-6)
    # vmap over samples equals the loop
    xs = jnp.array([[0.2, -0.05, 0.8, 0.1, 0.2], [1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, -2.0, 0.0, 0.0]])
    np.testing.assert_allclose(np.asarray(jax.vmap(f)(xs)), np.stack([f(x) for x in xs]), atol=1e-13)


def test_gradient_safe_at_rest():
    # with smoothing (as used in simulate), all gradients at v_s = 0 = omega_s are finite
    p = jc.hertz_params(jc.CeltParams.paper())
    law = jc.IntegralLaw()
    ex, ey, n = jnp.eye(3)

    def loads(x):
        kin = ContactKinematics(*x)
        L = law.loads(kin, ex, ey, n, p)
        return jnp.concatenate([L.t, L.m_s, L.m_r])

    J = jax.jit(jax.jacfwd(loads))(jnp.zeros(5))
    assert np.all(np.isfinite(np.asarray(J)))
    # exact law (no smoothing) at zero slip and spin: the centre is chosen safely, grads finite
    Je = jax.jit(jax.jacfwd(lambda x: jnp.stack(patch_integrals(x[0], x[1], x[2], B))))(jnp.zeros(3))
    assert np.all(np.isfinite(np.asarray(Je)))
