"""Smoke tests of the speed/accuracy benchmarks' quick path on a tiny scene.

No timings are asserted (machines differ); only accuracy statements that hold on any machine.
"""

import pathlib
import sys

import numpy as np
import pytest

from jaxcelt.studies import benchmarking as bm

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "benchmarks"))


@pytest.fixture(scope="module")
def tiny():
    # fixed-table spin, 0.25 s: non-chaotic, sliding (not stiff), ~100 steps at 1e-12
    return bm.make_scene("spin_reversal", 1)


@pytest.fixture(scope="module")
def ref(tiny):
    import reference

    return reference.reference(tiny, tol=1e-12)


def test_reference_solvers_agree(ref):
    # Two independent integrators (diffrax Dopri8; scipy DOP853 on the numba port, or on the JAX
    # field if numba is missing) at tol 1e-12 over 0.25 s. Observed agreement ~1e-13; 1e-9 leaves
    # a 1e4 margin for platform differences, while any disagreement in the right-hand side or a
    # solver bug shows up at >= 1e-6.
    assert ref["A"]["status"] == 0
    assert ref["max_agreement"] < 1e-9, ref["max_agreement"]
    assert ref["trusted_index"] == ref["periods"]


def test_numba_port_matches_jax(tiny):
    pytest.importorskip("numba")
    import _numba_model as nm

    # same formulas, different summation order: agreement to a few ulps of the largest entry
    # (observed 2e-15 .. 6e-15 relative); a wrong term shows up at >= 1e-6
    assert nm.check_against_jax(tiny.params, n_samples=5) < 1e-12
    # the interpreted source (the "plain Python RHS" peer) is the same function
    assert nm.check_against_jax(tiny.params, n_samples=2, interpreted=True) < 1e-12


def test_numba_ensemble_matches_reference(tiny, ref):
    pytest.importorskip("numba")
    import _numba_model as nm

    # hand-written DP5 at rtol 1e-10 over 0.25 s: observed error ~1e-10; 1e-7 catches a broken
    # tableau, controller or sample placement (those give >= 1e-4)
    ys, steps, evals, status = nm.ensemble(np.asarray(tiny.y0)[None], tiny.ts, tiny.params, 1e-10, 1e-12)
    assert status[0] == 0 and steps[0] > 0 and evals[0] >= 6 * steps[0]
    assert bm.state_error(ys[0], np.asarray(ref["A"]["ys"])) < 1e-7


def test_work_precision_quick_path(tiny, ref):
    ys_ref = np.asarray(ref["A"]["ys"])
    loose = bm.run_diffrax(tiny, "Tsit5", rtol=1e-5, ys_ref=ys_ref, repeats=1)
    tight = bm.run_diffrax(tiny, "Tsit5", rtol=1e-9, ys_ref=ys_ref, repeats=1)
    assert loose["status"] == 0 and tight["status"] == 0
    # tolerance proportionality: 4 decades tighter must buy >= 2 decades of accuracy, and the
    # global error at rtol 1e-9 over 0.25 s stays below 1e-6 (observed ~1e-9)
    assert tight["error"] < 1e-2 * loose["error"]
    assert tight["error"] < 1e-6
    assert tight["compile_s"] >= 0 and tight["run_s"] > 0


def test_fixed_step_wrapper_takes_constant_steps(tiny, ref):
    dt = 2.5e-3
    r = bm.run_diffrax(tiny, "RK4-fixed", dt0=dt, ys_ref=np.asarray(ref["A"]["ys"]), repeats=0)
    assert r["rejected"] == 0
    assert r["steps"] == round(tiny.t1 / dt)
    assert r["error"] < 1e-3  # RK4 at 2.5 ms on a smooth sliding phase: observed ~1e-7


def test_mujoco_stone_matches_params_and_spin_decay():
    mujoco = pytest.importorskip("mujoco")
    import mujoco_peer as mp

    import jaxcelt as jc
    from jaxcelt.physics.params import inertia_tensor

    p = jc.CeltParams.paper(q_pi=0.0)
    m = mujoco.MjModel.from_xml_string(mp.mjcf(p))
    # same mass and the same inertia tensor (MuJoCo stores its principal moments): eigenvalues
    # agree to round-off of the XML's decimal numbers; without B12 they would differ by up to 11 %
    assert abs(m.body_mass[1] - float(p.m)) < 1e-12
    eig = np.sort(np.linalg.eigvalsh(np.asarray(inertia_tensor(p))))
    assert np.allclose(np.sort(m.body_inertia[1]), eig, rtol=1e-9, atol=0)
    # pure spin on a fixed table: the torsional coefficient is the paper's pure-spin moment per unit
    # N, so spin decays at mu a_hat 4 E S2 m g / B3 = 2.5176 rad/s^2 in both models. Observed: MuJoCo
    # 2.5226 (0.2 %), jaxcelt 2.5174 (0.01 %); 2 % tolerance (MuJoCo's soft contact is not exact);
    # a wrong torsional coefficient (e.g. without mu or a_hat) is off by > 20 %.
    rate = mp.friction(p)[1] * float(p.m) * float(p.g) / float(p.B3)
    t, ws, tilt, _, _ = mp.run_mujoco(p, (0.0, 0.0, 10.0), 1.0, 2e-3, repeats=1)
    assert abs((ws[0] - ws[-1]) / (t[-1] - t[0]) - rate) < 0.02 * rate
    sol = jc.simulate(p, jc.initial_state(p, omega=(0.0, 0.0, 10.0)), 1.0, ts=np.array([0.0, 1.0]))
    assert abs(10.0 - float(sol.ys[-1, 5]) - rate) < 0.02 * rate
