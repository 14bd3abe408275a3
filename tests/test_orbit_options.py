"""One options object for the orbit solvers (`jaxcelt.orbits.options.ShootingOptions`) and the former names.

* ``options=ShootingOptions(...)`` and the same settings as single keywords give the same orbit (bit for bit);
  a keyword given with ``options`` overrides that one field.
* Bad settings are a ValueError naming the field; an unknown keyword is a TypeError naming it.
* The wobblestone's public names do not warn; the renamed generic ones and the old module paths do.
"""

import dataclasses
import warnings

import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.orbits.options import ShootingOptions, resolve_options
from jaxcelt.orbits.shooting import find_periodic_orbit


def oscillator(t, y, p):
    d, w0, F, w = p
    return jnp.stack([y[1], -d * y[1] - w0**2 * y[0] + F * jnp.cos(w * t)])


P = jnp.array([0.3, 1.0, 0.5, 1.3])


def test_options_equal_keywords_and_keywords_override():
    kw = dict(rtol=1e-10, atol=1e-11, newton_tol=1e-9, newton_max_steps=20)
    a = find_periodic_orbit(oscillator, jnp.zeros(2), P, period=2 * jnp.pi / P[3], **kw)
    b = find_periodic_orbit(oscillator, jnp.zeros(2), P, period=2 * jnp.pi / P[3], options=ShootingOptions(**kw))
    np.testing.assert_array_equal(np.asarray(a.y), np.asarray(b.y))
    np.testing.assert_array_equal(np.asarray(a.multipliers), np.asarray(b.multipliers))
    assert int(a.status) == 0
    base = ShootingOptions(rtol=1e-6, newton_max_steps=3)
    assert resolve_options(base, ShootingOptions(), rtol=1e-9) == dataclasses.replace(base, rtol=1e-9)
    assert resolve_options(None, base) is base
    assert resolve_options(None, base, solver=None) is base  # None counts as not given


def test_bad_options():
    with pytest.raises(ValueError, match="rtol"):
        ShootingOptions(rtol=0.0)
    with pytest.raises(ValueError, match="newton_max_steps"):
        ShootingOptions(newton_max_steps=1.5)
    with pytest.raises(ValueError, match="options"):
        resolve_options({"rtol": 1e-9}, ShootingOptions())
    with pytest.raises(TypeError, match="rtoll"):
        resolve_options(None, ShootingOptions(), rtoll=1e-9)
    with pytest.raises(dataclasses.FrozenInstanceError):
        ShootingOptions().rtol = 1.0


def test_public_names_do_not_warn_and_former_names_do():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert jc.periodic_orbit is jc.orbits.celt.periodic_orbit
        assert jc.continue_orbit is jc.orbits.celt.continue_orbit
        assert jc.CeltOrbit is jc.orbits.CeltOrbit
    import jaxcelt.orbits.branch as branch

    for old, new in branch._RENAMED.items():
        with pytest.warns(DeprecationWarning, match=new):
            assert getattr(branch, old) is getattr(branch, new)
    for old, name in (
        ("periodic", "find_periodic_orbit"),
        ("orbit_continuation", "continue_pseudo_arclength"),
        ("orbit_continuation", "switch_at_period_doubling"),
        ("orbit_continuation", "Bifurcation"),
        ("bifurcation_point", "locate_bifurcation"),
        ("celt_orbit", "locate_orbit_bifurcation"),
    ):
        with pytest.warns(DeprecationWarning):
            assert callable(getattr(getattr(jc, old), name))
