"""scripts/paper_14.py: the read-off of a fold curve's crossing of 14 rad/s (fast, against analytic curves) and one
point of docs/orbits/paper_14.json recomputed (slow)."""

from __future__ import annotations

import json
import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from paper_14 import crossing  # noqa: E402


def test_crossing_of_a_line_is_exact():
    # omega = 16 - 5 p crosses 14 at p = 0.4 exactly; linear interpolation of a line is exact up to rounding (1e-12)
    p = np.linspace(0.0, 1.0, 7)
    (c,) = crossing(16 - 5 * p, p)
    assert c["p"] == pytest.approx(0.4, abs=1e-12)
    assert c["segment"] == 2


def test_crossing_of_a_parabola_within_the_chord_error():
    # omega = 13 + 25 (p - 0.5)^2 crosses 14 at p = 0.3 and 0.7; the chord's error is at most
    # h^2 max|omega''| / (8 min|omega'|) = 1e-4 * 50 / (8 * 10) ~ 6e-5 for h = 0.01, so 1e-4 must hold
    p = np.arange(0.0, 1.0 + 1e-9, 0.01)
    got = [c["p"] for c in crossing(13 + 25 * (p - 0.5) ** 2, p)]
    assert got == pytest.approx([0.3, 0.7], abs=1e-4)


def test_crossing_none_touch_and_bad_input():
    assert crossing([15.0, 14.5, 14.9], [0.0, 1.0, 2.0]) == []
    # a point exactly on the level counts once, whether inside the curve or at its end
    assert [c["p"] for c in crossing([15.0, 14.0, 13.0], [0.0, 1.0, 2.0])] == [1.0]
    assert [c["p"] for c in crossing([15.0, 14.0], [0.0, 1.0])] == [1.0]
    with pytest.raises(ValueError, match="omega"):
        crossing([1.0, 2.0], [1.0])


@pytest.mark.slow
def test_stable_orbit_at_14_recomputed():
    # the stable sheet at 14 rad/s of docs/orbits/paper_14.json, solved again by jc.periodic_orbit from its recorded
    # state: the same orbit to the Newton tolerance (state within 1e-7) and the same multiplier moduli to 1e-6
    # (the variational solve at rtol 1e-11 reproduces them far better; 1e-6 leaves room for another machine's
    # floating point), stable as recorded
    from paper_14 import _params

    import jaxcelt as jc

    res = json.loads((ROOT / "docs/orbits/paper_14.json").read_text())
    a, s = next((a, s) for a in res["at_14"].values() for s in a["sheets_at_14"] if s["stable"])
    name = a["parameter"]
    o = jc.periodic_orbit(_params(name, a[name], 14.0), np.asarray(s["state"]), max_steps=20_000)
    assert int(o.status) == 0
    assert np.max(np.abs(np.asarray(o.y) - np.asarray(s["state"]))) < 1e-7
    assert np.abs(np.asarray(o.multipliers)) == pytest.approx(s["multipliers_abs"], abs=1e-6)
    assert bool(o.stable)
