"""Benchmark: one stroboscopic frequency sweep, four ways, side by side.

1. jaxcelt vmapped (`jaxcelt.bifurcation`: the lane pool, exact section times), with Tsit5 (the
   default), with Dopri5 (the numba loop's own method: Dormand-Prince 5(4), the same controller)
   and with Dopri8 (the same 8th-order Dormand-Prince family as scipy's DOP853)
2. jaxcelt one lane at a time (`jaxcelt.simulate` in a Python loop; subset, extrapolated)
3. scipy ``solve_ivp(DOP853)`` with the numba RHS, lane by lane: stopping invalid lanes on
   every lane (measured, no extrapolation; ``--scipy-stop-lanes``), integrating on from a subset
4. numba hand-written adaptive Dormand-Prince 5(4) ensemble (prange over lanes; all lanes)

Subset extrapolations weight the subset by each lane's cost: t_subset x (sum of jaxcelt's
step counts over all lanes) / (sum over the subset), from the jaxcelt pool run doing the same
work. Lane costs are heavy-tailed here (lanes that stay valid take ~8x the steps of lanes
that stop), so the plain lane-count extrapolation (t_subset x lanes / subset, also reported)
depends on which lanes the subset happens to hold.

Same rtol/atol for all; accuracy of each checked on a few lanes over a short horizon
against scipy DOP853 at rtol 1e-12 (chaotic lanes make long-horizon comparisons
meaningless). Compile time reported apart. Writes JSON + a bar chart.

    .venv/bin/python benchmarks/bench_sweep.py --n-freq 400 --periods 300 --out docs/bifurcation
    .venv/bin/python benchmarks/bench_sweep.py --quick      # a couple of minutes
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import jax
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import _numba_model as nm  # noqa: E402

import jaxcelt as jc  # noqa: E402
from jaxcelt.provenance import write_result  # noqa: E402
from jaxcelt.sweeps.api import bifurcation  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402

LANE_STEPS: dict = {}  # (stop_on_invalid, solver, devices) -> per-lane steps of a jaxcelt pool run


def weighted_extrapolation(t_subset, sub, weights):
    """Cost-weighted (ratio) extrapolation of a subset timing to all lanes."""
    return float(t_subset * weights.sum() / weights[sub].sum())


def lane_setup(p, vals, transient, sample):
    P, B, Bi = nm.pack(p)
    PP = np.tile(P, (len(vals), 1))
    PP[:, nm.WPI] = vals
    TS = np.stack([2 * np.pi / w * np.arange(transient, transient + sample) for w in vals])
    Y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    return PP, B, Bi, TS, Y0


def scipy_lane(y0, ts, P, B, Bi, rtol, atol, stop_invalid=False):
    """scipy DOP853 on the numba RHS; ``stop_invalid``: a terminal event at N = 0 or n3 = 0
    (the same validity criterion as jaxcelt's ``stop_on_invalid``; N from the RHS output by
    N = m ((v_dot + w x v) . n + g), see ``_numba_model._dopri_lane``)."""
    from scipy.integrate import solve_ivp

    out = np.empty(13)
    nfev = [0]

    def f(t, y):
        nm.rhs(t, y, P, B, Bi, out)
        nfev[0] += 1
        return out.copy()

    def lift_off(t, y):
        nm.rhs(t, y, P, B, Bi, out)
        return P[nm.M] * (np.dot(out[0:3] + np.cross(y[3:6], y[0:3]), y[6:9]) + P[nm.GRAV])

    def tipped(t, y):
        return y[8]

    lift_off.terminal = tipped.terminal = True
    events = [lift_off, tipped] if stop_invalid else None
    sol = solve_ivp(f, (0.0, ts[-1]), y0, method="DOP853", t_eval=ts, rtol=rtol, atol=atol, events=events)
    ys = np.full((len(ts), 13), np.inf)  # inf after a terminal event, as in jaxcelt
    y = np.asarray(sol.y, dtype=float).reshape(13, -1).T
    ys[: len(y)] = y
    return ys, sol.nfev, sol.status


def time_jaxcelt(p, vals, transient, a, scheduler, stop, devices, solver=None, reps=1):
    """Compile apart, then the sweep; step-slot accounting from the pool's loop counters."""
    import diffrax

    from jaxcelt.ensemble import SweepConfig, lanes_params, run_lanes

    solver = solver if solver is not None else diffrax.Tsit5()
    kw = dict(
        sample_periods=a.sample, rtol=a.rtol, atol=a.atol, chunk_size=a.chunk_size, sort_by_cost=True,
        width=a.width, stop_on_invalid=stop, devices=devices, solver=solver,
    )  # fmt: skip
    cs = min(a.chunk_size, len(vals))
    t = time.perf_counter()
    if scheduler == "pool":
        cfg = SweepConfig(
            transient_periods=transient, sample_periods=a.sample, rtol=a.rtol, atol=a.atol, stop_on_invalid=stop,
            solver=solver,
        )  # fmt: skip
        y0 = np.tile(np.asarray(jc.initial_state(p)), (cs, 1))
        run_lanes(
            lanes_params(p, "omega_pi", vals[:cs]), y0, cfg, pad_to=cs, width=a.width, compile_only=True,
            devices=devices,
        )  # fmt: skip
        compile_note = "compile only (all lanes marked padding)"
    else:
        bifurcation(p, vals[:cs], transient_periods=0, **kw)
        compile_note = "compile + a sample-periods-only run of one chunk"
    t_compile = time.perf_counter() - t
    runs = []
    for _ in range(reps):  # identical runs (deterministic lanes); the median time is reported
        chunks = []
        t = time.perf_counter()
        r = bifurcation(
            p, vals, transient_periods=transient, on_chunk=lambda ci, c, chunks=chunks: chunks.append(c), **kw
        )
        runs.append(time.perf_counter() - t)
    t_run = float(np.median(runs))
    useful = int(r.num_steps.sum())
    ndev = len(devices)
    if scheduler == "pool":
        # pool_slot_steps: the step slots a chunk paid, summed over its devices and drain widths
        slots = int(sum(int(c["pool_slot_steps"][0]) for c in chunks))
    else:
        slots = int(sum(int(c["num_steps"].max()) * len(c["num_steps"]) for c in chunks))
    LANE_STEPS[(stop, type(solver).__name__, ndev)] = np.asarray(r.num_steps, dtype=float)
    per_period = r.num_steps / (transient + a.sample)
    inval = ~r.valid
    # RHS evaluations per step: the tableau's stages less the first (FSAL): Tsit5 6, Dopri8 13.
    # The pool's validity monitor reads N from the last (FSAL) evaluation: no extra evaluation.
    ne = len(solver.tableau.c)
    return dict(
        solver=type(solver).__name__,
        rhs_per_step=ne,
        devices=ndev,
        seconds=t_run,
        seconds_each_run=runs,
        compile_seconds=t_compile,
        compile_note=compile_note,
        total_steps=useful,
        step_slots=slots,
        wasted_slot_fraction=1 - useful / slots,
        us_per_rhs_slot=t_run / (slots * ne) * 1e6,
        us_per_useful_rhs=t_run / (useful * ne) * 1e6,
        # core-seconds per RHS evaluation, everything else (bookkeeping, wasted slots) counted
        # as overhead: comparable with numba_dp5_ensemble's us_per_rhs_cpu (threads x wall / evaluations)
        core_us_per_rhs=t_run * ndev / (useful * ne) * 1e6,
        steps_per_period_percentiles_0_25_50_75_90_100=[
            float(x) for x in np.percentile(per_period, [0, 25, 50, 75, 90, 100])
        ],
        lanes_invalid=int(inval.sum()),
        steps_in_invalid_lanes_fraction=float(r.num_steps[inval].sum() / max(useful, 1)),
        status_counts={int(k): int(v) for k, v in zip(*np.unique(r.status, return_counts=True))},
    )


