"""Synthetic measured data and the data file format (jaxcelt.identify.records)."""

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.identify.observe import OBSERVABLES, observe
from jaxcelt.identify.records import MeasuredData, generate_data, load_data, save_data


@pytest.fixture(scope="module")
def setup():
    p = jc.CeltParams.paper()
    y0 = jc.initial_state(p, omega=(0.0, 0.0, 5.0), n=(np.sin(0.17), 0.0, np.cos(0.17)))
    return p, y0


@pytest.fixture(scope="module")
def clean(setup):
    p, y0 = setup
    return generate_data(p, y0, 0.2, rate=50, kinds=tuple(OBSERVABLES))


def test_observe_shapes_and_values(setup):
    p, y0 = setup
    for kind, k in OBSERVABLES.items():
        assert observe(y0, p, kind).shape == (k,)
    np.testing.assert_array_equal(observe(y0, p, "omega"), y0[3:6])
    np.testing.assert_array_equal(observe(y0, p, "orientation"), np.r_[y0[6:9], y0[12]])
    np.testing.assert_allclose(observe(y0, p, "centre"), jc.centre_position(y0, p))
    with pytest.raises(ValueError, match="unknown observation kind"):
        observe(y0, p, "gps")


def test_clean_data_are_simulated_samples(setup, clean):
    p, y0 = setup
    tr = clean.trajectories[0]
    # sampling: 0, 1/rate, ..., t1 inclusive
    np.testing.assert_allclose(tr.ts, np.arange(11) / 50, atol=1e-14)
    sol = jc.simulate(p, y0, float(tr.ts[-1]), ts=tr.ts, rtol=1e-10, atol=1e-12)
    # same solver and tolerances: identical up to round-off
    np.testing.assert_allclose(tr.obs["state"], np.asarray(sol.ys), rtol=0, atol=1e-12)
    om = np.asarray(jax.vmap(lambda y: observe(y, p, "omega"))(sol.ys))
    np.testing.assert_allclose(tr.obs["omega"], om, atol=1e-12)
    # noise-free: sigma is the nominal 1% of the channel RMS
    np.testing.assert_allclose(tr.sigma["omega"], 0.01 * np.sqrt(np.mean(om**2, axis=0)), rtol=1e-12)
    np.testing.assert_array_equal(tr.y0, np.asarray(y0))
    assert clean.meta["true_params"]["mu"] == pytest.approx(float(p.mu))


def test_noise_level_and_reproducibility(setup, clean):
    p, y0 = setup
    a = generate_data(p, y0, 0.2, rate=50, kinds=tuple(OBSERVABLES), noise=0.05, seed=1)
    b = generate_data(p, y0, 0.2, rate=50, kinds=tuple(OBSERVABLES), noise=0.05, seed=1)
    c = generate_data(p, y0, 0.2, rate=50, kinds=tuple(OBSERVABLES), noise=0.05, seed=2)
    np.testing.assert_array_equal(a.trajectories[0].obs["omega"], b.trajectories[0].obs["omega"])
    assert not np.allclose(a.trajectories[0].obs["omega"], c.trajectories[0].obs["omega"])
    # standardised noise over all 23 channels x 11 samples (253 draws): its std is 1 within
    # ~3 standard errors (se ~ 1/sqrt(2*253) = 0.045) -> tolerance 0.15
    z = np.concatenate(
        [
            ((a.trajectories[0].obs[k] - clean.trajectories[0].obs[k]) / a.trajectories[0].sigma[k]).ravel()
            for k in OBSERVABLES
        ]
    )
    assert abs(np.std(z) - 1) < 0.15
    assert abs(np.mean(z)) < 0.2


@pytest.mark.parametrize("suffix", [".npz", ".nc"])
def test_save_load_round_trip(tmp_path, clean, suffix):
    d2 = MeasuredData((clean.trajectories[0], clean.trajectories[0].subset(["omega"])), clean.meta)
    path = save_data(d2, tmp_path / f"d{suffix}")
    back = load_data(path)
    assert back.meta == d2.meta
    assert len(back.trajectories) == 2
    for t0, t1 in zip(d2.trajectories, back.trajectories):
        assert t0.kinds == t1.kinds
        np.testing.assert_array_equal(t0.ts, t1.ts)
        for k in t0.kinds:
            np.testing.assert_array_equal(t0.obs[k], t1.obs[k])
            np.testing.assert_array_equal(t0.sigma[k], t1.sigma[k])
        np.testing.assert_array_equal(t0.y0, t1.y0)
        assert (t0.omega_pi, t0.q_pi) == (t1.omega_pi, t1.q_pi)


def test_unknown_y0_and_bad_files(tmp_path, clean):
    tr = dataclasses.replace(clean.trajectories[0], y0=None)
    back = load_data(save_data(MeasuredData((tr,)), tmp_path / "a.npz"))
    assert back.trajectories[0].y0 is None
    np.savez(tmp_path / "b.npz", format=np.array("something else"))
    with pytest.raises(ValueError, match="not a jaxcelt data file"):
        load_data(tmp_path / "b.npz")
    with pytest.raises(ValueError, match=".npz or .nc"):
        save_data(clean, tmp_path / "c.pkl")


