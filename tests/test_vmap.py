"""Batching and compilation of `simulate` , plus an implicit-solver smoke test.

* A vmapped batch of 64 parameter sets (and initial states) equals 64 single runs to 1e-11 (identical step sequences; rounding only).
* New parameter values, initial states, t1, save times and tolerances do not retrace the solve.
  Detection: `jaxcelt.integrate.solve` builds its diffrax term from the module-level `vector_field`, which
  Python calls only while JAX traces the solve; the test swaps it for
  ``eqx.debug.assert_max_traces(vector_field, max_traces=0)``, so any retrace of the simulate
  path raises. Positive controls (a new batch size must retrace) prove the detectors work.
"""

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
import jaxcelt.physics.model as jmodel
from jaxcelt.integrate.solve import _fill_implicit_tols

B = 64
T1 = 0.3
TS = jnp.linspace(0.0, T1, 11)


def _params_and_states(seed, size=B):
    rng = np.random.default_rng(seed)
    ps, ys = [], []
    for _ in range(size):
        p = jc.CeltParams.paper(
            mu=rng.uniform(0.1, 0.4),
            k_r=rng.uniform(0.2, 0.6),
            b_Ts=rng.uniform(0.3, 0.8),
            m_Ts=rng.uniform(0.6, 1.2),
            omega_pi=rng.uniform(14.0, 19.0),
            q_pi=rng.uniform(0.02, 0.05),
            B12=rng.uniform(-2e-4, 2e-4),
        )
        n = np.array([rng.normal(0, 0.05), rng.normal(0, 0.05), 1.0])
        y0 = jc.initial_state(p, omega=rng.normal(0, 0.5, 3), n=n / np.linalg.norm(n), psi=rng.uniform(-np.pi, np.pi))
        ps.append(p)
        ys.append(np.asarray(y0))
    batched = jax.tree_util.tree_map(lambda *xs: jnp.stack(xs), *ps)
    return ps, np.stack(ys), batched


def _batched_solve(p, y0, t1, ts):
    sol = jc.simulate(p, y0, t1, ts=ts, rtol=1e-8, atol=1e-10)
    return sol.ys, sol.status, sol.num_steps


_vmapped = jax.jit(jax.vmap(_batched_solve, in_axes=(0, 0, None, None)))


def test_vmap_batch_equals_single_runs():
    """Tolerance 1e-11 (absolute + relative). Each lane takes exactly the step sequence of its single
    run (checked: equal step counts), so only XLA's vectorised rounding differs, and a batching
    bug would show at the solver tolerance (1e-8), not at 1e-11. The ulp-level differences grow
    with the (fast, partly unstable) dynamics of the spinning lanes: measured max 1.1e-12 over
    0.3 s (1.8e-12 with a 0.2 s horizon's different final steps) since the RHS uses the
    polynomial sin/cos and exp/log powers (1.9e-13 before), 2e-11 at 0.4 s and 1e-10 at 0.5 s."""
    ps, y0s, batched = _params_and_states(0)
    ys_b, status_b, steps_b = (np.asarray(x) for x in _vmapped(batched, jnp.asarray(y0s), T1, TS))
    assert np.all(status_b == 0)
    assert len(np.unique(steps_b)) > 5  # lanes really take different step sequences
    for i in range(B):
        sol = jc.simulate(ps[i], y0s[i], T1, ts=TS, rtol=1e-8, atol=1e-10)
        assert int(sol.num_steps) == int(steps_b[i])
        np.testing.assert_allclose(ys_b[i], np.asarray(sol.ys), rtol=1e-11, atol=1e-11)
    # the batch is diverse (different motions)
    assert np.ptp(ys_b[:, -1, 4]) > 0.1


