"""Benchmark: one stroboscopic frequency sweep, four ways, side by side.

1. jaxcelt vmapped (`jaxcelt.bifurcation`, chunks of lanes, Tsit5 + exact section times)
2. jaxcelt one lane at a time (`jaxcelt.simulate` in a Python loop; subset, extrapolated)
3. scipy ``solve_ivp(DOP853)`` with the numba RHS, lane by lane (subset, extrapolated)
4. numba hand-written adaptive Dormand-Prince 5(4) ensemble (prange over lanes; all lanes)

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
from jaxcelt.sweep import bifurcation  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402


def lane_setup(p, vals, transient, sample):
    P, B, Bi = nm.pack(p)
    PP = np.tile(P, (len(vals), 1))
    PP[:, nm.WPI] = vals
    TS = np.stack([2 * np.pi / w * np.arange(transient, transient + sample) for w in vals])
    Y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    return PP, B, Bi, TS, Y0


def scipy_lane(y0, ts, P, B, Bi, rtol, atol):
    from scipy.integrate import solve_ivp

    out = np.empty(13)
    nfev = [0]

    def f(t, y):
        nm.rhs(t, y, P, B, Bi, out)
        nfev[0] += 1
        return out.copy()

    sol = solve_ivp(f, (0.0, ts[-1]), y0, method="DOP853", t_eval=ts, rtol=rtol, atol=atol)
    return sol.y.T, sol.nfev, sol.status


def time_jaxcelt(p, vals, transient, a, scheduler, stop):
    """Compile apart, then the sweep; step-slot accounting from the pool's loop counters."""
    from jaxcelt.sweep import SweepConfig, lanes_params, run_lanes

    kw = dict(
        sample_periods=a.sample, rtol=a.rtol, atol=a.atol, chunk_size=a.chunk_size, sort_by_cost=True,
        scheduler=scheduler, width=a.width, stop_on_invalid=stop,
    )  # fmt: skip
    cs = min(a.chunk_size, len(vals))
    t = time.perf_counter()
    if scheduler == "pool":
        cfg = SweepConfig(
            transient_periods=transient, sample_periods=a.sample, rtol=a.rtol, atol=a.atol, stop_on_invalid=stop
        )
        y0 = np.tile(np.asarray(jc.initial_state(p)), (cs, 1))
        run_lanes(lanes_params(p, "omega_pi", vals[:cs]), y0, cfg, pad_to=cs, width=a.width, compile_only=True)
        compile_note = "compile only (all lanes marked padding)"
    else:
        bifurcation(p, vals[:cs], transient_periods=0, **kw)
        compile_note = "compile + a sample-periods-only run of one chunk"
    t_compile = time.perf_counter() - t
    chunks = []
    t = time.perf_counter()
    r = bifurcation(p, vals, transient_periods=transient, on_chunk=lambda ci, c: chunks.append(c), **kw)
    t_run = time.perf_counter() - t
    useful = int(r.num_steps.sum())
    if scheduler == "pool":
        slots = int(sum(int(c["pool_iterations"][0]) * int(c["pool_width"][0]) for c in chunks))
    else:
        slots = int(sum(int(c["num_steps"].max()) * len(c["num_steps"]) for c in chunks))
    per_period = r.num_steps / (transient + a.sample)
    inval = ~r.valid
    # Tsit5: 6 RHS per step (FSAL) + 1 normal-force evaluation of the validity monitor
    return dict(
        seconds=t_run,
        compile_seconds=t_compile,
        compile_note=compile_note,
        total_steps=useful,
        step_slots=slots,
        wasted_slot_fraction=1 - useful / slots,
        us_per_rhs_slot=t_run / (slots * 7) * 1e6,
        us_per_useful_rhs=t_run / (useful * 7) * 1e6,
        steps_per_period_percentiles_0_25_50_75_90_100=[
            float(x) for x in np.percentile(per_period, [0, 25, 50, 75, 90, 100])
        ],
        lanes_invalid=int(inval.sum()),
        steps_in_invalid_lanes_fraction=float(r.num_steps[inval].sum() / max(useful, 1)),
        status_counts={int(k): int(v) for k, v in zip(*np.unique(r.status, return_counts=True))},
    )


