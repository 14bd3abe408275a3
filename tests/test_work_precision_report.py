"""The work-precision analysis path on a synthetic results dict: no solves, no timings.

Checks that `benchmarks/work_precision.py`'s cheapest-per-target selection and Markdown report pick
the right runs, and that `jaxcelt.plotting.performance.plot_work_precision` draws one log-log figure
per scene plus the float32 and contact-law figures. Exact comparisons: the inputs are constructed.
"""

import pathlib
import sys

import matplotlib.pyplot as plt
import pytest

from jaxcelt.plotting.performance import plot_work_precision

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "benchmarks"))
wp = pytest.importorskip("work_precision")


def _run(solver, kind, rtol, error, run_s, evals, status=0, dtype="float64"):
    return dict(
        scene="s", solver=solver, kind=kind, rtol=rtol, dt0=None, error=error, run_s=run_s, compile_s=1.0,
        rhs_evals=evals, rhs_evals_how="counted" if kind == "implicit" else "steps x stages + 1",
        accepted=10, rejected=2, status=status, dtype=dtype,
    )  # fmt: skip


@pytest.fixture
def res():
    runs = [
        _run("A", "explicit", 1e-4, 5e-5, 0.010, 1000),
        _run("A", "explicit", 1e-6, 5e-7, 0.030, 3000),
        _run("B", "explicit", 1e-4, 2e-5, 0.020, 800),  # fewer evaluations, slower
        _run("B", "explicit", 1e-6, 2e-9, 0.025, 1500),
        _run("C", "implicit", 1e-6, 1e-7, 0.001, 10),  # fastest at 1e-6, but implicit: not in the evals column
        _run("A", "explicit", 1e-8, float("inf"), 0.5, 99999, status=1),  # failed: never "cheapest"
    ]
    sc = dict(scene="s", description="synthetic scene", periods=1, runs=runs)
    f32 = dict(
        scene="s",
        description="synthetic scene",
        periods=1,
        runs=[_run("A", "explicit", 1e-4, 6e-5, 0.01, 900, dtype="float32")],
    )
    laws = [
        dict(law="L1", scene="s", description="synthetic scene", runs=runs[:2]),
        dict(law="L2", scene="s", description="synthetic scene", runs=runs[2:4]),
    ]
    return dict(scenes=[sc], float32=[f32], laws=laws, config=dict(f32_rtols=[1e-4, 1e-6]))  # fmt: skip


def test_cheapest_selection(res):
    runs = res["scenes"][0]["runs"]
    by_time = wp._cheapest(runs, 1e-4, "run_s")
    assert [r["solver"] for r in by_time] == ["C", "A", "B"]
    assert by_time[1]["rtol"] == 1e-4  # A's cheapest run that reaches 1e-4
    explicit = [r for r in runs if r["kind"] != "implicit"]
    assert wp._cheapest(explicit, 1e-4, "rhs_evals")[0]["solver"] == "B"
    assert wp._cheapest(runs, 1e-10, "run_s") == []  # nobody reached it; the failed run does not count


def test_report_rows(res):
    rep = wp.report(res)
    line = next(x for x in rep.splitlines() if x.startswith("| 1e-06 |"))
    assert "C rtol 1e-06" in line.split("|")[2]  # fastest
    assert "B rtol 1e-06: 1 500" in line.split("|")[4]  # fewest evaluations among explicit runs
    assert "none reached it" in next(x for x in rep.splitlines() if x.startswith("| 1e-10 |"))
    assert "10*" in rep  # implicit counts are marked


def test_plot_work_precision_figures(res):
    figs = plot_work_precision(res)
    assert set(figs) == {"s", "float32", "laws"}
    ax = figs["s"].axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert ax.get_xlabel().startswith("run time [s]")
    assert figs["s"].axes[1].get_xlabel().startswith("RHS evaluations")
    for f in figs.values():
        plt.close(f)
