"""jaxcelt against the integrators people would otherwise use, same scene, same accuracy.

Single trajectory (scene rest17 from rest, error at the stroboscopic samples against the Dopri8
1e-13 reference): jaxcelt (diffrax Tsit5 / Dopri8 / Kvaerno5-Newton, jit-compiled), scipy
solve_ivp DOP853 / LSODA / Radau with the numba RHS and DOP853 with the same RHS source run by the
interpreter (``benchmarks/_numba_model.py``), the hand-written numba adaptive Dormand-Prince 5(4)
loop, and SUNDIALS CVODE (scikit-sundae; Adams and BDF) on the numba RHS. Each runs a tolerance
ladder; "equal accuracy" = the cheapest run of each peer whose error is below each ``--targets``
value; ratio = its run time / jaxcelt Tsit5's at the same target (compile times reported apart).

Ensemble scaling: lanes 1 ... 4096 (perturbed initial spins) with ``jax.vmap(simulate)`` against
the numba ``prange`` DP5 ensemble: trajectories/s, lane-steps/s, peak RSS, compile time.

Ensemble batch sizes each run in a fresh subprocess (``--scaling-worker``), so the peak RSS is that
batch's; compile time is measured apart (``jit(...).lower().compile()``; numba: first call).

MuJoCo/MJX (a different contact model): ``benchmarks/mujoco_peer.py``.

    python benchmarks/peers.py [--quick] [--out docs/performance] [--scaling-budget 900]
"""

from __future__ import annotations

import argparse
import json
import pathlib
import resource
import sys
import time

import jax
import jax.numpy as jnp
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _numba_model as nm  # noqa: E402

import jaxcelt as jc  # noqa: E402
from jaxcelt.integrate import solvers  # noqa: E402
from jaxcelt.provenance import write_result  # noqa: E402
from jaxcelt.studies import benchmarking as bm  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402


def _scipy(scene, method, f, rtol):
    from scipy.integrate import solve_ivp

    t0 = time.perf_counter()
    ys = [np.asarray(scene.y0, float)]
    nfev = 0
    ok = True
    for a, b in zip(scene.ts[:-1], scene.ts[1:]):
        s = solve_ivp(f, (a, b), ys[-1], method=method, rtol=rtol, atol=rtol * 1e-2)
        nfev += s.nfev
        if s.status != 0:
            ok = False
            break
        ys.append(s.y[:, -1])
    while len(ys) < len(scene.ts):
        ys.append(np.full(13, np.nan))
    return np.array(ys), time.perf_counter() - t0, nfev, ok


def _cvode(scene, method, rtol):
    from sksundae.cvode import CVODE

    P, B, Bi = nm.pack(scene.params)

    def rhs(t, y, yp):
        nm.rhs(t, y, P, B, Bi, yp)

    s = CVODE(rhs, method=method, rtol=rtol, atol=rtol * 1e-2, max_num_steps=1_000_000)
    t0 = time.perf_counter()
    r = s.solve(np.asarray(scene.ts, float), np.asarray(scene.y0, float))
    sec = time.perf_counter() - t0
    ys = np.asarray(r.y, float)
    if ys.shape != (len(scene.ts), 13):
        ys = np.full((len(scene.ts), 13), np.nan)
    return ys, sec, int(r.nfev), bool(r.success)


def _best(run, *args, repeats=3, cap_s=2.0):
    """Best wall time of up to ``repeats`` calls ``run(*args)`` (shared machine); a call longer
    than ``cap_s`` is not repeated."""
    best = None
    for _ in range(repeats):
        r = run(*args)
        if best is None or r[1] < best[1]:
            best = r
        if r[1] > cap_s:
            break
    return best


def _numba_ens(scene, rtol, lanes=1, Y0=None):
    Y0 = np.tile(np.asarray(scene.y0, float), (lanes, 1)) if Y0 is None else Y0
    t0 = time.perf_counter()
    out, steps, evals, status = nm.ensemble(Y0, scene.ts, scene.params, rtol, rtol * 1e-2, 1_000_000)
    sec = time.perf_counter() - t0
    return (out[0] if lanes == 1 else out), sec, int(evals.sum()), bool(np.all(status == 0))


