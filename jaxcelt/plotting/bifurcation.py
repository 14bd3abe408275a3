"""Bifurcation-diagram figures: the paper's Fig. 3 (omega_2 at the section vs omega_pi) coloured by
regime or Lyapunov exponent, and per-frequency panels like Figs. 4-7 (local phase plot
omega_1-omega_3, global path of O, stroboscopic section)."""

from __future__ import annotations

import numpy as np

__all__ = ["bifurcation_figure", "orbit_figure", "REGIME_COLOURS"]

REGIME_COLOURS = {
    "periodic": "#1f77b4",
    "quasi-periodic": "#2ca02c",
    "chaotic": "#d62728",
    "aperiodic": "#9467bd",
    "converging": "#17becf",
    "uncertain": "#e6ab02",
    "invalid": "#7f7f7f",
    "failed": "#000000",
}


def _lyapunov_bins(lam: np.ndarray, band: float):
    """Discrete colour bins for Lyapunov exponents (BoundaryNorm): strong colours everywhere."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    inner = [-0.5, -band, band, 0.3, 0.6, 1.0]
    lo = min(-1.0, float(np.nanmin(lam)) - 1e-9) if np.isfinite(lam).any() else -1.0
    hi = max(1.5, float(np.nanmax(lam)) + 1e-9) if np.isfinite(lam).any() else 1.5
    bounds = [lo, *inner, hi]
    colours = ["#08306b", "#4292c6", "#737373", "#fdae61", "#f46d43", "#d73027", "#67000d"]
    return ListedColormap(colours), BoundaryNorm(bounds, len(colours)), bounds


def bifurcation_figure(
    ds,
    *,
    color_by: str = "regime",
    component: str = "omega2",
    title: str = "",
    lyapunov_band: float = 0.02,
):
    """Fig. 3-style diagram from a sweep dataset (`jaxcelt.sweeps.dataset.to_dataset`/`open_sweep`).

    Args:
        ds: xarray Dataset with ``section`` (value, [start,] sample, state), ``regime``,
            ``period``, ``global_motion``, ``lyapunov``.
        color_by: ``"regime"`` (periodic / quasi-periodic / chaotic / invalid / failed;
            unbounded global motion drawn with hollow markers in a strip below) or
            ``"lyapunov"`` (largest exponent [1/s] in discrete bins: blues below
            ``-lyapunov_band``, grey within +-``lyapunov_band`` (neutral: quasi-periodic or
            not converged), oranges to dark red above -- no pale colours near 0).
        lyapunov_band: half-width of the neutral bin [1/s] (default: `classify_regimes`'
            chaos threshold).
        component: state component plotted (``"omega2"`` as in the paper).

    Returns the matplotlib Figure.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    from jaxcelt.sweeps.regimes import REGIMES

    name = ds.attrs.get("swept_parameter", "omega_pi")
    sec = ds["section"].sel(state=component).values
    vals = ds[name].values
    if sec.ndim == 3:  # multi-start: flatten starts into the sample axis
        regime = np.repeat(ds["regime"].values[:, :, None], sec.shape[2], axis=2).reshape(len(vals), -1)
        lyap = np.repeat(ds["lyapunov"].values[:, :, None], sec.shape[2], axis=2).reshape(len(vals), -1)
        glob = ds["global_motion"].values.max(axis=1)
        sec = sec.reshape(len(vals), -1)
    else:
        regime = np.repeat(ds["regime"].values[:, None], sec.shape[1], axis=1)
        lyap = np.repeat(ds["lyapunov"].values[:, None], sec.shape[1], axis=1)
        glob = ds["global_motion"].values
    x = np.repeat(vals[:, None], sec.shape[1], axis=1)
    ok = np.isfinite(sec)
    fig, (ax, axg) = plt.subplots(
        2,
        1,
        figsize=(10, 6.2),
        sharex=True,
        gridspec_kw=dict(height_ratios=[5, 0.45], hspace=0.06),
        constrained_layout=True,
    )
    ms = 4 if sec.size < 5000 else 1.5
    xlabel = {"omega_pi": r"forcing frequency $\omega_\pi$ [rad/s]"}.get(name, name)
    if color_by == "lyapunov":
        lam = lyap[ok]
        fin = np.isfinite(lam)
        cmap, norm, bounds = _lyapunov_bins(lam, lyapunov_band)
        sc = ax.scatter(x[ok][fin], sec[ok][fin], c=lam[fin], s=ms, cmap=cmap, norm=norm, linewidths=0)
        if (~fin).any():
            ax.scatter(x[ok][~fin], sec[ok][~fin], s=ms, color="#d9d9d9", linewidths=0, label="no exponent")
            ax.legend(loc="upper left", fontsize=8, markerscale=3)
        cb = fig.colorbar(sc, ax=ax, label=r"largest Lyapunov exponent $\lambda_1$ [1/s]", pad=0.01, spacing="uniform")
        cb.set_ticks(bounds)
        cb.set_ticklabels([f"{b:.2g}" for b in bounds])
    else:
        handles = []
        for code, label in REGIMES.items():
            m = ok & (regime == code)
            if not m.any():
                continue
            ax.scatter(x[m], sec[m], s=ms, color=REGIME_COLOURS[label], linewidths=0)
            handles.append(Line2D([], [], ls="", marker="o", color=REGIME_COLOURS[label], label=label))
        ax.legend(handles=handles, loc="upper left", fontsize=9, framealpha=0.9, title="local regime", title_fontsize=9)
    ax.set_ylabel({"omega2": r"$\omega_2$ at $t_k = k\,2\pi/\omega_\pi$ [rad/s]"}.get(component, component))
    ax.grid(alpha=0.3)
    ax.set_title(title or "Stroboscopic bifurcation diagram (cf. paper Fig. 3)", fontsize=12)
    # global motion strip
    colours = np.where(glob == 1, "tab:orange", np.where(glob == 0, "tab:cyan", "0.7"))
    axg.scatter(vals, np.zeros_like(vals), c=list(colours), marker="s", s=18, linewidths=0)
    axg.set_yticks([])
    axg.set_ylabel("O", rotation=0, labelpad=12, va="center")
    axg.legend(
        handles=[
            Line2D([], [], ls="", marker="s", color="tab:cyan", label="bounded"),
            Line2D([], [], ls="", marker="s", color="tab:orange", label="unbounded wandering"),
        ],
        loc="upper right",
        bbox_to_anchor=(1.0, -0.9),
        ncol=2,
        fontsize=8,
        frameon=False,
    )
    axg.set_xlabel(xlabel)
    return fig


