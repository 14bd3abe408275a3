"""The lane engine's own interface (`jaxcelt.ensemble`): the fused Runge-Kutta stepper against
diffrax's own step in the same pool, and the pool's statistics against what the schedule implies."""

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from _sweep_common import KW, VALUES, assert_same_lanes

import jaxcelt as jc
from jaxcelt.ensemble import (
    DiffraxStepper,
    FusedERKStepper,
    LaneState,
    lane_outputs,
    lanes_params,
    make_stepper,
    run_pool,
    split_lane_args,
    start_lanes,
)


def _pool(params, kind, width):
    """The pool over the lanes of the shared sweep settings (VALUES, KW) with the given stepper."""
    pb = lanes_params(params, "omega_pi", VALUES)
    L = len(VALUES)
    y0 = jnp.tile(jnp.asarray(jc.initial_state(params)), (L, 1))
    T = 2 * np.pi / VALUES
    ts = jnp.asarray(T[:, None] * (KW["transient_periods"] + np.arange(KW["sample_periods"]))[None])
    vary = tuple(bool(np.any(np.asarray(x) != np.asarray(x)[:1])) for x in jax.tree_util.tree_leaves(pb))
    opts = dict(rtol=KW["rtol"], atol=KW["atol"], max_steps=KW["max_steps"], stop_on_invalid=False)

    @jax.jit
    def run(pb, y0, ts, tols, opaque_true):
        stepper = make_stepper(diffrax.Tsit5(), None, opaque_true=opaque_true, **opts)
        assert isinstance(stepper, FusedERKStepper)
        if kind == "diffrax":  # diffrax's own Tsit5 step, as `simulate` takes it
            stepper = DiffraxStepper(
                solver=stepper.solver, term=stepper.term, max_steps=opts["max_steps"], stop_on_invalid=False
            )
        pv, args_of = split_lane_args(pb, vary)
        t0 = jnp.asarray(0.0)
        lanes, samples = start_lanes(stepper, pv, args_of, y0, ts, jnp.ones(L, bool), tols, t0)
        assert isinstance(lanes, LaneState)
        lanes, samples, stats = run_pool(
            stepper, lanes, samples, pv, args_of, ts, t0, width=width, pause_frac=jnp.asarray(jnp.inf)
        )
        return lane_outputs(stepper, lanes), samples, stats

    out, samples, stats = run(pb, y0, ts, jnp.asarray([KW["rtol"], KW["atol"]]), jnp.asarray(True))
    lanes = {k: np.asarray(v) for k, v in out.as_dict().items()}
    lanes["samples"] = np.asarray(samples)
    return lanes, stats


@pytest.fixture(scope="module")
def fused(paper_params):
    return _pool(paper_params, "fused", width=len(VALUES))


@pytest.mark.slow  # a second pool compile (~1 min on 2 busy cores); the fused step against `simulate`: test_sweep
def test_fused_stepper_equals_diffrax_stepper(fused, paper_params):
    # Same method (Tsit5), controller, first step and section clipping; the fused step sums the
    # stages in another order than diffrax's generic Runge-Kutta step. So: the same step counts
    # and statuses, samples within SAMPLE_ATOL (1e-10, as for the pool against `simulate`; see
    # _sweep_common), min N to rtol 1e-7 (N is a stiff function of the state, test_sweep).
    ref, _ = _pool(paper_params, "diffrax", width=len(VALUES))
    got, _ = fused
    assert_same_lanes(got, ref, keys=("samples", "num_steps", "status", "first_invalid_kind", "y_final"))
    np.testing.assert_allclose(got["min_N"], ref["min_N"], rtol=1e-7)
    # max tilt: the fused step keeps min n3 and takes arccos once, diffrax's monitor takes the max
    # of arccos(n3); arccos amplifies an n3 difference by 1/sin(tilt) (~25 at 0.04 rad), so rtol 1e-7
    np.testing.assert_allclose(got["max_tilt"], ref["max_tilt"], rtol=1e-7)


def test_pool_stats_follow_the_schedule(fused):
    # With a slot for every lane there is no queue, no pause and no drain: the loop runs until the
    # slowest lane is done, one step per lane and iteration, and pays every slot each iteration.
    lanes, stats = fused
    assert np.all(lanes["status"] == 0)
    assert stats.width == len(VALUES)
    assert int(stats.iterations) == int(lanes["num_steps"].max())
    assert int(stats.slot_steps) == int(stats.iterations) * stats.width
    assert int(stats.slot_steps) >= int(lanes["num_steps"].sum())


@pytest.mark.parametrize(
    ("name", "value"), [("drain_factor", 1), ("drain_factor", 2.5), ("min_drain_width", 0), ("drain_min_steps", -1)]
)
def test_drain_options_are_checked(paper_params, name, value):
    # checked before anything is traced: a clear error naming the option
    from jaxcelt.ensemble.stroboscopic import SweepConfig, run_lanes

    pb = lanes_params(paper_params, "omega_pi", VALUES[:2])
    y0 = np.tile(np.asarray(jc.initial_state(paper_params)), (2, 1))
    with pytest.raises(ValueError, match=name):
        run_lanes(pb, y0, SweepConfig(transient_periods=1, sample_periods=1), stats=True, **{name: value})


def test_drain_widths_schedule():
    # the documented schedule (`DRAIN_FACTOR`): no queue, no drain; 96 slots go straight to 4;
    # a wider pool passes through factor-of-8 widths while they stay >= 8 x 4
    from jaxcelt.ensemble.pool import drain_widths

    assert drain_widths(96, 50) == [50]
    assert drain_widths(96, 200) == [96, 4]
    assert drain_widths(256, 1000) == [256, 32, 4]
    assert drain_widths(96, 200, drain_factor=4) == [96, 24, 4]
    assert drain_widths(4, 200) == [4]


def test_remaining_steps_prediction():
    # steps so far x remaining span / elapsed span, for running lanes only; numpy in, numpy out.
    # Slots: a lane 1/4 through its span after 100 steps (300 more), one not stepped yet (0),
    # a finished one (0), an empty slot (0).
    from types import SimpleNamespace

    from jaxcelt.ensemble.pool import remaining_steps

    lane = SimpleNamespace(
        tprev=np.array([2.5, 0.0, 10.0, 3.0]), t1=np.full(4, 10.0), num_steps=np.array([100, 0, 80, 7]),
        done=np.array([False, False, True, False]),
    )  # fmt: skip
    L = 6  # lanes per device: lane index 6 marks an empty slot
    carry = SimpleNamespace(
        slots=SimpleNamespace(lane=lane), lane=np.array([0, 1, 2, L]), samples=np.zeros((L, 3, 13)), nxt=np.array(0)
    )
    np.testing.assert_allclose(remaining_steps(carry, 0.0), [300.0, 0.0, 0.0, 0.0], rtol=1e-15)