def single(scene, ys_ref, rtols, targets, numpy_rhs: bool, quick: bool = False):
    rows = []
    fn = nm.numba_rhs(scene.params)
    fp = nm.python_rhs(scene.params)
    _numba_ens(scene, 1e-6)  # compile
    for m in ("DOP853", "Radau"):  # warm up the scipy paths (numba specialises on the call signature)
        _scipy(bm.BenchmarkScene(scene.name, scene.params, scene.y0, 0.01, np.array([0.0, 0.01]), ""), m, fn, 1e-4)
    sim = scene.t1

    def add(name, ys, sec, nfev, ok, rtol, compile_s=None):
        err = bm.state_error(ys, ys_ref) if ok else float("inf")
        rows.append(
            dict(
                name=name,
                rtol=rtol,
                run_s=sec,
                compile_s=compile_s,
                rhs_evals=nfev,
                ok=ok,
                error=err,
                run_s_per_sim_s=sec / sim,
            )
        )
        print(f"  {name:28s} rtol {rtol:.0e}: err {err:.2e} run {sec * 1e3:9.1f} ms nfev {nfev} ok {ok}", flush=True)

    for rtol in rtols:
        for solver in ("Tsit5", "Dopri8") if quick else ("Tsit5", "Dopri8", "Kvaerno5-Newton"):
            r = bm.run_diffrax(scene, solver, rtol=rtol, ys_ref=ys_ref, repeats=3)
            nfe = r["steps"] * 6 if solver == "Tsit5" else None
            row = dict(name=f"jaxcelt {solver}", rtol=rtol, run_s=r["run_s"], compile_s=r["compile_s"], rhs_evals=nfe)
            rows.append(dict(row, ok=r["status"] == 0, error=r["error"], run_s_per_sim_s=r["run_s"] / sim))
            print(
                f"  jaxcelt {solver:20s} rtol {rtol:.0e}: err {r['error']:.2e} run {r['run_s'] * 1e3:9.1f} ms compile {r['compile_s']:.1f}s",
                flush=True,
            )
        for m in ("DOP853", "LSODA", "Radau"):
            add(f"scipy {m} + numba RHS", *_best(_scipy, scene, m, fn, rtol), rtol)
            if numpy_rhs and m == "DOP853":
                add(f"scipy {m} + Python RHS (interpreted)", *_best(_scipy, scene, m, fp, rtol), rtol)
        add("numba DP5 (hand-written)", *_best(_numba_ens, scene, rtol), rtol)
        for m in ("Adams", "BDF"):
            try:
                add(f"CVODE {m} + numba RHS", *_best(_cvode, scene, m, rtol), rtol)
            except ImportError:
                pass
    return rows, [equal_accuracy(rows, t) for t in targets]


def equal_accuracy(rows, target):
    """Cheapest run per peer with error <= target; ratio = its run time / jaxcelt Tsit5's (same target)."""
    best = {}
    for r in rows:
        if r["ok"] and np.isfinite(r["error"]) and r["error"] <= target:
            if r["name"] not in best or r["run_s"] < best[r["name"]]["run_s"]:
                best[r["name"]] = r
    ref = best.get("jaxcelt Tsit5")
    return [
        dict(r, target=target, ratio_vs_jaxcelt=None if ref is None else r["run_s"] / ref["run_s"])
        for _name, r in sorted(best.items(), key=lambda kv: kv[1]["run_s"])
    ]


