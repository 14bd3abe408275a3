"""`jaxcelt._compile_options.jit_anywhere`: compiler options at top level, the plain program inside another trace."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxcelt import _compile_options


def _fn(x):
    return jnp.sin(x) * jnp.exp(-x) + x**2


# another compiled program (options, batching, an outer jit): equal to rounding, a few ULP of values of order 1
RTOL = 1e-13


@pytest.mark.parametrize("filter_jit", [True, False])
def test_jit_anywhere_equal_at_top_level_and_in_every_trace(filter_jit):
    f = _compile_options.jit_anywhere(_fn, filter_jit=filter_jit)
    x = jnp.linspace(0.1, 2.0, 5)
    ref = np.asarray(_fn(x))
    np.testing.assert_allclose(f(x), ref, rtol=RTOL)
    # inside a user's jit JAX refuses compiler options on the nested program: the plain one runs
    np.testing.assert_allclose(jax.jit(lambda y: f(y) + 1.0)(x), ref + 1.0, rtol=RTOL)
    # concrete arguments, yet inside an outer trace
    np.testing.assert_allclose(jax.jit(lambda y: f(x) * y)(2.0), 2.0 * ref, rtol=RTOL)
    np.testing.assert_allclose(jax.vmap(f)(x[:, None])[:, 0], ref, rtol=RTOL)
    np.testing.assert_allclose(jax.lax.map(f, x), ref, rtol=RTOL)
    d = jnp.cos(x) * jnp.exp(-x) - jnp.sin(x) * jnp.exp(-x) + 2 * x  # d/dx of _fn, by hand
    np.testing.assert_allclose(jax.vmap(jax.grad(lambda y: f(y)))(x), d, rtol=RTOL)
    np.testing.assert_allclose(jnp.diag(jax.jacfwd(f)(x)), d, rtol=RTOL)


def test_jit_anywhere_applies_the_options_at_top_level_only(monkeypatch):
    # options XLA does not know make the top-level program fail to compile, which shows they are passed there;
    # inside another trace the plain program runs and succeeds
    monkeypatch.setattr(
        _compile_options, "compiler_options", lambda kind: {"xla_no_such_option": True} if kind == "cpu" else None
    )
    f = _compile_options.jit_anywhere(_fn)
    x = jnp.linspace(0.1, 2.0, 5)
    if jax.default_backend() == "cpu":
        with pytest.raises(Exception, match="xla_no_such_option"):
            f(x)
    np.testing.assert_allclose(jax.jit(f)(x), np.asarray(_fn(x)), rtol=RTOL)


def test_jit_anywhere_passes_the_functions_own_errors_on():
    def bad(x):
        raise ValueError("top-level compiler_options of my own")  # worded like JAX's refusal, yet at top level

    f = _compile_options.jit_anywhere(bad)
    with pytest.raises(ValueError, match="of my own"):
        f(jnp.ones(3))
    with pytest.raises(ValueError, match="of my own"):
        jax.jit(f)(jnp.ones(3))
