"""Lanes integrated on past validity end where the stone lies on its side (status 4,
`jaxcelt.integrate.solve.HEADING_GAP`) instead of failing at the heading's singularity.

At omega_pi = 10.8271 rad/s (the 400-frequency grid's lane 33, from rest, 300 periods, Tsit5 at rtol 1e-8) the
lane tips past 90° near t = 2.9 s and, integrated on, ran to max_steps = 10^6 before this rule
(docs/bifurcation/max-steps.md); the numba Dormand-Prince loop of the benchmarks ends such lanes by the same rule.
"""

from __future__ import annotations

import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
from jaxcelt.integrate.solve import HEADING_GAP, STATUS
from jaxcelt.sweeps.regimes import REGIMES, classify

P = jc.CeltParams.paper()
OMEGA = np.linspace(10.0, 20.0, 400)[33]  # 10.8271 rad/s


def _lane(engine: str, stop_on_invalid: bool, periods: tuple[int, int] = (200, 100)):
    pb = lanes_params(P, "omega_pi", np.array([OMEGA]))
    y0 = np.asarray(jc.initial_state(P))[None]
    cfg = SweepConfig(transient_periods=periods[0], sample_periods=periods[1], stop_on_invalid=stop_on_invalid)
    return run_lanes(pb, y0, cfg, engine=engine)


def test_status_4_is_documented():
    import math
    from pathlib import Path

    assert "singularity" in STATUS[4]
    # the status-codes page gives the angle HEADING_GAP leaves: arcsin(sqrt(gap)) in degrees
    deg = math.degrees(math.asin(math.sqrt(HEADING_GAP)))
    page = (Path(__file__).resolve().parents[1] / "docs/explanation/status-codes.md").read_text(encoding="utf-8")
    assert f"to within about {deg:.2f}".rstrip("0") + "°" in " ".join(page.split())


def test_lane_on_its_side_ends_with_status_4():
    r = _lane("pool", stop_on_invalid=False)
    assert r["status"][0] == 4
    assert r["first_invalid_kind"][0] > 0  # it had left validity before
    n2 = r["y_final"][0, 7]
    assert 1 - n2 * n2 < HEADING_GAP
    # it ends early instead of spending the step budget (measured 5 752 steps; 10^6 before the rule)
    assert r["num_steps"][0] < 100_000
    # labelled invalid, like a lane stopped at its first invalid state
    lab = classify(r["samples"], r["status"], r["valid"], r["samples"][..., 9:12])
    assert REGIMES[int(lab["regime"][0])] == "invalid"
    # stopping at the first invalid state ends it earlier, with status 2
    s = _lane("pool", stop_on_invalid=True)
    assert s["status"][0] == 2 and s["num_steps"][0] < r["num_steps"][0]


@pytest.mark.slow
def test_kernel_ends_it_the_same_way():
    # the lane kernel (interpreted here) applies the same rule: status 4, the same first invalid time
    # to the integration tolerance (the two programs' paths agree until past validity; measured equal to 1e-9)
    a = _lane("pool", stop_on_invalid=False, periods=(20, 5))
    b = _lane("kernel", stop_on_invalid=False, periods=(20, 5))
    assert a["status"][0] == 4 and b["status"][0] == 4
    assert abs(a["first_invalid_t"][0] - b["first_invalid_t"][0]) <= 1e-6