def orbit_figure(ts, ys, r_O, section_index, *, omega_pi: float, label: str = ""):
    """Figs. 4-7-style panels for one frequency: (a) local phase plot omega_1-omega_3 with the
    section points, (b) global path of O on the base, (c) stroboscopic section omega_1-omega_2.

    Args:
        ts (n,), ys (n, 13): a densely saved trajectory after the transient.
        r_O (n, 3): global position of O [m] at ``ts``.
        section_index: indices into ts of the stroboscopic times.
    """
    import matplotlib.pyplot as plt

    ys = np.asarray(ys)
    r = np.asarray(r_O) * 1e3
    si = np.asarray(section_index)
    fig, ax = plt.subplots(1, 3, figsize=(13.5, 4.3), constrained_layout=True)
    a = ax[0]
    a.plot(ys[:, 3], ys[:, 5], lw=0.5, color="tab:blue")
    a.plot(ys[si, 3], ys[si, 5], "o", ms=3.5, color="tab:red", label="section")
    a.set(xlabel=r"$\omega_1$ [rad/s]", ylabel=r"$\omega_3$ [rad/s]", title="(a) local phase plot")
    a.legend(fontsize=8, loc="best")
    a.grid(alpha=0.3)
    a = ax[1]
    a.plot(r[:, 0], r[:, 1], lw=0.6, color="tab:blue")
    a.plot(r[0, 0], r[0, 1], "go", ms=5, label="start")
    a.plot(r[-1, 0], r[-1, 1], "rs", ms=5, label="end")
    a.set(xlabel=r"$X_1$ of O [mm]", ylabel=r"$X_2$ of O [mm]", title="(b) global path of the centre O")
    a.set_aspect("equal", adjustable="datalim")
    a.legend(fontsize=8, loc="best")
    a.grid(alpha=0.3)
    a = ax[2]
    a.plot(ys[si, 3], ys[si, 4], "o", ms=3, color="tab:red")
    a.set(xlabel=r"$\omega_1$ [rad/s]", ylabel=r"$\omega_2$ [rad/s]", title="(c) stroboscopic section")
    a.grid(alpha=0.3)
    fig.suptitle(rf"$\omega_\pi$ = {omega_pi:g} rad/s" + (f" — {label}" if label else ""), fontsize=12)
    return fig
