"""Charts of the speed/accuracy study: reference agreement, work-precision diagrams,
stability map, peer comparison. Each function takes the JSON-able dicts written by
``benchmarks/*.py`` and returns matplotlib figures (never shows or saves)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg", force=False)
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

__all__ = [
    "plot_reference_agreement",
    "plot_work_precision",
    "plot_work_precision_scene",
    "plot_work_precision_float32",
    "plot_work_precision_laws",
    "plot_peers",
]


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


_SOLVER_STYLE = {
    # colour and marker per method; marker shape = kind (o explicit, s implicit, ^ fixed step)
    "Tsit5": ("tab:blue", "o"),
    "Dopri5": ("tab:cyan", "o"),
    "Dopri8": ("tab:red", "o"),
    "Kvaerno3": ("tab:olive", "s"),
    "Kvaerno5": ("tab:brown", "s"),
    "Kvaerno3-Newton": ("tab:green", "s"),
    "Kvaerno5-Newton": ("tab:purple", "s"),
    "RK4-fixed": ("tab:orange", "^"),
    "Heun-fixed": ("tab:gray", "^"),
}


def _ladder_value(r) -> str:
    """Short label of a ladder point: log10 of rtol, or the fixed step in ms."""
    if r.get("rtol") is not None:
        return f"{np.log10(r['rtol']):.0f}"
    if r.get("dt0") is not None:
        return f"{r['dt0'] * 1e3:.2g}"
    return ""


def _wp_lines(axes, runs, group, style, annotate=True):
    """Plot runs grouped by ``group(r)`` on ``axes`` = {x-key: Axes}; ``style(name) -> (colour, marker, ls)``."""
    ok = [r for r in runs if "run_s" in r]
    names = list(dict.fromkeys(group(r) for r in ok))
    for nm in names:
        rr = [r for r in ok if group(r) == nm]
        c, mk, ls = style(nm, rr[0])
        err = np.array([r["error"] if r["error"] is not None and np.isfinite(r["error"]) else np.nan for r in rr])
        bad = np.array([r["status"] != 0 or not np.isfinite(err[i]) for i, r in enumerate(rr)])
        err = np.maximum(err, 1e-16)
        for xkey, ax in axes.items():
            if xkey == "rtol":
                x = np.array([np.nan if r.get("rtol") is None else r["rtol"] for r in rr], float)
            elif xkey == "rhs_evals":
                x = np.array([np.nan if r.get("rhs_evals") is None else r["rhs_evals"] for r in rr], float)
            else:
                x = np.array([r[xkey] for r in rr], float)
            ax.loglog(x, err, marker=mk, ls=ls, color=c, ms=4, lw=1.2, label=nm)
            if bad.any():
                ax.loglog(x[bad], np.where(np.isfinite(err[bad]), err[bad], 1e-16), "x", color="k", ms=8, mew=1.5)
            if annotate and xkey == "rhs_evals":
                for xi, ei, r in zip(x, err, rr):
                    if np.isfinite(xi) and np.isfinite(ei):
                        ax.annotate(
                            _ladder_value(r), (xi, ei), xytext=(3, 2), textcoords="offset points", fontsize=6, color=c
                        )


def _wp_finish(fig, axes, title, legend_ax, note=None):
    labels = {
        "run_s": "run time [s] (compile excluded; best of 1-2 repeats)",
        "rhs_evals": "RHS evaluations (implicit: without Jacobian columns)",
        "rtol": "rtol (atol = 1e-2 rtol)",
    }
    for xkey, ax in axes:
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())  # decade labels only (no overlap)
        ax.set_xlabel(labels[xkey])
        ax.set_ylabel("max |y - y_ref| at the samples (SI)")
        ax.grid(alpha=0.3, which="both")
    legend_ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    fig.suptitle(title, fontsize=10)
    if note:
        fig.text(0.01, 0.005, note, fontsize=7, va="bottom")
    fig.tight_layout(rect=(0, 0.03 if note else 0, 1, 1))


def _solver_style(nm, r):
    c, mk = _SOLVER_STYLE.get(r.get("solver", nm), ("k", "o"))
    return c, mk, "--" if r.get("kind") == "fixed" else "-"


_WP_NOTE = (
    "o explicit, s implicit, ^ fixed step; x = failed / max_steps. Numbers beside the points (right): "
    "log10 rtol, or the fixed step in ms."
)


def plot_work_precision_scene(scene: dict):
    """Two panels for one scene: error vs run time and error vs RHS evaluations, one line per method."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.8))
    _wp_lines({"run_s": a1, "rhs_evals": a2}, scene["runs"], lambda r: r["solver"], _solver_style)
    _wp_finish(fig, [("run_s", a1), ("rhs_evals", a2)], f"Work-precision: {scene['description']} (float64)", a2,
               _WP_NOTE)  # fmt: skip
    return fig


