"""Figures and JSON of orbit branches (`jaxcelt.plotting.orbits`, `jaxcelt.orbits.branch.branch_to_dict`).

A constructed branch with a known stability pattern (stable, unstable, stable: two changes)
and two marked points: the figure must draw three segments, solid-dashed-solid, mark both points
with their labels, and the dict must be JSON-serialisable and keep every point.
"""

import json

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from jaxcelt.orbits.branch import ArclengthBranch, branch_to_dict  # noqa: E402
from jaxcelt.orbits.points import Bifurcation  # noqa: E402
from jaxcelt.physics.model import STATE_NAMES  # noqa: E402
from jaxcelt.plotting.orbits import branch_figure, multipliers_figure  # noqa: E402


def _branch():
    m = 9
    lam = np.r_[np.linspace(1.0, 2.0, 5), np.linspace(1.8, 1.2, 4)]  # turns back once (a fold)
    y = np.zeros((m, 13))
    y[:, 4] = np.linspace(-1, 1, m)
    mu = np.tile(np.array([0.5 + 0.5j, 0.5 - 0.5j, 0.1, 0.01, 0.0, 0.0, 0.0, 0.0]), (m, 1))
    mu[3:6, 0] = 1.5  # unstable middle
    stable = np.all(np.abs(mu) < 1, axis=1)
    bifs = [
        Bifurcation("fold", 1.95, (lam[3], lam[4]), mu[4], y[4]),
        Bifurcation("Neimark-Sacker", 1.5, (lam[6], lam[7]), mu[6], y[6]),
    ]
    return ArclengthBranch(lam, y, np.zeros((m, 9)), mu, stable, np.zeros(m), bifs, "end value reached", 2)


def test_branch_figure_stable_solid_unstable_dashed_points_labelled():
    br = _branch()
    fig = branch_figure([br], labels=["period-1"])
    ax = fig.axes[0]
    segs = [ln for ln in ax.lines if len(ln.get_xdata()) > 1]
    assert [ln.get_linestyle() for ln in segs] == ["-", "--", "-"]
    # consecutive segments share their end points (no gap in the drawn branch)
    assert segs[0].get_xdata()[-1] == segs[1].get_xdata()[0]
    texts = [t.get_text() for t in ax.texts]
    assert texts == ["LP 1.950", "NS 1.500"]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "period-1" in legend and "fold (LP)" in legend and "Neimark-Sacker (NS)" in legend
    fig2 = multipliers_figure(br)
    assert len(fig2.axes[0].lines) >= 8


def test_branch_to_dict_is_json_and_complete():
    br = _branch()
    d = json.loads(json.dumps(branch_to_dict(br, STATE_NAMES)))
    assert len(d["values"]) == 9 and d["start"] == 2
    assert d["stable"] == [bool(s) for s in br.stable]
    np.testing.assert_array_equal(d["state"]["omega2"], br.y[:, 4])
    assert [b["kind"] for b in d["bifurcations"]] == ["fold", "Neimark-Sacker"]
    np.testing.assert_allclose(d["max_abs_multiplier"][3], 1.5)
    re, im = np.asarray(d["multipliers"][0]).T
    np.testing.assert_array_equal(re + 1j * im, br.multipliers[0])
