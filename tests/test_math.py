"""The float64 sin/cos of the right-hand side (`jaxcelt._math.sincos`) against numpy's libm."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxcelt._math import sincos


@pytest.mark.parametrize("R", [1.0, 10.0, 1e3, 1e5])
def test_sincos_within_2_ulp_of_numpy(R):
    # tolerance: 2 ulp of the result (libm is correctly rounded to < 1 ulp; Cephes' polynomials
    # are documented at ~1 ulp); angles and phases in runs stay far below 1e5 rad
    x = np.random.default_rng(0).uniform(-R, R, 100_000)
    s, c = jax.jit(sincos)(x)
    for got, ref in ((s, np.sin(x)), (c, np.cos(x))):
        ulp = np.spacing(np.abs(ref))
        assert np.max(np.abs(np.asarray(got) - ref) / ulp) <= 2.0


def test_sincos_special_points_and_gradient():
    x = np.array([0.0, -0.0, np.pi / 4, np.pi / 2, np.pi, -3 * np.pi / 4, 2 * np.pi, 1e-300])
    s, c = sincos(x)
    np.testing.assert_allclose(np.asarray(s), np.sin(x), rtol=0, atol=3e-16)
    np.testing.assert_allclose(np.asarray(c), np.cos(x), rtol=0, atol=3e-16)
    # exact derivatives (custom JVP), also under vmap
    xs = jnp.linspace(-20.0, 20.0, 41)
    ds = jax.vmap(jax.grad(lambda t: sincos(t)[0]))(xs)
    dc = jax.vmap(jax.grad(lambda t: sincos(t)[1]))(xs)
    np.testing.assert_allclose(np.asarray(ds), np.cos(np.asarray(xs)), rtol=0, atol=3e-16)
    np.testing.assert_allclose(np.asarray(dc), -np.sin(np.asarray(xs)), rtol=0, atol=3e-16)


def test_sincos_nan_and_float32():
    s, c = sincos(jnp.asarray([np.nan, np.inf]))
    assert np.all(np.isnan(np.asarray(s))) and np.all(np.isnan(np.asarray(c)))
    s32, c32 = sincos(jnp.asarray([0.5], jnp.float32))
    assert s32.dtype == jnp.float32
    np.testing.assert_allclose(np.asarray(s32), np.sin(0.5), rtol=1e-6)
