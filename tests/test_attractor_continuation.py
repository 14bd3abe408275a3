"""Global continuation of attractors (`jaxcelt.continue_attractors`, `continue_section_attractors`).

Known answers:

* the forced two-well Duffing oscillator x'' + 0.25 x' - x + x^3 = F cos t, F = 0.1, 0.15, 0.2 (two coexisting
  period-1 attractors, one per well): basin fractions against a plain scipy `solve_ivp` census on the same
  starts (DOP853, each start classified by the well of its final section point, x < 0 or x > 0). Tolerance:
  |f_jaxcelt - f_scipy| <= 3 binomial standard errors, and lane by lane at least 95 % of the starts in the same
  well (both integrate the same ODE to tight tolerances, so only starts on a basin boundary may differ;
  measured: all agree);
* the Floquet multipliers of those orbits: a complex pair, so |mu|^2 = det M = exp(-delta T) (Liouville,
  the divergence of the field is -delta): |mu| = exp(-0.25 pi) to 1e-7 (Newton at rtol 1e-11);
* the orbits are continued from value to value (each attractor's ``orbit_period`` 1 with its own multipliers);
* the continuation's lanes equal `jaxcelt.sweeps.api.sweep` lanes at the same parameters and starts
  (tolerance 1e-8 (1 + |x|): two compiled programs of the same steps, measured ~1e-12);
* resume: a run stopped after k values and resumed gives the same dataset, without recomputing the
  finished values; a damaged value file is recomputed.
"""

from __future__ import annotations

import dataclasses
import importlib.util
from pathlib import Path

import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.sweeps.continuation_core import continuation_summary, continue_section_attractors
from jaxcelt.sweeps.continuation_match import cycle_distance, group_lanes, match_attractors, set_distance
from jaxcelt.sweeps.dataset import DamagedChunkWarning


