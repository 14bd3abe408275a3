"""The atlas (`jaxcelt.sweeps.atlas`, `jaxcelt.plotting.atlas`, ``jaxcelt atlas``): structure, figure, bad input, resume.

The default tests run a tiny atlas (2 values, 2 starts, short lanes, no branches): seconds to tens of seconds. The
slow ones check the physics of its parts against what they were not computed from: lambda_1 of the Lyapunov
spectrum on a periodic attractor against log|mu_max| / T of its Floquet multipliers (Newton and the variational
equations, `jaxcelt.periodic_orbit`), and the fold of the period-1 branch against the independent run of
``scripts/orbit_branches.py`` (docs/orbits/branches.json, its own start and step sizes).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.sweeps.atlas import AtlasOptions, AtlasResult, atlas

TINY = dict(starts=(4, 1), transient_periods=10, sample_periods=4, lyapunov_periods=0, seeds_per_attractor=1,
            brute_values=3, brute_transient=5, brute_sample=4, branches=False)  # fmt: skip
TINY_CLI = ["--values", "2", "--omega", "15", "15.5", "--starts", "2", "1", "--transient", "10", "--sample", "4",
            "--lyapunov-periods", "0", "--spectrum-periods", "0", "--brute-values", "3", "--brute-transient", "5",
            "--brute-sample", "4", "--no-branches"]  # fmt: skip


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("atlas")
    p = jc.CeltParams.paper(q_pi=0.04)
    return atlas(p, [15.0, 15.5], options=AtlasOptions(**TINY, out=str(out / "continuation"))), out


def test_tiny_atlas_structure(tiny):
    res, out = tiny
    assert isinstance(res, AtlasResult)
    ds = res.continuation
    assert ds.sizes["omega_pi"] == 2 and ds.sizes["lane"] == 4
    np.testing.assert_allclose(res.values, [15.0, 15.5])
    # every start is an attractor's, tipping over or failed: the fractions add up to 1 (to rounding)
    total = np.nansum(ds["fraction"].values, axis=0) + ds["tipping_fraction"].values + ds["failed_fraction"].values
    np.testing.assert_allclose(total, 1.0, atol=1e-12)
    assert res.brute is not None and np.asarray(res.brute.samples).shape == (3, 4, 13)
    assert res.lambda1.shape == (ds.sizes["attractor"], 2) and np.isnan(res.lambda1).all()  # spectrum off
    assert res.branches == []
    s = res.summary()
    json.dumps(s)  # JSON-ready
    assert [r["value"] for r in s["continuation"]["values"]] == [15.0, 15.5]
    assert (out / "continuation" / "continuation.nc").exists()  # the continuation's resumable files


def test_plot_atlas_writes_png(tiny, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from jaxcelt.plotting.atlas import plot_atlas

    path = plot_atlas(tiny[0], tmp_path / "atlas.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 20_000


@pytest.mark.parametrize(
    "kw, name",
    [(dict(starts=(0, 4)), "starts"), (dict(sample_periods=1), "sample_periods"), (dict(tilt=-0.1), "tilt"),
     (dict(spectrum_periods=-1), "spectrum_periods"), (dict(max_branches=0), "max_branches")],
)  # fmt: skip
def test_options_bad_input_names_the_field(kw, name):
    with pytest.raises(ValueError, match=name):
        AtlasOptions(**kw)


@pytest.mark.parametrize("values", [[15.0], [16.0, 15.0], [15.0, np.nan], [-1.0, 2.0], "x"])
def test_atlas_bad_values(values):
    with pytest.raises(ValueError, match="values"):
        atlas(jc.CeltParams.paper(), values, options=AtlasOptions(**TINY))


def test_atlas_bad_options_type():
    with pytest.raises(ValueError, match="options"):
        atlas(jc.CeltParams.paper(), [15.0, 16.0], options=dict(TINY))


@pytest.mark.parametrize(
    "argv",
    [["--omega", "20", "10"], ["--values", "1"], ["--starts", "0", "4"], ["--sample", "1"], ["--q-pi", "-1"],
     ["--transient", "x"]],
)  # fmt: skip
def test_cli_bad_input_one_line_exit_2(argv, tmp_path, capsys):
    from jaxcelt.cli import main

    with pytest.raises(SystemExit) as e:
        main(["atlas", "--out", str(tmp_path / "o"), *argv])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("jaxcelt atlas: error:") and "\n" not in err


def test_cli_requires_out(capsys):
    from jaxcelt.cli import main

    with pytest.raises(SystemExit) as e:
        main(["atlas"])
    assert e.value.code == 2 and "--out" in capsys.readouterr().err


def test_cli_writes_and_resumes(tmp_path, capsys):
    """The command writes atlas.png/json/nc; after a 'kill' (the merged file and one value file gone) the rerun
    reads the other value back (its file untouched) and recomputes the missing one, with the same outcomes."""
    import xarray as xr

    from jaxcelt.cli import main

    out = tmp_path / "a"
    assert main(["atlas", "--out", str(out), *TINY_CLI]) == 0
    for f in ("atlas.png", "atlas.json", "atlas.nc"):
        assert (out / f).stat().st_size > 0
    d = json.loads((out / "atlas.json").read_text())
    assert "provenance" in d and d["seconds"]["command"] >= d["seconds"]["continuation"] > 0
    files = sorted((out / "continuation" / "values").glob("value_*.nc"))
    assert len(files) == 2
    with xr.open_dataset(out / "atlas.nc") as f:
        first = f.load()
    (out / "continuation" / "continuation.nc").unlink()
    files[1].unlink()
    kept = files[0].stat().st_mtime_ns
    assert main(["atlas", "--out", str(out), *TINY_CLI]) == 0
    assert files[0].stat().st_mtime_ns == kept and files[1].exists()
    with xr.open_dataset(out / "atlas.nc") as f:
        again = f.load()
    np.testing.assert_array_equal(first["outcome"].values, again["outcome"].values)


@pytest.mark.slow
def test_spectrum_on_periodic_attractor_matches_floquet():
    """lambda_1 of `lyapunov_spectrum` (200 periods) at a period-1 attractor's section point against
    log|mu_max| / T of its refined orbit: the finite-time error decays like 1/time; tolerance 0.02 1/s (about
    the 1/(200 T) = 0.012 1/s scale of that error, with margin) where |log|mu_max|/T| is about 0.17 1/s."""
    p = jc.CeltParams.paper(q_pi=0.04)
    o = AtlasOptions(starts=(8, 1), transient_periods=300, sample_periods=8, lyapunov_periods=0, brute_values=0,
                     branches=False, spectrum_periods=200, spectrum_transient=20)  # fmt: skip
    res = atlas(p, [15.5, 15.6], options=o)
    ds = res.continuation
    per = (ds["kind"].values == "periodic") & (ds["period"].values == 1) & np.isfinite(ds["multiplier_max"].values)
    assert per.any(), "no period-1 attractor found at 15.5-15.6 rad/s"
    for a, j in np.argwhere(per):
        T = 2 * np.pi / res.values[j]
        expected = np.log(ds["multiplier_max"].values[a, j]) / T
        assert abs(res.lambda1[a, j] - expected) < 0.02, (a, j, res.lambda1[a, j], expected)


@pytest.mark.slow
def test_branches_fold_and_mirror():
    """Both mirror period-1 branches through the continuation's orbits at 15-16 rad/s, each with the fold that
    scripts/orbit_branches.py found at 14.8801 rad/s (docs/orbits/branches.json; interpolated folds, tolerance
    0.01 rad/s for the coarser steps here)."""
    p = jc.CeltParams.paper(q_pi=0.04)
    o = AtlasOptions(starts=(8, 1), transient_periods=200, sample_periods=8, lyapunov_periods=0, brute_values=0,
                     branch_max_points=60)  # fmt: skip
    res = atlas(p, [14.5, 15.5, 16.0], options=o)
    assert len(res.branches) >= 2
    folds = [[b.value for b in br.bifurcations if b.kind == "fold"] for _, br in res.branches[:2]]
    for f in folds:
        assert any(abs(v - 14.8801) < 0.01 for v in f), folds
    # mirror pair: omega_2 of one branch is minus the other's at the same value
    (_, b0), (_, b1) = res.branches[:2]
    y0 = np.interp(15.5, *zip(*sorted(zip(b0.values, np.asarray(b0.y)[:, 4]), key=lambda t: t[0])))
    y1 = np.interp(15.5, *zip(*sorted(zip(b1.values, np.asarray(b1.y)[:, 4]), key=lambda t: t[0])))
    assert abs(y0 + y1) < 0.02 * max(abs(y0), 0.1)


def test_half_turn_is_the_symmetry_relabelling():
    """`half_turn` equals the half-turn relabelling derived in tests/test_symmetry.py (Q = diag(-1, -1, 1),
    M = I, psi read off the turned axes) on a tilted, spinning state; applied twice it is the identity.
    Tolerance 1e-12 (rounding of psi + pi)."""
    from test_symmetry import transform_state

    from jaxcelt.sweeps.atlas import half_turn

    p = jc.CeltParams.paper()
    n = np.array([0.05, -0.03, 1.0]) / np.linalg.norm([0.05, -0.03, 1.0])
    y = np.asarray(jc.initial_state(p, psi=0.7, omega=(0.3, -0.2, 1.1), n=n))
    expected = transform_state(y, (-1, -1, 1), (1, 1, 1))
    got = half_turn(y)
    d = got - expected
    d[12] = np.mod(d[12] + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(d)) < 1e-12
    back = half_turn(got) - y
    back[12] = np.mod(back[12] + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(back)) < 1e-12