def eval_costs(p, vals, width, reps=2000):
    """Per-lane cost of one vector-field evaluation and one validity-monitor evaluation
    (normal force), vmapped over `width` lanes inside one jitted loop (no dispatch)."""
    import jax.numpy as jnp

    from jaxcelt.contact import get_contact_law
    from jaxcelt.model import vector_field
    from jaxcelt.solve import _invalid_kind
    from jaxcelt.sweep import lanes_params

    law = get_contact_law(None)
    pb = lanes_params(p, "omega_pi", vals[:width])
    y0 = jnp.tile(jnp.asarray(jc.initial_state(p)), (pb.omega_pi.shape[0], 1))

    def loop(fn):
        def body(i, y):
            out = jax.vmap(lambda pp, yy: fn(0.1 * i, yy, pp))(pb, y)
            return y + 1e-30 * jnp.sum(jnp.atleast_2d(out.T).T[..., :1], axis=-1, keepdims=True)

        return jax.jit(lambda y: jax.lax.fori_loop(0, reps, body, y))

    res = {}
    for name, fn in (
        ("rhs", lambda t, y, pp: vector_field(t, y, pp, law)),
        ("monitor", lambda t, y, pp: _invalid_kind(t, y, pp, law)[1]),
    ):
        f = loop(fn)
        jax.block_until_ready(f(y0))
        t = time.perf_counter()
        jax.block_until_ready(f(y0))
        res[f"{name}_us_per_lane"] = (time.perf_counter() - t) / (reps * pb.omega_pi.shape[0]) * 1e6
    res["monitor_share_of_step"] = res["monitor_us_per_lane"] / (
        6 * res["rhs_us_per_lane"] + res["monitor_us_per_lane"]
    )
    res["width"] = int(pb.omega_pi.shape[0])
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=300, help="total periods (transient + samples)")
    ap.add_argument("--sample", type=int, default=100)
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--atol", type=float, default=1e-10)
    ap.add_argument("--chunk-size", type=int, default=400, help="lanes per pool launch (resumable unit)")
    ap.add_argument("--width", type=int, default=32, help="pool slots (vmap width)")
    ap.add_argument("--with-chunks", action="store_true", help="also time the old chunk scheduler")
    ap.add_argument("--subset", type=int, default=4, help="lanes for the lane-by-lane methods (extrapolated)")
    ap.add_argument("--subset-periods", type=int, default=30, help="periods for the lane-by-lane methods")
    ap.add_argument("--quick", action="store_true", help="40 freq x 40 periods")
    ap.add_argument("--out", type=Path, default=Path("docs/bifurcation"))
    a = ap.parse_args()
    if a.quick:
        a.n_freq, a.periods, a.sample, a.subset_periods = 40, 40, 10, 20
        a.with_chunks = True
    transient = a.periods - a.sample
    V = versions()
    print(" ".join(f"{k}={v}" for k, v in V.items()), flush=True)
    print(f"numba threads: {nm.nb.get_num_threads()}, os.cpu_count: {os.cpu_count()}", flush=True)
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    res: dict = dict(
        versions=V,
        config=dict(
            n_freq=a.n_freq,
            periods=a.periods,
            sample=a.sample,
            rtol=a.rtol,
            atol=a.atol,
            chunk_size=a.chunk_size,
            width=a.width,
        ),
        note="2 shared CPU cores (other jobs running): timings are noisy, +-30%",
    )
    PP, B, Bi, TS, Y0 = lane_setup(p, vals, transient, a.sample)
    y_ref = np.asarray(jc.initial_state(p))

    # per-RHS cost
    nm.rhs_loop(y_ref, PP[0], B, Bi, 10)
    t = time.perf_counter()
    nm.rhs_loop(y_ref, PP[0], B, Bi, 2_000_000)
    rhs_numba = (time.perf_counter() - t) / 2_000_000
    res["numba_rhs_us"] = rhs_numba * 1e6

    # 1. jaxcelt vmapped: lane pool (default), with and without stop_on_invalid; the old
    #    chunk scheduler (every slot waits for the chunk's slowest lane) for comparison
    runs = [("pool", False), ("pool", True)] + ([("chunks", False)] if a.with_chunks else [])
    for sched, stop in runs:
        key = f"jaxcelt_{sched}" + ("_stop_on_invalid" if stop else "")
        res[key] = time_jaxcelt(p, vals, transient, a, sched, stop)
        print(key, res[key], flush=True)
    res["jaxcelt_vmapped"] = res["jaxcelt_pool_stop_on_invalid"]  # the main-job setting
    res["per_lane_eval_cost"] = eval_costs(p, vals, a.width)
    print("per-lane evaluation cost", res["per_lane_eval_cost"], flush=True)

    # 4. numba DP5 ensemble (all lanes, all periods)
    sub = np.linspace(0, a.n_freq - 1, a.subset).astype(int)
    nm.dopri_ensemble(Y0[:2], TS[:2, :1] * 0 + TS[:2, :1] / max(transient, 1), PP[:2], B, Bi, a.rtol, a.atol, 10**7)
    t = time.perf_counter()
    ys_nb, st_nb, ev_nb, status_nb = nm.dopri_ensemble(Y0, TS, PP, B, Bi, a.rtol, a.atol, 10**7)
    t_nb = time.perf_counter() - t
    res["numba_dp5_ensemble"] = dict(
        seconds=t_nb,
        total_steps=int(st_nb.sum()),
        rhs_evals=int(ev_nb.sum()),
        us_per_rhs_wall=t_nb / ev_nb.sum() * 1e6,
        threads=nm.nb.get_num_threads(),
        us_per_rhs_cpu=t_nb * nm.nb.get_num_threads() / ev_nb.sum() * 1e6,
        failed_lanes=int(np.sum(status_nb != 0)),
    )
    print("numba ensemble", res["numba_dp5_ensemble"], flush=True)

    # 2./3. lane-by-lane on a subset, fewer periods; extrapolated per lane-period
    tr_s = max(a.subset_periods - a.sample // 10, 1)
    ss = a.subset_periods - tr_s
    PPs, _, _, TSs, Y0s = lane_setup(p, vals[sub], tr_s, ss)
    factor = (a.n_freq / len(sub)) * (a.periods / a.subset_periods)
    pw0 = p.replace(omega_pi=float(vals[sub[0]]))
    f1 = jax.jit(lambda pp, y0, ts: jc.simulate(pp, y0, ts[-1], ts=ts, exact_ts=True, rtol=a.rtol, atol=a.atol))
    t = time.perf_counter()
    jax.block_until_ready(f1(pw0, Y0s[0], TSs[0]))
    t_c1 = time.perf_counter() - t
    t = time.perf_counter()
    steps1 = 0
    for i, k in enumerate(sub):
        s = jax.block_until_ready(f1(p.replace(omega_pi=float(vals[k])), Y0s[i], TSs[i]))
        steps1 += int(s.num_steps)
    t1 = time.perf_counter() - t
    res["jaxcelt_lane_by_lane"] = dict(
        subset_seconds=t1, lanes=len(sub), periods=a.subset_periods, extrapolated_seconds=t1 * factor, compile_seconds=t_c1,
        us_per_step=t1 / steps1 * 1e6,
    )  # fmt: skip
    print("jaxcelt lane by lane", res["jaxcelt_lane_by_lane"], flush=True)
    t = time.perf_counter()
    nfev = 0
    for i in range(len(sub)):
        _, nf, _ = scipy_lane(Y0s[i], TSs[i], PPs[i], B, Bi, a.rtol, a.atol)
        nfev += nf
    t_sp = time.perf_counter() - t
    res["scipy_dop853_numba_rhs"] = dict(
        subset_seconds=t_sp, lanes=len(sub), periods=a.subset_periods, extrapolated_seconds=t_sp * factor, rhs_evals=nfev,
        us_per_rhs=t_sp / nfev * 1e6,
    )  # fmt: skip
    print("scipy", res["scipy_dop853_numba_rhs"], flush=True)

    # accuracy: 5 periods, subset lanes, vs scipy DOP853 rtol 1e-12
    PPa, _, _, TSa, Y0a = lane_setup(p, vals[sub], 0, 6)
    TSa = TSa[:, 1:]
    ref = np.stack([scipy_lane(Y0a[i], TSa[i], PPa[i], B, Bi, 1e-12, 1e-14)[0] for i in range(len(sub))])
    ra = bifurcation(p, vals[sub], transient_periods=1, sample_periods=5, rtol=a.rtol, atol=a.atol)
    ys_a, *_ = nm.dopri_ensemble(Y0a, TSa, PPa, B, Bi, a.rtol, a.atol, 10**7)
    sp_a = np.stack([scipy_lane(Y0a[i], TSa[i], PPa[i], B, Bi, a.rtol, a.atol)[0] for i in range(len(sub))])
    res["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"] = dict(
        jaxcelt=float(np.max(np.abs(ra.samples - ref))),
        numba_dp5=float(np.max(np.abs(ys_a - ref))),
        scipy_dop853=float(np.max(np.abs(sp_a - ref))),
    )
    print("accuracy", res["accuracy_max_abs_err_5_periods_vs_dop853_1e-12"], flush=True)
    jv = res["jaxcelt_pool"]  # same work as the loops (every lane integrated to the end)
    js = res["jaxcelt_pool_stop_on_invalid"]
    scale = (400 * 300) / (a.n_freq * a.periods)
    sp = res["scipy_dop853_numba_rhs"]["extrapolated_seconds"]
    res["summary"] = dict(
        jaxcelt_pool_s=jv["seconds"],
        jaxcelt_pool_stop_on_invalid_s=js["seconds"],
        jaxcelt_chunks_s=res.get("jaxcelt_chunks", {}).get("seconds"),
        compile_s=jv["compile_seconds"],
        # the target is 400 frequencies x 300 periods; smaller runs are scaled linearly
        extrapolated_400x300_pool_s=jv["seconds"] * scale,
        extrapolated_400x300_pool_stop_on_invalid_s=js["seconds"] * scale,
        extrapolated_400x300_numba_ensemble_s=None,
        target_120s_met=bool(js["seconds"] * scale <= 120),
        speedup_vs_scipy_numba_loop=sp / jv["seconds"],
        speedup_vs_scipy_numba_loop_stop_on_invalid=sp / js["seconds"],
        speedup_vs_jaxcelt_lane_by_lane=res["jaxcelt_lane_by_lane"]["extrapolated_seconds"] / jv["seconds"],
        numba_ensemble_s=t_nb,
        per_rhs_ratio_jax_slot_vs_numba_cpu=jv["us_per_rhs_slot"] / res["numba_dp5_ensemble"]["us_per_rhs_cpu"],
        per_rhs_ratio_jax_useful_vs_numba_cpu=jv["us_per_useful_rhs"] / res["numba_dp5_ensemble"]["us_per_rhs_cpu"],
        wall_ratio_pool_vs_numba_ensemble=jv["seconds"] / t_nb,
    )
    res["summary"]["extrapolated_400x300_numba_ensemble_s"] = t_nb * scale
    print(json.dumps(res["summary"], indent=1), flush=True)
    a.out.mkdir(parents=True, exist_ok=True)
    tag = "quick" if a.quick else f"{a.n_freq}x{a.periods}"
    (a.out / f"bench_sweep_{tag}.json").write_text(json.dumps(res, indent=1))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = ["jaxcelt pool", "jaxcelt pool\nstop_on_invalid"]
    secs = [jv["seconds"], js["seconds"]]
    colors = ["tab:blue", "tab:purple"]
    if "jaxcelt_chunks" in res:
        names.append("jaxcelt chunks\n(before)")
        secs.append(res["jaxcelt_chunks"]["seconds"])
        colors.append("tab:gray")
    names += ["numba DP5\nensemble", "jaxcelt\nlane by lane*", "scipy DOP853\n+ numba RHS*"]
    secs += [t_nb, res["jaxcelt_lane_by_lane"]["extrapolated_seconds"], sp]
    colors += ["tab:green", "tab:cyan", "tab:orange"]
    fig, ax = plt.subplots(figsize=(9, 4.4), constrained_layout=True)
    bars = ax.bar(names, secs, color=colors)
    ax.set_yscale("log")
    for b_, s_ in zip(bars, secs):
        ax.text(b_.get_x() + b_.get_width() / 2, s_ * 1.1, f"{s_:.3g} s", ha="center", fontsize=10)
    if (a.n_freq, a.periods) == (400, 300):
        ax.axhline(120, color="k", ls="--", lw=0.8, label="target 120 s")
        ax.legend(fontsize=9)
    ax.set_ylabel("wall time [s] (log)")
    ax.set_title(
        f"{a.n_freq} frequencies x {a.periods} periods, rtol {a.rtol:g}, 2 shared CPU cores\n* extrapolated from {len(sub)} lanes x {a.subset_periods} periods; compile excluded; jax {jax.__version__}",
        fontsize=10,
    )
    fig.savefig(a.out / f"bench_sweep_{tag}.png", dpi=130)
    print("wrote", a.out, flush=True)


if __name__ == "__main__":
    main()