def _script():
    """The Duffing problem and the scipy census, defined once in scripts/attractor_continuation.py (which writes
    the committed result)."""
    spec = importlib.util.spec_from_file_location(
        "attractor_continuation", Path(__file__).resolve().parents[1] / "scripts" / "attractor_continuation.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


S = _script()
DELTA, T = S.DELTA, S.T_DUFFING
duffing_model, grid_starts, scipy_wells = S.duffing_model, S.grid_starts, S.scipy_wells
F_VALUES = [0.1, 0.15, 0.2]
SETTINGS = dict(transient_periods=100, sample_periods=8)


@pytest.fixture(scope="module")
def duffing_run(tmp_path_factory):
    starts = grid_starts(6)
    out = tmp_path_factory.mktemp("duffing")
    ds = continue_section_attractors(duffing_model(), "F", F_VALUES, starts, out=str(out), **SETTINGS)
    return starts, ds, out


def test_duffing_fractions_match_scipy(duffing_run):
    starts, ds, _ = duffing_run
    N = len(starts)
    for j, F in enumerate(F_VALUES):
        x_scipy = scipy_wells(F, starts, SETTINGS["transient_periods"] + SETTINGS["sample_periods"] - 1)
        present = np.flatnonzero(ds["exists"].values[:, j])
        assert len(present) == 2 and set(ds["kind"].values[present, j]) == {"periodic"}
        assert ds["tipping_fraction"].values[j] == 0 and ds["failed_fraction"].values[j] == 0
        left = [a for a in present if ds["section_point"].values[a, j, 0] < 0]
        assert len(left) == 1
        f_jax = ds["fraction"].values[left[0], j]
        sigma = ds["fraction_stderr"].values[left[0], j]
        f_scipy = np.mean(x_scipy < 0)
        assert abs(f_jax - f_scipy) <= 3 * sigma, (F, f_jax, f_scipy, sigma)
        assert np.isclose(sigma, np.sqrt(f_jax * (1 - f_jax) / N), rtol=1e-12)
        lane_left = ds["outcome"].values[j] == left[0]
        assert np.mean(lane_left == (x_scipy < 0)) >= 0.95
        assert np.isclose(ds["fraction"].values[present, j].sum(), 1.0)


def test_duffing_multipliers_and_ids(duffing_run):
    _, ds, _ = duffing_run
    assert ds.sizes["attractor"] == 2  # the same two attractors continued over every value
    assert np.all(ds["exists"].values == 1)
    assert np.all(ds["period"].values == 1) and np.all(ds["stable"].values == 1)
    assert np.all(ds["refine_status"].values == "converged")
    np.testing.assert_allclose(ds["multiplier_max"].values, np.exp(-DELTA * T / 2), rtol=0, atol=1e-7)
    # the orbit that goes with each attractor is its own refined orbit here
    assert np.all(ds["orbit_period"].values == 1)
    np.testing.assert_array_equal(ds["orbit_multiplier_max"].values, ds["multiplier_max"].values)
    # each id stays in its well as F grows (matching by section distance)
    x = ds["section_point"].values[:, :, 0]
    assert np.all(np.sign(x) == np.sign(x[:, :1]))
    assert ds["n_seeds"].values[0] == 0 and np.all(ds["n_seeds"].values[1:] > 0)
    s = continuation_summary(ds)
    assert [len(v["attractors"]) for v in s["values"]] == [2, 2, 2]


def test_duffing_resume(duffing_run, tmp_path):
    starts, ds, _ = duffing_run
    calls = []
    model = duffing_model()

    class Stop(Exception):
        pass

    def stopping(value, y0, o):
        if len(calls) == 2:
            raise Stop  # a kill after two finished values
        calls.append(value)
        return model.run(value, y0, o)

    out = str(tmp_path / "run")
    with pytest.raises(Stop):
        continue_section_attractors(
            dataclasses.replace(model, run=stopping), "F", F_VALUES, starts, out=out, **SETTINGS
        )
    assert calls == F_VALUES[:2]

    def counting(value, y0, o):
        calls.append(value)
        return model.run(value, y0, o)

    counted = dataclasses.replace(model, run=counting)
    ds2 = continue_section_attractors(counted, "F", F_VALUES, starts, out=out, **SETTINGS)
    assert calls == F_VALUES  # only the third value was computed on resume
    ds.attrs, ds2.attrs = dict(ds.attrs), dict(ds2.attrs)
    import xarray as xr

    xr.testing.assert_identical(ds, ds2)
    # a damaged file is recomputed (with a warning), giving the same dataset
    p = tmp_path / "run" / "values" / "value_00001.nc"
    p.write_bytes(p.read_bytes()[:200])
    with pytest.warns(DamagedChunkWarning):
        ds3 = continue_section_attractors(counted, "F", F_VALUES, starts, out=out, **SETTINGS)
    assert calls[3:] == [F_VALUES[1]]  # value 1 recomputed; value 2 read back (same seeds)
    xr.testing.assert_identical(ds, ds3)
    # other settings in the same directory are refused
    with pytest.raises(ValueError, match="out"):
        continue_section_attractors(counted, "F", F_VALUES, starts, out=out, transient_periods=50, sample_periods=8)


def test_duffing_tipping_outcome(duffing_run):
    """A validity region x < 0: starts ending in the right well have 'tipped over', an outcome of its own."""
    starts, ds, _ = duffing_run
    model = duffing_model(valid=lambda ys: ys[..., 0] < 0.0)
    dt = continue_section_attractors(model, "F", F_VALUES[:1], starts, refine=False, **SETTINGS)
    left = [a for a in range(ds.sizes["attractor"]) if ds["section_point"].values[a, 0, 0] < 0][0]
    assert dt.sizes["attractor"] == 1
    np.testing.assert_allclose(dt["tipping_fraction"].values[0], 1 - ds["fraction"].values[left, 0])
    np.testing.assert_allclose(dt["fraction"].values[0, 0], ds["fraction"].values[left, 0])
    assert set(dt["outcome"].values[0]) == {0, -1}


def test_section_geometry_known_answers():
    rng = np.random.default_rng(0)
    cyc = rng.normal(size=(3, 4))
    assert cycle_distance(cyc, np.roll(cyc, 2, axis=0)) == 0.0
    assert cycle_distance(cyc, cyc[:2]) == np.inf
    # two samples of one circle interleave; a circle shifted by 1 does not
    th = rng.uniform(0, 2 * np.pi, (3, 16))
    circ = lambda t, c: np.stack([np.cos(t) + c, np.sin(t)], axis=-1)  # noqa: E731
    coords = np.stack([circ(th[0], 0), circ(th[1], 0), circ(th[2], 1.0)])
    label, groups = group_lanes(np.array([5, 5, 5]), np.zeros(3, int), coords, group_tol=1e-3, set_factor=3.0)
    assert list(label) == [0, 0, 1] and len(groups) == 2
    assert set_distance(coords[0], coords[0]) == 0.0
    # matching: nearest first, one to one; within a tie band the seeds decide
    d = np.array([[0.01, 0.5], [0.02, 0.6]])
    assert list(match_attractors(d, np.zeros((2, 2)), match_tol=1.0, tie_rtol=0.0)) == [0, 1]
    assert list(match_attractors(d, np.array([[0, 0], [1.0, 0]]), match_tol=1.0, tie_rtol=1.5)) == [1, 0]
    assert list(match_attractors(d, np.zeros((2, 2)), match_tol=0.015, tie_rtol=0.0)) == [0, -1]


def test_wobblestone_lanes_equal_sweep():
    from jaxcelt.sweeps.api import sweep

    p = jc.CeltParams.paper(omega_pi=15.6)
    st = jc.attractor_starts(p, n=(4, 1))
    vals = [15.4, 15.6]
    ds = jc.continue_attractors(p, "omega_pi", vals, starts=st, transient_periods=6, sample_periods=4, refine=False)
    r = sweep(p, "omega_pi", vals, y0=st.y0, transient_periods=6, sample_periods=4, stop_on_invalid=True)
    ref = np.asarray(r.samples)[:, :, -1]
    assert np.max(np.abs(ds["lane_final"].values - ref) / (1 + np.abs(ref))) <= 1e-8
    assert ds.sizes["lane"] == 4 and np.array_equal(ds["psi0"].values, st.psi0)
    np.testing.assert_allclose(ds["fraction"].values.sum(0) + ds["tipping_fraction"].values
                               + ds["failed_fraction"].values, 1.0)  # fmt: skip


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda p: jc.continue_attractors(p, "nope", [15.0]), "name"),
        (lambda p: jc.continue_attractors(p, "omega_pi", []), "values"),
        (lambda p: jc.continue_attractors(p, "omega_pi", [15.0, np.nan]), "values"),
        (lambda p: jc.continue_attractors(p, "omega_pi", [15.0], starts=np.zeros((3, 12))), "starts"),
        (lambda p: jc.continue_attractors(None, "omega_pi", [15.0]), "params"),
        (lambda p: jc.continue_attractors(p, "omega_pi", [15.0], sample_periods=1), "sample_periods"),
        (lambda p: jc.continue_attractors(p, "omega_pi", [15.0], match_tol=-1.0), "match_tol"),
        (lambda p: jc.continue_attractors(p, "omega_pi", [15.0], sweep="fast"), "sweep"),
        (lambda p: jc.ContinuationOptions(seeds_per_attractor=1.5), "seeds_per_attractor"),
        (lambda p: continue_section_attractors(duffing_model(), "F", [0.1], np.zeros((0, 2))), "starts"),
    ],
)
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call(jc.CeltParams.paper())


@pytest.mark.slow
def test_duffing_bigger_census_and_chaos():
    """The committed check (10 x 10 starts, F = 0.1 .. 0.25, `duffing_check`) against scipy as above, then
    F = 0.3 (a chaotic attractor: one non-periodic set, every start on it)."""
    d = S.duffing_check()
    for r in d["values"]:
        assert [a["period"] for a in r["attractors"]] == [1, 1]
        assert r["diff_over_sigma"] <= 3 and r["lane_agreement"] >= 0.95
    ds = continue_section_attractors(duffing_model(), "F", [0.25, 0.3], grid_starts(10), refine=False,
                                     transient_periods=150, sample_periods=16)  # fmt: skip
    last = np.flatnonzero(ds["exists"].values[:, -1])
    assert len(last) == 1 and ds["kind"].values[last[0], -1] == "aperiodic"
    assert ds["fraction"].values[last[0], -1] == 1.0
