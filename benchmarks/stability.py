"""Stability map (issue 7): where do methods fail?

(a) stiffness from the friction smoothing: eps = eps_R from 1e-2 to 1e-10 on the stick-slip scene;
    explicit Tsit5 against implicit Kvaerno5 (diffrax's default chord root finder and full Newton);
    verdict per cell: ok / slow (> ``--slow`` steps per base period) / failed (max_steps, solver
    failure, non-finite) / wrong attractor (final state off the eps-specific reference by > 1e-2).
(b) fixed-step blow-up threshold in dt (RK4, Heun, Euler) at two eps values.
(c) float32 against float64 over long horizons at omega_pi = 14, 17, 19: time where the two
    separate by > 1e-2, and whether the regime label (period of the stroboscopic samples) changes.
(d) gradient of loss = omega2 at the last section sample with respect to mu against the horizon,
    next to e^{lambda T}; reverse mode through diffrax's RecursiveCheckpointAdjoint.

    python benchmarks/stability.py [--quick] [--out docs/performance] [--parts a,b,c,d]
"""

from __future__ import annotations

import argparse
import json
import pathlib
import time

import jax
import jax.numpy as jnp
import numpy as np

import jaxcelt as jc
from jaxcelt import benchmarking as bm
from jaxcelt.regimes import detect_period
from jaxcelt.versions import versions


def _verdict(status, ys, ys_ref, steps, periods, slow_per_period, wrong_tol=1e-2):
    ys = np.asarray(ys, float)
    if status != 0 or not np.all(np.isfinite(ys)):
        return "failed"
    if ys_ref is not None and np.max(np.abs(ys[-1] - np.asarray(ys_ref)[-1])) > wrong_tol:
        return "wrong attractor"
    if steps > slow_per_period * periods:
        return "slow"
    return "ok"


def part_a(quick: bool, slow_per_period: float):
    # The stick-slip scene: from rest at q_pi = 0.04 m the stone slides all the time and eps does
    # not matter (checked: identical step counts for eps 1e-2 ... 1e-6); stiffness appears only
    # while sticking.
    periods = 1
    epss = [1e-4, 1e-6, 1e-8] if quick else [1e-2, 1e-4, 1e-6, 1e-8, 1e-10]
    methods = (
        [("Tsit5", 1e-6), ("Kvaerno5", 1e-6), ("Kvaerno5-Newton", 1e-6)]
        if quick
        else [
            ("Tsit5", 1e-6),
            ("Tsit5", 1e-8),
            ("Dopri8", 1e-8),
            ("Kvaerno5", 1e-6),
            ("Kvaerno5-Newton", 1e-6),
            ("Kvaerno5-Newton", 1e-8),
        ]
    )
    max_steps = 50_000 if quick else 200_000
    rows = []
    for eps in epss:
        sc = bm.make_scene("stick_slip", periods, eps=eps, eps_R=eps)
        # eps-specific reference: implicit at 1e-10 (explicit references are infeasible at tiny eps)
        rref = bm.run_diffrax(sc, "Kvaerno5-Newton", rtol=1e-10, atol=1e-12, repeats=0, max_steps=max_steps)
        ys_ref = np.array([rref["final_state"]]) if rref["status"] == 0 else None
        for name, tol in methods:
            r = bm.run_diffrax(sc, name, rtol=tol, repeats=0, max_steps=max_steps)
            ys = np.array([r["final_state"]])
            err = None if ys_ref is None else bm.state_error(ys, ys_ref)
            v = _verdict(r["status"], ys, ys_ref, r["steps"], periods, slow_per_period)
            rows.append(
                dict(method=f"{name} rtol {tol:.0e}", eps=eps, steps=r["steps"], accepted=r["accepted"], rejected=r["rejected"],
                     status=r["status"], run_s=r["run_s"], compile_s=r["compile_s"], error_vs_ref=err, verdict=v,
                     ref_status=rref["status"], ref_steps=rref["steps"])
            )  # fmt: skip
            print(
                f"(a) eps {eps:.0e} {name:16s} rtol {tol:.0e}: {v:15s} steps {r['accepted']}+{r['rejected']} status {r['status']} err {err} run {r['run_s']:.2f}s",
                flush=True,
            )
    return rows


def part_b(quick: bool):
    periods = 1 if quick else 2
    dts = [2e-3, 5e-4, 1e-4, 2e-5] if quick else [1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5]
    epss = [1e-4] if quick else [1e-4, 1e-6]
    methods = ["RK4-fixed"] if quick else ["RK4-fixed", "Heun-fixed", "Euler-fixed"]
    rows = []
    for eps in epss:
        sc = bm.make_scene("stick_slip", periods, eps=eps, eps_R=eps)
        ref = bm.run_diffrax(sc, "Kvaerno5-Newton", rtol=1e-10, atol=1e-12, repeats=0)
        ys_ref = np.array([ref["final_state"]])
        for name in methods:
            for dt in dts:
                r = bm.run_diffrax(sc, name, dt0=dt, repeats=0, max_steps=int(sc.t1 / dt) + 10)
                ys = np.array([r["final_state"]])
                err = bm.state_error(ys, ys_ref)
                v = "failed" if not np.isfinite(err) or err > 1.0 else ("wrong attractor" if err > 1e-2 else "ok")
                rows.append(
                    dict(
                        method=f"{name} eps {eps:.0e}",
                        dt=dt,
                        eps=eps,
                        steps=r["steps"],
                        error_vs_ref=err,
                        verdict=v,
                        run_s=r["run_s"],
                    )
                )
                print(f"(b) eps {eps:.0e} {name:12s} dt {dt:.0e}: {v:15s} err {err:.2e}", flush=True)
    return rows