def test_no_retrace_on_new_values(monkeypatch):
    """New values of everything dynamic reuse the compiled solve (single and vmapped paths)."""
    p = jc.CeltParams.paper()
    y0 = jc.initial_state(p)
    ts = jnp.linspace(0.0, 0.2, 7)  # a shape no other test uses, so the first call below traces
    counting = eqx.debug.assert_max_traces(jc.vector_field, max_traces=None)
    monkeypatch.setattr(jmodel, "vector_field", counting)
    jc.simulate(p, y0, 0.2, ts=ts)
    assert eqx.debug.get_num_traces(counting) > 0  # the detector sees the trace
    # dt0=None vs a given dt0 is a change of structure (one more compilation, by design)
    jc.simulate(p, y0, 0.2, ts=ts, dt0=1e-3)

    # from now on any trace of the simulate path raises
    monkeypatch.setattr(jmodel, "vector_field", eqx.debug.assert_max_traces(jc.vector_field, max_traces=0))
    p2 = p.replace(mu=0.31, k_r=0.2, omega_pi=15.6, b_Ts=0.7, m_Ts=1.1, q_pi=0.03, v_pi_sign=-1.0)
    y2 = jc.initial_state(p2, omega=(0.1, -0.2, 1.0), n=(0.05, 0.0, float(np.sqrt(1 - 0.05**2))), psi=0.3)
    for kwargs in (
        dict(),
        dict(rtol=1e-9, atol=1e-11),
        dict(t0=0.05),
        dict(dt0=1e-4),
    ):
        sol = jc.simulate(p2, y2, 0.3, ts=jnp.linspace(kwargs.get("t0", 0.0), 0.3, 7), **kwargs)
        assert bool(sol.success)

    # vmapped path. Under jax.vmap the inner jitted solve is batched from its cached jaxpr, so
    # vector_field (still max_traces=0) must not be called at all; the outer function is guarded
    # by its own counter: one trace for the first batch, none for new values.
    _, y0s, batched = _params_and_states(1, size=8)  # small batch: this test is about tracing
    outer = eqx.debug.assert_max_traces(lambda pp, yy: jc.simulate(pp, yy, 0.2, ts=ts).ys, max_traces=1)
    run = jax.jit(jax.vmap(outer))
    a = run(batched, jnp.asarray(y0s))
    _, y0s2, batched2 = _params_and_states(2, size=8)
    b = run(batched2, jnp.asarray(y0s2))
    assert eqx.debug.get_num_traces(outer) == 1
    assert np.abs(np.asarray(a) - np.asarray(b)).max() > 1e-3  # new values did give new results
    with pytest.raises(RuntimeError):  # positive control: a new batch size must retrace
        run(jax.tree_util.tree_map(lambda x: x[:4], batched), jnp.asarray(y0s[:4]))


def test_implicit_solver_tolerances_filled():
    """Cheap check (no compilation): diffeqsolve cannot reach through MonitoredSolver to give the
    implicit solver's root finder the step-size controller's tolerances, so simulate fills them."""
    solver = _fill_implicit_tols(diffrax.Kvaerno5(), 1e-9, 1e-11)
    rf = solver.root_finder
    assert float(rf.rtol) == 1e-9 and float(rf.atol) == 1e-11


@pytest.mark.slow
def test_implicit_solver_smoke():
    """Kvaerno5 through simulate (root-finder tolerances pre-filled behind the MonitoredSolver
    wrapper) from rest on the vibrating base: success, finite, and within 1e-6 of a tight Tsit5
    solve after 0.2 s (rtol 1e-8 vs 1e-11). Slow: compiling Kvaerno5 costs ~23 s of CPU."""
    p = jc.CeltParams.paper()
    y0 = jc.initial_state(p)
    ts = jnp.linspace(0.0, 0.2, 5)
    imp = jc.simulate(p, y0, 0.2, ts=ts, solver=diffrax.Kvaerno5(), rtol=1e-8, atol=1e-10)
    ref = jc.simulate(p, y0, 0.2, ts=ts, rtol=1e-11, atol=1e-13)
    assert bool(imp.success) and bool(imp.valid), imp.summary()
    assert np.all(np.isfinite(np.asarray(imp.ys)))
    np.testing.assert_allclose(np.asarray(imp.ys), np.asarray(ref.ys), rtol=0, atol=1e-6)
    assert np.abs(np.asarray(ref.ys[-1, 3:6])).max() > 0.01  # something happened
