"""Contact laws: registry, exact limits of the approximants vs the integral law, dissipativity, gradient safety."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.physics.contact.integral import HERTZ_S, patch_integrals
from jaxcelt.physics.contact.laws import ContactKinematics, pade_friction
from jaxcelt.physics.contact.registry import CONTACT_LAWS, law_name

B = 0.1813
APPROX = ["generalised_pade", "pade", "coulomb_spin", "coulomb"]


def _p():
    return jc.CeltParams.paper(eps=1e-14, **{k: HERTZ_S[k] for k in ("S0", "S2", "S3")})


def _fr(name, vx, vy, w, dc=0.0, ds=0.0):
    kin = ContactKinematics(*(jnp.asarray(x, dtype=float) for x in (vx, vy, w, vx, vy)))
    return np.array(jc.get_contact_law(name).friction(kin, dc, ds, _p()))


def test_registry_and_names():
    assert set(APPROX + ["integral"]) <= set(CONTACT_LAWS)
    for name in CONTACT_LAWS:
        law = jc.get_contact_law(name)
        assert law_name(law) == name and law.rolling_resistance
        assert law_name(jc.get_contact_law(name + ":norr")) == name + ":norr"
    with pytest.raises(ValueError):
        jc.get_contact_law("nope")
    with pytest.raises(ValueError):
        jc.get_contact_law("pade:maybe")


def test_pade_is_generalised_with_unit_exponents():
    p = jc.CeltParams.paper(m_Ts=1.0, m_Ms=1.0)
    kin = ContactKinematics(*(jnp.asarray(x) for x in (0.3, -0.7, 1.3, 0.2, 0.1)))
    a = np.array(jc.Pade().friction(kin, 0.1, -0.2, p))
    b = np.array(jc.GeneralisedPade().friction(kin, 0.1, -0.2, p))
    np.testing.assert_allclose(a, b, rtol=1e-14)


@pytest.mark.parametrize("name", APPROX)
def test_pure_sliding_exact(name):
    # every law gives T = v_s/|v_s| at omega_s = 0 (eps = 1e-14 so the smoothing is invisible)
    T = _fr(name, 0.6, -0.8, 0.0)
    np.testing.assert_allclose(T[:2], [0.6, -0.8], atol=1e-10)


@pytest.mark.parametrize("name", ["generalised_pade", "pade", "coulomb_spin"])
def test_pure_spin_exact(name):
    K, E, G, H = (float(x) for x in jc.contact_integrals(B))
    M = _fr(name, 0.0, 0.0, -2.0)[2]
    ref = float(patch_integrals(0.0, 0.0, -2.0, B)[2])
    assert abs(M - (-4 * E * HERTZ_S["S2"])) < 1e-10 and abs(M - ref) < 1e-6


@pytest.mark.parametrize("name", ["generalised_pade", "pade"])
def test_slopes_at_zero_slip_match_integral_law(name):
    # the Pade family is built to have the exact slopes dT/dv_s at v_s = 0 (MODEL.md section 7)
    law = jc.get_contact_law(name)
    p = _p()

    def T(v, k):
        kin = ContactKinematics(v * (k == 0), v * (k == 1), jnp.asarray(1.5), 0.0, 0.0)
        return law.friction(kin, 0.0, 0.0, p)[k]

    for k in (0, 1):
        ga = jax.grad(T)(0.0, k)
        gi = jax.grad(lambda v, k=k: patch_integrals(v * (k == 0), v * (k == 1), 1.5, B)[k])(0.0)
        assert abs(float(ga) - float(gi)) < 1e-6


def test_coulomb_spin_slopes_are_not_exact():
    # documents a limit it does not satisfy: slope at v_s = 0 is 1/sqrt(eps), not 4 G S0/|w|
    g = jax.grad(lambda v: _p_law_T("coulomb_spin", v))(0.0)
    assert float(g) > 1e3


def _p_law_T(name, v):
    kin = ContactKinematics(v, jnp.asarray(0.0), jnp.asarray(1.5), v, jnp.asarray(0.0))
    return jc.get_contact_law(name).friction(kin, 0.0, 0.0, _p())[0]


@pytest.mark.parametrize("name", APPROX + ["integral"])
def test_dissipative_and_gradient_safe(name):
    # friction power T.v_s + M_s omega_s >= 0 (MODEL.md section 9 A7), on random samples
    law = jc.get_contact_law(name)
    p = jc.hertz_params(jc.CeltParams.paper())
    rng = np.random.default_rng(0)
    X = rng.normal(size=(64, 5)) * np.array([3, 3, 3, 1, 1])
    f = jax.jit(jax.vmap(lambda x: law.friction(ContactKinematics(*x), 0.2, -0.3, p)))
    Tx, Ty, M = (np.asarray(a) for a in f(jnp.asarray(X)))
    assert np.all(Tx * X[:, 0] + Ty * X[:, 1] + M * X[:, 2] >= -1e-12)
    # gradients of the whole right-hand side at rest are finite (zero slip and spin)
    y0 = jc.initial_state(p)
    J = jax.jit(jax.jacfwd(lambda y: jc.vector_field(0.0, y, p, law)))(y0)
    assert np.all(np.isfinite(np.asarray(J)))


def test_pade_friction_kernel_matches_regression():
    # MODEL.md section 10 regression values of T_sx, T_sy, M_s through the shared kernel
    kin = ContactKinematics(*(jnp.asarray(x) for x in (-95.32158376, 33.02544353, 2.02555947, 0.0, 0.0)))
    p = jc.CeltParams.paper()
    T = np.array(pade_friction(kin, -0.2647549185, 0.4120477463, p, p.m_Ts, p.m_Ms))
    np.testing.assert_allclose(T, [-0.9454266651, 0.3268436384, 3.5416791537e-4], rtol=1e-8)


@pytest.mark.parametrize("name", APPROX)
def test_wide_batch_form_agrees(name):
    # `wide_batch` (the lane pool's wide pools) computes the Pade laws' logarithms by
    # `jaxcelt._math.log` (<= 1 ulp from libm's), the others are unchanged. Friction values and
    # their gradients agree to rounding: rtol 1e-13 (a few ulp through exp(log(.) / m) chains).
    law = jc.get_contact_law(name)
    wide = law.wide_batch()
    assert law_name(wide) == name and wide.rolling_resistance == law.rolling_resistance
    rng = np.random.default_rng(1)
    vx, vy, w = rng.normal(size=(3, 200)) * np.array([[1.0], [1.0], [3.0]])
    p = _p()

    def fr(law_, vx, vy, w):
        kin = ContactKinematics(vx, vy, w, vx, vy)
        return jnp.stack(law_.friction(kin, 0.05, -0.02, p))

    a = jax.vmap(lambda *x: fr(law, *x))(vx, vy, w)
    b = jax.vmap(lambda *x: fr(wide, *x))(vx, vy, w)
    np.testing.assert_allclose(np.asarray(b), np.asarray(a), rtol=1e-13, atol=1e-15)
    ga = jax.vmap(jax.grad(lambda *x: fr(law, *x).sum(), argnums=(0, 1, 2)))(vx, vy, w)
    gb = jax.vmap(jax.grad(lambda *x: fr(wide, *x).sum(), argnums=(0, 1, 2)))(vx, vy, w)
    np.testing.assert_allclose(np.asarray(gb), np.asarray(ga), rtol=1e-12, atol=1e-14)
    if name in ("generalised_pade", "pade"):
        assert wide.vector_log and not law.vector_log
    else:
        assert wide is law