def part_c(quick: bool):
    periods = 20 if quick else 100
    ws = [17] if quick else [14, 17, 19]
    rows = []
    for w in ws:
        sc = bm.make_scene(f"rest{w}", periods)
        r64 = bm.run_diffrax(sc, "Tsit5", rtol=1e-10, repeats=0)
        s64 = jc.simulate(sc.params, sc.y0, sc.t1, ts=sc.ts, rtol=1e-10, atol=1e-12, exact_ts=True)
        y64 = np.asarray(s64.ys)
        for rtol in [1e-4, 1e-6]:
            s32 = jc.simulate(
                sc.params, sc.y0, sc.t1, ts=sc.ts, rtol=rtol, atol=rtol * 1e-2, exact_ts=True, dtype=jnp.float32
            )
            y32 = np.asarray(s32.ys, dtype=np.float64)
            d = np.max(np.abs(y32 - y64), axis=1)
            d = np.where(np.isfinite(d), d, np.inf)
            sep = np.nonzero(d > 1e-2)[0]
            tsep = float(sc.ts[sep[0]]) if len(sep) else None
            half = periods // 2
            k64 = detect_period(y64[half:, 3:9], tol=1e-3)
            k32 = detect_period(y32[half:, 3:9], tol=1e-3)
            rows.append(
                dict(omega_pi=w, periods=periods, rtol32=rtol, status32=int(s32.status), steps32=int(s32.num_steps), steps64=r64["steps"],
                     t_separate=tsep, err_at_1_period=float(d[1]), err_at_5_periods=float(d[min(5, periods)]), max_err=float(np.max(d)),
                     period64=k64, period32=k32, regime_changed=bool(k64 != k32))
            )  # fmt: skip
            print(
                f"(c) w {w} f32 rtol {rtol:.0e}: separates (>1e-2) at t = {tsep}, err@1T {d[1]:.1e} @5T {d[5]:.1e}, period f64 {k64} f32 {k32}",
                flush=True,
            )
    return rows


def part_d(quick: bool):
    horizons = [1, 2, 4] if quick else [1, 2, 4, 8, 16, 32]
    rows = []
    for w in [17] if quick else [14, 17, 19]:
        p0 = jc.CeltParams.paper(omega_pi=float(w))
        y0 = jc.initial_state(p0)
        T = 2 * np.pi / w

        for P in horizons:

            def loss(mu, P=P, p0=p0, y0=y0, T=T):
                p = p0.replace(mu=mu)
                sol = jc.simulate(
                    p, y0, P * T, ts=jnp.array([P * T]), rtol=1e-8, atol=1e-10, exact_ts=True, max_steps=50_000
                )
                return sol.ys[-1, 4]

            g = jax.jit(jax.value_and_grad(loss))
            t0 = time.perf_counter()
            val, grad = jax.block_until_ready(g(jnp.asarray(0.2241)))
            t1 = time.perf_counter()
            val, grad = jax.block_until_ready(g(jnp.asarray(0.2241)))
            t2 = time.perf_counter()
            h = 1e-6
            fd = (loss(jnp.asarray(0.2241 + h)) - loss(jnp.asarray(0.2241 - h))) / (2 * h)
            rows.append(
                dict(
                    omega_pi=w,
                    periods=P,
                    horizon_s=P * T,
                    loss=float(val),
                    grad=float(grad),
                    grad_fd=float(fd),
                    first_s=t1 - t0,
                    run_s=t2 - t1,
                )
            )
            print(
                f"(d) w {w} T = {P:3d} periods: dloss/dmu = {float(grad):.3e} (FD {float(fd):.3e}), run {t2 - t1:.2f}s",
                flush=True,
            )
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--parts", default="a,b,c,d")
    ap.add_argument("--slow", type=float, default=5000.0, help="steps per base period above which a run is 'slow'")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    info = versions()
    info["device"] = bm.device_string()
    print("versions:", info, flush=True)
    res = dict(versions=info, slow_steps_per_period=args.slow)
    parts = args.parts.split(",")
    tag = "_quick" if args.quick else ""
    for part, fn in (
        ("a", lambda: part_a(args.quick, args.slow)),
        ("b", lambda: part_b(args.quick)),
        ("c", lambda: part_c(args.quick)),
        ("d", lambda: part_d(args.quick)),
    ):
        if part in parts:
            t = time.perf_counter()
            res[part] = fn()
            res[f"{part}_seconds"] = time.perf_counter() - t
            (out / f"stability{tag}.json").write_text(json.dumps(res, indent=1, default=float))
    from jaxcelt.plotting.performance import plot_stability_map

    if "a" in res:
        plot_stability_map(res["a"], "eps", "(a) friction-smoothing stiffness, stick-slip scene").savefig(
            out / f"stability_eps{tag}.png", dpi=110
        )
    if "b" in res:
        plot_stability_map(res["b"], "dt", "(b) fixed-step blow-up, stick-slip scene").savefig(
            out / f"stability_dt{tag}.png", dpi=110
        )
    print("wrote", out / f"stability{tag}.json")
    return res


if __name__ == "__main__":
    main()
