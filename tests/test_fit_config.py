"""The options object of a fit (`jaxcelt.identify.options.FitOptions`): checks, and how `fit` takes it."""

import dataclasses

import pytest

import jaxcelt as jc
from jaxcelt.identify import FitOptions
from jaxcelt.identify.strategies import config_of

PAPER = jc.CeltParams.paper()


def test_defaults_are_fit_defaults():
    import inspect

    sig = inspect.signature(jc.fit).parameters
    for f in dataclasses.fields(FitOptions):
        assert sig[f.name].default == f.default or (f.name == "free" and tuple(sig[f.name].default) == f.default)
        assert sig[f.name].kind is inspect.Parameter.KEYWORD_ONLY


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        (dict(optimiser="sgd"), "optimiser"),
        (dict(max_iter=0), "max_iter"),
        (dict(free=("mu", "nope")), "unknown parameter"),
        (dict(free=("omega_pi",)), "cannot be fitted"),
        (dict(free=("mu", "mu")), "free"),
        (dict(windows=0), "windows"),
        (dict(window_states="guess"), "window_states"),
    ],
)
def test_bad_options_raise(changes, match):
    with pytest.raises(ValueError, match=match):
        FitOptions(**changes)


def test_frozen_and_keyword_only():
    c = FitOptions(free=["mu", "k_r"], windows=2)
    assert c.free == ("mu", "k_r")
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.windows = 3
    with pytest.raises(TypeError):
        FitOptions(("mu",))
    assert c.replace(windows=3).windows == 3 and c.windows == 2


def test_keywords_override_fields_of_options():
    # the rule of every options object in jaxcelt: options= as the base, a keyword that differs from its default
    # replaces that field
    base = FitOptions(free=("mu",), max_iter=5)
    kw = {f.name: f.default for f in dataclasses.fields(FitOptions)}
    assert FitOptions.from_keywords(kw, base) is base
    assert FitOptions.from_keywords({**kw, "windows": 2}, base) == base.replace(windows=2)
    data = jc.MeasuredData((jc.Trajectory(ts=[0.0, 0.1], obs={"omega": [[0, 0, 1.0]] * 2},
                                          sigma={"omega": [1.0, 1, 1]}, omega_pi=17.0, q_pi=0.0),))  # fmt: skip
    with pytest.raises(ValueError, match="FitOptions"):
        jc.fit(data, PAPER, options={"windows": 2})


def test_strategies_merge_keywords_into_a_config():
    base = FitOptions(free=("mu",), max_iter=5)
    assert config_of({"options": base}) is base
    assert config_of({"options": base, "windows": 2}) == base.replace(windows=2)
    assert config_of({"max_iter": 7}) == FitOptions(max_iter=7)
