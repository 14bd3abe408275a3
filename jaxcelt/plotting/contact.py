"""Figures of the contact-law study: error maps over the slip-spin plane, cost vs error."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

__all__ = ["plot_error_maps", "plot_cost_vs_error", "plot_convergence"]


def plot_error_maps(maps: dict, *, title: str = "", vmax: float | None = None):
    """maps: {label: `jaxcelt.physics.contact.calibrate.error_map` dict}. One panel per label: |error| over
    alpha = atan2(omega_s, |v_s|) (x) and slip direction beta (y), log colour scale."""
    n = len(maps)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 1, 3.6), sharey=True, squeeze=False, layout="constrained")
    vmax = vmax or max(float(np.nanmax(m["err"])) for m in maps.values())
    im = None
    for ax, (label, m) in zip(axes[0], maps.items()):
        err = np.log10(np.maximum(m["err"], 1e-6))
        im = ax.pcolormesh(
            np.degrees(m["alpha"]),
            np.degrees(m["beta"]),
            err.T,
            vmin=-4,
            vmax=np.log10(vmax),
            cmap="viridis",
            shading="auto",
        )
        ax.set_title(f"{label}\nmax {np.max(m['err']):.2g}, rms {np.sqrt(np.mean(m['err'] ** 2)):.2g}", fontsize=9)
        ax.set_xlabel("alpha = atan(w_s/|v_s|) [deg]")
    axes[0][0].set_ylabel("slip direction beta [deg]")
    fig.colorbar(im, ax=axes[0].tolist(), label="log10 |(T_sx, T_sy, M_s) - integral|")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def plot_cost_vs_error(results: dict, *, tol: float | None = None):
    """results: {scene: [RungResult...]} -> scatter of run wall time vs error, one marker per law."""
    fig, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
    rungs = [r.rung for r in next(iter(results.values()))]
    markers = "os^vD<>xP*"
    colors = plt.cm.tab10(np.arange(len(results)))
    for si, res in enumerate(results.values()):
        for ri, r in enumerate(res):
            err = max(r.error, 1e-6)
            ax.scatter(r.run_s, err, marker=markers[ri % len(markers)], color=colors[si], s=45)
    for ri, name in enumerate(rungs):
        ax.scatter([], [], marker=markers[ri % len(markers)], color="gray", label=name)
    for si, scene in enumerate(results):
        ax.scatter([], [], marker="s", color=colors[si], label=f"scene: {scene}")
    if tol:
        ax.axhline(tol, color="k", ls="--", lw=0.8, label=f"tolerance {tol:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("run wall time after compilation [s] (2 CPU cores)")
    ax.set_ylabel("relative error vs integral law (reference = 1e-6)")
    ax.legend(fontsize=7, ncol=2, loc="center left", bbox_to_anchor=(1.0, 0.5))
    ax.grid(True, which="both", alpha=0.3)
    return fig


def plot_convergence(data: dict):
    """data: {case label: (nodes (k,), error (k,))} -> log-log error vs number of nodes."""
    fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
    for label, (nodes, err) in data.items():
        ax.loglog(nodes, np.maximum(err, 1e-16), "o-", label=label)
    ax.set_xlabel("quadrature nodes (4 n_angle n_radial)")
    ax.set_ylabel("max |error| of (T_sx, T_sy, M_s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    return fig
