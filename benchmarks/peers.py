"""jaxcelt against the integrators people would otherwise use (issue 7), same scene, same accuracy.

Single trajectory (scene rest17 from rest, error at the stroboscopic samples against the Dopri8
1e-13 reference): jaxcelt (diffrax Tsit5 / Kvaerno5-Newton, jit-compiled), scipy solve_ivp
DOP853 / LSODA / Radau with a plain NumPy RHS and with a numba RHS (``benchmarks/_numba_model.py``), a
hand-written numba adaptive Dormand-Prince ensemble, and SUNDIALS CVODE (scikit-sundae; Adams and
BDF) on the numba RHS. Each runs a small tolerance ladder; "equal accuracy" = the cheapest run of
each peer whose error is below ``--target``; ratio = its time / jaxcelt Tsit5's.

Ensemble scaling: lanes 1 ... N (perturbed initial spins) with ``jax.vmap(simulate)`` against the
numba ``prange`` ensemble: throughput (trajectories per second) and compile time.

MuJoCo/MJX: not run (see docs/performance.md).

    python benchmarks/peers.py [--quick] [--out docs/performance]
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
from jaxcelt import benchmarking as bm  # noqa: E402
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


def _numba_ens(scene, rtol, lanes=1, Y0=None):
    Y0 = np.tile(np.asarray(scene.y0, float), (lanes, 1)) if Y0 is None else Y0
    t0 = time.perf_counter()
    out, steps, evals, status = nm.ensemble(Y0, scene.ts, scene.params, rtol, rtol * 1e-2, 1_000_000)
    sec = time.perf_counter() - t0
    return (out[0] if lanes == 1 else out), sec, int(evals.sum()), bool(np.all(status == 0))


def single(scene, ys_ref, rtols, target, numpy_rhs: bool, quick: bool = False):
    rows = []
    fn = nm.numba_rhs(scene.params)
    fp = nm.python_rhs(scene.params)
    _numba_ens(scene, 1e-6)  # compile
    for m in ("DOP853", "Radau"):  # warm up the scipy paths (numba specialises on the call signature)
        _scipy(bm.Scene(scene.name, scene.params, scene.y0, 0.01, np.array([0.0, 0.01]), ""), m, fn, 1e-4)
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
            r = bm.run_diffrax(scene, solver, rtol=rtol, ys_ref=ys_ref, repeats=2)
            nfe = r["steps"] * 6 if solver == "Tsit5" else None
            row = dict(name=f"jaxcelt {solver}", rtol=rtol, run_s=r["run_s"], compile_s=r["compile_s"], rhs_evals=nfe)
            rows.append(dict(row, ok=r["status"] == 0, error=r["error"], run_s_per_sim_s=r["run_s"] / sim))
            print(
                f"  jaxcelt {solver:20s} rtol {rtol:.0e}: err {r['error']:.2e} run {r['run_s'] * 1e3:9.1f} ms compile {r['compile_s']:.1f}s",
                flush=True,
            )
        for m in ("DOP853", "LSODA", "Radau"):
            add(f"scipy {m} + numba RHS", *_scipy(scene, m, fn, rtol), rtol)
            if numpy_rhs and m == "DOP853":
                add(f"scipy {m} + Python RHS (interpreted)", *_scipy(scene, m, fp, rtol), rtol)
        add("numba DP5 (hand-written)", *_numba_ens(scene, rtol), rtol)
        for m in ("Adams", "BDF"):
            try:
                add(f"CVODE {m} + numba RHS", *_cvode(scene, m, rtol), rtol)
            except ImportError:
                pass
    # equal accuracy: cheapest run per peer with error <= target
    best = {}
    for r in rows:
        if r["ok"] and np.isfinite(r["error"]) and r["error"] <= target:
            if r["name"] not in best or r["run_s"] < best[r["name"]]["run_s"]:
                best[r["name"]] = r
    ref = best.get("jaxcelt Tsit5")
    table = []
    for _name, r in sorted(best.items(), key=lambda kv: kv[1]["run_s"]):
        table.append(dict(r, ratio_vs_jaxcelt=None if ref is None else r["run_s"] / ref["run_s"]))
    return rows, table


def scaling(scene, lanes_list, rtol):
    rows = []
    rng = np.random.default_rng(0)
    p = scene.params

    @jax.jit
    def batch(W):
        def one(w):
            y0 = jc.initial_state(p, omega=w)
            return jc.simulate(p, y0, scene.t1, ts=jnp.asarray(scene.ts), rtol=rtol, atol=rtol * 1e-2, exact_ts=True).ys

        return jax.vmap(one)(W)

    for L in lanes_list:
        W = rng.normal(size=(L, 3)) * 0.05
        t0 = time.perf_counter()
        jax.block_until_ready(batch(jnp.asarray(W)))
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        jax.block_until_ready(batch(jnp.asarray(W)))
        run = time.perf_counter() - t0
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        rows.append(
            dict(
                name="jaxcelt vmap Tsit5",
                lanes=L,
                run_s=run,
                compile_s=max(first - run, 0),
                lanes_per_s=L / run,
                peak_rss_mb=rss,
            )
        )
        print(
            f"  jaxcelt vmap {L:5d} lanes: run {run:.2f}s compile {first - run:.1f}s -> {L / run:.1f} traj/s, peak RSS {rss:.0f} MB",
            flush=True,
        )
        Y0 = np.stack([np.asarray(jc.initial_state(p, omega=w)) for w in W])
        _, sec, _, ok = _numba_ens(scene, rtol, L, Y0)
        rows.append(
            dict(name=f"numba DP5 prange ({_numba_threads()} threads)", lanes=L, run_s=sec, lanes_per_s=L / sec, ok=ok)
        )
        print(f"  numba prange {L:5d} lanes: run {sec:.2f}s -> {L / sec:.1f} traj/s", flush=True)
    return rows


def _numba_threads():
    import numba

    return numba.get_num_threads()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--target", type=float, default=1e-5, help="equal-accuracy target (max state error)")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    info = versions()
    info["device"] = bm.device_string()
    print("versions:", info, flush=True)
    periods = 2 if args.quick else 5
    scene = bm.make_scene("rest17", periods)
    sol = jc.simulate(
        scene.params,
        scene.y0,
        scene.t1,
        ts=scene.ts,
        solver=bm.make_solver("Dopri8"),
        rtol=1e-13,
        atol=1e-13,
        exact_ts=True,
    )
    ys_ref = np.asarray(sol.ys)
    print(f"single trajectory: {scene.description}", flush=True)
    rtols = [1e-6, 1e-8] if args.quick else [1e-5, 1e-6, 1e-7, 1e-8, 1e-10]
    rows, table = single(scene, ys_ref, rtols, args.target, numpy_rhs=True, quick=args.quick)
    print("ensemble scaling", flush=True)
    lanes = [1, 8, 32] if args.quick else [1, 16, 64, 256, 1024]
    sc_rows = scaling(bm.make_scene("rest17", 1), lanes, 1e-8)
    res = dict(
        versions=info, scene=scene.description, target=args.target, single=rows, equal_accuracy=table, scaling=sc_rows
    )
    tag = "_quick" if args.quick else ""
    (out / f"peers{tag}.json").write_text(json.dumps(res, indent=1, default=float))
    from jaxcelt.plotting.performance import plot_peers

    plot_peers(table, sc_rows).savefig(out / f"peers{tag}.png", dpi=110)
    print(f"equal accuracy (error <= {args.target:.0e}):")
    for r in table:
        print(
            f"  {r['name']:28s} rtol {r['rtol']:.0e} err {r['error']:.1e} {r['run_s'] * 1e3:9.1f} ms  x{r['ratio_vs_jaxcelt'] or float('nan'):.2f}"
        )
    return res


if __name__ == "__main__":
    main()