def test_trajectory_validation(clean):
    tr = clean.trajectories[0]
    with pytest.raises(ValueError, match="increasing"):
        dataclasses.replace(tr, ts=tr.ts[::-1])
    with pytest.raises(ValueError, match="shape"):
        dataclasses.replace(tr, obs={"omega": tr.obs["omega"][:, :2]}, sigma={"omega": tr.sigma["omega"]})
    with pytest.raises(ValueError, match="sigma"):
        dataclasses.replace(tr, obs={"omega": tr.obs["omega"]}, sigma={"omega": -tr.sigma["omega"]})
    with pytest.raises(ValueError, match="not in the record"):
        tr.subset(["omega"]).subset(["state"])
    assert clean.subset(["centre"]).trajectories[0].kinds == ("centre",)


def test_from_arrays_and_csv_errors(tmp_path):
    from jaxcelt.identify.records import from_arrays, load_csv

    t = np.linspace(0.0, 1.0, 11)
    w = np.column_stack([np.sin(t), np.cos(t), 0.1 + t])
    tr = from_arrays(t, omega=w, omega_pi=17.0, q_pi=0.04)
    # default weights: 1 % of each channel's RMS
    np.testing.assert_allclose(tr.sigma["omega"], 0.01 * np.sqrt(np.mean(w**2, axis=0)), rtol=1e-12)
    assert tr.y0 is None
    with pytest.raises(ValueError, match="unknown observation kind"):
        from_arrays(t, gyro=w, omega_pi=17.0, q_pi=0.04)
    with pytest.raises(ValueError, match="non-finite"):
        from_arrays(t, omega=np.full_like(w, np.nan), omega_pi=17.0, q_pi=0.04)
    bad = tmp_path / "bad.csv"
    bad.write_text("t,omega1,omega2\n0,1,2\n0.1,1,2\n")
    with pytest.raises(ValueError, match="needs all of the columns"):
        load_csv(bad, omega_pi=17.0, q_pi=0.04)
    nofreq = tmp_path / "nofreq.csv"
    nofreq.write_text("t,omega1,omega2,omega3\n0,1,2,3\n0.1,1,2,3\n")
    with pytest.raises(ValueError, match="omega_pi"):
        load_csv(nofreq)
    assert load_csv(nofreq, omega_pi=17.0, q_pi=0.04).obs["omega"].shape == (2, 3)


def test_accelerometer_is_the_specific_force_of_the_trajectory():
    # independent of the vector field's algebra: central differences (h = 1e-6 s) of the global
    # velocity of C along a tight simulate (rtol 1e-12), plus g E3, rotated into body axes
    # (R rows E1, E2, n; MODEL.md section 4). The smoothed friction (eps = 1e-4 m/s) changes on
    # ~1e-4 s, so the jerk reaches ~1e4 m/s^3 (h = 1e-4 s gave 1e-4 errors): truncation
    # h^2 |v'''| / 6 ~ 2e-9, integration noise ~1e-13 / h ~ 1e-7: 1e-5 m/s^2 (1e-6 of g).
    from jaxcelt.physics.model import horizontal_frame

    p = jc.CeltParams.paper(omega_pi=15.6)
    y0 = jc.initial_state(p, psi=np.radians(157.5))
    h = 1e-6
    centres = np.array([2.0, 2.37, 3.1])
    ts = np.sort(np.r_[centres - h, centres, centres + h])
    sol = jc.simulate(p, y0, float(ts[-1]), ts=jnp.asarray(ts), rtol=1e-12, atol=1e-14, exact_ts=True)
    ys = np.asarray(sol.ys)

    def v_global(y):
        fr = horizontal_frame(jnp.asarray(y[6:9]), y[12])
        return np.array([np.dot(fr.E1, y[0:3]), np.dot(fr.E2, y[0:3]), np.dot(y[6:9], y[0:3])])

    for i in range(len(centres)):
        ym, yc, yp = ys[3 * i : 3 * i + 3]
        a = (v_global(yp) - v_global(ym)) / (2 * h)
        f_glob = a + np.array([0.0, 0.0, float(p.g)])
        fr = horizontal_frame(jnp.asarray(yc[6:9]), yc[12])
        f_body = np.asarray(fr.E1) * f_glob[0] + np.asarray(fr.E2) * f_glob[1] + yc[6:9] * f_glob[2]
        got = np.asarray(observe(jnp.asarray(yc), p, "accel", centres[i]))
        assert np.linalg.norm(got) > 1.0  # a moving stone, not a trivial check
        np.testing.assert_allclose(got, f_body, atol=1e-5)


def test_accelerometer_at_rest_reads_g_along_the_vertical():
    # the stone at rest in its equilibrium on a still base: no acceleration, the accelerometer
    # reads +g along the vertical (and the gyro 0); turned by psi it reads the same in body axes
    p = jc.CeltParams.paper(q_pi=0.0)
    for psi in (0.0, 1.3):
        y = jnp.asarray(jc.initial_state(p, psi=psi))
        np.testing.assert_allclose(np.asarray(observe(y, p, "accel")), [0.0, 0.0, float(p.g)], atol=1e-12)