def eval_costs(p, vals, width, reps=2000):
    """Per-lane cost of one vector-field evaluation and of one fused Tsit5 step of the pool
    (6 RHS + bookkeeping), vmapped over `width` lanes inside one jitted loop (no dispatch)."""
    from bench_step_parts import step_parts

    v = vals[:width]
    y0 = np.tile(np.asarray(jc.initial_state(p)), (len(v), 1))
    c = step_parts(p, v, y0, reps=reps, parts=("rhs", "fused step (pool)"))
    res = {"rhs_us_per_lane": c["rhs"], "fused_step_us_per_lane": c["fused step (pool)"]}
    res["rhs_share_of_step"] = 6 * res["rhs_us_per_lane"] / res["fused_step_us_per_lane"]
    res["width"] = len(v)
    return res


def _numba_ensemble(Y0, TS, PP, B, Bi, a, stop, reps=1):
    runs = []
    for _ in range(reps):
        t = time.perf_counter()
        _, st, ev, status = nm.dopri_ensemble(Y0, TS, PP, B, Bi, a.rtol, a.atol, 10**6, stop)  # = jaxcelt max_steps
        runs.append(time.perf_counter() - t)
    t_nb = float(np.median(runs))
    th = nm.nb.get_num_threads()
    return dict(
        seconds=t_nb,
        seconds_each_run=runs,
        total_steps=int(st.sum()),
        rhs_evals=int(ev.sum()),
        us_per_rhs_wall=t_nb / ev.sum() * 1e6,
        threads=th,
        us_per_rhs_cpu=t_nb * th / ev.sum() * 1e6,
        status_counts={int(k): int(v) for k, v in zip(*np.unique(status, return_counts=True))},
    )


