"""Attractor census (`jaxcelt.attractors`): grouping on constructed cycles, a tiny wobblestone
census, bad input."""

from __future__ import annotations

import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.sweeps.census import group, same_cycle


def _cycle(k: int, seed: int) -> np.ndarray:
    """A synthetic section cycle (k, 13) with distinct points; psi in [0, 2 pi)."""
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(k, 13))
    c[:, 12] = rng.uniform(0, 2 * np.pi, k)
    return c


def test_same_cycle_shift_psi_turns_and_position():
    a = _cycle(3, 0)
    b = np.roll(a, 1, axis=0)  # the same orbit entered one section point later
    b[:, 12] += 2 * np.pi * np.array([1, -2, 5])  # psi modulo 2 pi
    b[:, 9:11] += 7.0  # cyclic r_C1, r_C2: the orbit wandered on the base
    assert same_cycle(a, b, 1e-9)
    # a perturbation of (v, omega, n) above the tolerance (scale 1 + max|x|) separates them
    scale = 1.0 + np.max(np.abs(a[:, :9]))
    c = a.copy()
    c[1, 4] += 3e-3 * scale
    assert not same_cycle(a, c, 1e-3)
    assert same_cycle(a, c, 4e-3)
    # psi differing by pi is another orbit (the forcing is along X1)
    d = a.copy()
    d[:, 12] += np.pi
    assert not same_cycle(a, d, 1e-3)
    # a reversed order is not a cyclic shift of a 3-cycle
    assert not same_cycle(a, a[::-1], 1e-6)


def test_group_known_answer():
    A, B, C = _cycle(1, 1), _cycle(2, 2), _cycle(2, 3)
    near = lambda x, s: x + 1e-6 * np.random.default_rng(s).normal(size=x.shape)  # noqa: E731
    lanes = [
        ("periodic", 1, A),
        ("periodic", 2, B),
        ("chaotic", 0, None),
        ("periodic", 2, np.roll(near(B, 4), 1, axis=0)),
        ("invalid", 0, None),
        ("periodic", 2, C),
        ("periodic", 1, near(A, 5)),
        ("aperiodic", 0, None),
        ("chaotic", 0, None),
    ]
    kinds = np.array([x[0] for x in lanes], dtype=object)
    periods = np.array([x[1] for x in lanes])
    label, rows = group(kinds, periods, [x[2] for x in lanes], 1e-4)
    # rows: A, B, C (first appearance), then chaotic, aperiodic, invalid
    assert [(r[0], r[1]) for r in rows] == [
        ("periodic", 1),
        ("periodic", 2),
        ("periodic", 2),
        ("chaotic", 0),
        ("aperiodic", 0),
        ("invalid", 0),
    ]
    np.testing.assert_array_equal(label, [0, 1, 3, 1, 5, 2, 0, 4, 3])


@pytest.fixture(scope="module")
def tiny_census():
    p = jc.CeltParams.paper(omega_pi=15.6)
    # psi0 = 90 deg tilted by 0.05 rad leaves the model's validity within the first periods at
    # 15.6 rad/s (checked against `jaxcelt.simulate` below); 157.5 deg at rest is the paper's start
    starts = jc.attractor_starts(p, psi0=(0.0, 2 * np.pi), tilt=(-0.1, 0.1), n=(2, 2))
    y0 = np.concatenate([starts.y0, [jc.initial_state(p, psi=np.radians(157.5))] * 2])
    return p, y0, jc.attractors(p, y0, transient_periods=2, sample_periods=4)


def test_tiny_census_labels_and_fractions(tiny_census):
    p, y0, c = tiny_census
    n = y0.shape[0]
    assert c.label.shape == (n,) and c.kind.shape == (n,)
    assert sum(a.count for a in c.table) == n
    assert abs(sum(a.fraction for a in c.table) - 1.0) < 1e-12  # n counts over n: exact up to rounding
    for i in range(n):  # every lane sits in the row of its own kind (and period)
        a = c.table[c.label[i]]
        assert a.kind == c.kind[i] and a.k == c.period[i]
    # the two identical starts end in the same row
    assert c.label[4] == c.label[5]
    d = c.to_dict()
    assert len(d["attractors"]) == len(c.table) and len(d["lanes"]["label"]) == n


