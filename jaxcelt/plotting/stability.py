"""Charts of the stability map (``benchmarks/stability.py``): verdict grid over
(method, eps), fixed-step error against dt, float32/float64 separation, gradient norm against
horizon. Each function takes the rows of a ``docs/performance/stability_<part>.json`` file and
returns a matplotlib figure (never shows or saves)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg", force=False)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

__all__ = ["VERDICT_COLOR", "plot_verdict_grid", "plot_dt_scan", "plot_float32_separation", "plot_gradient_horizon"]

VERDICT_COLOR = {
    "ok": "#4caf50",
    "slow": "#ffc107",
    "unverified": "#90caf9",
    "wrong attractor": "#8e24aa",
    "failed": "#e53935",
    "not run": "#bdbdbd",
}


def plot_verdict_grid(rows: list[dict], title: str = "Stability map", slow: float | None = None):
    """Grid of verdicts: rows = method (+ rtol), columns = eps (= eps_R); cell text = steps
    (accepted + rejected) and, for finished runs, the error against the reference."""
    methods = list(dict.fromkeys(r["method"] for r in rows))
    xs = sorted({r["eps"] for r in rows}, reverse=True)
    fig, ax = plt.subplots(figsize=(1.5 * len(xs) + 3.8, 0.62 * len(methods) + 2.2))
    for i, m in enumerate(methods):
        for j, x in enumerate(xs):
            rr = [r for r in rows if r["method"] == m and r["eps"] == x]
            state = rr[0]["verdict"] if rr else "not run"
            ax.add_patch(plt.Rectangle((j, i), 1, 1, color=VERDICT_COLOR.get(state, "#bdbdbd"), ec="w", lw=2))
            if rr and rr[0].get("steps") is not None:
                txt = f"{rr[0]['steps']:,} steps"
                if rr[0].get("error_vs_ref") is not None:
                    txt += f"\nerr {rr[0]['error_vs_ref']:.0e}"
                elif rr[0].get("status") == 1:
                    txt += "\n(max_steps hit)"
                if rr[0].get("run_s") is not None:
                    txt += f"\n{rr[0]['run_s']:.3g} s"
                ax.text(j + 0.5, i + 0.5, txt, ha="center", va="center", fontsize=7)
    ax.set_xlim(0, len(xs))
    ax.set_ylim(0, len(methods))
    ax.set_xticks(np.arange(len(xs)) + 0.5, [f"{x:.0e}" for x in xs], fontsize=8)
    ax.set_yticks(np.arange(len(methods)) + 0.5, methods, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("friction smoothing eps = eps_R [s^-2]")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in VERDICT_COLOR.values()]
    ax.legend(handles, list(VERDICT_COLOR), ncol=6, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.18))
    sub = "cell: steps per period (accepted + rejected), max error vs eps-specific reference, run time (loaded CPU)"
    if slow is not None:
        sub += f"; slow = > {slow:,.0f} steps"
    ax.set_title(f"{title}\n({sub})", fontsize=9)
    fig.tight_layout()
    return fig


def plot_dt_scan(rows: list[dict], wrong_tol: float = 1e-2):
    """Error against the fixed step dt (log-log), one panel per scene; blow-ups drawn at the top
    (x markers), the explicit stability limits 2.785/rho (RK4) and 2/rho (Heun) as vertical lines."""
    scenes = [r for r in rows if r.get("kind") == "scene"]
    cells = [r for r in rows if r.get("kind") == "cell" and r.get("verdict") != "not run"]
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.6 * len(scenes), 3.9), squeeze=False)
    colors = {"RK4-fixed": "#1f77b4", "Heun-fixed": "#d62728"}
    for ax, sc in zip(axes.flat, scenes):
        top = 10.0
        for name, c in colors.items():
            rr = sorted([r for r in cells if r["scene"] == sc["scene"] and r["method"] == name], key=lambda r: r["dt"])
            dt = np.array([r["dt"] for r in rr])
            err = np.array([r["error_vs_ref"] if r["error_vs_ref"] is not None else np.nan for r in rr], float)
            blow = np.array([r["verdict"] == "blow-up" for r in rr])
            ok = ~blow & np.isfinite(err)
            ax.loglog(dt[ok], err[ok], "o-", color=c, ms=4, label=name.replace("-fixed", ""))
            if blow.any():
                ax.loglog(
                    dt[blow],
                    np.full(blow.sum(), top),
                    "x",
                    color=c,
                    ms=8,
                    mew=2,
                    label=f"{name.replace('-fixed', '')} blow-up",
                )
            lim = sc["dt_limit_RK4"] if name.startswith("RK4") else sc["dt_limit_Heun"]
            ax.axvline(lim, color=c, ls="--", lw=1, label=f"{name.replace('-fixed', '')} limit {lim:.1e} s")
        ax.axhline(wrong_tol, color="k", ls=":", lw=1, label=f"wrong (> {wrong_tol:g})")
        ax.set_title(f"{sc['scene']}\nrho(df/dy) = {sc['spectral_radius']:.2g} 1/s", fontsize=9)
        ax.set_xlabel("fixed step dt [s]")
        ax.set_ylabel("max |y - y_ref| over samples [SI]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6.5, loc="lower right")
    fig.suptitle(
        "(b) fixed-step error against dt (x at top: NaN/inf, status != 0 or validity monitor fired)", fontsize=10
    )
    fig.tight_layout()
    return fig


def plot_float32_separation(rows: list[dict], sep_tol: float = 1e-2):
    """max |y - y_f64| at each stroboscopic sample against periods, one panel per omega_pi:
    float32 (rtol 1e-5) and the float64 control at the same tolerance."""
    ws = sorted({r["omega_pi"] for r in rows})
    fig, axes = plt.subplots(1, len(ws), figsize=(4.4 * len(ws), 3.6), squeeze=False, sharey=True)
    style = {"f32": ("float32, rtol 1e-5", "#d62728"), "f64_loose": ("float64, rtol 1e-5", "#1f77b4")}
    for ax, w in zip(axes.flat, ws):
        for r in [r for r in rows if r["omega_pi"] == w]:
            lab, c = style[r["run"]]
            d = np.maximum(np.asarray(r["err_per_period"], float), 1e-16)
            ax.semilogy(
                np.arange(len(d)), d, "-", color=c, label=f"{lab}: {r['regime']} (f64 rtol 1e-8: {r['regime_f64']})"
            )
        ax.axhline(sep_tol, color="k", ls=":", lw=1, label=f"separated ({sep_tol:g})")
        ax.set_title(f"from rest, omega_pi = {w} rad/s", fontsize=9)
        ax.set_xlabel("time [base periods]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6.5, loc="lower right")
    axes[0, 0].set_ylabel("max |y - y_(f64, rtol 1e-8)| [SI]")
    fig.suptitle("(c) float32 against float64 (Tsit5), stroboscopic samples", fontsize=10)
    fig.tight_layout()
    return fig


def plot_gradient_horizon(rows: list[dict]):
    """Left: |d loss/d mu| against the horizon with the finite-time Lyapunov growth
    exp(sum of per-period log growth), scaled to the gradient at one period. Right: reverse-mode
    run time and compiled temporary memory against the horizon."""
    ly = {r["omega_pi"]: r for r in rows if r.get("kind") == "lyapunov"}
    g = [r for r in rows if r.get("kind") == "grad" and r.get("grad") is not None]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.0))
    colors = {17: "#1f77b4", 19: "#d62728", 14: "#2ca02c"}
    for w in sorted({r["omega_pi"] for r in g}):
        rr = sorted([r for r in g if r["omega_pi"] == w], key=lambda r: r["periods"])
        P = np.array([r["periods"] for r in rr])
        G = np.abs([r["grad"] for r in rr])
        FD = np.abs([r["grad_fd"] for r in rr])
        c = colors.get(w, None)
        a1.semilogy(P, G, "o-", color=c, label=f"omega_pi = {w}: |dL/dmu| reverse mode")
        a1.semilogy(P, FD, "+", color=c, ms=9, label=f"omega_pi = {w}: central difference")
        if w in ly:
            cum = np.cumsum(ly[w]["log_growth"])
            growth = np.exp(cum[P - 1] - cum[0]) * G[0]
            a1.semilogy(P, growth, "--", color=c, lw=1,
                        label=f"omega_pi = {w}: tangent growth (lambda = {ly[w]['exponent']:.2f} 1/s), scaled")  # fmt: skip
        a2.semilogy(P, [r["grad_run_s"] for r in rr], "o-", color=c, label=f"omega_pi = {w}: grad run time [s]")
        a2.semilogy(P, [r["fwd_run_s"] for r in rr], "s:", color=c, ms=4, label=f"omega_pi = {w}: forward run time [s]")
        a2.semilogy(
            P,
            [max(r["temp_MB"], 1e-3) for r in rr],
            "^--",
            color=c,
            ms=5,
            label=f"omega_pi = {w}: compiled temp memory [MB]",
        )
    a1.set_xlabel("horizon [base periods]")
    a1.set_ylabel("|d loss / d mu| [SI]")
    a1.set_title("(d) gradient norm against horizon", fontsize=10)
    a1.grid(alpha=0.3, which="both")
    a1.legend(fontsize=6.5)
    a2.set_xlabel("horizon [base periods]")
    a2.set_ylabel("seconds / MB")
    a2.set_title("reverse mode (RecursiveCheckpointAdjoint): cost", fontsize=10)
    a2.grid(alpha=0.3, which="both")
    a2.legend(fontsize=6.5)
    fig.tight_layout()
    return fig