def plot_work_precision_float32(res: dict):
    """float32 against float64 (same solvers), one row per scene: error vs rtol, run time, RHS evaluations."""
    rows = res.get("float32", [])
    fig, axes = plt.subplots(len(rows), 3, figsize=(15, 3.9 * len(rows)), squeeze=False)
    for row, f32 in zip(axes, rows):
        solvers = {r["solver"] for r in f32["runs"]}
        f64 = [sc for sc in res.get("scenes", []) if sc["scene"] == f32["scene"]]
        runs = list(f32["runs"]) + [r for sc in f64 for r in sc["runs"] if r["solver"] in solvers]

        def style(nm, r):
            c, mk = _SOLVER_STYLE.get(r["solver"], ("k", "o"))
            return c, ("v" if r["dtype"] == "float32" else mk), ("--" if r["dtype"] == "float32" else "-")

        _wp_lines(dict(zip(["rtol", "run_s", "rhs_evals"], row)), runs, lambda r: f"{r['solver']} {r['dtype']}",
                  style, annotate=False)  # fmt: skip
        for ax in row:
            ax.set_title(f32["description"], fontsize=9)
        row[0].axhline(1.19e-7, color="k", lw=0.8, ls=":")
        row[0].invert_xaxis()
    _wp_finish(fig, [(k, ax) for row in axes for k, ax in zip(["rtol", "run_s", "rhs_evals"], row)],
               "float32 (dashed, v) vs float64 (solid); dotted: float32 machine epsilon 1.2e-7", axes[0, 2],
               "x at 1e-16: run failed (max_steps hit, no result).")  # fmt: skip
    return fig


_LAW_COLOR = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown"]


def plot_work_precision_laws(res: dict):
    """Contact-law family on one scene: colour = law, line style = solver; two panels."""
    laws = [L for L in res.get("laws", []) if L.get("runs")]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.8))
    runs = [dict(r, law_key=L["law"]) for L in laws for r in L["runs"]]
    cols = {L["law"]: _LAW_COLOR[i % len(_LAW_COLOR)] for i, L in enumerate(laws)}

    def style(nm, r):
        return cols[r["law_key"]], ("o" if r["solver"] == "Tsit5" else "D"), ("-" if r["solver"] == "Tsit5" else "--")

    _wp_lines({"run_s": a1, "rhs_evals": a2}, runs, lambda r: f"{r['law_key']} / {r['solver']}", style)
    desc = laws[0]["description"] if laws else ""
    _wp_finish(fig, [("run_s", a1), ("rhs_evals", a2)],
               f"Work-precision per contact law ({desc}); each law against its own Dopri8 1e-13 reference", a2,
               "solid o: Tsit5, dashed D: Dopri8; numbers beside the points: log10 rtol.")  # fmt: skip
    return fig


def plot_work_precision(res: dict) -> dict:
    """All work-precision figures of a ``work_precision.json`` dict: one per scene, float32, laws."""
    figs = {}
    for sc in res.get("scenes", []):
        if any("run_s" in r for r in sc["runs"]):
            figs[sc["scene"]] = plot_work_precision_scene(sc)
    if any(any("run_s" in r for r in f["runs"]) for f in res.get("float32", [])):
        figs["float32"] = plot_work_precision_float32(res)
    if any(L.get("runs") for L in res.get("laws", [])):
        figs["laws"] = plot_work_precision_laws(res)
    return figs


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
