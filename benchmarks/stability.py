"""Stability map: where do methods fail?

(a) stiffness from the friction smoothing: eps = eps_R = 1e-2 ... 1e-10 on the stick-slip scene
    (1 period); Tsit5, Dopri8, Kvaerno5 with diffrax's chord root finder, Kvaerno5 with full
    Newton. Verdict per cell: ok / slow (> ``--slow`` steps per base period) / failed
    (max_steps, solver failure, non-finite) / wrong attractor (stroboscopic samples off the
    eps-specific reference by > ``WRONG_TOL``) / unverified (finished, but no trusted reference
    at that eps). Plus the from-rest scene (omega_pi = 17, 5 periods) with Tsit5 at every eps.
(b) fixed-step RK4 and Heun: dt scan on the from-rest scene (2 periods) and the stick-slip scene
    (eps 1e-4 and 1e-6); error against an adaptive reference, "wrong" (error > 1e-2), "blow-up"
    (non-finite, status != 0 or validity monitor fired), next to the explicit stability limit
    2.785/rho (RK4) and 2/rho (Heun) from the spectral radius rho of the Jacobian along the
    reference.
(c) float32 against float64 from rest at omega_pi = 14, 17, 19 over 50 periods: time at which the
    trajectories separate by > 1e-2 and whether the regime label (`jaxcelt.sweeps.regimes.classify`)
    changes; float64 at the float32 tolerance as control.
(d) |d loss / d mu| against the horizon (1 ... 32 periods) at omega_pi = 17 and 19, loss = mean
    squared (v, omega) over the stroboscopic samples, next to the finite-time Lyapunov growth
    from `jaxcelt.integrate.lyapunov.celt_lyapunov`; compiled memory of reverse mode
    (RecursiveCheckpointAdjoint) against horizon and max_steps.
(e) geometric singularities: n2 -> 1 (psi equation), contact near the tip of the long axis,
    lift-off (N -> 0).

Every cell has a step budget (max_steps) and the script has a wall-time budget per part: cells
whose predicted time exceeds ``--cell-budget`` or that start after ``--part-budget`` are recorded
as "not run". JSON is rewritten after every cell (``stability_<part>.json``).

    python benchmarks/stability.py [--quick] [--parts a,b,c,d,e] [--out docs/performance]
    python benchmarks/stability.py --plot-only      # redraw stability_*.png from the JSON files
"""

from __future__ import annotations

import argparse
import json
import pathlib
import resource
import time

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

import jaxcelt as jc
from jaxcelt.integrate import solvers
from jaxcelt.integrate.lyapunov import celt_lyapunov
from jaxcelt.plotting import results
from jaxcelt.provenance import write_result
from jaxcelt.studies import benchmarking as bm
from jaxcelt.sweeps.regimes import classify, regime_names
from jaxcelt.versions import versions

WRONG_TOL = 1e-2  # max |y - y_ref| over samples and components (SI) that counts as a wrong attractor


