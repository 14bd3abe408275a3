"""Sweeps: vmapped lanes equal single `simulate` runs, failing lanes are isolated, sharding is
transparent, following an attractor carries states. Compared against `jaxcelt.simulate` (the core
entry point, not written for the sweep) and against numpy recomputation of the section times."""

import dataclasses
import json
import os
import subprocess
import sys
import textwrap

import jax
import numpy as np
import pytest
from _sweep_common import KW, SAMPLE_ATOL, VALUES, assert_same_lanes, assert_steps_close

import jaxcelt as jc
from jaxcelt.commands.args import parse_range
from jaxcelt.ensemble import lanes_params
from jaxcelt.sweeps.api import bifurcation
from jaxcelt.sweeps.following import follow_attractor


@pytest.fixture(scope="module")
def base(paper_params):
    return bifurcation(paper_params, VALUES, **KW)


def test_parse_range():
    np.testing.assert_array_equal(parse_range("10:20:3"), [10.0, 15.0, 20.0])
    np.testing.assert_array_equal(parse_range("14,15.6"), [14.0, 15.6])
    with pytest.raises(ValueError):
        parse_range("10:20")


def test_lanes_params(paper_params):
    pb = lanes_params(paper_params, "mu", np.array([0.1, 0.2]))
    assert pb.mu.shape == (2,) and pb.m.shape == (2,)
    with pytest.raises(ValueError, match="unknown parameter"):
        lanes_params(paper_params, "nope", np.array([1.0]))


def test_sweep_equals_single_simulate(base, paper_params):
    # Same solver, tolerances and exact section times: a lane of the vmapped chunk must be the
    # single-trajectory solve up to floating-point reassociation (<= 1e-10 demanded by the issue;
    # observed ~1e-13, the chaotic lanes amplify roundoff over 7 periods).
    assert np.all(base.status == 0)
    for i, w in enumerate(VALUES):
        p = paper_params.replace(omega_pi=w)
        T = 2 * np.pi / w
        ts = T * np.arange(KW["transient_periods"], KW["transient_periods"] + KW["sample_periods"])
        np.testing.assert_allclose(base.t_samples[i], ts, rtol=1e-15, atol=0)
        sol = jc.simulate(p, jc.initial_state(p), ts[-1], ts=ts, exact_ts=True, rtol=1e-8, atol=1e-10, max_steps=4000)
        err = np.max(np.abs(np.asarray(sol.ys) - base.samples[i]))
        assert err <= 1e-10, (w, err)
        assert int(sol.num_steps) == int(base.num_steps[i])
        # N is a stiff function of the state (friction relaxation ~ 3.5e4 1/s): 1e-13 in y
        # gives ~1e-9 in N, hence the looser tolerance
        np.testing.assert_allclose(float(sol.validity.min_N), base.min_N[i], rtol=1e-7)


def test_lyapunov_stage_equals_celt_lyapunov_and_starts_deferred_work(paper_params):
    # The sweep's Lyapunov stage (vmapped over the successful lanes in padded groups) against
    # celt_lyapunov on one lane from that lane's first sample: the same estimator compiled in another
    # program. Where rounding flips an accept decision the step sequences part and the two differ
    # at the solver tolerance (rtol 1e-8 over 2 periods), far below 1e-6 1/s; a wrong start, time or
    # period count changes lambda by ~0.1 1/s. The stage also starts programs deferred for later
    # (`prepare_dense_trajectory(defer=True)`): queued before the sweep, started by it, then used by
    # `dense_trajectory`.
    from jaxcelt import _executable_cache as ec
    from jaxcelt.sweeps.dense import dense_trajectory, prepare_dense_trajectory

    okw = dict(transient_periods=1, periods=1, points_per_period=3)
    prepare_dense_trajectory(paper_params.replace(omega_pi=14.0), defer=True, **okw)
    assert ec._DEFERRED
    vals = np.array([14.0, 17.0])
    r = bifurcation(paper_params, vals, **{**KW, "chunk_size": 2}, lyapunov_periods=2)
    assert not ec._DEFERRED
    for i, w in enumerate(vals):
        p = paper_params.replace(omega_pi=float(w))
        lr = jc.celt_lyapunov(p, r.samples[i, 0], periods=2, t0=r.t_samples[i, 0], rtol=1e-8, atol=1e-10, max_steps=4000)
        assert np.isfinite(r.lyapunov[i]), w
        np.testing.assert_allclose(r.lyapunov[i], float(lr.exponent), rtol=0, atol=1e-6, err_msg=str(w))
    n = len(ec._MEMORY)
    o = dense_trajectory(paper_params.replace(omega_pi=17.0), **okw)
    assert o["status"] == 0 and len(ec._MEMORY) == n  # the deferred program, not a new one


