"""Figures of one trajectory: omega components, tilt, normal force, path of the geometric centre."""

from __future__ import annotations

import numpy as np


def trajectory_figure(ts, ys, diag, *, title: str = "", omega_pi: float | None = None):
    """Four-panel figure. ``ys`` (n, 13), ``diag`` a `jaxcelt.Diagnostics` at the same times.

    Returns the matplotlib Figure (the caller saves or shows it).
    """
    import matplotlib.pyplot as plt

    ts = np.asarray(ts)
    ys = np.asarray(ys)
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), constrained_layout=True)
    a = ax[0, 0]
    for i, c in enumerate(("tab:blue", "tab:orange", "tab:green")):
        a.plot(ts, ys[:, 3 + i], color=c, lw=0.8, label=rf"$\omega_{i + 1}$")
    a.set(xlabel="t [s]", ylabel=r"$\omega$ [rad/s] (body axes)", title="angular velocity")
    a.legend(loc="upper right", fontsize=9)
    a = ax[0, 1]
    a.plot(ts, np.degrees(np.asarray(diag.tilt)), color="k", lw=0.8)
    a.axhline(90, color="tab:red", ls="--", lw=0.8, label="90°: contact leaves the lower half-surface")
    a.set(xlabel="t [s]", ylabel="tilt arccos(n3) [deg]", title="tilt")
    a.legend(loc="upper right", fontsize=8)
    a = ax[1, 0]
    a.plot(ts, np.asarray(diag.N), color="tab:purple", lw=0.8)
    a.axhline(0, color="tab:red", ls="--", lw=0.8)
    a.set(xlabel="t [s]", ylabel="N [N]", title="normal force (lift-off if N ≤ 0)")
    a = ax[1, 1]
    rO = np.asarray(diag.r_O) * 1e3
    a.plot(rO[:, 0], rO[:, 1], color="tab:blue", lw=0.6)
    a.plot(rO[0, 0], rO[0, 1], "go", ms=5, label="start")
    a.plot(rO[-1, 0], rO[-1, 1], "rs", ms=5, label="end")
    a.set(xlabel=r"$r_{O,X1}$ [mm]", ylabel=r"$r_{O,X2}$ [mm]", title="geometric centre O on the base (global)")
    a.set_aspect("equal", adjustable="datalim")
    a.legend(loc="best", fontsize=8)
    if title:
        fig.suptitle(title)
    return fig