def _scipy_lanes(PP, B, Bi, TS, Y0, lanes, a, stop, weights):
    """scipy loop over ``lanes`` (all lanes: measured; a subset: extrapolated, cost-weighted)."""
    per = np.zeros(len(lanes))
    nfev = 0
    status = []
    for i, k in enumerate(lanes):
        t = time.perf_counter()
        _, nf, stt = scipy_lane(Y0[k], TS[k], PP[k], B, Bi, a.rtol, a.atol, stop_invalid=stop)
        per[i] = time.perf_counter() - t
        nfev += nf
        status.append(int(stt))
    t_sp = float(per.sum())
    n = len(PP)
    out = dict(lanes=len(lanes), seconds_of_these_lanes=t_sp, rhs_evals=nfev, us_per_rhs=t_sp / nfev * 1e6)
    if len(lanes) == n:
        out.update(seconds=t_sp, measured_all_lanes=True)
        out["solver_status_counts"] = {int(k): int(v) for k, v in zip(*np.unique(status, return_counts=True))}
    else:
        out.update(
            seconds=weighted_extrapolation(t_sp, np.asarray(lanes), weights),
            measured_all_lanes=False,
            extrapolated_by_lane_count=t_sp * n / len(lanes),
        )  # fmt: skip
    return out, per


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=300, help="total periods (transient + samples)")
    ap.add_argument("--sample", type=int, default=100)
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--atol", type=float, default=1e-10)
    ap.add_argument("--chunk-size", type=int, default=400, help="lanes per pool launch (resumable unit)")
    ap.add_argument(
        "--width", type=int, default=None, help="pool slots per device (vmap width; default: the library's DEFAULT_WIDTH)"
    )
    ap.add_argument("--host-devices", default="auto", help="CPU JAX devices to shard lanes over ('auto' = CPU cores)")
    ap.add_argument("--subset", type=int, default=8, help="lanes (evenly spread) for the lane-by-lane methods")
    ap.add_argument(
        "--scipy-stop-lanes", default="all",
        help="'all' (measure the scipy loop stopping invalid lanes on every lane) or 'subset' (extrapolate)",
    )  # fmt: skip
    ap.add_argument("--quick", action="store_true", help="40 freq x 40 periods")
    ap.add_argument(
        "--reps", type=int, default=3,
        help="runs of each jaxcelt pool / numba ensemble timing, both modes (median reported: this VM's speed "
        "drifts by 10-20 %% between minutes, and one integrate-on run took 36 %% longer than its repeats); the "
        "lane-by-lane and scipy loops run once",
    )  # fmt: skip
    ap.add_argument("--out", type=Path, default=Path("docs/bifurcation"))
    a = ap.parse_args()
    if a.width is None:
        from jaxcelt.ensemble import DEFAULT_WIDTH

        a.width = DEFAULT_WIDTH
    n_host = (os.cpu_count() or 1) if a.host_devices == "auto" else int(a.host_devices)
    jax.config.update("jax_num_cpu_devices", n_host)  # before the first JAX operation
    if a.quick:
        a.n_freq, a.periods, a.sample, a.subset = 40, 40, 10, 4
    transient = a.periods - a.sample
    V = versions()
    devs = jax.devices()
    print(" ".join(f"{k}={v}" for k, v in V.items()), flush=True)
    print(f"devices: {devs}; numba threads: {nm.nb.get_num_threads()}, os.cpu_count: {os.cpu_count()}", flush=True)
    load = os.getloadavg()
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    res: dict = dict(
        versions=V,
        device=str(devs),
        config=dict(
            n_freq=a.n_freq,
            periods=a.periods,
            sample=a.sample,
            rtol=a.rtol,
            atol=a.atol,
            chunk_size=a.chunk_size,
            width_per_device=a.width,
            host_devices=len(devs),
        ),
        load_average_at_start=load,
    )
    PP, B, Bi, TS, Y0 = lane_setup(p, vals, transient, a.sample)
    y_ref = np.asarray(jc.initial_state(p))

    # per-RHS cost, numba, one core, tight loop
    nm.rhs_loop(y_ref, PP[0], B, Bi, 10)
    t = time.perf_counter()
    nm.rhs_loop(y_ref, PP[0], B, Bi, 2_000_000)
    res["numba_rhs_us"] = (time.perf_counter() - t) / 2_000_000 * 1e6

    # 1. jaxcelt vmapped (lane pool): stop-on-invalid (the CLI default) on all devices and on one;
    #    integrating invalid lanes on (the same work as the loops without events)
    import diffrax

    runs = [
        ("pool_stop_on_invalid", "pool", True, devs, None),
        ("pool_stop_on_invalid_dopri8", "pool", True, devs, diffrax.Dopri8()),
        ("pool", "pool", False, devs, None),
        # the numba loop's method: equal work step for step (same tableau and controller)
        ("pool_stop_on_invalid_dopri5", "pool", True, devs, diffrax.Dopri5()),
        ("pool_dopri5", "pool", False, devs, diffrax.Dopri5()),
    ]
    if len(devs) > 1:
        runs.insert(1, ("pool_stop_on_invalid_1dev", "pool", True, devs[:1], None))
    for key, sched, stop, dv, solver in runs:
        res[f"jaxcelt_{key}"] = time_jaxcelt(p, vals, transient, a, sched, stop, dv, solver, a.reps)
        print(key, res[f"jaxcelt_{key}"], flush=True)
    res["per_lane_eval_cost"] = eval_costs(p, vals, a.width)
    print("per-lane evaluation cost (vmapped, one device)", res["per_lane_eval_cost"], flush=True)

    # 2. numba DP5 ensemble (all lanes, all periods; 2 threads): integrate on / stop at invalid
    # compile with the same array layouts (C-contiguous) as the timed calls: numba specialises on layout
    nm.dopri_ensemble(Y0[:2].copy(), TS[:2, :1].copy(), PP[:2].copy(), B, Bi, a.rtol, a.atol, 10**7, True)
    for stop in (True, False):
        key = "numba_dp5_ensemble" + ("_stop_on_invalid" if stop else "")
        res[key] = _numba_ensemble(Y0, TS, PP, B, Bi, a, stop, a.reps)
        print(key, res[key], flush=True)

    # 3. lane by lane on an evenly spread subset, full length, extrapolated to all lanes
    sub = np.unique(np.linspace(0, a.n_freq - 1, a.subset).astype(int))
    f1 = jax.jit(lambda pp, y0, ts: jc.simulate(pp, y0, ts[-1], ts=ts, exact_ts=True, rtol=a.rtol, atol=a.atol))
    pw0 = p.replace(omega_pi=float(vals[sub[0]]))
    t = time.perf_counter()
    jax.block_until_ready(f1(pw0, Y0[0], TS[0]))
    t_c1 = time.perf_counter() - t
    t = time.perf_counter()
    for k in sub:
        jax.block_until_ready(f1(p.replace(omega_pi=float(vals[k])), Y0[k], TS[k]))
    t1 = time.perf_counter() - t
    # weights: per-lane steps of the jaxcelt pool run doing the same work (Tsit5, all devices)
    w_on, w_stop = LANE_STEPS[(False, "Tsit5", len(devs))], LANE_STEPS[(True, "Tsit5", len(devs))]
    res["jaxcelt_lane_by_lane"] = dict(
        subset_seconds=t1, lanes=len(sub), compile_seconds=t_c1,
        seconds=weighted_extrapolation(t1, sub, w_on),  # simulate integrates invalid lanes on
        extrapolated_by_lane_count=t1 * a.n_freq / len(sub),
    )  # fmt: skip
    print("jaxcelt lane by lane", res["jaxcelt_lane_by_lane"], flush=True)
    all_stop = a.scipy_stop_lanes == "all"
    for stop in (True, False):
        key = "scipy_dop853_numba_rhs" + ("_stop_on_invalid" if stop else "")
        lanes = np.arange(a.n_freq) if (stop and all_stop) else sub
        res[key], per = _scipy_lanes(PP, B, Bi, TS, Y0, lanes, a, stop, w_stop if stop else w_on)
        if stop and all_stop:
            # what the subset would have said, from the same per-lane timings
            res[key]["subset_extrapolated_by_lane_count"] = float(per[sub].sum() * a.n_freq / len(sub))
            res[key]["subset_extrapolated_cost_weighted"] = weighted_extrapolation(per[sub].sum(), sub, w_stop)
        print(key, res[key], flush=True)

    # accuracy: 5 periods, subset lanes, vs scipy DOP853 rtol 1e-12 (longer horizons are
    # dominated by the chaotic growth of any difference, not by the method)
    PPa, _, _, TSa, Y0a = lane_setup(p, vals[sub], 0, 6)
    TSa = TSa[:, 1:]
    ref = np.stack([scipy_lane(Y0a[i], TSa[i], PPa[i], B, Bi, 1e-12, 1e-14)[0] for i in range(len(sub))])
    ra = bifurcation(p, vals[sub], transient_periods=1, sample_periods=5, rtol=a.rtol, atol=a.atol)
    ra8 = bifurcation(
        p, vals[sub], transient_periods=1, sample_periods=5, rtol=a.rtol, atol=a.atol, solver=diffrax.Dopri8()
    )
    ra5 = bifurcation(
        p, vals[sub], transient_periods=1, sample_periods=5, rtol=a.rtol, atol=a.atol, solver=diffrax.Dopri5()
    )
    ys_a, *_ = nm.dopri_ensemble(Y0a, TSa, PPa, B, Bi, a.rtol, a.atol, 10**7)
    sp_a = np.stack([scipy_lane(Y0a[i], TSa[i], PPa[i], B, Bi, a.rtol, a.atol)[0] for i in range(len(sub))])
    res["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"] = dict(
        jaxcelt=float(np.max(np.abs(ra.samples - ref))),
        jaxcelt_dopri8=float(np.max(np.abs(ra8.samples - ref))),
        jaxcelt_dopri5=float(np.max(np.abs(ra5.samples - ref))),
        numba_dp5=float(np.max(np.abs(ys_a - ref))),
        scipy_dop853=float(np.max(np.abs(sp_a - ref))),
    )
    print("accuracy", res["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"], flush=True)
    js, jv = res["jaxcelt_pool_stop_on_invalid"], res["jaxcelt_pool"]
    j8 = res["jaxcelt_pool_stop_on_invalid_dopri8"]
    j5, j5v = res["jaxcelt_pool_stop_on_invalid_dopri5"], res["jaxcelt_pool_dopri5"]
    ns, nv = res["numba_dp5_ensemble_stop_on_invalid"], res["numba_dp5_ensemble"]
    ss, sv = res["scipy_dop853_numba_rhs_stop_on_invalid"], res["scipy_dop853_numba_rhs"]
    res["summary"] = dict(
        jaxcelt_stop_on_invalid_s=js["seconds"],
        jaxcelt_stop_on_invalid_1dev_s=res.get("jaxcelt_pool_stop_on_invalid_1dev", {}).get("seconds"),
        jaxcelt_integrate_on_s=jv["seconds"],
        compile_s=js["compile_seconds"],
        total_with_compile_s=js["seconds"] + js["compile_seconds"],
        target_120s_met=bool(js["seconds"] + js["compile_seconds"] <= 120) if (a.n_freq, a.periods) == (400, 300) else None,
        # same work: both stop invalid lanes / both integrate every lane to the end
        scipy_stop_measured_on_all_lanes=ss["measured_all_lanes"],
        speedup_vs_scipy_loop_same_work_stop=ss["seconds"] / js["seconds"],
        jaxcelt_dopri8_stop_on_invalid_s=j8["seconds"],
        speedup_vs_scipy_loop_same_work_stop_dopri8=ss["seconds"] / j8["seconds"],
        per_rhs_ratio_jaxcelt_dopri8_vs_numba=j8["core_us_per_rhs"] / ns["us_per_rhs_cpu"],
        speedup_vs_scipy_loop_same_work_integrate_on=sv["seconds"] / jv["seconds"],
        speedup_vs_scipy_loop_integrating_on=sv["seconds"] / js["seconds"],
        speedup_vs_jaxcelt_lane_by_lane=res["jaxcelt_lane_by_lane"]["seconds"] / js["seconds"],
        wall_ratio_vs_numba_ensemble_stop=js["seconds"] / ns["seconds"],
        wall_ratio_vs_numba_ensemble_integrate_on=jv["seconds"] / nv["seconds"],
        # the same method as the numba loop (Dopri5): equal work step for step
        wall_ratio_dopri5_vs_numba_ensemble_stop=j5["seconds"] / ns["seconds"],
        wall_ratio_dopri5_vs_numba_ensemble_integrate_on=j5v["seconds"] / nv["seconds"],
        core_us_per_rhs_jaxcelt=js["core_us_per_rhs"],
        core_us_per_rhs_numba=ns["us_per_rhs_cpu"],
        per_rhs_ratio_jaxcelt_vs_numba=js["core_us_per_rhs"] / ns["us_per_rhs_cpu"],
    )  # fmt: skip
    print(json.dumps(res["summary"], indent=1), flush=True)
    a.out.mkdir(parents=True, exist_ok=True)
    tag = "quick" if a.quick else f"{a.n_freq}x{a.periods}"
    write_result(a.out / f"bench_sweep_{tag}.json", res, load_at_start=res["load_average_at_start"])

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [
        (f"jaxcelt pool\n{len(devs)} dev", js["seconds"], jv["seconds"], "tab:blue"),
        (f"jaxcelt pool\nDopri5, {len(devs)} dev", j5["seconds"], j5v["seconds"], "tab:brown"),
        (f"jaxcelt pool\nDopri8, {len(devs)} dev", j8["seconds"], None, "tab:olive"),
    ]
    if "jaxcelt_pool_stop_on_invalid_1dev" in res:
        rows.append(("jaxcelt pool\n1 dev", res["jaxcelt_pool_stop_on_invalid_1dev"]["seconds"], None, "tab:cyan"))
    if "jaxcelt_chunks" in res:
        rows.append(("jaxcelt chunks\n(old)", None, res["jaxcelt_chunks"]["seconds"], "tab:gray"))
    rows += [
        (f"numba DP5\nensemble ({ns['threads']} thr)", ns["seconds"], nv["seconds"], "tab:green"),
        ("jaxcelt lane\nby lane*", None, res["jaxcelt_lane_by_lane"]["seconds"], "tab:purple"),
        ("scipy DOP853\n+ numba RHS*", ss["seconds"], sv["seconds"], "tab:orange"),
    ]
    fig, ax = plt.subplots(figsize=(10, 4.8), constrained_layout=True)
    x = np.arange(len(rows))
    for j, (lab, hatch, off) in enumerate((("stop at invalid", "", -0.2), ("integrate on", "//", 0.2))):
        hs = [r[1 + j] for r in rows]
        xs = [xi + off for xi, h in zip(x, hs) if h is not None]
        hv = [h for h in hs if h is not None]
        cs = [r[3] for r, h in zip(rows, hs) if h is not None]
        bars = ax.bar(xs, hv, width=0.38, color=cs, hatch=hatch, edgecolor="k", linewidth=0.5, label=lab)
        for b_, s_ in zip(bars, hv):
            ax.text(b_.get_x() + b_.get_width() / 2, s_ * 1.08, f"{s_:.3g}", ha="center", fontsize=8)
    ax.set_xticks(x, [r[0] for r in rows], fontsize=9)
    ax.set_yscale("log")
    if (a.n_freq, a.periods) == (400, 300):
        ax.axhline(120, color="k", ls="--", lw=0.8, label="target 120 s")
    ax.legend(fontsize=9)
    ax.set_ylabel("wall time [s], compile excluded (log)")
    ax.set_title(
        f"{a.n_freq} frequencies x {a.periods} periods, rtol {a.rtol:g}, {os.cpu_count()} CPU cores "
        f"(load {load[0]:.1f} at start)\n* "
        + ("stop: all lanes measured; integrate on: " if ss["measured_all_lanes"] else "")
        + f"extrapolated from {len(sub)} evenly spread full-length lanes (cost-weighted); "
        f"jax {jax.__version__}, diffrax {V.get('diffrax', '?')}",
        fontsize=10,
    )
    fig.savefig(a.out / f"bench_sweep_{tag}.png", dpi=130)
    print("wrote", a.out, flush=True)


if __name__ == "__main__":
    main()
