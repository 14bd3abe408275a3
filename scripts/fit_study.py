"""Identification study: writes docs/fit/*.json and *.png.

Sections (``--only`` picks some): ``recover`` (noise-free recovery, full state and IMU),
``compare`` (Adam vs L-BFGS vs Gauss-Newton vs LM on one problem), ``coverage`` (1% noise, 20
seeds), ``chaos`` (omega_pi = 19, 40 periods from rest: ``chaos-record`` validity and Lyapunov
exponent of the record, then ``chaos-multiple``, ``chaos-single``, ``chaos-single-damped``; each
can be run alone), ``gradnorm`` (gradient norm vs window length against e^{lambda T}; needs
``chaos-record`` first).

Usage: python scripts/fit_study.py [--only recover compare ...] [--seeds 20] [--out docs/fit]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import jaxcelt as jc
import jaxcelt.identify as F
import jaxcelt.identify.records as D
from jaxcelt.plotting import fit as FP
from jaxcelt.provenance import write_result

FREE = ("mu", "k_r", "b_Ts", "m_Ts")
PAPER = jc.CeltParams.paper()
# each 30-60% off the paper's value
TRUE = PAPER.replace(mu=0.2241 * 1.4, k_r=0.4345 * 0.6, b_Ts=0.5305 * 1.5, m_Ts=0.8161 * 1.35)
TILT = np.radians(10.0)


def spinning_start(p, spin=5.0):
    """Tilted (10 deg about body x2) and spinning (omega3) release on the vibrating base."""
    return jc.initial_state(p, omega=(0.0, 0.0, spin), n=(np.sin(TILT), 0.0, np.cos(TILT)))


def true_dict():
    return {n: float(getattr(TRUE, n)) for n in FREE}


def row(res, label):
    rel = res.relative_error(TRUE)
    return dict(
        label=label,
        optimiser=res.optimiser,
        windows=res.windows,
        n_iter=res.n_iter,
        converged=res.converged,
        loss=res.loss,
        max_rel_err=max(rel.values()),
        rel_err=rel,
        values=res.values,
        stderr=res.stderr,
        compile_s=res.compile_time,
        run_s=res.wall_time,
        total_s=res.total_time,
        loss_history=[float(v) for v in res.loss_history],
        param_history=res.param_history,
    )


def recover(out):
    data = D.generate_data(TRUE, spinning_start(TRUE), 1.0, rate=100, kinds=("state", "omega", "orientation", "centre"))
    D.save_data(data, out / "recover_data.npz")
    rows, results = [], {}
    for kinds in (("state",), ("omega",), ("orientation",), ("centre",)):
        res = F.fit(data.subset(kinds), PAPER, free=FREE, optimiser="lm", max_iter=60)
        print(kinds, res.summary(), flush=True)
        rows.append(row(res, "+".join(kinds)) | {"corr": np.asarray(res.corr).tolist()})
        results[kinds[0]] = res
    write_result(
        out / "recover.json",
        dict(
            true=true_dict(),
            start={n: float(getattr(PAPER, n)) for n in FREE},
            record="1 s, 100 Hz, omega_pi=17, 10 deg tilt, spin 5 rad/s",
            rows=rows,
        ),
    )
    FP.plot_fit(results["omega"], title="IMU-only fit (noise-free)", true=TRUE).savefig(
        out / "recover_imu.png", dpi=110
    )
    FP.plot_correlation([results[k] for k in results], list(results)).savefig(out / "recover_corr.png", dpi=110)


def compare(out):
    data = D.generate_data(TRUE, spinning_start(TRUE), 1.0, rate=100, kinds=("omega",), noise=0.01, seed=123)
    rows, results = [], []
    # same cap for all: 50k integrator steps per solve (a sane 1 s solve needs far fewer), and a
    # wall-clock budget per optimiser on this loaded machine
    common = dict(max_steps=50_000, max_time=420.0)
    for opt, kw in (
        ("lm", dict(max_iter=60)),
        ("gn", dict(max_iter=30)),
        ("gn-damped", dict(max_iter=30)),
        ("lbfgs", dict(max_iter=100)),
        ("adam", dict(max_iter=300, learning_rate=0.02)),
    ):
        kw = common | kw
        res = F.fit(data, PAPER, free=FREE, optimiser=opt, **kw)
        print(opt, res.summary(), flush=True)
        rows.append(row(res, opt) | {"max_iter": kw["max_iter"], "max_time_s": kw["max_time"]})
        results.append(res)
        write_result(out / "compare_partial.json", {"rows": rows})  # the optimisers done so far
    write_result(
        out / "compare.json",
        dict(problem="IMU (omega) 1 s at 100 Hz, 1% noise, seed 123, start: paper values", rows=rows),
    )
    FP.plot_loss_histories(results, [r.optimiser for r in results]).savefig(out / "compare_loss.png", dpi=110)
    FP.plot_parameter_traces(results, [r.optimiser for r in results], true=TRUE).savefig(
        out / "compare_traces.png", dpi=110
    )
    lines = [
        "| optimiser | iterations | converged | final loss | max rel. error | compile [s] | run [s] |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['optimiser']} | {r['n_iter']} | {r['converged']} | {r['loss']:.4g} | {r['max_rel_err']:.2e} | {r['compile_s']:.1f} | {r['run_s']:.1f} |"
        )
    (out / "compare_table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def coverage(out, seeds):
    y0 = spinning_start(TRUE)
    rows = []
    for kinds in (("omega",),):
        for seed in range(seeds):
            data = D.generate_data(TRUE, y0, 1.0, rate=100, kinds=kinds, noise=0.01, seed=seed)
            res = F.fit(data, PAPER, free=FREE, optimiser="lm", max_iter=60)
            cov = res.covers(TRUE)
            rows.append(
                dict(
                    seed=seed,
                    kinds=list(kinds),
                    covers=cov,
                    values=res.values,
                    stderr=res.stderr,
                    s2=res.s2,
                    converged=res.converged,
                    n_iter=res.n_iter,
                    run_s=res.wall_time,
                )
            )
            print(seed, cov, f"s2={res.s2:.3f}", f"{res.wall_time:.1f}s", flush=True)
    frac = {n: float(np.mean([r["covers"][n] for r in rows])) for n in FREE}
    all_in = float(np.mean([all(r["covers"].values()) for r in rows]))
    summary = dict(seeds=seeds, per_parameter_coverage=frac, joint_all_four_inside=all_in, true=true_dict(), rows=rows)
    write_result(out / "coverage.json", summary)
    print("coverage", frac, "all four inside:", all_in)
    FP.plot_coverage(rows, TRUE, FREE).savefig(out / "coverage.png", dpi=110)


# Chaotic regime (must show 3): the paper's parameters at omega_pi = 19, released at rest,
# 40 forcing periods (13.2 s), full state at 20 samples per period (60.5 Hz), noise-free. At
# omega_pi = 19 every release tried tips past 90 deg eventually (n3 < 0, outside the model; from
# rest after 48.7 periods); the record ends before that and stays valid (max tilt 47 deg), and
# along it the largest Lyapunov exponent (jaxcelt.integrate.lyapunov, Benettin) is positive. Roles: the data
# come from the paper's values, every fit starts from the study's TRUE values (mu +40%,
# k_r -40%, b_Ts +50%, m_Ts +35% off the truth).
CHAOS_OMEGA = 19.0
CHAOS_PERIODS = 40
CHAOS_SPP = 20  # samples per forcing period
CHAOS_TP = 2 * np.pi / CHAOS_OMEGA  # forcing period [s]
CHAOS_TRUTH = PAPER.replace(omega_pi=CHAOS_OMEGA)
CHAOS_START = TRUE.replace(omega_pi=CHAOS_OMEGA)
CHAOS_FIT = dict(sim_rtol=1e-8, sim_atol=1e-10, max_steps=100_000)


def chaos_data():
    p = CHAOS_TRUTH
    return D.generate_data(
        p,
        jc.initial_state(p),
        CHAOS_PERIODS * CHAOS_TP,
        rate=CHAOS_SPP / CHAOS_TP,
        kinds=("state",),
        omega_pis=[CHAOS_OMEGA],
    )


def _lyap(p, y0, periods, rtol=1e-9):
    from jaxcelt.integrate.lyapunov import celt_lyapunov

    r = celt_lyapunov(p, y0, periods=periods, rtol=rtol, atol=rtol * 1e-2, error_control="all", tangent="jvp")  # as its result file
    return np.asarray(r.log_growth), bool(r.success)


def chaos_record(out):
    """Validity of the record along the truth and its largest Lyapunov exponent."""
    p, tp = CHAOS_TRUTH, CHAOS_TP
    y0 = jc.initial_state(p)
    res = dict(record=_chaos_record_text())
    t = time.perf_counter()
    ts = np.linspace(0.0, CHAOS_PERIODS * tp, CHAOS_PERIODS * 40 + 1)
    sol = jc.simulate(p, y0, CHAOS_PERIODS * tp, ts=ts, rtol=1e-10, atol=1e-12)
    res["record_valid"] = bool(sol.valid)
    res["record_status"] = int(sol.status)
    res["record_max_tilt_deg"] = float(np.degrees(sol.validity.max_tilt))
    res["record_min_N"] = float(sol.validity.min_N)
    tilt = np.degrees(np.arccos(np.clip(np.asarray(sol.ys)[:, 8], -1, 1)))
    # how long the same motion stays valid (it tips over later)
    long = jc.simulate(p, y0, 100 * tp, rtol=1e-10, atol=1e-12)
    res["continuation_first_invalid_periods"] = float(long.validity.first_invalid_t) / tp
    res["continuation_first_invalid_kind"] = int(long.validity.first_invalid_kind)
    # Benettin exponent, renormalised once per period, along the record; two tolerances
    lams = {}
    for rtol in (1e-9, 1e-11):
        lg, ok = _lyap(p, y0, CHAOS_PERIODS, rtol)
        lams[rtol] = lg
        res[f"log_growth_rtol{rtol:g}"] = lg.tolist()
        res[f"success_rtol{rtol:g}"] = ok
    lg = lams[1e-9]
    n = CHAOS_PERIODS
    res["lambda_record"] = float(lg.sum() / (n * tp))
    res["lambda_record_skip1"] = float(lg[1:].sum() / ((n - 1) * tp))  # first period: alignment
    res["lambda_first_half"] = float(lg[: n // 2].sum() / (n // 2 * tp))
    res["lambda_second_half"] = float(lg[n // 2 :].sum() / (n // 2 * tp))
    res["lambda_record_rtol1e-11"] = float(lams[1e-11].sum() / (n * tp))
    res["periods_with_negative_growth"] = int(np.sum(lg < 0))
    res["lambda_T_record"] = res["lambda_record"] * n * tp
    # convergence reference: a release that stays valid longer (spin -3 rad/s, 80 periods)
    y_ref = jc.initial_state(p, omega=(0.0, 0.0, -3.0))
    ref = jc.simulate(p, y_ref, 80 * tp, rtol=1e-10, atol=1e-12)
    lg_ref, _ = _lyap(p, y_ref, 80)
    res["reference"] = dict(
        release="at rest on the base, spinning omega3 = -3 rad/s",
        valid_80_periods=bool(ref.valid),
        max_tilt_deg=float(np.degrees(ref.validity.max_tilt)),
        log_growth=lg_ref.tolist(),
        running_mean={int(k): float(lg_ref[:k].sum() / (k * tp)) for k in (10, 20, 40, 60, 80)},
    )
    # the start parameters from rest: where the trajectory leaves the model
    s0 = jc.simulate(CHAOS_START, y0, n * tp, rtol=1e-10, atol=1e-12)
    res["start_first_invalid_periods"] = float(s0.validity.first_invalid_t) / tp
    res["start_max_tilt_deg"] = float(np.degrees(s0.validity.max_tilt))
    # the same growth without linearisation: two releases 1e-7 apart (omega3), separation per
    # period (r_C left out, as in the Lyapunov norm), tight tolerances
    tk = np.arange(n + 1) * tp
    mask = np.r_[np.ones(9), np.zeros(3), 1.0]
    ya = np.asarray(jc.simulate(p, y0, n * tp, ts=tk, rtol=1e-12, atol=1e-14).ys)
    yb = np.asarray(
        jc.simulate(p, jc.initial_state(p, omega=(0.0, 0.0, 1e-7)), n * tp, ts=tk, rtol=1e-12, atol=1e-14).ys
    )
    sep = np.linalg.norm((yb - ya) * mask, axis=1)
    res["fd_log_separation_per_period"] = np.log(sep[1:] / sep[0]).tolist()
    res["tilt_deg"] = tilt.tolist()
    res["tilt_ts"] = ts.tolist()
    res["time_s"] = time.perf_counter() - t
    print({k: v for k, v in res.items() if not isinstance(v, (list, dict))}, flush=True)
    print(
        "fd log separation at 20, 40 periods:",
        res["fd_log_separation_per_period"][19],
        res["fd_log_separation_per_period"][-1],
    )
    write_result(out / "chaos_record.json", res)
    plot_chaos_record(out)


def plot_chaos_record(out):
    """chaos_record.png from chaos_record.json."""
    import matplotlib.pyplot as plt

    res = json.loads((out / "chaos_record.json").read_text())
    tp, n = CHAOS_TP, CHAOS_PERIODS
    lg = np.asarray(res["log_growth_rtol1e-09"])
    fig, ax = plt.subplots(1, 2, figsize=(11.5, 4.2), constrained_layout=True)
    a = ax[0]
    a.plot(res["tilt_ts"], res["tilt_deg"], lw=0.8, label="tilt arccos(n3) along the record (truth)")
    a.axhline(90, color="r", ls=":", label="90°: contact leaves the lower half (model invalid)")
    a.set(xlabel="t [s]", ylabel="tilt [deg]", title=f"record: ω_π = 19 rad/s, from rest, {n} periods", ylim=(0, 100))
    a.legend(fontsize=8, loc="upper left")
    a = ax[1]
    tk = tp * np.arange(1, n + 1)
    a.plot(
        tk, np.cumsum(lg), ".-", ms=3, label=f"record, Benettin: λ = {res['lambda_record']:.2f} 1/s over {n} periods"
    )
    a.plot(tk, np.cumsum(res["log_growth_rtol1e-11"]), ":", color="k", lw=1, label="same, rtol 1e-11")
    fd = res.get("fd_log_separation_per_period")
    if fd is not None:
        a.plot(tk, fd, "-", color="tab:green", lw=1, label="record, two releases 1e-7 apart (ω3): log separation")
    ref = res["reference"]
    lr = np.asarray(ref["log_growth"])
    a.plot(
        tp * np.arange(1, lr.size + 1),
        np.cumsum(lr),
        "-",
        lw=1,
        color="tab:orange",
        label=f"release spinning ω3 = −3 rad/s: λ = {ref['running_mean']['80']:.2f} 1/s over 80 periods",
    )
    a.axvline(n * tp, color="0.5", ls="--", lw=0.8, label="end of the record")
    a.set(xlabel="t [s]", ylabel="log growth of a perturbation (cumulative)", title="largest Lyapunov exponent")
    a.legend(fontsize=7.5, loc="lower right")
    fig.savefig(out / "chaos_record.png", dpi=110)


def _chaos_record_text():
    return (
        f"paper parameters, omega_pi={CHAOS_OMEGA:g}, from rest, {CHAOS_PERIODS} periods "
        f"({CHAOS_PERIODS * CHAOS_TP:.2f} s), full state at {CHAOS_SPP} samples/period "
        f"({CHAOS_SPP / CHAOS_TP:.1f} Hz), noise-free"
    )


def _chaos_fit(out, label, tag, optimiser="lm", **kw):
    data = chaos_data()
    D.save_data(data, out / "chaos_data.npz")
    truth = CHAOS_TRUTH
    t = time.perf_counter()
    res = F.fit(data, CHAOS_START, free=FREE, optimiser=optimiser, **(CHAOS_FIT | kw))
    print(label, f"{time.perf_counter() - t:.1f}s", res.summary(), flush=True)
    r = row(res, label)
    r["rel_err"] = res.relative_error(truth)
    r["max_rel_err"] = max(r["rel_err"].values())
    r["covers"] = res.covers(truth)
    r["loss_history"] = res.loss_history
    r["settings"] = {k: v for k, v in (CHAOS_FIT | kw).items()}
    write_result(
        out / f"chaos_{tag}.json",
        dict(
            record=_chaos_record_text(),
            start="TRUE values of the study (mu 0.3137, k_r 0.2607, b_Ts 0.7958, m_Ts 1.1017)",
            truth={n: float(getattr(truth, n)) for n in FREE},
            row=r,
        ),
    )
    plot_chaos_fit(out, tag)
    return res


def plot_chaos_fit(out, tag):
    """chaos_{tag}.png from chaos_{tag}.json and chaos_data.npz: measured vs fitted omega (the
    fitted trajectory re-simulated at the final values, per window from the window's data
    state for multiple shooting) and the relative parameter error per iteration."""
    import jax
    import matplotlib.pyplot as plt

    d = json.loads((out / f"chaos_{tag}.json").read_text())
    r, truth = d["row"], d["truth"]
    data = D.load_data(out / "chaos_data.npz")
    tr = data.trajectories[0]
    ts, ys = np.asarray(tr.ts), np.asarray(tr.obs["state"])
    p = CHAOS_TRUTH.replace(**r["values"])
    K = r["windows"]
    n = (ts.size - 1) // K
    idx = np.arange(K)[:, None] * n + np.arange(n + 1)[None, :]
    starts = np.asarray(tr.y0)[None] if K == 1 else ys[idx[:, 0]]
    proj = jax.vmap(lambda y: jc.project_state(y, p))(starts)

    def one(y0, tw):
        return jc.simulate(p, y0, tw[-1], t0=tw[0], ts=tw, rtol=1e-8, atol=1e-10, max_steps=200_000).ys

    fit_ys = np.asarray(jax.jit(jax.vmap(one))(proj, ts[idx]))
    fig, ax = plt.subplots(1, 4, figsize=(15, 3.6), constrained_layout=True)
    for j, c in enumerate((3, 4, 5)):
        a = ax[j]
        a.plot(ts, ys[:, c], ".", ms=2.5, color="0.45", label="measured")
        for k in range(K):
            a.plot(
                ts[idx[k]],
                fit_ys[k, :, c],
                lw=1.0,
                color=("tab:red", "tab:blue")[k % 2],
                label="fitted" if k == 0 else None,
            )
        a.set(xlabel="t [s]", ylabel=f"ω{j + 1} [rad/s]", title=f"ω{j + 1} (body frame)")
        if j == 0:
            a.legend(fontsize=8, loc="upper left")
    a = ax[3]
    for nme in FREE:
        err = [abs(h[nme] - truth[nme]) / truth[nme] for h in r["param_history"]]
        a.semilogy(err, marker=".", label=nme)
    a.axhline(0.01, color="k", ls=":", lw=0.8, label="1%")
    a.set(xlabel="iteration", ylabel="|fit − true| / true", title="parameter error")
    a.legend(fontsize=8)
    fig.suptitle(f"{r['label']}: max relative error {r['max_rel_err']:.2g} after {r['n_iter']} iterations")
    fig.savefig(out / f"chaos_{tag}.png", dpi=110)


def chaos_single(out):
    _chaos_fit(out, "single shooting, LM", "single", windows=1, max_iter=30, max_time=600.0)


def chaos_single_damped(out):
    _chaos_fit(
        out, "single shooting, damped GN", "single_gnd", optimiser="gn-damped", windows=1, max_iter=30, max_time=600.0
    )


def chaos_multiple(out):
    # window states from the (full-state) data; the continuity residual at the window ends is
    # then one more data term: weight 1 (not the 1e4 that ties optimised states), damped GN
    _chaos_fit(
        out,
        f"multiple shooting, {CHAOS_PERIODS} windows (states from data), damped GN",
        "multiple_gnd",
        optimiser="gn-damped",
        continuity_weight=1.0,
        windows=CHAOS_PERIODS,
        window_states="data",
        max_iter=30,
        max_time=900.0,
    )


def chaos(out):
    chaos_record(out)
    chaos_multiple(out)
    chaos_single(out)
    chaos_single_damped(out)


def gradnorm(out):
    """|dL/dtheta| of single shooting on [0, T] vs T, at the fit's start and near the truth."""
    data = chaos_data()
    rec = json.loads((out / "chaos_record.json").read_text())
    lam = rec["lambda_record"]
    near = CHAOS_TRUTH.replace(
        **{n: float(getattr(CHAOS_TRUTH, n)) * f for n, f in zip(FREE, (1.01, 0.99, 1.01, 0.99))}
    )
    res = dict(record=_chaos_record_text(), lambda_record=lam, points={})
    for tag, p in (("start", CHAOS_START), ("near", near)):
        t = time.perf_counter()
        T, g = F.gradient_norm_vs_window(data, p, free=FREE, **CHAOS_FIT)
        res["points"][tag] = dict(
            params={n: float(getattr(p, n)) for n in FREE},
            T=T.tolist(),
            grad_norm=g.tolist(),
            time_s=time.perf_counter() - t,
        )
        print(tag, f"{time.perf_counter() - t:.1f}s", "g at 1 period, end:", g[CHAOS_SPP - 1], g[-1], flush=True)
    write_result(out / "gradnorm.json", res)
    plot_gradnorm(out)


