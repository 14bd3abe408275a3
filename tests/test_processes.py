"""Lanes in worker processes (`jaxcelt.HostProcesses`) against the same lanes in this process."""

from __future__ import annotations

import numpy as np
import pytest
from _sweep_common import agreeing_lanes, assert_steps_close

import jaxcelt as jc
from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes


@pytest.fixture(scope="module")
def workers():
    with jc.HostProcesses(2) as hp:
        yield hp


def test_worker_processes_give_the_lanes_of_one_process(workers):
    # 7 lanes dealt to 2 workers (4 + 3: one padding lane in the second), the Lyapunov stage included.
    # The workers run single-device programs of another width than this process's pool: another
    # compiled program: statuses and step counts as tests/_sweep_common.py allows two programs, samples
    # to rounding, not bitwise. 1e-9: the step-to-step rounding of 1e-16 grown over 8 periods of these
    # lanes stays far below it.
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, 7)
    kw = dict(transient_periods=5, sample_periods=3, lyapunov_periods=2, stop_on_invalid=True)
    here = jc.bifurcation(p, vals, **kw)
    there = jc.bifurcation(p, vals, devices=workers, **kw)
    same = agreeing_lanes(there.status, here.status)  # two programs: one lane may flip (measured: none)
    assert_steps_close(there.num_steps, here.num_steps, where=same)
    assert (here.status == 2).any() and (here.status == 0).any()  # both kinds of lane are compared
    np.testing.assert_allclose(there.samples[same], here.samples[same], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(there.lyapunov, here.lyapunov, rtol=1e-7, atol=1e-9)


def test_an_error_in_a_worker_is_raised_here(workers):
    p = jc.CeltParams.paper()
    pb = lanes_params(p, "omega_pi", np.array([12.0, 14.0, 16.0]))
    y0 = np.tile(np.asarray(jc.initial_state(p)), (3, 1))
    with pytest.raises(ValueError, match="drain_factor"):
        run_lanes(pb, y0, SweepConfig(transient_periods=1, sample_periods=1), devices=workers, drain_factor=1, stats=True)
    # the workers still serve the next chunk
    out, stats = run_lanes(pb, y0, SweepConfig(transient_periods=1, sample_periods=1), devices=workers, stats=True)
    assert out["status"].tolist() == [0, 0, 0] and stats.slot_steps >= out["num_steps"].sum()


@pytest.mark.parametrize("n, cores, what", [(0, None, "n must"), ("x", None, "n must"), (2, [0], "cores must")])
def test_bad_host_processes_arguments(n, cores, what):
    with pytest.raises(ValueError, match=what):
        jc.HostProcesses(n, cores=cores)
