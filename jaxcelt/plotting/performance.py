"""Charts of the speed/accuracy study (issue 7): reference agreement, work-precision diagrams,
stability map, peer comparison. Each function takes the JSON-able dicts written by
``benchmarks/*.py`` and returns matplotlib figures (never shows or saves)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg", force=False)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

__all__ = ["plot_reference_agreement", "plot_work_precision", "plot_stability_map", "plot_peers"]

_MARK = {"explicit": "o", "implicit": "s", "fixed": "^"}


def plot_reference_agreement(results: list[dict]):
    """|y_A - y_B|(t) of the two reference solvers, one panel per scene, horizons overlaid."""
    scenes = sorted({r["scene"] for r in results}, key=lambda s: [r["scene"] for r in results].index(s))
    ncol = min(3, len(scenes))
    nrow = int(np.ceil(len(scenes) / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.4 * nrow), squeeze=False)
    for ax, sc in zip(axes.flat, scenes):
        for r in [r for r in results if r["scene"] == sc]:
            t = np.asarray(r["ts"])
            a = np.maximum(np.asarray(r["agreement"], float), 1e-17)
            ax.semilogy(t[1:], a[1:], "o-", ms=3, label=f"{r['periods']} samples, max {r['max_agreement']:.1e}")
        ax.axhline(results[0]["trust"], color="k", ls=":", lw=1, label=f"trust {results[0]['trust']:.0e}")
        ax.set_title(sc, fontsize=10)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("max |y_Dopri8 - y_DOP853|")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(scenes) :]:
        ax.axis("off")
    fig.suptitle(
        f"Reference agreement: diffrax Dopri8 vs scipy DOP853 (numba RHS), tol {results[0]['tol']:.0e}", fontsize=11
    )
    fig.tight_layout()
    return fig


def _wp_axes(fig_title, runs, groups_key="solver"):
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.6))
    names = list(dict.fromkeys(r[groups_key] for r in runs if "run_s" in r))
    cmap = plt.get_cmap("tab10")
    for i, nm in enumerate(names):
        rr = [r for r in runs if r.get(groups_key) == nm and "run_s" in r]
        err = np.array([r["error"] if np.isfinite(r["error"]) else np.nan for r in rr], float)
        err = np.maximum(err, 1e-16)
        mk = _MARK.get(rr[0].get("kind"), "o")
        lab = nm if groups_key == "solver" else f"{nm}"
        a1.loglog([r["run_s"] for r in rr], err, mk + "-", color=cmap(i % 10), label=lab)
        nfe = np.array([np.nan if r.get("rhs_evals") is None else r["rhs_evals"] for r in rr], float)
        a2.loglog(nfe, err, mk + "-", color=cmap(i % 10), label=lab)
        bad = [r for r in rr if r["status"] != 0 or not np.isfinite(r["error"])]
        for r in bad:
            a1.plot(r["run_s"], 1e-16 if not np.isfinite(r["error"]) else r["error"], "x", color="r", ms=9)
    a1.set_xlabel("run time [s] (compile excluded, best of repeats)")
    a2.set_xlabel("RHS evaluations")
    for a in (a1, a2):
        a.set_ylabel("max state error at samples")
        a.grid(alpha=0.3, which="both")
    a2.legend(fontsize=8, loc="best")
    fig.suptitle(fig_title, fontsize=11)
    fig.tight_layout()
    return fig


def plot_work_precision(res: dict) -> dict:
    """One figure per scene, plus float32 and contact-law figures when present."""
    figs = {}
    for sc in res.get("scenes", []):
        figs[sc["scene"]] = _wp_axes(
            f"Work-precision, {sc['description']} (o explicit, s implicit, ^ fixed step; x = failed)", sc["runs"]
        )
    if res.get("float32"):
        runs = [dict(r, solver=f"{r['solver']} {r.get('dtype', '')}") for r in res["float32"]]
        for sc in res.get("scenes", [])[:1]:
            runs += [
                dict(r, solver=f"{r['solver']} float64")
                for r in sc["runs"]
                if r["solver"] in ("Tsit5", "Dopri5", "RK4-fixed") and "run_s" in r
            ]
        figs["float32"] = _wp_axes("float32 vs float64 (rest17); float32 error floor = conditioning x 1.2e-7", runs)
    if res.get("laws"):
        runs = []
        for L in res["laws"]:
            runs += [dict(r, solver=f"{L['law']} / {r['solver']}") for r in L["runs"] if "run_s" in r]
        figs["laws"] = _wp_axes(
            "Work-precision per contact law (rest17; each law against its own Dopri8 1e-13 reference)", runs
        )
    return figs


_STATE_COLOR = {
    "ok": "#4caf50",
    "slow": "#ffc107",
    "failed": "#e53935",
    "wrong attractor": "#8e24aa",
    "not run": "#bdbdbd",
}


def plot_stability_map(rows: list[dict], x_key: str = "eps", title: str = "Stability map"):
    """Coloured grid: rows = method (+tolerance), columns = ``x_key`` values; cell text = steps."""
    methods = list(dict.fromkeys(r["method"] for r in rows))
    xs = sorted({r[x_key] for r in rows}, reverse=True)
    fig, ax = plt.subplots(figsize=(max(8.0, 1.15 * len(xs) + 3.5), 0.45 * len(methods) + 2.0))
    for i, m in enumerate(methods):
        for j, x in enumerate(xs):
            rr = [r for r in rows if r["method"] == m and r[x_key] == x]
            state = rr[0]["verdict"] if rr else "not run"
            ax.add_patch(plt.Rectangle((j, i), 1, 1, color=_STATE_COLOR[state], ec="w"))
            if rr:
                txt = f"{rr[0].get('steps', 0):.0f}" if rr[0].get("steps") is not None else ""
                ax.text(j + 0.5, i + 0.5, txt, ha="center", va="center", fontsize=7)
    ax.set_xlim(0, len(xs))
    ax.set_ylim(0, len(methods))
    ax.set_xticks(np.arange(len(xs)) + 0.5, [f"{x:.0e}" if isinstance(x, float) else str(x) for x in xs], fontsize=8)
    ax.set_yticks(np.arange(len(methods)) + 0.5, methods, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel(x_key)
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in _STATE_COLOR.values()]
    ax.legend(
        handles,
        list(_STATE_COLOR),
        ncol=5,
        fontsize=7,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.12 - 0.2 / max(len(methods), 1)),
    )
    ax.set_title(title + "\n(cell text: steps, accepted + rejected)", fontsize=10)
    fig.tight_layout()
    return fig


def plot_peers(rows: list[dict], scaling: list[dict] | None = None):
    """Bar chart of cost per simulated second (log) and, if given, ensemble throughput vs lanes."""
    n = 2 if scaling else 1
    fig, axes = plt.subplots(1, n, figsize=(6.5 * n, 4.2), squeeze=False)
    ax = axes[0, 0]
    names = [r["name"] for r in rows]
    vals = [r["run_s_per_sim_s"] for r in rows]
    colors = ["#1f77b4" if r["name"].startswith("jaxcelt") else "#888888" for r in rows]
    ax.barh(names, vals, color=colors)
    ax.set_xscale("log")
    ax.set_xlabel("wall seconds per simulated second (one trajectory)")
    for i, r in enumerate(rows):
        ax.text(vals[i], i, f" {vals[i]:.2g}  err {r.get('error', float('nan')):.0e}", va="center", fontsize=7)
    ax.invert_yaxis()
    ax.tick_params(axis="y", labelsize=8)
    ax.grid(alpha=0.3, axis="x")
    if scaling:
        a = axes[0, 1]
        for nm in dict.fromkeys(s["name"] for s in scaling):
            ss = [s for s in scaling if s["name"] == nm]
            a.loglog([s["lanes"] for s in ss], [s["lanes_per_s"] for s in ss], "o-", label=nm)
        a.set_xlabel("lanes (trajectories)")
        a.set_ylabel("trajectories per wall second")
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=8)
    fig.tight_layout()
    return fig