def plot_gradnorm(out):
    """gradnorm.png from gradnorm.json."""
    import matplotlib.pyplot as plt

    res = json.loads((out / "gradnorm.json").read_text())
    lam = res["lambda_record"]
    fig, a = plt.subplots(figsize=(7.6, 4.8), constrained_layout=True)
    i = CHAOS_SPP - 1  # one period: the multiple-shooting window
    for tag, lab, c in (
        ("start", "at the fit's start (35–50% off)", "tab:red"),
        ("near", "1% off the truth", "tab:blue"),
    ):
        d = res["points"][tag]
        T, g = np.asarray(d["T"]), np.asarray(d["grad_norm"])
        a.semilogy(T, g, lw=1.3, color=c, label=f"|∂L/∂z|, single shooting on [0, T], {lab}")
        a.semilogy(T[i:], g[i] * np.exp(lam * (T[i:] - T[i])), "--", color=c, lw=0.9)
        a.semilogy(T[i:], g[i] * np.exp(2 * lam * (T[i:] - T[i])), ":", color=c, lw=0.9)
    a.plot([], [], "k--", lw=0.9, label=rf"$\propto e^{{\lambda T}}$ from one period, λ = {lam:.2f} 1/s (record)")
    a.plot([], [], "k:", lw=0.9, label=r"$\propto e^{2\lambda T}$ from one period")
    a.axvline(
        CHAOS_TP, color="tab:green", ls="-.", lw=1, label=f"multiple-shooting window (1 period, {CHAOS_TP:.2f} s)"
    )
    a.set(
        xlabel="record length T [s]",
        ylabel="|∂L/∂z| (z: the fit's unconstrained parameters)",
        title="gradient norm vs window length, ω_π = 19 rad/s record",
    )
    a.legend(fontsize=7.5, loc="lower right")
    fig.savefig(out / "gradnorm.png", dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=["recover", "compare", "coverage", "chaos", "gradnorm"])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--out", default="docs/fit")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    from jaxcelt.versions import versions_string

    print(versions_string())
    for s in a.only:
        t = time.perf_counter()
        if s == "coverage":
            coverage(out, a.seeds)
        else:
            globals()[s.replace("-", "_")](out)
        print(f"== {s}: {time.perf_counter() - t:.1f} s", flush=True)


if __name__ == "__main__":
    main()