def _vmhwm_mb() -> float:
    """Peak resident set of this process (Linux VmHWM; unlike ru_maxrss it is not inherited over fork+exec)."""
    for line in pathlib.Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _scaling_worker(kind: str, L: int, rtol: float, periods: int) -> dict:
    """One batch size in a fresh process (VmHWM = this process's peak RSS): compile, then run.

    Runs are repeated (best of up to 3) while they take < 15 s in all: on the shared machine a
    single numba prange run once took 20 s instead of 0.06 s; every run time is kept in ``run_s_all``.
    """
    scene = bm.make_scene("rest17", periods)
    p = scene.params
    W = np.random.default_rng(0).normal(size=(L, 3)) * 0.05
    rss0 = _vmhwm_mb()
    if kind == "jax":

        @jax.jit
        def batch(W):
            def one(w):
                y0 = jc.initial_state(p, omega=w)
                s = jc.simulate(p, y0, scene.t1, ts=jnp.asarray(scene.ts), rtol=rtol, atol=rtol * 1e-2, exact_ts=True)
                return s.ys, s.num_steps, s.status

            return jax.vmap(one)(W)

        rss0 = _vmhwm_mb()
        t0 = time.perf_counter()
        batch.lower(jnp.asarray(W)).compile()
        compile_s = time.perf_counter() - t0
        jax.block_until_ready(batch(jnp.asarray(W)))  # first call (compiled above, cached)
        runs = []
        while len(runs) < 3 and sum(runs) < 15:
            t0 = time.perf_counter()
            ys, steps, status = jax.block_until_ready(batch(jnp.asarray(W)))
            runs.append(time.perf_counter() - t0)
        steps, ok = np.asarray(steps), bool(np.all(np.asarray(status) == 0))
        name = "jaxcelt vmap(simulate) Tsit5"
    else:
        Y0 = np.stack([np.asarray(jc.initial_state(p, omega=w)) for w in W])
        rss0 = _vmhwm_mb()
        t0 = time.perf_counter()
        nm.ensemble(Y0[:1], scene.ts[:2], p, rtol, rtol * 1e-2)  # numba: load/compile (cache=True)
        compile_s = time.perf_counter() - t0
        runs = []
        while len(runs) < 3 and sum(runs) < 15:
            t0 = time.perf_counter()
            ys, steps, evals, status = nm.ensemble(Y0, scene.ts, p, rtol, rtol * 1e-2, 1_000_000)
            runs.append(time.perf_counter() - t0)
        ok = bool(np.all(status == 0))
        name = f"numba DP5 prange ({nm.nb.get_num_threads()} threads)"
    rss, run = _vmhwm_mb(), min(runs)
    return dict(name=name, lanes=L, run_s=run, run_s_all=runs, compile_s=compile_s, lanes_per_s=L / run,
                lane_steps=int(np.sum(steps)), max_lane_steps=int(np.max(steps)),
                lane_steps_per_s=float(np.sum(steps)) / run, peak_rss_mb=rss, rss_before_run_mb=rss0,
                ok=ok, finite=bool(np.all(np.isfinite(np.asarray(ys)))))  # fmt: skip


def scaling(lanes_list, rtol, periods=1, budget_s=900.0):
    """Batch sizes in ascending order, one subprocess per (kind, size); stops when ``budget_s`` is spent."""
    import subprocess

    rows, skipped, t_start = [], [], time.perf_counter()
    for L in lanes_list:
        for kind in ("jax", "numba"):
            left = budget_s - (time.perf_counter() - t_start)
            if left < 30:
                skipped.append(dict(kind=kind, lanes=L, reason="budget spent"))
                continue
            cmd = [sys.executable, __file__, "--scaling-worker", kind, str(L), str(rtol), str(periods)]
            try:
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=left)
            except subprocess.TimeoutExpired:
                skipped.append(dict(kind=kind, lanes=L, reason=f"killed at the budget ({left:.0f} s)"))
                continue
            line = [x for x in r.stdout.splitlines() if x.startswith("{")]
            if r.returncode != 0 or not line:
                skipped.append(dict(kind=kind, lanes=L, reason=f"exit {r.returncode}: {r.stderr[-300:]}"))
                continue
            row = json.loads(line[-1])
            rows.append(row)
            print(f"  {row['name']:30s} {L:5d} lanes: run {row['run_s']:.3f}s compile {row['compile_s']:.1f}s -> "
                  f"{row['lanes_per_s']:.1f} traj/s, {row['lane_steps_per_s']:.3g} lane-steps/s, "
                  f"peak RSS {row['peak_rss_mb']:.0f} MB (before run {row['rss_before_run_mb']:.0f})", flush=True)  # fmt: skip
    for s in skipped:
        print(f"  skipped: {s}", flush=True)
    return rows, skipped


