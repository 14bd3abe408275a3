"""The sweeps' options object, the names they had before, and their old module paths."""

import warnings

import numpy as np
import pytest
from _sweep_common import KW, VALUES

import jaxcelt as jc
from jaxcelt.sweeps.api import bifurcation, sweep
from jaxcelt.sweeps.following import follow_attractor
from jaxcelt.sweeps.options import SweepOptions, resolve_options


def test_options_equal_keywords(paper_params):
    a = bifurcation(paper_params, VALUES, **KW)
    b = bifurcation(paper_params, VALUES, options=SweepOptions(**KW))
    c = sweep(paper_params, "omega_pi", VALUES, options=SweepOptions(**KW).replace(rtol=1.0), rtol=KW["rtol"])
    for r in (b, c):  # the same compiled program: bitwise
        np.testing.assert_array_equal(a.samples, r.samples)
        np.testing.assert_array_equal(a.num_steps, r.num_steps)


def test_resolve_options():
    assert resolve_options(None, {}, caller="f") == SweepOptions()
    assert resolve_options(None, {}, caller="f", defaults={"sample_periods": 50}).sample_periods == 50
    assert resolve_options(SweepOptions(rtol=1e-6), {"atol": 1e-9}, caller="f") == SweepOptions(rtol=1e-6, atol=1e-9)
    with pytest.raises(TypeError, match="sweep\\(\\) got unexpected keyword argument\\(s\\) 'rtl'"):
        resolve_options(None, {"rtl": 1e-6}, caller="sweep")
    with pytest.raises(ValueError, match="'options' must be a SweepOptions"):
        resolve_options({"rtol": 1e-6}, {}, caller="sweep")
    with pytest.raises(ValueError, match="dtype"):
        SweepOptions(dtype="float16").config()


def test_bad_keyword_is_a_type_error(paper_params):
    with pytest.raises(TypeError, match="transient"):
        bifurcation(paper_params, VALUES, transient=3)


def test_continuation_is_follow_attractor_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert jc.continuation is follow_attractor
        assert jc.follow_attractor is follow_attractor


def test_old_names_warn_and_work():
    from jaxcelt.commands.args import parse_range
    from jaxcelt.ensemble import run_lanes
    from jaxcelt.sweeps.dense import dense_trajectory

    with pytest.warns(DeprecationWarning, match="jaxcelt.sweep is deprecated"):
        from jaxcelt.sweep import parse_range as old_parse_range
    assert old_parse_range is parse_range
    with pytest.warns(DeprecationWarning):
        from jaxcelt.sweep import run_lanes as old_run_lanes
    assert old_run_lanes is run_lanes
    # the old path of a renamed function reaches the new one directly, with one warning naming it
    with pytest.warns(DeprecationWarning, match="use jaxcelt.sweeps.dense.dense_trajectory"):
        from jaxcelt.sweep import orbit
    assert orbit is dense_trajectory
    with pytest.raises(ValueError, match="periods"):
        orbit(jc.CeltParams.paper(), periods=0)
    # the old name at the new place is a thin alias that warns when called
    from jaxcelt.sweeps import dense

    with pytest.warns(DeprecationWarning, match="use jaxcelt.sweeps.dense.dense_trajectory"):
        with pytest.raises(ValueError, match="periods"):
            dense.orbit(jc.CeltParams.paper(), periods=0)


@pytest.mark.parametrize(
    "old, names",
    [
        ("sweep", ["SweepConfig", "SweepResult", "bifurcation", "sweep", "continuation", "lanes_params", "parse_range",
                   "orbit", "prepare_orbit", "run_lanes", "run_lanes_with_stats", "parameter_map", "sweep_lanes",
                   "DEFAULT_WIDTH", "MIN_DRAIN_WIDTH", "PILOT_FRACTION"]),
        ("dataset", ["SweepWriter", "to_dataset", "to_map_dataset", "to_lanes_dataset", "open_sweep", "SWEEP_FILE",
                     "DamagedChunkWarning", "LANE_FIELDS"]),
        ("regimes", ["REGIMES", "GLOBAL_MOTION", "detect_period", "classify", "regime_names"]),
        ("attractors", ["AttractorStarts", "Attractor", "AttractorCensus", "attractor_starts", "attractors",
                        "refine_attractor", "same_cycle", "group"]),
    ],
)  # fmt: skip
def test_old_module_paths_reach_every_name(old, names):
    import importlib

    module = importlib.import_module(f"jaxcelt.{old}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        for name in names:
            assert getattr(module, name) is not None, name