def test_tiny_census_invalid_lane_marked(tiny_census):
    p, y0, c = tiny_census
    assert c.kind[0] == "invalid"  # the lane that left the model's validity is marked ...
    assert c.kind[4] != "invalid" and c.kind[5] != "invalid"  # ... and does not poison the others
    assert c.table[c.label[0]].kind == "invalid"


@pytest.mark.slow
def test_tiny_census_validity_vs_simulate(tiny_census):
    p, y0, c = tiny_census
    T = 2 * np.pi / 15.6
    # independent check of validity: one `simulate` per start up to the last section time 5 T
    for i in (0, 4):
        sol = jc.simulate(p, y0[i], 5 * T, ts=np.array([5 * T]))
        assert (c.kind[i] == "invalid") == (not bool(sol.valid)), (i, c.kind[i])


def test_bad_input():
    p = jc.CeltParams.paper()
    with pytest.raises(ValueError, match="tilt"):
        jc.attractor_starts(p, tilt=(0.0, 2.0))
    with pytest.raises(ValueError, match="psi0"):
        jc.attractor_starts(p, psi0=(1.0, 0.0))
    with pytest.raises(ValueError, match="'n'"):
        jc.attractor_starts(p, n=(0, 3))
    with pytest.raises(ValueError, match="starts"):
        jc.attractors(p, np.zeros((3, 12)))
    with pytest.raises(ValueError, match="sample_periods"):
        jc.attractors(p, np.zeros((3, 13)), sample_periods=1)
    with pytest.raises(ValueError, match="group_tol"):
        jc.attractors(p, np.zeros((3, 13)), group_tol=-1.0)
    with pytest.raises(ValueError, match="params"):
        jc.attractors("paper", np.zeros((3, 13)))


def test_plot_basins_grid():
    pytest.importorskip("matplotlib")
    from jaxcelt.plotting.attractors import attractor_colours, plot_basins

    rows = [
        dict(kind="periodic", k=1, fraction=0.5, count=3, state=[0.0] * 12 + [2.0 + 4 * np.pi]),
        dict(kind="periodic", k=2, fraction=1 / 3, count=2),
        dict(kind="invalid", k=0, fraction=1 / 6, count=1),
    ]
    d = dict(
        omega_pi=15.6,
        n_lanes=6,
        grid_shape=[3, 2],
        attractors=rows,
        lanes=dict(label=[0, 0, 1, 0, 1, 2], psi0=list(np.repeat([0.5, 1.5, 2.5], 2)), tilt=[-0.1, 0.1] * 3),
    )
    fig = plot_basins(d)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    # psi of the representative modulo 360 deg: 2 rad = 114.6 deg
    assert texts == ["period-1 ($\\psi$ = 115°): 0.500 (3)", "period-2: 0.333 (2)", "invalid: 0.167 (1)"]
    assert len(set(attractor_colours(rows))) == 3
    with pytest.raises(ValueError, match="census"):
        plot_basins(dict(d, lanes=None))


def test_refine_failure_is_reported_not_raised():
    from jaxcelt.sweeps.census import Attractor, refine_attractor

    p = jc.CeltParams.paper(omega_pi=15.6)
    row = Attractor(kind="periodic", k=1, state=np.zeros(13), t_section=0.0, lane=0, count=1, fraction=1.0)
    # a state off the contact manifold: periodic_orbit rejects it; the row is marked, no exception
    refine_attractor(p, row)
    assert row.refine_status.startswith("error: ValueError") and row.multipliers is None and row.stable is None
    with pytest.raises(ValueError, match="'a'"):
        refine_attractor(
            p, Attractor(kind="chaotic", k=0, state=np.zeros(13), t_section=0.0, lane=0, count=1, fraction=1.0)
        )
