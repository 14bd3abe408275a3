"""A collapsing step size ends a solve (`jaxcelt.integrate.solve.MinStepController`, status 3) instead of
spending the whole step budget, as scipy's `solve_ivp` does ("required step size is less than
spacing between numbers")."""

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaxcelt as jc
from jaxcelt.ensemble import (
    DiffraxStepper,
    lane_outputs,
    lanes_params,
    make_stepper,
    run_pool,
    split_lane_args,
    start_lanes,
)
from jaxcelt.integrate.solve import MinStepController, status_code

RTOL, ATOL = 1e-8, 1e-10


def _blowup(controller, max_steps):
    """y' = y^2, y(0) = 1: y = 1 / (1 - t) leaves every float at t = 1."""
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(lambda t, y, args: y**2),
        diffrax.Tsit5(),
        0.0,
        2.0,
        None,
        jnp.asarray(1.0),
        stepsize_controller=controller,
        saveat=diffrax.SaveAt(steps=True),
        max_steps=max_steps,
        throw=False,
    )
    ts, ys = np.asarray(sol.ts), np.asarray(sol.ys)
    last = np.flatnonzero(np.isfinite(ts))[-1]
    return sol.result, float(ts[last]), float(ys[last]), int(sol.stats["num_steps"])


def test_collapsing_step_ends_the_solve_where_scipy_stops():
    max_steps = 100_000
    result, t_end, y_end, steps = _blowup(MinStepController(diffrax.PIDController(rtol=RTOL, atol=ATOL)), max_steps)
    assert result == diffrax.RESULTS.dt_min_reached
    assert status_code(result) == 3
    ref = solve_ivp(lambda t, y: y**2, (0.0, 2.0), [1.0], method="RK45", rtol=RTOL, atol=ATOL)
    assert ref.status == -1 and "spacing between numbers" in ref.message  # scipy gives up too
    # Both stop at the pole of their own numerical solution, where the step needed (proportional
    # to the distance to the pole) falls below 10 ULPs of t: y is past 1e12 there, and the pole
    # sits within the global error of the exact one (t = 1), i.e. within 10 rtol.
    assert y_end > 1e12 and ref.y[0, -1] > 1e12
    assert abs(t_end - 1.0) < 10 * RTOL and abs(ref.t[-1] - 1.0) < 10 * RTOL
    assert steps < max_steps // 20  # a few hundred steps, not the budget
    # Without the rule diffrax rejects and retries at t ~ 1 until the budget is spent.
    plain, _, _, plain_steps = _blowup(diffrax.PIDController(rtol=RTOL, atol=ATOL), max_steps)
    assert plain == diffrax.RESULTS.max_steps_reached and plain_steps == max_steps


def test_min_step_rule_leaves_a_smooth_solve_alone():
    """A damped oscillator: the wrapped controller takes the same steps to rounding (another
    compiled program, so not bitwise)."""

    def solve(controller):
        return diffrax.diffeqsolve(
            diffrax.ODETerm(lambda t, y, a: jnp.stack([y[1], -y[0] - 0.1 * y[1]])),
            diffrax.Tsit5(),
            0.0,
            20.0,
            None,
            jnp.asarray([1.0, 0.0]),
            stepsize_controller=controller,
            saveat=diffrax.SaveAt(ts=jnp.linspace(0.0, 20.0, 11)),
        )

    a = solve(diffrax.PIDController(rtol=RTOL, atol=ATOL))
    b = solve(MinStepController(diffrax.PIDController(rtol=RTOL, atol=ATOL)))
    assert b.result == diffrax.RESULTS.successful
    assert int(a.stats["num_steps"]) == int(b.stats["num_steps"])
    np.testing.assert_allclose(np.asarray(b.ys), np.asarray(a.ys), rtol=0, atol=1e-12)


@pytest.mark.parametrize("kind", ["fused", "diffrax"])
def test_lane_at_the_heading_singularity_fails_fast(paper_params, kind):
    """A lane lying on its side (n = (0, -1, 0): the heading's 1/(1 - n2^2) is 0/0) gets a NaN
    derivative; integrated on, it ends with status 3 after a few hundred rejected steps instead of
    max_steps, and its neighbour in the pool is untouched."""
    max_steps = 50_000
    pb = lanes_params(paper_params, "omega_pi", np.array([14.0, 15.0]))
    y = jnp.asarray(jc.initial_state(paper_params))
    y0 = jnp.stack([y, y.at[6:9].set(jnp.array([0.0, -1.0, 0.0]))])
    ts = jnp.tile(jnp.linspace(0.1, 0.5, 5), (2, 1))
    vary = tuple(bool(np.any(np.asarray(x) != np.asarray(x)[:1])) for x in jax.tree_util.tree_leaves(pb))

    @jax.jit
    def run(pb, y0, ts, tols):
        opts = dict(rtol=RTOL, atol=ATOL, max_steps=max_steps, stop_on_invalid=False)
        st = make_stepper(diffrax.Tsit5(), None, opaque_true=jnp.asarray(True), **opts)
        if kind == "diffrax":
            st = DiffraxStepper(solver=st.solver, term=st.term, max_steps=max_steps, stop_on_invalid=False)
        pv, args_of = split_lane_args(pb, vary)
        t0 = jnp.asarray(0.0)
        lanes, samples = start_lanes(st, pv, args_of, y0, ts, jnp.ones(2, bool), tols, t0)
        lanes, samples, _ = run_pool(st, lanes, samples, pv, args_of, ts, t0, width=2, pause_frac=jnp.asarray(jnp.inf))
        return lane_outputs(st, lanes)

    out = run(pb, y0, ts, jnp.asarray([RTOL, ATOL]))
    assert list(np.asarray(out.status)) == [0, 3]
    assert int(out.num_steps[1]) < 1000
    ref = jc.simulate(
        paper_params.replace(omega_pi=14.0),
        y,
        ts[0, -1],
        ts=ts[0],
        exact_ts=True,
        rtol=RTOL,
        atol=ATOL,
        stop_on_invalid=False,
    )
    assert int(out.num_steps[0]) == int(ref.num_steps)
