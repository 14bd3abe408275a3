"""The lane kernel's other modes: any ODE (`jaxcelt.ensemble.kernel_ode.solve_lanes`), mixed precision
(``field_dtype="float32"``) and the stiffness switch (``stiffness="auto"``, `jaxcelt.ensemble.stiff`
with the Rodas4P step of `jaxcelt.ensemble.rosenbrock`).

Off a GPU the kernel runs in Pallas' interpreter; that the GPU program can be built is checked by
lowering it for CUDA (Triton), which needs no GPU. GPU timings: ``benchmarks/gpu_ensemble.py``,
``benchmarks/gpu_map.py``.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaxcelt as jc
from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes
from jaxcelt.ensemble.kernel_ode import solve_lanes
from jaxcelt.ensemble.rosenbrock import RODAS4P, lu_factor, lu_solve

P = jc.CeltParams.paper()


def _lorenz(t, y, a):
    (rho,) = a
    return jnp.stack([10.0 * (y[1] - y[0]), rho * y[0] - y[1] - y[0] * y[2], y[0] * y[1] - (8.0 / 3.0) * y[2]])


def test_solve_lanes_lorenz_against_scipy():
    # Tsit5 at rtol = atol = 1e-8 over t in [0, 1] against scipy's DOP853 at 1e-12 (independent code):
    # final states within 1e-6 of max|state| (measured 3e-9); every lane succeeds
    L = 40  # not a multiple of the block: padding lanes are dropped
    rho = np.linspace(0.0, 21.0, L)
    y0 = np.tile([1.0, 0.0, 0.0], (L, 1))
    out = jax.jit(lambda y0, rho: solve_lanes(_lorenz, y0, (rho,), 0.0, 1.0, rtol=1e-8, atol=1e-8))(y0, rho)
    assert out["y1"].shape == (L, 3) and np.all(np.asarray(out["status"]) == 0)
    ref = np.array([
        solve_ivp(lambda t, y, r=r: np.asarray(_lorenz(t, y, (r,))), (0, 1), [1.0, 0, 0], method="DOP853",
                  rtol=1e-12, atol=1e-12).y[:, -1]
        for r in rho
    ])  # fmt: skip
    assert np.max(np.abs(np.asarray(out["y1"]) - ref)) <= 1e-6 * np.max(np.abs(ref))


def test_solve_lanes_names_bad_input():
    y0 = np.zeros((4, 3))
    with pytest.raises(ValueError, match="t1"):
        solve_lanes(_lorenz, y0, (np.ones(4),), 1.0, 0.0)
    with pytest.raises(ValueError, match="rtol"):
        solve_lanes(_lorenz, y0, (np.ones(4),), 0.0, 1.0, rtol=-1.0)
    with pytest.raises(ValueError, match="y0"):
        solve_lanes(_lorenz, np.zeros(3), (np.ones(4),), 0.0, 1.0)
    with pytest.raises(ValueError, match="solver"):
        import diffrax

        solve_lanes(_lorenz, y0, (np.ones(4),), 0.0, 1.0, solver=diffrax.Kvaerno5())


def _rodas_solve(f, J, ft, y, t1, n):
    T, h = RODAS4P, t1 / n
    for k in range(n):
        t = k * h
        LU = lu_factor([list(r) for r in np.eye(len(y)) / (T.gamma * h) - J(t, y)])
        ks = []
        for i in range(len(T.c)):
            u = y + sum(T.a[i, j] * ks[j] for j in range(i))
            r = f(t + T.c[i] * h, u) + T.d[i] * h * ft(t, y) + sum(T.C[i, j] / h * ks[j] for j in range(i))
            ks.append(np.array(lu_solve(LU, list(r))))
        y = y + sum(T.b[i] * ks[i] for i in range(len(T.c)))
    return y


@pytest.mark.parametrize("lam", [-1.0, -1e4])
def test_rodas4p_is_fourth_order_also_on_a_stiff_problem(lam):
    # y0' = -y0^2 + sin 3t + y1, y1' = lam (y1 - cos t): fixed steps h = 1/20 .. 1/160 against scipy's
    # Radau at 1e-13. The observed order log2(e(h)/e(h/2)) must be >= 3.5 on both the non-stiff (lam = -1)
    # and the stiff (lam = -1e4, Prothero-Robinson-like) problem (measured 3.9-4.1; Hairer & Wanner's
    # Rodas4 falls to ~1 on the stiff one)
    f = lambda t, y: np.array([-(y[0] ** 2) + np.sin(3 * t) + y[1], lam * (y[1] - np.cos(t))])  # noqa: E731
    J = lambda t, y: np.array([[-2 * y[0], 1.0], [0.0, lam]])  # noqa: E731
    ft = lambda t, y: np.array([3 * np.cos(3 * t), lam * np.sin(t)])  # noqa: E731
    ref = solve_ivp(f, (0, 1), [1.0, 1.0], method="Radau", rtol=1e-13, atol=1e-14, jac=J).y[:, -1]
    errs = [np.max(np.abs(_rodas_solve(f, J, ft, np.array([1.0, 1.0]), 1.0, n) - ref)) for n in (20, 40, 80, 160)]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(orders >= 3.5), orders


def test_lu_solve_matches_numpy():
    # elimination without pivoting on a W-like matrix (I/(gamma h) - J): 1e-12 relative (measured 1e-15)
    rng = np.random.default_rng(1)
    A = np.eye(13) * 40.0 - rng.standard_normal((13, 13))
    b = rng.standard_normal(13)
    x = np.array(lu_solve(lu_factor([list(r) for r in A]), list(b)))
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-12)


@pytest.mark.parametrize("mode", [dict(stiffness="auto"), dict(field_dtype="float32", rtol=1e-6, atol=1e-8)])
def test_kernel_modes_lower_for_cuda_without_a_gpu(mode, kernel_cuda_text):
    assert "triton" in kernel_cuda_text(SweepConfig(stop_on_invalid=True, **mode))


def test_mixed_precision_follows_float64():
    # the field in float32 (state, sums and error control float64) at rtol 1e-6 against the float64
    # kernel at 1e-8: samples within 1e-2 of max(|x|, 1e-2) after 5 periods (measured 1.5e-5), all lanes ok
    xs, ys = np.array([15.6, 17.0, 18.0, 19.0]), np.array([0.04, 0.04, 0.05, 0.06])
    pb = eqx.tree_at(lambda q: q.q_pi, lanes_params(P, "omega_pi", xs), jnp.asarray(ys))
    y0 = np.tile(np.asarray(jc.initial_state(P)), (4, 1))
    kw = dict(transient_periods=2, sample_periods=3, stop_on_invalid=True)
    a = run_lanes(pb, y0, SweepConfig(**kw), engine="kernel")
    b = run_lanes(pb, y0, SweepConfig(rtol=1e-6, atol=1e-8, field_dtype="float32", **kw), engine="kernel")
    assert np.all(a["status"] == 0) and np.all(b["status"] == 0)
    assert np.all(np.abs(b["samples"] - a["samples"]) <= 1e-2 * np.maximum(np.abs(a["samples"]), 1e-2))


def test_mixed_precision_and_stiffness_are_the_kernels():
    pb = lanes_params(P, "omega_pi", np.array([15.0]))
    y0 = np.asarray(jc.initial_state(P))[None]
    for mode in (dict(field_dtype="float32"), dict(stiffness="auto")):
        with pytest.raises(ValueError, match="lane kernel"):
            run_lanes(pb, y0, SweepConfig(transient_periods=1, sample_periods=1, **mode), engine="pool")
    with pytest.raises(ValueError, match="stiffness"):
        SweepConfig(stiffness="on")
    with pytest.raises(ValueError, match="field_dtype"):
        SweepConfig(field_dtype="float16")


@pytest.mark.slow
def test_stiffness_switch_on_a_sticking_lane():
    # omega_pi = 10 rad/s, q_pi = 0.02 m: base acceleration 2 m/s^2 < mu g, the stone sticks and the
    # explicit steps are stability-limited. With the switch the lane takes Rodas4P steps, fewer steps in
    # all, and its samples agree with the explicit kernel's to 1e-5 of max(|x|, 1e-3): two methods, each
    # at rtol 1e-8 per step over ~10^4 steps (measured: at most 1.0e-9 absolute)
    pb = eqx.tree_at(lambda q: q.q_pi, lanes_params(P, "omega_pi", np.array([10.0])), jnp.asarray([0.02]))
    y0 = np.asarray(jc.initial_state(P))[None]
    kw = dict(transient_periods=1, sample_periods=1, stop_on_invalid=True)
    off = run_lanes(pb, y0, SweepConfig(**kw), engine="kernel")
    auto = run_lanes(pb, y0, SweepConfig(stiffness="auto", **kw), engine="kernel")
    assert off["status"][0] == 0 and auto["status"][0] == 0
    assert auto["stiff_steps"][0] > 0 and off["stiff_steps"][0] == 0
    assert auto["num_steps"][0] < off["num_steps"][0]
    d = np.abs(auto["samples"] - off["samples"])
    assert np.all(d <= 1e-5 * np.maximum(np.abs(off["samples"]), 1e-3))