def plot_scaling(rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(14, 4.0))
    for name in dict.fromkeys(r["name"] for r in rows):
        rr = [r for r in rows if r["name"] == name]
        L = [r["lanes"] for r in rr]
        ax[0].loglog(L, [r["lanes_per_s"] for r in rr], "o-", label=name)
        ax[1].loglog(L, [r["lane_steps_per_s"] for r in rr], "o-", label=name)
        ax[2].semilogx(L, [r["peak_rss_mb"] for r in rr], "o-", label=f"{name}: peak RSS")
        if name.startswith("jaxcelt"):
            ax[2].semilogx(
                L, [r["compile_s"] * 100 for r in rr], "s--", color="grey", label="jaxcelt compile time x100 [s]"
            )
    ax[0].set_ylabel("trajectories per wall second")
    ax[1].set_ylabel("lane-steps per wall second")
    ax[2].set_ylabel("MB  (compile: s x 100)")
    for a in ax:
        a.set_xlabel("lanes")
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=7)
    fig.suptitle(
        "ensemble scaling: rest17, 1 period, rtol 1e-8, perturbed initial spins (CPU, 2 cores, shared)", fontsize=9
    )
    fig.tight_layout()
    return fig


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--targets", default="1e-5,1e-8", help="equal-accuracy targets (max state error)")
    ap.add_argument("--periods", type=int, default=2, help="periods of the single-trajectory scene")
    ap.add_argument("--lanes", default="1,4,16,64,256,1024,4096")
    ap.add_argument("--scaling-budget", type=float, default=900.0, help="wall-second cap of the ensemble scaling")
    ap.add_argument("--scaling-worker", nargs=4, metavar=("KIND", "LANES", "RTOL", "PERIODS"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.scaling_worker:
        k, L, rtol, per = args.scaling_worker
        print(json.dumps(_scaling_worker(k, int(L), float(rtol), int(per)), default=float))
        return None
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    info = versions()
    info["device"] = bm.device_string()
    info["numba_threads"] = nm.nb.get_num_threads()
    info["loadavg_start"] = list(__import__("os").getloadavg())
    print("versions:", info, flush=True)
    scene = bm.make_scene("rest17", args.periods)
    sol = jc.simulate(
        scene.params,
        scene.y0,
        scene.t1,
        ts=scene.ts,
        solver=solvers.make_solver("Dopri8"),
        rtol=1e-13,
        atol=1e-13,
        exact_ts=True,
    )
    ys_ref = np.asarray(sol.ys)
    print(f"single trajectory: {scene.description}", flush=True)
    rtols = [1e-6, 1e-8] if args.quick else [1e-5, 1e-6, 1e-7, 1e-8, 1e-10]
    targets = [float(x) for x in args.targets.split(",")]
    rows, tables = single(scene, ys_ref, rtols, targets, numpy_rhs=True, quick=args.quick)
    info["loadavg_after_single"] = list(__import__("os").getloadavg())
    print("ensemble scaling", flush=True)
    lanes = [1, 8, 32] if args.quick else [int(x) for x in args.lanes.split(",")]
    sc_rows, skipped = scaling(lanes, 1e-8, 1, args.scaling_budget)
    info["loadavg_end"] = list(__import__("os").getloadavg())
    res = dict(
        versions=info,
        scene=scene.description,
        targets=targets,
        single=rows,
        equal_accuracy={f"{t:.0e}": tab for t, tab in zip(targets, tables)},
        scaling_scene="rest17, 1 period, rtol 1e-8 (atol 1e-10), initial spin + N(0, 0.05^2) rad/s per component",
        scaling=sc_rows,
        scaling_skipped=skipped,
    )
    tag = "_quick" if args.quick else ""
    write_result(out / f"peers{tag}.json", res, load_at_start=info["loadavg_start"], default=float)
    from jaxcelt.plotting.performance import plot_peers

    plot_peers(tables[0]).savefig(out / f"peers{tag}.png", dpi=110)
    if sc_rows:
        plot_scaling(sc_rows).savefig(out / f"peers_scaling{tag}.png", dpi=110)
    for t, table in zip(targets, tables):
        print(f"equal accuracy (error <= {t:.0e}):")
        for r in table:
            print(
                f"  {r['name']:36s} rtol {r['rtol']:.0e} err {r['error']:.1e} {r['run_s'] * 1e3:9.1f} ms  x{r['ratio_vs_jaxcelt'] or float('nan'):.2f}"
            )
    return res


if __name__ == "__main__":
    main()
