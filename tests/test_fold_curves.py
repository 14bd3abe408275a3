"""`jaxcelt.continue_orbit_bifurcation`: the wobblestone's fold continued in two parameters.

* slow: from the fold of the period-1 branch (docs/orbits/branches.json, 14.8801 rad/s) the curve in
  (omega_pi, q_pi) starts at the fold `locate_orbit_bifurcation` finds at q_pi = 0.04 (both are Newton solves of
  the same equations to 1e-9..1e-10 in the unknowns: 1e-6 in omega_pi), and its next points are folds too (a
  multiplier at +1, q_pi increasing from 0.04).
* fast: bad names, bounds and grouped fields raise ValueError naming the parameter.
"""

import json
from pathlib import Path

import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.physics.model import STATE_NAMES

ROOT = Path(__file__).resolve().parents[1]


def _fold_start():
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    br = next(iter(d["branches"].values()))["branch"]
    b = next(b for b in br["bifurcations"] if b["kind"] == "fold")
    return np.array([b["state"][n] for n in STATE_NAMES]), float(b["value"])


@pytest.mark.slow
def test_fold_curve_starts_at_located_fold():
    y, w = _fold_start()
    p = jc.CeltParams.paper(omega_pi=w)
    bp = jc.orbits.locate_orbit_bifurcation(p, y, "omega_pi", w, kind="fold", wrt=())
    assert int(bp.status) == 0
    curve = jc.continue_orbit_bifurcation(
        p, y, ("omega_pi", "q_pi"), ((10.0, 20.0), (0.02, 0.06)), direction=1, scale=(1.0, 0.01), ds=0.1,
        max_points=3, detect=(),
    )  # fmt: skip
    assert curve.start == 0 and len(curve.p1) == 3
    assert abs(curve.p1[0] - float(bp.value)) < 1e-6
    assert curve.p2[0] == pytest.approx(0.04, abs=1e-12)
    assert np.all(np.diff(curve.p2) > 0)
    # every point is a fold: one multiplier at +1
    assert np.max(np.min(np.abs(curve.multipliers - 1.0), axis=1)) < 1e-6
    assert list(curve.status[:2]) in ([0, 0], [0, 1])


@pytest.mark.parametrize(
    "names, match",
    [
        (("omega_pi", "q_pix"), "q_pix"),
        (("omega_pi", "eps=eps_Rx"), "eps=eps_Rx"),
        (("omega_pi", "omega_pi"), "omega_pi"),
        (("omega_pi", "eps=eps"), "eps=eps"),
        (("omega_pi",), "names"),
    ],
)
def test_bad_names(names, match):
    p = jc.CeltParams.paper(omega_pi=14.88)
    with pytest.raises(ValueError, match=match):
        jc.continue_orbit_bifurcation(p, np.zeros(13), names, ((10.0, 20.0), (0.0, 1.0)))


def test_grouped_fields_must_agree_and_bounds_name_the_parameter():
    p = jc.CeltParams.paper(omega_pi=14.88, eps_R=2e-4)
    with pytest.raises(ValueError, match="'eps=eps_R'.*differ"):
        jc.continue_orbit_bifurcation(p, np.zeros(13), ("omega_pi", "eps=eps_R"), ((10.0, 20.0), (1e-5, 1e-3)))
    p = jc.CeltParams.paper(omega_pi=14.88)
    with pytest.raises(ValueError, match="'q_pi' = 0.04 lies outside"):
        jc.continue_orbit_bifurcation(p, np.zeros(13), ("omega_pi", "q_pi"), ((10.0, 20.0), (0.05, 0.06)))


def test_the_wobblestone_curve_reuses_its_compiled_stepper_for_the_same_stone():
    # continue_bifurcation keeps its compiled stepper keyed on args_of: the wrapper hands back the same function for
    # the same stone (other start values of the two continued fields), another for another stone
    from jaxcelt.orbits.celt_curves import _args_of

    p = jc.CeltParams.paper()
    a = _args_of(p.replace(omega_pi=14.88), ("omega_pi",), ("q_pi",))
    assert a is _args_of(p.replace(omega_pi=14.9, q_pi=0.041), ("omega_pi",), ("q_pi",))
    other = _args_of(p.replace(mu=0.2), ("omega_pi",), ("q_pi",))
    assert other is not a
    assert float(a(15.0, 0.05).q_pi) == 0.05 and float(other(15.0, 0.05).mu) == 0.2