class Part:
    """Rows of one part, written to JSON after every cell; wall-time budget bookkeeping."""

    def __init__(self, name, out, budget, meta):
        self.name, self.path, self.budget = name, out / f"stability_{name}.json", budget
        self.t0 = time.perf_counter()
        self.res = dict(meta, part=name, rows=[], part_budget_s=budget)
        self.load_at_start = meta.get("versions", {}).get("loadavg_at_start")
        self.compiled = set()

    @property
    def over(self):
        return time.perf_counter() - self.t0 > self.budget

    def add(self, row, msg=None):
        self.res["rows"].append(row)
        self.res["elapsed_s"] = time.perf_counter() - self.t0
        self.res["maxrss_MB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        self.write()
        if msg:
            print(f"({self.name}) {msg}", flush=True)

    def set(self, key, val):
        self.res[key] = val
        self.write()

    def write(self):
        write_result(self.path, self.res, load_at_start=self.load_at_start, default=_json_default)


def _json_default(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return float(x)


def _f(x):
    x = float(x)
    return x if np.isfinite(x) else None


def make_solver(name, rtol, atol):
    """`solvers.make_solver` plus "Kvaerno5-chord": diffrax's VeryChord root finder with the
    controller's tolerances given explicitly (`jaxcelt.simulate` replaces a *default* VeryChord
    by full Newton, so diffrax's default behaviour has to be requested explicitly)."""
    if name == "Kvaerno5-chord":
        return diffrax.Kvaerno5(root_finder=diffrax.VeryChord(rtol=rtol, atol=atol, norm=optx.rms_norm))
    return solvers.make_solver(name)


def solve(part, sc, name, *, rtol=1e-8, atol=None, dt0=None, max_steps=300_000, dtype=None, y0=None, **kw):
    """One solve; returns (sol, ys float64, run_s, compile_s). The first call of each compiled
    configuration is run twice to separate compile time from run time."""
    atol = rtol * 1e-2 if atol is None else atol
    fixed = solvers.SOLVERS.get(name, (None, "implicit"))[1] == "fixed"
    solver = make_solver(name, rtol, atol)
    y0 = sc.y0 if y0 is None else y0

    def fn():
        return jc.simulate(
            sc.params, y0, sc.t1, ts=sc.ts, solver=solver, rtol=rtol, atol=atol, dt0=dt0,
            exact_ts=not fixed, dtype=dtype, max_steps=max_steps, **kw,
        )  # fmt: skip

    implicit = solvers.SOLVERS.get(name, (None, "implicit"))[1] == "implicit"
    key = (name, rtol if implicit else None, len(sc.ts), max_steps, str(dtype), fixed, tuple(kw.items()))
    t = time.perf_counter()
    sol = jax.block_until_ready(fn())
    first = time.perf_counter() - t
    compile_s = None
    run_s = first
    if key not in part.compiled:
        part.compiled.add(key)
        t = time.perf_counter()
        sol = jax.block_until_ready(fn())
        run_s = time.perf_counter() - t
        compile_s = max(first - run_s, 0.0)
    return sol, np.asarray(sol.ys, dtype=np.float64), run_s, compile_s


def _predict(history, max_steps):
    """Predicted wall time of the next eps cell from the last two of the same method."""
    if not history:
        return 0.0
    last = history[-1]
    growth = 10.0 if len(history) < 2 else max(history[-1]["run_s"] / max(history[-2]["run_s"], 1e-3), 1.0)
    per_step = last["run_s"] / max(last["steps"], 1)
    return float(min(last["run_s"] * growth, per_step * max_steps * 1.2))


# --------------------------------------------------------------------------------------------
# (a)


def part_a(part, args):
    epss = [1e-2, 1e-4, 1e-6] if args.quick else [1e-2, 1e-4, 1e-6, 1e-8, 1e-10]
    methods = [
        ("Tsit5", 1e-6), ("Dopri8", 1e-6), ("Kvaerno5-chord", 1e-6), ("Kvaerno5-Newton", 1e-6),
        ("Tsit5", 1e-8), ("Kvaerno5-Newton", 1e-8),
    ]  # fmt: skip
    if args.a_eps:
        epss = [float(e) for e in args.a_eps.split(",")]
    if args.quick:
        methods = [("Tsit5", 1e-6), ("Kvaerno5-Newton", 1e-6)]
    if args.a_methods:
        methods = [(m.split(":")[0], float(m.split(":")[1])) for m in args.a_methods.split(",")]
    ms = args.max_steps
    part.set("setup", dict(scene="stick_slip, omega_pi 17, q_pi 0.01 m, 1 period, 5 samples per period",
                           max_steps=ms, slow_steps_per_period=args.slow, wrong_tol=WRONG_TOL,
                           cell_budget_s=args.cell_budget,
                           reference="Dopri8 rtol 1e-12 atol 1e-14 (eps-specific); second opinion Kvaerno5-Newton rtol 1e-9"))  # fmt: skip
    # references first (cheap to expensive); a reference that cannot finish leaves its eps unverified
    refs, hist = {}, {}
    for eps in epss:
        sc = bm.make_scene("stick_slip", 1, eps=eps, eps_R=eps)
        ref = {}
        for rname, rtol, atol in (("Dopri8", 1e-12, 1e-14), ("Kvaerno5-Newton", 1e-9, 1e-11))[
            : 2 if args.a_second_ref else 1
        ]:
            h = hist.setdefault(("ref", rname), [])
            pred = _predict(h, ms)
            if pred > args.cell_budget or part.over:
                ref[rname] = dict(status="not run", predicted_s=pred)
                part.add(dict(kind="reference", method=f"{rname} rtol {rtol:.0e}", eps=eps, verdict="not run", predicted_s=pred),
                         f"ref eps {eps:.0e} {rname}: not run (predicted {pred:.0f} s)")  # fmt: skip
                continue
            sol, ys, run_s, comp = solve(part, sc, rname, rtol=rtol, atol=atol, max_steps=ms)
            st, steps = int(sol.status), int(sol.num_steps)
            h.append(dict(run_s=run_s, steps=steps))
            ref[rname] = dict(status=st, ys=ys if st == 0 and np.all(np.isfinite(ys)) else None)
            part.add(dict(kind="reference", method=f"{rname} rtol {rtol:.0e}", eps=eps, status=st, steps=steps,
                          accepted=int(sol.num_accepted_steps), rejected=int(sol.num_rejected_steps), run_s=run_s,
                          compile_s=comp, final_omega3=_f(ys[-1, 5])),
                     f"ref eps {eps:.0e} {rname}: status {st} steps {steps} run {run_s:.1f}s")  # fmt: skip
        a, b = ref["Dopri8"].get("ys"), ref.get("Kvaerno5-Newton", {}).get("ys")
        agree = bm.state_error(a, b) if a is not None and b is not None else None
        refs[eps] = dict(ys=a, second=b, agreement=agree)
        part.add(dict(kind="reference_agreement", eps=eps, agreement=agree),
                 f"ref eps {eps:.0e}: |Dopri8 - K5N| = {agree}")  # fmt: skip

    for name, rtol in methods:
        for eps in epss:
            sc = bm.make_scene("stick_slip", 1, eps=eps, eps_R=eps)
            h = hist.setdefault((name, rtol), [])
            pred = _predict(h, ms)
            label = f"{name} rtol {rtol:.0e}"
            if pred > args.cell_budget or part.over:
                why = (
                    "part budget used"
                    if part.over
                    else f"predicted {pred:.0f} s > cell budget {args.cell_budget:.0f} s"
                )
                part.add(dict(kind="cell", method=label, eps=eps, verdict="not run", why=why),
                         f"eps {eps:.0e} {label}: not run ({why})")  # fmt: skip
                continue
            sol, ys, run_s, comp = solve(part, sc, name, rtol=rtol, max_steps=ms)
            st, steps = int(sol.status), int(sol.num_steps)
            h.append(dict(run_s=run_s, steps=steps))
            r = refs[eps]
            ys_ref = r["ys"] if r["ys"] is not None else None
            err = bm.state_error(ys, ys_ref) if ys_ref is not None else None
            err2 = bm.state_error(ys, r["second"]) if r["second"] is not None else None
            if st != 0 or not np.all(np.isfinite(ys)):
                v = "failed"
            elif ys_ref is None:
                v = "unverified"
            elif err > WRONG_TOL:
                v = "wrong attractor"
            elif steps > args.slow:
                v = "slow"
            else:
                v = "ok"
            part.add(dict(kind="cell", method=label, solver=name, rtol=rtol, eps=eps, status=st, steps=steps,
                          accepted=int(sol.num_accepted_steps), rejected=int(sol.num_rejected_steps), run_s=run_s,
                          compile_s=comp, error_vs_ref=err, error_vs_second_ref=err2, verdict=v,
                          final_omega3=_f(ys[-1, 5]), valid=bool(sol.valid)),
                     f"eps {eps:.0e} {label:24s}: {v:15s} steps {int(sol.num_accepted_steps)}+{int(sol.num_rejected_steps)} "
                     f"status {st} err {err} err2 {err2} run {run_s:.2f}s")  # fmt: skip

    # from rest (q_pi = 0.04 m, never sticks): Tsit5 rtol 1e-6 against Tsit5 rtol 1e-12, 5 periods
    for eps in epss if args.a_rest else []:
        if part.over:
            break
        sc = bm.make_scene("rest17", 5, eps=eps, eps_R=eps)
        _, yr, _, _ = solve(part, sc, "Tsit5", rtol=1e-12, atol=1e-14, max_steps=ms)
        sol, ys, run_s, comp = solve(part, sc, "Tsit5", rtol=1e-6, max_steps=ms)
        err = bm.state_error(ys, yr)
        part.add(dict(kind="rest", method="Tsit5 rtol 1e-06 (rest17, 5 periods)", eps=eps, status=int(sol.status),
                      steps=int(sol.num_steps), accepted=int(sol.num_accepted_steps),
                      rejected=int(sol.num_rejected_steps), run_s=run_s, error_vs_ref=err),
                 f"rest17 eps {eps:.0e} Tsit5 1e-6: steps {int(sol.num_steps)} err {err:.2e}")  # fmt: skip


# --------------------------------------------------------------------------------------------
# (b)


def _spectral_radius(sc, ts_dense):
    """Spectral radius of d f / d y [1/s] at the states of the reference trajectory at
    ``ts_dense`` (array) and the most negative real part of its eigenvalues."""
    sol = jc.simulate(sc.params, sc.y0, sc.t1, ts=ts_dense, rtol=1e-10, atol=1e-12, max_steps=400_000)
    ys = sol.ys
    jac = jax.jit(jax.vmap(jax.jacfwd(lambda y, t: jc.vector_field(t, y, sc.params)), in_axes=(0, 0)))(ys, ts_dense)
    ev = np.linalg.eigvals(np.asarray(jac))
    return np.max(np.abs(ev), axis=1), float(np.min(ev.real))


def part_b(part, args):
    dts = [1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6]
    if args.quick:
        dts = [1e-2, 1e-3, 1e-4, 1e-5]
    ms = 400_000
    scenes = [
        ("rest17, 2 periods", bm.make_scene("rest17", 2)),
        ("stick-slip eps 1e-4", bm.make_scene("stick_slip", 1, eps=1e-4, eps_R=1e-4)),
        ("stick-slip eps 1e-6", bm.make_scene("stick_slip", 1, eps=1e-6, eps_R=1e-6)),
    ][: 2 if args.quick else 3]
    part.set("setup", dict(dts=dts, wrong_tol=WRONG_TOL, reference="Tsit5 rtol 1e-12 atol 1e-14", max_steps=ms))
    for label, sc in scenes:
        _, ys_ref, _, _ = solve(part, sc, "Tsit5", rtol=1e-12, atol=1e-14, max_steps=ms)
        rhos, re_min = _spectral_radius(sc, np.linspace(0.0, sc.t1, 200))
        rho = float(np.max(rhos))
        limits = dict(RK4=2.785 / rho, Heun=2.0 / rho)
        part.add(dict(kind="scene", scene=label, spectral_radius=rho, min_real_eig=re_min,
                      rho_percentiles_10_50_90=np.percentile(rhos, [10, 50, 90]).tolist(),
                      rho_t0=float(rhos[0]), frac_samples_rho_above_half_max=float(np.mean(rhos > 0.5 * rho)),
                      dt_limit_RK4=limits["RK4"], dt_limit_Heun=limits["Heun"]),
                 f"{label}: rho = {rho:.3g} 1/s, min Re = {re_min:.3g}; RK4 limit {limits['RK4']:.2e}, Heun {limits['Heun']:.2e}")  # fmt: skip
        for name in ("RK4-fixed", "Heun-fixed"):
            for dt in dts:
                if sc.t1 / dt > ms:
                    continue
                if part.over:
                    part.add(dict(kind="cell", scene=label, method=name, dt=dt, verdict="not run", why="part budget"))
                    continue
                sol, ys, run_s, comp = solve(part, sc, name, dt0=dt, max_steps=ms)
                err = bm.state_error(ys, ys_ref)
                finite = bool(np.all(np.isfinite(ys)))
                st = int(sol.status)
                if not finite or st != 0 or not bool(sol.valid) or err > 1.0:
                    v = "blow-up"
                elif err > WRONG_TOL:
                    v = "wrong"
                else:
                    v = "ok"
                kind = int(sol.validity.first_invalid_kind)
                part.add(dict(kind="cell", scene=label, method=name, dt=dt, steps=int(sol.num_steps), status=st,
                              finite=finite, valid=bool(sol.valid), invalid_kind=jc.INVALID_KINDS[kind],
                              first_invalid_t=_f(sol.validity.first_invalid_t), error_vs_ref=_f(err) if finite else None,
                              verdict=v, run_s=run_s, dt_over_limit=dt / limits[name.split("-")[0]]),
                         f"{label} {name} dt {dt:.0e}: {v:8s} err {err:.2e} valid {bool(sol.valid)} dt/limit {dt / limits[name.split('-')[0]]:.2g}")  # fmt: skip


# --------------------------------------------------------------------------------------------
# (c)


def _regime(ys, sol, p):
    r_O = np.asarray(jax.vmap(lambda y: jc.centre_position(y, p))(jnp.asarray(ys)))
    half = ys.shape[0] // 2
    lab = classify(
        ys[None, half:], np.array([int(sol.status)]), np.array([bool(sol.valid)]), r_O[None, half:], tol=1e-3
    )
    return str(regime_names(lab["regime"], lab["period"])[0]), int(lab["period"][0])


def part_c(part, args):
    periods = 10 if args.quick else args.c_periods
    part.set("setup", dict(periods=periods, solver="Tsit5", f32="rtol 1e-5 atol 1e-7", f64="rtol 1e-8 atol 1e-10",
                           control="float64 at rtol 1e-5 atol 1e-7", separation=WRONG_TOL,
                           regime="jaxcelt.sweeps.regimes.classify on the last half of the stroboscopic samples, tol 1e-3, no Lyapunov exponent"))  # fmt: skip
    for w in (14, 17, 19):
        sc = bm.make_scene(f"rest{w}", periods)
        runs = {}
        for tag, rtol, dtype in (
            ("f64", 1e-8, jnp.float64),
            ("f32", 1e-5, jnp.float32),
            ("f64_loose", 1e-5, jnp.float64),
        ):
            sol, ys, run_s, comp = solve(part, sc, "Tsit5", rtol=rtol, dtype=dtype, max_steps=args.max_steps)
            runs[tag] = (sol, ys, run_s)
        sol64, y64, _ = runs["f64"]
        reg64 = _regime(y64, sol64, sc.params)
        for tag in ("f32", "f64_loose"):
            sol, ys, run_s = runs[tag]
            d = np.max(np.abs(ys - y64), axis=1)
            d = np.where(np.isfinite(d), d, np.inf)
            sep = np.nonzero(d > WRONG_TOL)[0]
            reg = _regime(ys, sol, sc.params)
            part.add(dict(omega_pi=w, run=tag, periods=periods, status=int(sol.status), steps=int(sol.num_steps),
                          steps_f64=int(sol64.num_steps), run_s=run_s, t_separate=float(sc.ts[sep[0]]) if len(sep) else None,
                          periods_separate=int(sep[0]) if len(sep) else None, err_per_period=d.tolist(),
                          regime=reg[0], period=reg[1], regime_f64=reg64[0], period_f64=reg64[1],
                          first_invalid_t=_f(sol.validity.first_invalid_t), first_invalid_kind=jc.INVALID_KINDS[int(sol.validity.first_invalid_kind)],
                          first_invalid_t_f64=_f(sol64.validity.first_invalid_t),
                          first_invalid_kind_f64=jc.INVALID_KINDS[int(sol64.validity.first_invalid_kind)],
                          regime_changed=reg != reg64),
                     f"w {w} {tag}: separates (>1e-2) after {sep[0] if len(sep) else None} periods; regime {reg} vs f64 {reg64}; steps {int(sol.num_steps)} vs {int(sol64.num_steps)}")  # fmt: skip


# --------------------------------------------------------------------------------------------
# (d)


def part_d(part, args):
    horizons = [1, 2] if args.quick else [1, 2, 4, 8, 16, 32]
    mu0 = 0.2241
    ms = 100_000
    part.set("setup", dict(horizons_periods=horizons, loss="mean over k = 1..P of |(v, omega)(kT)|^2 [SI]",
                           rtol=1e-8, atol=1e-10, max_steps=ms, adjoint="RecursiveCheckpointAdjoint() (diffrax default)",
                           fd="central difference, h = 1e-6"))  # fmt: skip
    for w in (17, 19):
        p0 = jc.CeltParams.paper(omega_pi=float(w))
        y0 = jc.initial_state(p0)
        T = 2 * np.pi / w
        ly = celt_lyapunov(p0, y0, periods=max(horizons), error_control="all", tangent="jvp")  # as its result file
        lg = np.asarray(ly.log_growth)
        part.add(dict(kind="lyapunov", omega_pi=w, exponent=float(ly.exponent), log_growth=lg.tolist(),
                      success=bool(ly.success)),
                 f"w {w}: lambda = {float(ly.exponent):.3f} 1/s over {max(horizons)} periods")  # fmt: skip
    for P in horizons:
        for w in (17, 19):
            if part.over:
                part.add(dict(kind="grad", omega_pi=w, periods=P, verdict="not run", why="part budget"))
                continue
            p0 = jc.CeltParams.paper(omega_pi=float(w))
            y0 = jc.initial_state(p0)
            T = 2 * np.pi / w
            ts = jnp.asarray(T * np.arange(1, P + 1))

            def loss(mu, p0=p0, y0=y0, ts=ts, P=P, T=T):
                # y0 + 0 mu: a traced y0 makes simulate skip its host-side check_state, which
                # cannot run when only some parameter leaves (here mu) are traced
                sol = jc.simulate(
                    p0.replace(mu=mu), y0 + 0.0 * mu, P * T, ts=ts, rtol=1e-8, atol=1e-10, exact_ts=True, max_steps=ms
                )
                return jnp.mean(jnp.sum(sol.ys[:, :6] ** 2, axis=1))

            t = time.perf_counter()
            comp = jax.jit(jax.value_and_grad(loss)).lower(jnp.asarray(mu0)).compile()
            compile_s = time.perf_counter() - t
            mem = comp.memory_analysis()
            t = time.perf_counter()
            val, g = jax.block_until_ready(comp(jnp.asarray(mu0)))
            run_s = time.perf_counter() - t
            fwd = jax.jit(loss)
            t = time.perf_counter()
            fwd(jnp.asarray(mu0)).block_until_ready()
            fwd_first = time.perf_counter() - t
            t = time.perf_counter()
            h = 1e-6
            fd = (fwd(jnp.asarray(mu0 + h)) - fwd(jnp.asarray(mu0 - h))) / (2 * h)
            fwd_s = (time.perf_counter() - t) / 2
            m = dict(
                temp_MB=getattr(mem, "temp_size_in_bytes", 0) / 2**20,
                argument_MB=getattr(mem, "argument_size_in_bytes", 0) / 2**20,
                output_MB=getattr(mem, "output_size_in_bytes", 0) / 2**20,
            )
            part.add(dict(kind="grad", omega_pi=w, periods=P, horizon_s=P * T, loss=float(val), grad=float(g),
                          grad_fd=float(fd), grad_run_s=run_s, grad_compile_s=compile_s, fwd_run_s=fwd_s,
                          fwd_first_s=fwd_first, **m,
                          maxrss_MB=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
                     f"w {w} P {P:2d}: dL/dmu = {float(g):.3e} (FD {float(fd):.3e}), grad {run_s:.2f}s fwd {fwd_s:.2f}s temp {m['temp_MB']:.1f} MB")  # fmt: skip
    # memory against max_steps at a fixed horizon (1 period): diffrax sizes the checkpoint buffers
    # from max_steps, not from the steps actually taken
    p0 = jc.CeltParams.paper(omega_pi=17.0)
    y0 = jc.initial_state(p0)
    T = 2 * np.pi / 17
    for ms2 in () if args.quick else (1_000, 10_000, 100_000, 1_000_000):
        if part.over:
            break

        def loss2(mu, ms2=ms2):
            sol = jc.simulate(
                p0.replace(mu=mu),
                y0 + 0.0 * mu,
                T,
                ts=jnp.asarray([T]),
                rtol=1e-8,
                atol=1e-10,
                exact_ts=True,
                max_steps=ms2,
            )
            return jnp.sum(sol.ys[:, :6] ** 2)

        t = time.perf_counter()
        comp = jax.jit(jax.grad(loss2)).lower(jnp.asarray(mu0)).compile()
        compile_s = time.perf_counter() - t
        mem = comp.memory_analysis()
        t = time.perf_counter()
        jax.block_until_ready(comp(jnp.asarray(mu0)))
        run_s = time.perf_counter() - t
        part.add(dict(kind="memory_vs_max_steps", max_steps=ms2, temp_MB=getattr(mem, "temp_size_in_bytes", 0) / 2**20,
                      grad_run_s=run_s, compile_s=compile_s),
                 f"max_steps {ms2}: temp {getattr(mem, 'temp_size_in_bytes', 0) / 2**20:.1f} MB, grad {run_s:.2f}s")  # fmt: skip


# --------------------------------------------------------------------------------------------
# (e)


def part_e(part, args):
    p = jc.CeltParams.paper(omega_pi=17.0)
    T = 2 * np.pi / 17
    sc = bm.BenchmarkScene("e", p, np.zeros(13), 0.5 * T, np.linspace(0.0, 0.5 * T, 11), "")
    part.set(
        "setup", dict(solver="Tsit5 rtol 1e-8", horizon_s=0.5 * T, semi_axes_m=[float(p.a1), float(p.a2), float(p.a3)])
    )

    def st_stop(sol):
        return int(sol.status) == 2

    def run(case, x, y0, stop=False, horizon=None):
        s = sc if horizon is None else bm.BenchmarkScene("e", p, np.zeros(13), horizon, np.linspace(0.0, horizon, 11), "")
        sol, ys, run_s, _ = solve(part, s, "Tsit5", rtol=1e-8, y0=y0, max_steps=20_000, stop_on_invalid=stop)
        # after a stop_on_invalid stop diffrax fills the later samples with inf: not a NaN
        finite = (
            bool(np.all(np.isfinite(ys[np.asarray(sol.ts) <= float(sol.validity.first_invalid_t)])))
            if st_stop(sol)
            else bool(np.all(np.isfinite(ys)))
        )
        kind = int(sol.validity.first_invalid_kind)
        st = int(sol.status)
        if st == 2:
            v = "stopped at invalid state"
        elif not finite:
            v = "NaN/inf" + (" (flagged invalid)" if kind else " (NOT flagged)")
        elif st != 0:
            v = f"failed ({jc.STATUS[st]})"
        elif kind:
            v = "flagged invalid"
        else:
            v = "ok"
        part.add(dict(case=case, x=x, stop_on_invalid=stop, status=st, status_text=jc.STATUS[st], steps=int(sol.num_steps),
                      accepted=int(sol.num_accepted_steps), rejected=int(sol.num_rejected_steps), finite=finite,
                      invalid_kind=jc.INVALID_KINDS[kind], first_invalid_t=_f(sol.validity.first_invalid_t),
                      min_N=_f(sol.validity.min_N), max_tilt_deg=_f(np.degrees(float(sol.validity.max_tilt))),
                      max_abs_psi=_f(np.nanmax(np.abs(ys[:, 12]))) if np.any(np.isfinite(ys[:, 12])) else None,
                      verdict=v, run_s=run_s),
                 f"{case} {x}: {v}; status {jc.STATUS[st]}, steps {int(sol.num_steps)}, invalid {jc.INVALID_KINDS[kind]} "
                 f"at {_f(sol.validity.first_invalid_t)}, min N {_f(sol.validity.min_N)}")  # fmt: skip

    # (i) n2 -> 1: body x2 axis towards the vertical (the stone on its side), psi' ~ 1/(1 - n2^2)
    for delta in (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6):
        n = (0.0, float(np.sqrt(1 - delta**2)), delta)
        try:
            y0 = np.asarray(jc.initial_state(p, n=n, omega=(0.0, 0.0, 1.0)))
        except ValueError as e:
            part.add(dict(case="n2 -> 1 (n3 = delta)", x=delta, verdict=f"refused by initial_state: {e}"[:300]),
                     f"n2 -> 1 {delta}: initial_state refuses ({e})")  # fmt: skip
            continue
        run("n2 -> 1 (n3 = delta)", delta, y0)
    # closer than initial_state allows: overwrite n of a near state by hand (v then violates the
    # contact constraint by O(a delta), which is what a user doing this would get)
    for delta in (1e-6, 1e-7, 0.0):
        y0 = np.array(jc.initial_state(p, n=(0.0, float(np.sqrt(1 - 1e-8)), 1e-4), omega=(0.0, 0.0, 1.0)))
        y0[6:9] = (0.0, np.sqrt(1 - delta**2), delta)
        try:
            run("n2 -> 1 hand-built (n3 = delta)", delta, y0)
        except Exception as e:  # noqa: BLE001 - record what the library does
            part.add(dict(case="n2 -> 1 hand-built (n3 = delta)", x=delta, verdict=f"exception: {type(e).__name__}: {e}"[:300]),
                     f"n2 -> 1 hand-built {delta}: {type(e).__name__}: {e}")  # fmt: skip
    # (ii) contact near the tip of the long axis a1: tilt about body x2 so n1 -> sin(theta)
    for deg in (60.0, 80.0, 85.0, 89.0, 89.9):
        th = np.radians(deg)
        y0 = np.asarray(jc.initial_state(p, n=(float(np.sin(th)), 0.0, float(np.cos(th))), omega=(0.0, 0.0, 1.0)))
        run("tilt towards the tip (deg)", deg, y0)
    # (iii) lift-off: tilted 40 deg towards the tip and pitching back at -omega2: the centre of
    # mass swings on a small radius of curvature and N = m (g - centripetal) crosses 0
    for tilt, w2s in ((40.0, (10.0, 11.0, 12.0, 13.0, 14.0, 16.0, 20.0)), (20.0, (12.0, 16.0, 20.0, 25.0))):
        for w2 in w2s:
            th = np.radians(tilt)
            y0 = np.asarray(jc.initial_state(p, n=(float(np.sin(th)), 0.0, float(np.cos(th))), omega=(0.0, -w2, 0.0)))
            case = f"pitching at {tilt:g} deg tilt, -omega2 (rad/s)"
            run(case, w2, y0)
            run(case, w2, y0, stop=True)


def plot_all(out, slow):
    from jaxcelt.plotting.stability import (
        plot_dt_scan,
        plot_float32_separation,
        plot_gradient_horizon,
        plot_verdict_grid,
    )

    cells = results.stability_results(out).get("a", [])
    if cells:
        title = "(a) friction-smoothing stiffness: stick-slip scene (omega_pi 17, q_pi 0.01 m), 1 period"
        plot_verdict_grid(cells, title, slow=slow).savefig(out / "stability_eps.png", dpi=110)
    for tag, fn, png in (("b", plot_dt_scan, "stability_dt.png"), ("c", plot_float32_separation, "stability_float32.png"),
                         ("d", plot_gradient_horizon, "stability_grad.png")):  # fmt: skip
        f = out / f"stability_{tag}.json"
        if f.exists():
            fn(json.loads(f.read_text())["rows"]).savefig(out / png, dpi=110)
            print("wrote", out / png)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--parts", default="a,b,c,d,e")
    ap.add_argument("--slow", type=float, default=5000.0, help="steps per base period above which a run is 'slow'")
    ap.add_argument("--max-steps", type=int, default=300_000)
    ap.add_argument("--cell-budget", type=float, default=180.0, help="skip a cell predicted to take longer [s]")
    ap.add_argument("--part-budget", type=float, default=1500.0, help="stop starting cells after this [s]")
    ap.add_argument("--c-periods", type=int, default=50)
    ap.add_argument("--a-methods", default="", help="(a) only these, e.g. Kvaerno5-Newton:1e-6,Tsit5:1e-6")
    ap.add_argument("--a-no-rest", dest="a_rest", action="store_false", help="(a) skip the from-rest scene")
    ap.add_argument("--a-eps", default="", help="(a) only these eps, e.g. 1e-10")
    ap.add_argument("--a-no-second-ref", dest="a_second_ref", action="store_false", help="(a) Dopri8 reference only")
    ap.add_argument("--tag", default="", help="suffix of the part name in the JSON file name")
    ap.add_argument("--quick", action="store_true", help="small version (minutes): files stability_<part>_quick.json")
    ap.add_argument("--plot-only", action="store_true", help="only redraw the PNGs from the JSON files")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.plot_only:
        plot_all(out, args.slow)
        return
    info = versions()
    info["device"] = bm.device_string()
    with open("/proc/loadavg") as f:
        info["loadavg_at_start"] = f.read().split()[:3]
    print("versions:", info, flush=True)
    fns = dict(a=part_a, b=part_b, c=part_c, d=part_d, e=part_e)
    for name in args.parts.split(","):
        part = Part(name + args.tag + ("_quick" if args.quick else ""), out, args.part_budget, dict(versions=info))
        fns[name](part, args)
        with open("/proc/loadavg") as f:
            part.set("loadavg_at_end", f.read().split()[:3])
        print(f"wrote {part.path} after {time.perf_counter() - part.t0:.0f} s", flush=True)


if __name__ == "__main__":
    main()