@pytest.mark.parametrize("n_ok,per_device,n_devices", [(27, 16, 2), (32, 16, 2), (33, 16, 2), (5, 4, 3), (1, 16, 1), (0, 8, 2)])
def test_lyapunov_groups_deal_every_lane_once_round_robin(n_ok, per_device, n_devices):
    # The Lyapunov stage's groups: every successful lane computed in exactly one position of its own (the others
    # are padding), lanes j of a group on device j mod n_devices (device d holds the contiguous block d of the
    # sharded group), so that the costly first lanes of a cost-ordered group are spread over the devices.
    from jaxcelt.ensemble.stroboscopic import lyapunov_groups

    rng = np.random.default_rng(0)
    ok = rng.permutation(100)[:n_ok]
    groups = lyapunov_groups(ok, per_device, n_devices)
    G = per_device * n_devices
    assert len(groups) == -(-n_ok // G)
    seen = []
    for g, (idx, own) in enumerate(groups):
        assert idx.shape == own.shape == (G,)
        part = ok[g * G : (g + 1) * G]
        assert set(idx.tolist()) == set(part.tolist())  # padding copies a lane of the group
        assert own.sum() == len(part)
        for j, lane in enumerate(part):
            pos = np.flatnonzero((idx == lane) & own)
            assert pos.size == 1, (lane, pos)
            assert pos[0] // per_device == j % n_devices  # the device holding position pos[0]
        seen += idx[own].tolist()
    assert sorted(seen) == sorted(ok.tolist())


def test_failing_lane_is_isolated(base, paper_params):
    # A lane made stiff (mu = 30: the sticking relaxation rate ~ mu g/(a_hat sqrt(eps)),
    # MODEL.md section 10, grows 130x) exhausts max_steps; it is flagged and the other lanes
    # are unchanged: same step counts, samples within SAMPLE_ATOL (a varying mu compiles
    # another program than the base sweep, so rounding may differ; see _sweep_common).
    y0 = np.asarray(jc.initial_state(paper_params))
    params = paper_params
    from jaxcelt.ensemble import SweepConfig, run_lanes

    cfg = SweepConfig(transient_periods=3, sample_periods=4, max_steps=4000)
    pb = lanes_params(params, "omega_pi", VALUES)
    import equinox as eqx

    pb = eqx.tree_at(lambda p: p.mu, pb, np.array([0.2241, 0.2241, 30.0, 0.2241]))
    out = run_lanes(pb, np.tile(y0, (4, 1)), cfg)
    assert out["status"][2] == 1  # max_steps reached
    assert np.all(out["status"][[0, 1, 3]] == 0)
    for i in (0, 1, 3):
        assert_steps_close(out["num_steps"][i], base.num_steps[i])
        assert np.isfinite(out["samples"][i]).all()
        np.testing.assert_allclose(out["samples"][i], base.samples[i], rtol=0, atol=SAMPLE_ATOL)


def test_multistart_shapes(paper_params):
    y0 = np.stack([jc.initial_state(paper_params), jc.initial_state(paper_params, omega=(0.0, 0.0, -2.0))])
    r = bifurcation(paper_params, VALUES[:2], y0=y0, **KW)  # 2 values x 2 starts = 4 lanes: same chunk shape
    assert r.samples.shape == (2, 2, KW["sample_periods"], 13)
    assert r.values.shape == (2, 2)
    assert not np.allclose(r.samples[:, 0], r.samples[:, 1])


def test_bad_inputs(paper_params):
    with pytest.raises(ValueError):
        bifurcation(paper_params, [-1.0], transient_periods=1, sample_periods=1)
    with pytest.raises(ValueError):
        bifurcation(paper_params, [15.0], transient_periods=1, sample_periods=0)


@pytest.mark.slow
def test_continuation_carries_state(paper_params):
    res = follow_attractor(paper_params, "omega_pi", [16.0, 16.5], direction="up", transient_periods=2, sample_periods=2)
    up = res["up"]
    assert up.samples.shape == (2, 1, 2, 13)
    # the second value started where the first ended: rerun it by hand from that state
    p = paper_params.replace(omega_pi=16.5)
    T = 2 * np.pi / 16.5
    ts = T * np.arange(2, 4)
    sol = jc.simulate(p, up.y_final[0, 0], ts[-1], ts=ts, exact_ts=True)
    assert np.max(np.abs(np.asarray(sol.ys) - up.samples[1, 0])) <= 1e-10


@pytest.mark.slow
def test_two_host_devices_equal_one():
    # Forced 2 CPU devices (XLA flag) in a fresh process: the sharded chunk must equal the
    # one-device chunk. Both run in the same process so only the device count differs.
    code = textwrap.dedent(
        """
        import jax, numpy as np, jaxcelt as jc
        from jaxcelt.sweeps.api import bifurcation
        assert len(jax.local_devices()) == 2, jax.local_devices()
        p = jc.CeltParams.paper()
        v = np.array([12.0, 14.0, 17.0, 19.0])
        kw = dict(transient_periods=3, sample_periods=4, max_steps=4000, chunk_size=4)
        a = bifurcation(p, v, **kw)
        b = bifurcation(p, v, devices=jax.local_devices()[:1], **kw)
        kw2 = dict(kw, chunk_size=2)  # same per-device batch (2 lanes) as the sharded run
        c = bifurcation(p, v, devices=jax.local_devices()[:1], **kw2)
        print("MAXDIFF", float(np.max(np.abs(a.samples - b.samples))), bool(np.array_equal(a.samples, c.samples)))
        """
    )
    env = dict(os.environ, XLA_FLAGS="--xla_force_host_platform_device_count=2")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    line = [s for s in out.stdout.splitlines() if s.startswith("MAXDIFF")][0]
    maxdiff = float(line.split()[1])
    # Against a 1-device chunk of 4 lanes the vector width differs (2 lanes per device), so
    # XLA's roundoff differs and chaotic lanes amplify it over 7 periods: observed 2.4e-11;
    # the 1e-10 applies. (Not bitwise even at equal per-device width: shard_map
    # compiles a different program. The flag printed last records that.)
    assert maxdiff <= 1e-10, line


def test_stop_on_invalid_lanes_equal_simulate(base, paper_params):
    # omega_pi = 12 leaves the lower half-surface (n3 <= 0) within the 7 periods: with
    # stop_on_invalid the lane ends there (status 2, later samples inf), exactly like
    # simulate(..., stop_on_invalid=True) (diffrax Event); the valid lanes are unchanged.
    r = bifurcation(paper_params, VALUES, stop_on_invalid=True, **KW)
    assert base.first_invalid_kind[0] > 0 and np.all(base.first_invalid_kind[1:] == 0)
    assert r.status[0] == 2 and np.all(r.status[1:] == 0)
    assert not r.valid[0]
    for i, w in enumerate(VALUES):
        p = paper_params.replace(omega_pi=w)
        ts = r.t_samples[i]
        sol = jc.simulate(p, jc.initial_state(p), ts[-1], ts=ts, exact_ts=True, max_steps=4000, stop_on_invalid=True)
        ys = np.asarray(sol.ys)
        # simulate and the pool are two compiled programs: the same status and step counts within
        # STEPS_RTOL (measured: equal), hence the same stopped samples
        assert int(sol.status) == r.status[i]
        assert_steps_close(int(sol.num_steps), r.num_steps[i])
        np.testing.assert_array_equal(np.isfinite(ys), np.isfinite(r.samples[i]))
        fin = np.isfinite(ys)
        assert np.max(np.abs(ys[fin] - r.samples[i][fin]), initial=0.0) <= 1e-10
        # same step, its end time to roundoff (vmapped vs single solve are not bitwise; the
        # stiff approach to the invalid state amplifies it: observed 1.1e-10 s at t = 3.1 s)
        np.testing.assert_allclose(float(sol.validity.first_invalid_t), r.first_invalid_t[i], rtol=1e-9)
    assert np.isinf(r.samples[0, -1]).all()  # stopped before the last section
    assert r.num_steps[0] < base.num_steps[0]
    # valid lanes: stop_on_invalid compiles another program; same lanes within SAMPLE_ATOL
    np.testing.assert_allclose(r.samples[1:], base.samples[1:], rtol=0, atol=SAMPLE_ATOL)
    assert_steps_close(r.num_steps[1:], base.num_steps[1:])


def _vmapped_simulate(params, values, *, transient_periods, sample_periods, rtol, atol, max_steps, **_):
    """Test oracle (the engine before the lane pool): one jax.vmap of `jaxcelt.simulate` over the
    lanes, every lane integrated to the end by the vmapped while loop."""
    import jax.numpy as jnp

    pb = lanes_params(params, "omega_pi", values)
    y0 = jc.initial_state(params)

    def lane(p):
        ts = 2 * jnp.pi / p.omega_pi * (transient_periods + jnp.arange(sample_periods, dtype=jnp.float64))
        sol = jc.simulate(p, y0, ts[-1], ts=ts, exact_ts=True, rtol=rtol, atol=atol, max_steps=max_steps)
        return sol.ys, sol.num_steps, sol.status, sol.validity.first_invalid_kind

    ys, steps, status, kind = jax.jit(jax.vmap(lane))(pb)
    return {"samples": ys, "num_steps": steps, "status": status, "first_invalid_kind": kind}


@pytest.mark.slow
def test_pool_equals_vmapped_simulate(base, paper_params):
    # the lane pool (refilled slots, pilot pause, fused step) and one vmapped simulate over the
    # same lanes (the engine the pool replaced) give the same lanes, per assert_same_lanes
    ref = _vmapped_simulate(paper_params, VALUES, **KW)
    got = {k: getattr(base, k) for k in ("samples", "num_steps", "status", "first_invalid_kind")}
    assert_same_lanes(got, ref, keys=("samples", "num_steps", "status", "first_invalid_kind"))


@pytest.mark.parametrize("solver", ["Dopri8", "Heun"])
def test_pool_other_solvers_equal_simulate(paper_params, solver):
    # Dopri8 (13 stages, FSAL) runs the pool's fused Runge-Kutta step (`_erk_lane_step`);
    # Heun (no FSAL) falls back to diffrax's own step (`_lane_step`, step for step as
    # `simulate`: samples to rounding, same step counts). The fused step sums the error
    # estimate in another order than diffrax's tensordot; Dopri8's 8th-order error weights
    # cancel strongly, so the first proposed steps differ at ~1e-15 relative and the lane
    # drifts from `simulate` by rounding amplified through the step-size control (measured
    # over 3 periods at rtol 1e-7: 5 of 436 steps, samples ~1e-9 apart). Tolerance: 10 rtol
    # on the samples and 3 % on the step count -- what "same method, same tolerance" means.
    import diffrax

    from jaxcelt.ensemble import erk_tableau

    s = getattr(diffrax, solver)()
    fused = erk_tableau(s) is not None
    assert fused == (solver == "Dopri8")
    vals = VALUES[1:3]
    tol = 1e-7 if fused else 1e-5  # Heun is 2nd order
    kw = dict(transient_periods=1, sample_periods=3, rtol=tol, atol=tol / 100, max_steps=100_000)
    r = bifurcation(paper_params, vals, solver=s, **kw)
    for i, w in enumerate(vals):
        p = paper_params.replace(omega_pi=w)
        ts = r.t_samples[i]
        sol = jc.simulate(p, jc.initial_state(p), ts[-1], ts=ts, exact_ts=True, solver=s, **{k: kw[k] for k in ("rtol", "atol", "max_steps")})  # fmt: skip
        assert int(sol.status) == r.status[i] == 0
        err = np.max(np.abs(np.asarray(sol.ys) - r.samples[i]))
        if fused:
            assert abs(int(sol.num_steps) - int(r.num_steps[i])) <= 0.03 * int(sol.num_steps)
            assert err <= 10 * kw["rtol"], err
        else:
            assert int(sol.num_steps) == int(r.num_steps[i])
            assert err <= 1e-10, err


def test_pool_drain_compaction_keeps_lanes(paper_params):
    # 40 lanes through 32 slots: once <= 4 lanes are left the pool continues 4 wide, stepping in
    # its inner loop (the drain; drain_min_steps=0: whatever the lanes left are predicted to
    # cost). Lanes must not depend on the width they ran at: compare with a pool that is 8 wide
    # from the start, and with the same pool finishing at its full width (the default here: the
    # last lanes' few hundred steps do not pay for compiling the drain). Different widths are different compiled programs
    # (on an AVX-512 CPU ~half the samples differ at <= 1.6e-12 relative), so: same step
    # counts and statuses, samples within SAMPLE_ATOL (see _sweep_common).
    from jaxcelt.ensemble import SweepConfig, run_lanes

    vals = np.linspace(12.0, 19.0, 40)
    y0 = np.tile(np.asarray(jc.initial_state(paper_params)), (len(vals), 1))
    pb = lanes_params(paper_params, "omega_pi", vals)
    cfg = SweepConfig(transient_periods=0, sample_periods=2, max_steps=4000)
    one = jax.local_devices()[:1]
    wide = run_lanes(pb, y0, cfg, width=32, devices=one, drain_min_steps=0)
    narrow = run_lanes(pb, y0, cfg, width=8, devices=one)
    it, paid = int(wide["pool_iterations"][0]), int(wide["pool_slot_steps"][0])
    assert paid < 32 * it  # the drain ran narrower
    assert paid >= int(wide["num_steps"].sum())
    assert_same_lanes(wide, narrow)
    full = run_lanes(pb, y0, cfg, width=32, devices=one)
    it, paid = int(full["pool_iterations"][0]), int(full["pool_slot_steps"][0])
    assert paid == 32 * it  # no drain: every iteration paid 32 slots
    assert_same_lanes(full, wide)
    with pytest.raises(ValueError, match="drain_min_steps"):
        run_lanes(pb, y0, cfg, width=32, devices=one, drain_min_steps=-1)


def test_drain_compiles_early_integrating_on_and_runs_only_when_needed(paper_params, monkeypatch):
    # Integrating every lane on, the drain's program is sent to compile with the pool's others (lanes that stick
    # to the base are long); stopping at invalid states, only when the lanes left need it. Whether it runs depends
    # on the lanes alone: these lanes' last few hundred steps are below DRAIN_MIN_STEPS, so the pool finishes at
    # its full width (every iteration paid 32 slots), with the same lanes as a pool that does drain
    # (drain_min_steps=0). Same step counts and statuses, samples within SAMPLE_ATOL (another width is another
    # compiled program; see test_pool_drain_compaction_keeps_lanes).
    from jaxcelt.ensemble import SweepConfig, lane_programs, run_lanes

    sent = []
    real = lane_programs.compile_later
    monkeypatch.setattr(lane_programs, "compile_later", lambda fn: sent.append(getattr(fn, "__name__", "")) or real(fn))
    vals = np.linspace(12.0, 19.0, 40)
    y0 = np.tile(np.asarray(jc.initial_state(paper_params)), (len(vals), 1))
    pb = lanes_params(paper_params, "omega_pi", vals)
    one = jax.local_devices()[:1]
    on = SweepConfig(transient_periods=0, sample_periods=2, max_steps=4000, stop_on_invalid=False)
    full = run_lanes(pb, y0, on, width=32, devices=one)
    assert sent.count("drain_program") == 1  # sent with the others, not run
    it, paid = int(full["pool_iterations"][0]), int(full["pool_slot_steps"][0])
    assert paid == 32 * it
    drained = run_lanes(pb, y0, on, width=32, devices=one, drain_min_steps=0)
    it, paid = int(drained["pool_iterations"][0]), int(drained["pool_slot_steps"][0])
    assert paid < 32 * it
    assert_same_lanes(full, drained)
    sent.clear()
    run_lanes(pb, y0, dataclasses.replace(on, stop_on_invalid=True), width=32, devices=one)
    assert "drain_program" not in sent


def test_wide_vector_pool_keeps_lanes(paper_params):
    # A pool of >= WIDE_VECTORS_MIN_SLOTS slots per device is compiled for 512-bit vectors on a CPU
    # (`jaxcelt._compile_options.pool_compiler_options`), a narrower one with XLA's defaults: two
    # compiled programs that may round differently (on a CPU without AVX-512 they are the same).
    # Lanes must not depend on it: same step counts and statuses, samples within SAMPLE_ATOL.
    from jaxcelt._compile_options import WIDE_VECTORS_MIN_SLOTS, pool_compiler_options
    from jaxcelt.ensemble import SweepConfig, run_lanes

    W = WIDE_VECTORS_MIN_SLOTS
    assert pool_compiler_options("cpu", W) == {"xla_cpu_prefer_vector_width": 512}
    assert pool_compiler_options("cpu", W // 4) is None and pool_compiler_options("gpu", W) is None
    vals = np.linspace(12.0, 19.0, W)
    y0 = np.tile(np.asarray(jc.initial_state(paper_params)), (len(vals), 1))
    pb = lanes_params(paper_params, "omega_pi", vals)
    cfg = SweepConfig(transient_periods=0, sample_periods=2, max_steps=4000)
    one = jax.local_devices()[:1]
    wide = run_lanes(pb, y0, cfg, width=W, devices=one)
    narrow = run_lanes(pb, y0, cfg, width=W // 4, devices=one)
    assert_same_lanes(wide, narrow)


def test_narrow_pool_inner_loop_keeps_lanes(paper_params):
    # A pool of at most SEQUENTIAL_WIDTH slots steps in an inner loop until a lane reaches a
    # section time, finishes or pauses, and its stepper sees only each lane's next two section
    # times (`run_pool`). 12 lanes through 3 slots (a queue, pilot pauses, refills, lanes that stop
    # invalid and lanes that run out of steps) must equal the same lanes through 12 slots stepped
    # once per iteration. Another width is another compiled program: same steps and statuses,
    # floats within SAMPLE_ATOL (min_N to rtol 1e-7, as in the pilot test below).
    from jaxcelt.ensemble import SweepConfig, run_lanes
    from jaxcelt.ensemble.pool import SEQUENTIAL_WIDTH

    # from rest, omega_pi = 10 and 10.5 need > 3000 steps to their first invalid state (~4.9
    # periods), 11.5 and 12.25 ~2100-2300 (~5.5-6 periods); 14-19 stay valid over 7 periods.
    # (Near 13.9 a lane amplifies rounding to ~1.6e-10 over these 7 periods between any two pool
    # widths, with or without the inner loop: a lane the 1e-10 tolerance does not cover.)
    vals = np.concatenate([[10.0, 10.5, 11.5, 12.25], np.linspace(14.0, 19.0, 8)])
    y0 = np.tile(np.asarray(jc.initial_state(paper_params)), (len(vals), 1))
    pb = lanes_params(paper_params, "omega_pi", vals)
    cfg = SweepConfig(transient_periods=1, sample_periods=6, max_steps=2800, stop_on_invalid=True)
    one = jax.local_devices()[:1]
    narrow = run_lanes(pb, y0, cfg, width=3, devices=one)
    wide = run_lanes(pb, y0, cfg, width=len(vals), devices=one)
    assert 3 <= SEQUENTIAL_WIDTH < len(vals)
    assert set(np.unique(wide["status"])) >= {0, 1, 2}  # finished, out of steps, stopped invalid
    # one width, every slot paid at every step; the inner loop's steps are counted as iterations
    it, paid = int(narrow["pool_iterations"][0]), int(narrow["pool_slot_steps"][0])
    assert paid == 3 * it and paid >= int(narrow["num_steps"].sum())
    assert_same_lanes(narrow, wide, keys=("samples", "num_steps", "status"))
    # max tilt = arccos(min n3) amplifies an n3 difference by 1/sin(tilt) (~20 at 0.05 rad): rtol 1e-7
    np.testing.assert_allclose(narrow["max_tilt"], wide["max_tilt"], rtol=1e-7)
    # final states of the lanes that ran to the end; the others end tumbling towards lift-off,
    # where two widths' rounding grows to ~1e-7 in 5 periods (with or without the inner loop)
    ok = wide["status"] == 0
    np.testing.assert_allclose(narrow["y_final"][ok], wide["y_final"][ok], rtol=0, atol=SAMPLE_ATOL)
    np.testing.assert_allclose(narrow["first_invalid_t"], wide["first_invalid_t"], rtol=1e-9)
    np.testing.assert_allclose(narrow["min_N"], wide["min_N"], rtol=1e-7)


def test_pool_pilot_pause_keeps_lanes(paper_params):
    # With more lanes than slots every lane first pauses after a tenth of its time span and
    # waits; free slots then take the waiting lanes costliest first (`_pool`). A pause falls
    # between two steps, so each lane must equal a run without pauses -- including lanes that
    # run out of steps (max_steps: status 1) and lanes that stop invalid. The pilot is another
    # compiled program, so: same steps and statuses, floats within SAMPLE_ATOL (min_N to rtol
    # 1e-7: N is a stiff function of the state, see test_sweep_equals_single_simulate).
    from jaxcelt.ensemble import SweepConfig, run_lanes

    vals = np.linspace(10.0, 19.0, 40)
    y0 = np.tile(np.asarray(jc.initial_state(paper_params)), (len(vals), 1))
    pb = lanes_params(paper_params, "omega_pi", vals)
    cfg = SweepConfig(transient_periods=1, sample_periods=2, max_steps=1500, stop_on_invalid=True)
    one = jax.local_devices()[:1]
    pilot = run_lanes(pb, y0, cfg, width=8, devices=one, pilot_fraction=0.1)
    plain = run_lanes(pb, y0, cfg, width=8, devices=one, pilot_fraction=0)
    assert set(np.unique(plain["status"])) >= {0, 1}  # the case covers finished and failed lanes
    # the schedules differ (the pilot reorders the lanes), the lanes do not
    assert int(pilot["pool_slot_steps"][0]) != int(plain["pool_slot_steps"][0])
    assert_same_lanes(pilot, plain, keys=("samples", "num_steps", "status", "y_final", "max_tilt"))
    np.testing.assert_allclose(pilot["first_invalid_t"], plain["first_invalid_t"], rtol=1e-9)
    np.testing.assert_allclose(pilot["min_N"], plain["min_N"], rtol=1e-7)


QPI = np.array([0.04, 0.05])  # the paper's q_pi and a stronger forcing


@pytest.fixture(scope="module")
def pmap(paper_params, tmp_path_factory):
    out = tmp_path_factory.mktemp("map") / "map"
    return jc.parameter_map(paper_params, x=("omega_pi", VALUES), y=("q_pi", QPI), out=str(out), **KW), out


def test_parameter_map_lanes_equal_bifurcation(pmap, base, paper_params):
    # Every grid point is a lane of the same engine: column q_pi = 0.04 equals the base sweep,
    # column 0.05 a bifurcation sweep with q_pi = 0.05. The map varies two parameters and mixes
    # the lanes differently in its chunks: another compiled program, so same steps and statuses
    # and samples within SAMPLE_ATOL (see _sweep_common), not bitwise.
    ds, _ = pmap
    assert ds["section"].dims == ("omega_pi", "q_pi", "sample", "state")
    assert ds["section"].shape == (len(VALUES), len(QPI), KW["sample_periods"], 13)
    assert ds["regime"].dims == ("omega_pi", "q_pi") and ds["lyapunov"].shape == (len(VALUES), len(QPI))
    np.testing.assert_array_equal(ds["omega_pi"].values, VALUES)
    np.testing.assert_array_equal(ds["q_pi"].values, QPI)
    other = bifurcation(paper_params.replace(q_pi=float(QPI[1])), VALUES, **KW)
    assert np.any(other.num_steps != base.num_steps)  # the second column is a different sweep
    for j, ref in enumerate((base, other)):
        col = {k: ds[v].isel(q_pi=j).values for k, v in (("samples", "section"), ("num_steps", "num_steps"),
                                                         ("status", "status"))}  # fmt: skip
        assert_same_lanes(col, {"samples": ref.samples, "num_steps": ref.num_steps, "status": ref.status})
        # t_section is computed in the same way from omega_pi alone
        np.testing.assert_allclose(ds["t_section"].isel(q_pi=j).values, ref.t_samples, rtol=1e-15, atol=0)
    assert ds.attrs["x_parameter"] == "omega_pi" and ds.attrs["y_parameter"] == "q_pi"


def test_parameter_map_resume(pmap, paper_params):
    # the map writes chunk by chunk like a sweep: remove one chunk and the merged file, rerun:
    # only that chunk is computed again and the dataset is identical (same program, same machine)
    ds, out = pmap
    os.remove(out / "chunks" / "chunk_00001.nc")
    os.remove(out / "sweep.nc")
    seen = []
    again = jc.parameter_map(
        paper_params,
        x=("omega_pi", VALUES),
        y=("q_pi", QPI),
        out=str(out),
        on_chunk=lambda ci, r: seen.append(ci),
        **KW,
    )
    assert seen == [1]
    assert again.identical(ds)
    from jaxcelt.sweeps.dataset import open_sweep

    assert open_sweep(out).identical(ds)


def test_parameter_map_bad_inputs(paper_params):
    with pytest.raises(ValueError, match="different parameters"):
        jc.parameter_map(paper_params, x=("mu", [0.1]), y=("mu", [0.2]))
    with pytest.raises(ValueError, match="unknown parameter"):
        jc.parameter_map(paper_params, x=("omega_pi", [15.0]), y=("nope", [0.2]))
    with pytest.raises(ValueError, match="'mu'"):
        jc.parameter_map(paper_params, x=("omega_pi", [15.0]), y=("mu", [-0.2, 0.2]))
    with pytest.raises(ValueError, match="pair"):
        jc.parameter_map(paper_params, x="omega_pi", y=("mu", [0.2]))


def test_map_figure(pmap, tmp_path):
    # the figure of a map: two panels with the parameters' axis labels (units), a regime
    # legend naming the regimes present, and a colour bar for lambda_1 when computed
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from jaxcelt.plotting.map import map_categories, map_figure

    ds, _ = pmap
    fig = map_figure(ds)
    axes = fig.get_axes()
    assert axes[0].get_xlabel() == r"forcing frequency $\omega_\pi$ [rad/s]"
    assert axes[0].get_ylabel() == r"forcing amplitude $q_\pi$ [m]"
    cat, cats = map_categories(ds["regime"].values, ds["period"].values)
    legend = [t.get_text() for t in axes[0].get_legend().get_texts()]
    assert legend == [cats[i][0] for i in sorted(set(cat.ravel().tolist()))]
    fig.savefig(tmp_path / "m.png")
    plt.close(fig)
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_map_cli_rejects_bad_axis(capsys):
    from jaxcelt.cli import main

    # one stderr line naming the flag or parameter, exit 2, before any work (jaxcelt.cli)
    for argv, named in (
        (["map", "--x", "omega_pi:10:20:3", "--out", "unused"], "argument --x: expected NAME=START:STOP:COUNT"),
        (["map", "--y", "q_pi=-0.1:0.1:3", "--x", "omega_pi=15", "--out", "unused"], "'q_pi'"),
        (["map", "--x", "nonsense=1:2:3", "--out", "unused"], "'nonsense'"),
    ):
        with pytest.raises(SystemExit) as e:
            main(argv)
        assert e.value.code == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("jaxcelt map: error: ") and named in err[0], err


@pytest.mark.slow
def test_map_cli_equals_api(tmp_path, paper_params):
    # `jaxcelt map` writes the dataset of jc.parameter_map with the same settings (1e-10: the CLI
    # runs on --host-devices 1 here but the compiled program may still differ, see _sweep_common),
    # plus summary.json and the figure
    from jaxcelt.sweeps.dataset import open_sweep

    out = tmp_path / "m"
    cmd = [sys.executable, "-m", "jaxcelt", "map", "--x", "omega_pi=14,17", "--y", "q_pi=0.04,0.05", "--transient",
           "1", "--sample", "2", "--lyapunov", "0", "--host-devices", "1", "--out", str(out)]  # fmt: skip
    subprocess.run(cmd, check=True, capture_output=True)
    ds = open_sweep(out)
    ref = jc.parameter_map(paper_params, x=("omega_pi", [14.0, 17.0]), y=("q_pi", [0.04, 0.05]), transient_periods=1,
                           sample_periods=2, stop_on_invalid=True)  # fmt: skip
    a = {"samples": ds["section"].values, "num_steps": ds["num_steps"].values, "status": ds["status"].values}
    b = {"samples": ref["section"].values, "num_steps": ref["num_steps"].values, "status": ref["status"].values}
    assert_same_lanes(a, b)
    s = json.loads((out / "summary.json").read_text())
    assert s["cells"] == 4 and sum(s["regime_counts"].values()) == 4
    assert (out / "map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


_TWO_PROCESS = """
import sys
import jax
jax.config.update("jax_num_cpu_devices", 1)
jax.distributed.initialize(coordinator_address=sys.argv[1], num_processes=2, process_id=int(sys.argv[2]))
import numpy as np
import jaxcelt as jc
values = np.array([12.0, 14.0, 17.0, 19.0, 12.5, 14.5, 17.5, 19.5])
kw = dict(transient_periods=3, sample_periods=4, rtol=1e-8, atol=1e-10, max_steps=4000, chunk_size=4)
seen = []
r = jc.bifurcation(jc.CeltParams.paper(), values, out=sys.argv[3], on_chunk=lambda ci, res: seen.append(ci), **kw)
print("PROCESS", jax.process_index(), jax.process_count(), "CHUNKS", seen, "RESULT", r is not None, flush=True)
"""


@pytest.mark.slow
def test_two_processes_equal_one(paper_params, tmp_path):
    # A sweep run by 2 processes joined with jax.distributed (localhost, CPU): process i computes
    # the chunks i mod 2 into the shared directory, process 0 assembles the dataset after a
    # barrier. It must equal a one-process sweep of the same lanes: same steps and statuses,
    # samples within SAMPLE_ATOL (the processes compile their own programs; see _sweep_common).
    import socket

    from jaxcelt.sweeps.dataset import open_sweep

    with socket.socket() as s:
        s.bind(("localhost", 0))
        port = s.getsockname()[1]
    out = tmp_path / "shared"
    env = dict(os.environ, JAXCELT_CACHE_DIR="off")
    env.pop("XLA_FLAGS", None)
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", _TWO_PROCESS, f"localhost:{port}", str(i), str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )  # fmt: skip
        for i in range(2)
    ]
    outs = [p.communicate(timeout=600) for p in procs]
    for p, (_, e) in zip(procs, outs):
        assert p.returncode == 0, e[-3000:]
    lines = [[s for s in o.splitlines() if s.startswith("PROCESS")][0] for o, _ in outs]
    assert lines[0] == "PROCESS 0 2 CHUNKS [0] RESULT True", lines
    assert lines[1] == "PROCESS 1 2 CHUNKS [1] RESULT False", lines
    ds = open_sweep(out)
    values = np.concatenate([VALUES, VALUES + 0.5])
    np.testing.assert_array_equal(ds["omega_pi"].values, values)
    one = bifurcation(paper_params, values, **KW)
    got = {"samples": ds["section"].values, "num_steps": ds["num_steps"].values, "status": ds["status"].values}
    assert_same_lanes(got, {"samples": one.samples, "num_steps": one.num_steps, "status": one.status})
    # the regimes stored by the 2-process run are those of its own lanes (labels are not compared
    # with the one-process run's: samples of two compiled programs differ by rounding, and a label
    # decided at a threshold could flip)
    own = dataclasses.replace(one, samples=ds["section"].values)
    np.testing.assert_array_equal(ds["regime"].values, open_sweep_regimes(own, paper_params))


def open_sweep_regimes(result, params):
    from jaxcelt.ensemble import SweepConfig
    from jaxcelt.sweeps.dataset import to_dataset

    cfg = SweepConfig(**{k: v for k, v in KW.items() if k != "chunk_size"})
    return to_dataset(result, params, cfg)["regime"].values


def test_float32_pool_agrees_with_float64(paper_params):
    """A float32 pool (``dtype="float32"``) against a float64 pool at the same loose tolerance, a few
    sliding periods (omega_pi 15 and 17 from rest: no sticking). Tolerance 2e-3 on the samples: both
    runs are within ~rtol 1e-6 of the true solution per step and float32 rounding (~6e-8 relative) adds
    up over ~10^3 steps; the state components are O(0.01-10). Results come back as float64 arrays."""
    kw = dict(transient_periods=2, sample_periods=3, rtol=1e-6, atol=1e-8)
    r64 = bifurcation(paper_params, [15.0, 17.0], **kw)
    r32 = bifurcation(paper_params, [15.0, 17.0], dtype="float32", **kw)
    assert r32.samples.dtype == np.float64
    # both stay valid (no sticking, far from lift-off or tipping: a status, not a comparison of programs)
    assert np.all(r64.status == 0) and np.all(r32.status == 0)
    np.testing.assert_allclose(r32.samples, r64.samples, rtol=0, atol=2e-3)
    with pytest.raises(ValueError, match="dtype"):
        bifurcation(paper_params, [15.0], dtype="float16", **kw)


def test_float32_pool_over_300_periods(paper_params):
    """float32 lanes late in time: over 300 periods (t up to 126 s, where float32 times are 7.6e-6 s
    apart) a float32 pool gives every lane the float64 pool's status. With float32 times every one
    of these lanes ended with a collapsed step (status 3); the pool now steps float32 lanes in float64
    time with the forcing phase from one period (`jaxcelt.ensemble.float64_times`,
    `jaxcelt.physics.model.field_time`). Statuses only: over 300 periods the chaotic lanes' samples part."""
    om = np.repeat([15.0, 17.5, 20.0], 2)
    q = np.tile([0.04, 0.06], 3)
    kw = dict(transient_periods=270, sample_periods=30, stop_on_invalid=True, rtol=1e-6, atol=1e-8)
    from jaxcelt.sweeps.api import sweep_lanes

    r64 = sweep_lanes(paper_params, {"omega_pi": om, "q_pi": q}, **kw)
    r32 = sweep_lanes(paper_params, {"omega_pi": om, "q_pi": q}, dtype="float32", **kw)
    s32, s64 = r32["status"].values, r64["status"].values
    assert not np.any(s32 == 3)  # no collapsed step (the failure this guards against)
    assert np.sum(s32 == s64) >= len(s64) - 1  # two programs: a lane near lift-off may flip (measured: none)
    assert np.sum(s32 == 0) >= 2  # lanes that run to the end, not only invalid ones
    assert np.all(np.isfinite(r32["section"].values[r32["status"].values == 0]))


def test_sweep_lanes_any_batch_equals_bifurcation(base, paper_params, tmp_path):
    """`sweep_lanes` over an arbitrary batch (omega_pi and q_pi drawn per lane, shuffled, plus one
    lane with another start): each lane equals the `bifurcation` lane with the same parameters and
    start (another compiled program: same steps and status, samples within SAMPLE_ATOL)."""
    from jaxcelt.sweeps.api import sweep_lanes

    om = np.array([17.0, 12.0, 19.0, 14.0, 17.0])
    q = np.array([0.04, 0.04, 0.04, 0.04, 0.05])
    ds = sweep_lanes(paper_params, {"omega_pi": om, "q_pi": q}, out=str(tmp_path / "lanes"), **KW)
    assert ds["section"].dims == ("lane", "sample", "state") and ds["q_pi"].dims == ("lane",)
    idx = [int(np.flatnonzero(VALUES == w)[0]) for w in om[:4]]
    got = {"samples": ds["section"].values, "num_steps": ds["num_steps"].values, "status": ds["status"].values}
    first4 = {k: v[:4] for k, v in got.items()}
    assert_same_lanes(first4, {"samples": base.samples[idx], "num_steps": base.num_steps[idx], "status": base.status[idx]})
    ref = bifurcation(paper_params.replace(q_pi=0.05), [17.0], **KW)
    assert_same_lanes({k: v[4:] for k, v in got.items()},
                      {"samples": ref.samples, "num_steps": ref.num_steps, "status": ref.status})  # fmt: skip
    assert (tmp_path / "lanes" / "sweep.nc").exists()
    # starts only (no parameter varied): y0 (L, 13)
    y0 = np.stack([np.asarray(jc.initial_state(paper_params)), np.asarray(jc.initial_state(paper_params, psi=0.5))])
    ds2 = sweep_lanes(paper_params, {}, y0=y0, **KW)
    assert ds2.sizes["lane"] == 2 and np.all(ds2["status"].values == 0)
    with pytest.raises(ValueError, match="same length"):
        sweep_lanes(paper_params, {"omega_pi": om, "q_pi": q[:2]}, **KW)
    with pytest.raises(ValueError, match="mu"):
        sweep_lanes(paper_params, {"mu": [0.2, -0.1]}, **KW)


def test_orbit_equals_simulate(paper_params):
    # `dense_trajectory` (the phase plots' trajectories) is `simulate` stepping onto the save times, compiled
    # as its own program with XLA's loop emitters: the same steps, so states equal to rounding
    # (SAMPLE_ATOL, see _sweep_common), and the centre O of `centre_position` at every state.
    from jaxcelt.physics.diagnostics import centre_position
    from jaxcelt.sweeps.dense import dense_trajectory

    p = paper_params.replace(omega_pi=17.0)
    o = dense_trajectory(p, transient_periods=2, periods=3, points_per_period=8)
    sol = jc.simulate(p, jc.initial_state(p), o["ts"][-1], ts=o["ts"], exact_ts=True)
    assert o["status"] == int(sol.status) == 0 and o["valid"]
    np.testing.assert_allclose(o["ys"], np.asarray(sol.ys), rtol=0, atol=SAMPLE_ATOL)
    r_O = np.stack([np.asarray(centre_position(y, p)) for y in np.asarray(sol.ys)])
    np.testing.assert_allclose(o["r_O"], r_O, rtol=0, atol=1e-12)  # metres; states agree to ~1e-13
    T = 2 * np.pi / 17.0
    np.testing.assert_allclose(o["ts"][o["section_index"]], T * (2 + np.arange(4)), rtol=1e-14)
    with pytest.raises(ValueError, match="rtol"):
        dense_trajectory(p, transient_periods=1, periods=1, rtol=-1.0)
    with pytest.raises(ValueError, match="y0"):
        dense_trajectory(p, np.zeros(13), transient_periods=1, periods=1)
    with pytest.raises(ValueError, match="periods"):
        dense_trajectory(p, transient_periods=1, periods=0)


def test_prepare_orbit_compiles_the_program_orbit_runs(paper_params):
    # `prepare_dense_trajectory` traces now and compiles on a worker thread; a later `dense_trajectory` with the same
    # settings and another parameter value and start must run that program (one new executable in
    # the process's store, not two) and give what a fresh `simulate` gives (SAMPLE_ATOL).
    from jaxcelt import _executable_cache as ec
    from jaxcelt.sweeps.dense import dense_trajectory, prepare_dense_trajectory

    kw = dict(transient_periods=1, periods=2, points_per_period=5)
    p1, p2 = paper_params.replace(omega_pi=14.0), paper_params.replace(omega_pi=16.0)
    n0 = len(ec._MEMORY)
    assert prepare_dense_trajectory(p1, **kw) is None
    assert len(ec._MEMORY) == n0 + 1
    o = dense_trajectory(p2, jc.initial_state(p2, omega=[0.0, 1.0, 0.0]), **kw)
    assert len(ec._MEMORY) == n0 + 1
    sol = jc.simulate(p2, jc.initial_state(p2, omega=[0.0, 1.0, 0.0]), o["ts"][-1], ts=o["ts"], exact_ts=True)
    np.testing.assert_allclose(o["ys"], np.asarray(sol.ys), rtol=0, atol=SAMPLE_ATOL)
    with pytest.raises(ValueError, match="atol"):
        prepare_dense_trajectory(p1, atol=0.0, **kw)
