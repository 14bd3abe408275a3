"""The float64 sin/cos and log of the right-hand side (`jaxcelt._math.sincos`, `jaxcelt._math.log`)
against numpy's libm."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxcelt._math import log, sincos


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


@pytest.mark.parametrize("normal", [False, True])
def test_log_within_1_ulp_of_numpy(normal):
    # tolerance: 1 ulp of the result (fdlibm documents its log at < 1 ulp; libm is correctly
    # rounded to < 1 ulp); arguments over the whole normal range and densely near 1, where
    # log x is small and the mantissa reduction matters most. ``normal=True`` (no special-value
    # handling) must give the same values on positive normal arguments.
    rng = np.random.default_rng(0)
    x = np.concatenate([
        np.exp(rng.uniform(-708.0, 709.0, 200_000)), rng.uniform(0.5, 2.0, 200_000),
        [2.2250738585072014e-308, np.nextafter(1.0, 0.0), np.nextafter(1.0, 2.0), 1.7976931348623157e308],
    ])  # fmt: skip
    got, ref = np.asarray(jax.jit(lambda x: log(x, normal=normal))(x)), np.log(x)
    err = np.abs(got - ref)
    assert np.max(err / np.spacing(np.abs(ref))) <= 1.0
    assert np.asarray(log(1.0, normal=normal)) == 0.0
    # derivative 1/x (custom JVP), to rounding of one division
    xs = jnp.linspace(0.1, 50.0, 41)
    d = jax.vmap(jax.grad(lambda x: log(x, normal=normal)))(xs)
    np.testing.assert_allclose(np.asarray(d), 1 / np.asarray(xs), rtol=1e-15)


def test_log_special_values_and_gradient():
    x = jnp.asarray([0.0, -0.0, -1.0, np.inf, -np.inf, np.nan])
    got = np.asarray(jax.jit(log)(x))
    np.testing.assert_array_equal(got, np.asarray(jax.jit(jnp.log)(x)))  # -inf, -inf, nan, inf, nan, nan
    # derivative 1/x (custom JVP), also under vmap; to rounding of one division
    xs = jnp.linspace(0.1, 50.0, 41)
    d = jax.vmap(jax.grad(log))(xs)
    np.testing.assert_allclose(np.asarray(d), 1 / np.asarray(xs), rtol=1e-15)
    l32 = log(jnp.asarray([2.0], jnp.float32))
    assert l32.dtype == jnp.float32
    np.testing.assert_allclose(np.asarray(l32), np.log(2.0), rtol=1e-6)
