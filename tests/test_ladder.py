"""Ladder of laws on a scene; recommendation; needed state components."""

import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.studies.ladder import Rung, RungResult, Scene, builtin_scenes, needed_state, recommend, run_ladder


def _r(name, err, t, status=0, valid=True):
    return RungResult(name, err, {}, t, t, 1, status, valid)


def test_recommend_cheapest_within_tolerance():
    res = [
        _r("integral", 0, 5),
        _r("a", 0.01, 1.0),
        _r("b", 0.04, 0.2),
        _r("c", 0.2, 0.01),
        _r("d", 0.0, 0.1, valid=False),
    ]
    assert recommend(res, 0.05) == "b"
    assert recommend(res, 0.001) == "integral"


def test_scene_validation():
    p = jc.CeltParams.paper()
    with pytest.raises(ValueError):
        Scene("x", p, np.asarray(jc.initial_state(p)), 1.0, ("nonsense",))
    with pytest.raises(ValueError):
        Scene("x", p, np.asarray(jc.initial_state(p)), -1.0)


def test_short_ladder_runs():
    sc = builtin_scenes()["fast_spin"]
    sc = Scene("fs", sc.params, sc.y0, 0.2, ("omega3",), n_save=21)
    res = run_ladder(sc, (Rung("integral", jc.IntegralLaw()), Rung("noslip", "noslip")))
    assert res[0].error == 0.0 and res[0].status == 0
    assert np.isfinite(res[1].error) and res[1].error > 0


@pytest.mark.slow
def test_needed_state():
    sc = builtin_scenes()
    fixed = needed_state(sc["fast_spin"])
    assert "psi" in fixed["droppable"] and "rC1" in fixed["droppable"]
    moving = needed_state(sc["base14"])
    assert "psi" in moving["needed"] and "rC1" in moving["droppable"]


def test_recommend_breaks_timing_ties_by_steps():
    # run times within 25 % are timing noise: the rung with fewer accepted steps wins
    a = RungResult("a", 0.01, {}, 0.100, 1.0, 500, 0, True)
    b = RungResult("b", 0.01, {}, 0.110, 1.0, 300, 0, True)
    c = RungResult("c", 0.01, {}, 0.300, 1.0, 100, 0, True)  # fewer steps but clearly slower
    ref = RungResult("integral", 0.0, {}, 5.0, 10.0, 300, 0, True)
    assert recommend([ref, a, b, c], 0.05) == "b"
