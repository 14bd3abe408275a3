"""The atlas figure (`jaxcelt.sweeps.atlas.AtlasResult`): three panels sharing the omega_pi axis.

(a) brute-force section points omega_2 (grey) with every continued periodic branch on top (stable solid, unstable
dashed; fold / period-doubling / Neimark-Sacker points marked and labelled); (b) the attractors' basin fractions
stacked, tipping over in its own colour; (c) lambda_1 and lambda_2 of every attractor (error bars: their standard
errors), with the zero line; lambda_1's marker is the label from the spectrum (`AtlasResult.kind_spectrum`: a
2-torus, a sink, chaos, or uncertain), its colour the attractor's.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plot_atlas", "atlas_figure"]

_TIPPING = "#d62728"
SPECTRUM_MARKERS = {
    "chaotic": ("^", "chaotic: λ₁ > 0"),
    "quasi-periodic": ("D", "2-torus: λ₁ ≈ 0, λ₂ < 0"),
    "converging": ("v", "sink (periodic orbit): λ₁ < 0"),
    "uncertain": ("X", "uncertain: near-NS focus, 3-torus, or too short"),
}
"""marker and legend text of lambda_1 per label from the spectrum (`jaxcelt.sweeps.regimes.spectrum_regime`)"""
READ_OFF = (14.0, 15.6, 17.0, 19.0)
"""the paper's frequencies [rad/s], marked by dotted lines"""


def _clip(ax, res, branch_ys: list) -> None:
    """Limit omega_2 to the branches and the bulk (2nd-98th percentile) of the brute-force points, so that a few
    fast-spinning lanes do not squash the branches; say so on the panel when points are cut off."""
    ys = [np.concatenate(branch_ys)] if branch_ys else []
    pts = np.asarray(res.brute.samples)[..., 4] if res.brute is not None else np.zeros(0)
    pts = pts[np.isfinite(pts)]
    if pts.size:
        ys.append(np.percentile(pts, [2, 98]))
    if not ys:
        return
    lo, hi = float(np.min(np.concatenate(ys))), float(np.max(np.concatenate(ys)))
    pad = 0.15 * max(hi - lo, 0.2)
    lo, hi = lo - pad, hi + pad
    ax.set_ylim(lo, hi)
    cut = int(np.sum((pts < lo) | (pts > hi)))
    if cut:
        ax.text(0.995, 0.015, f"{cut} of {pts.size} brute-force points beyond this range (fast spin) not shown",
                transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="0.35")  # fmt: skip


def _palette(n: int) -> list:
    import matplotlib.pyplot as plt

    cmap = plt.get_cmap("tab20")
    base = [cmap(k) for k in (0, 2, 4, 8, 10, 12, 16, 18, 14, 1, 5, 9, 11, 13, 17, 19)]  # no red: tipping over
    return [base[k % len(base)] for k in range(n)]


def _kind_runs(ds, a: int) -> str:
    """'period-1 15-16, uncertain 16.5-19': the kinds attractor ``a`` takes over runs of values."""
    w = ds["omega_pi"].values
    runs: list[list] = []
    for j in np.flatnonzero(ds["exists"].values[a]):
        kind = str(ds["kind"].values[a, j])
        name = f"period-{int(ds['period'].values[a, j])}" if kind == "periodic" else kind
        if runs and runs[-1][0] == name and runs[-1][3] == j - 1:
            runs[-1][2], runs[-1][3] = w[j], j
        else:
            runs.append([name, w[j], w[j], j])
    parts = [f"{n} {lo:g}" + (f"–{hi:g}" if hi > lo else "") for n, lo, hi, _ in runs]
    if len(parts) > 3:
        parts = parts[:3] + ["…"]
    return f"#{a}: " + ", ".join(parts)


def _branch_panel(ax, res, colour) -> None:
    from matplotlib.lines import Line2D

    from jaxcelt.plotting.orbits import BIFURCATION_MARKERS, _runs

    handles = []
    if res.brute is not None:
        sec = np.asarray(res.brute.samples)[..., 4]
        x = np.broadcast_to(np.asarray(res.brute.values)[:, None], sec.shape)
        ok = np.isfinite(sec)
        ax.scatter(x[ok], sec[ok], s=2, color="0.6", linewidths=0, zorder=1, rasterized=True)
        psi = np.degrees(res.options.brute_psi0)
        handles.append(Line2D([], [], ls="", marker="o", ms=4, color="0.6",
                              label=f"brute force: section points from rest, ψ₀ = {psi:g}°"))  # fmt: skip
    spare = ("#08519c", "#ff7f0e", "#2ca02c", "#e377c2", "#8c564b", "#17becf")
    owners = getattr(res, "branch_attractors", None) or [-1] * len(res.branches)
    ys_all: list[np.ndarray] = []
    placed: list[tuple[float, float]] = []
    marked = set()
    ylo, yhi = ax.get_ylim() if res.brute is not None else (0.0, 1.0)
    for n, ((label, br), owner) in enumerate(zip(res.branches, owners, strict=True)):
        c = colour[owner] if owner >= 0 else spare[n % len(spare)]  # the colour of its attractor in (b), (c)
        lam, y = np.asarray(br.values), np.asarray(br.y)[:, 4]
        ys_all.append(y)
        for a, b, stable in _runs(np.asarray(br.stable)):
            ax.plot(lam[a : b + 1], y[a : b + 1], ls="-" if stable else "--", lw=2.0 if stable else 1.3, color=c,
                    zorder=3)  # fmt: skip
        handles.append(Line2D([], [], color=c, lw=2, label=label))
        for bif in br.bifurcations:
            m, short, mc = BIFURCATION_MARKERS[bif.kind]
            yb = float(np.asarray(bif.y)[4])
            ax.plot([bif.value], [yb], ls="", marker=m, ms=8, mfc=mc, mec="k", zorder=5)
            marked.add(bif.kind)
            placed.append((float(bif.value), yb, short))
    _clip(ax, res, ys_all)
    # labels of the bifurcation points: one per (kind, value) (a mirror pair shares them), stacked, not overlapping
    seen: dict[tuple[str, str], list[float]] = {}
    for v, yb, short in placed:
        seen.setdefault((short, f"{v:.3f}"), []).append(yb)
    span = (ax.get_ylim()[1] - ax.get_ylim()[0]) or 1.0
    used: list[tuple[float, float]] = []
    for (short, v), ys in sorted(seen.items(), key=lambda kv: float(kv[0][1])):
        x, ytxt = float(v), max(ys) + 0.08 * span
        while any(abs(x - ux) < 0.9 and abs(ytxt - uy) < 0.07 * span for ux, uy in used):
            ytxt += 0.08 * span
        used.append((x, ytxt))
        ax.annotate(f"{short} {float(v):.3f}", (x, max(ys)), xytext=(x, ytxt), textcoords="data", fontsize=8,
                    ha="center", arrowprops=dict(arrowstyle="-", color="0.3", lw=0.6),
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8), zorder=6)  # fmt: skip
    del ylo, yhi
    handles.append(Line2D([], [], color="k", lw=2.0, label="stable orbit"))
    handles.append(Line2D([], [], color="k", lw=1.3, ls="--", label="unstable orbit"))
    for kind, (m, short, mc) in BIFURCATION_MARKERS.items():
        if kind in marked:
            handles.append(Line2D([], [], ls="", marker=m, ms=8, mfc=mc, mec="k", label=f"{kind} ({short})"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.set_ylabel("ω₂ on the section [rad/s]")
    ax.grid(alpha=0.3)


def _fraction_panel(ax, res, colour) -> None:
    ds = res.continuation
    w = ds["omega_pi"].values
    base = np.zeros(len(w))
    for a in ds["attractor"].values:
        f = np.nan_to_num(ds["fraction"].values[a])
        if not np.any(f > 0):
            continue
        ax.fill_between(w, base, base + f, step="mid", color=colour[a], alpha=0.9, lw=0, label=_kind_runs(ds, a))
        base = base + f
    tip = ds["tipping_fraction"].values
    ax.fill_between(w, base, base + tip, step="mid", facecolor="#f4cccc", edgecolor=_TIPPING, hatch="//", lw=0,
                    label="tipping over (lifted off / on its side)")  # fmt: skip
    base = base + tip
    fail = ds["failed_fraction"].values
    if np.any(fail > 0):
        ax.fill_between(w, base, base + fail, step="mid", color="k", lw=0, label="failed solve")
    ax.set_ylim(0, 1)
    ax.set_ylabel("basin fraction\nof the fresh starts")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.grid(alpha=0.3)


def _lyapunov_panel(ax, res, colour) -> None:
    from matplotlib.lines import Line2D

    ds = res.continuation
    w = ds["omega_pi"].values
    n_att = ds.sizes["attractor"]
    dx = 0.012 * (w[-1] - w[0]) if len(w) > 1 else 0.0
    has_spec = np.isfinite(res.lambda1).any()
    kinds = getattr(res, "kind_spectrum", None)
    handles = []
    shown: set[str] = set()
    for a in range(n_att):
        ex = ds["exists"].values[a]
        if not ex.any():
            continue
        off = (a - (n_att - 1) / 2) * dx / max(n_att, 1)
        if has_spec:
            for lam, err, m, ls in ((res.lambda1, res.lambda1_stderr, "o", "-"), (res.lambda2, res.lambda2_stderr,
                                                                                 "s", ":")):  # fmt: skip
                y = np.where(ex, lam[a], np.nan)
                by_kind = m == "o" and kinds is not None
                ax.errorbar(w + off, y, yerr=np.where(ex, err[a], np.nan), color=colour[a], marker="" if by_kind else m,
                            ms=4, ls=ls, lw=1, capsize=2, mfc=colour[a] if m == "o" else "white")  # fmt: skip
                if by_kind:  # lambda_1's marker: the label from the spectrum
                    for kind, (mk, _) in SPECTRUM_MARKERS.items():
                        sel = ex & (kinds[a] == kind) & np.isfinite(y)
                        if sel.any():
                            ax.plot((w + off)[sel], y[sel], ls="", marker=mk, ms=6, color=colour[a], mec="k",
                                    mew=0.5, zorder=4)  # fmt: skip
                            shown.add(kind)
        else:
            y = np.where(ex, ds["lyapunov"].values[a], np.nan)
            ax.errorbar(w + off, y, yerr=np.where(ex, ds["lyapunov_stderr"].values[a], np.nan), color=colour[a],
                        marker="o", ms=4, lw=1, capsize=2)  # fmt: skip
        handles.append(Line2D([], [], color=colour[a], marker="o", label=f"#{a}"))
    ax.axhline(0.0, color="k", lw=0.8)
    # the range of the exponents themselves: a short window's large error bar must not squash the others
    lam = np.r_[res.lambda1.ravel(), res.lambda2.ravel()] if has_spec else ds["lyapunov"].values.ravel()
    lam = lam[np.isfinite(lam)]
    if lam.size:
        lo, hi = min(float(lam.min()), 0.0), max(float(lam.max()), 0.0)
        pad = 0.25 * max(hi - lo, 0.2)
        ax.set_ylim(lo - pad, hi + pad)
    if has_spec:
        handles += [Line2D([], [], color="k", marker="" if shown else "o", ls="-", label="λ₁"),
                    Line2D([], [], color="k", marker="s", mfc="white", ls=":", label="λ₂")]  # fmt: skip
        handles += [Line2D([], [], color="0.6", mec="k", mew=0.5, marker=mk, ls="", ms=6, label=f"λ₁ marker, {text}")
                    for kind, (mk, text) in SPECTRUM_MARKERS.items() if kind in shown]  # fmt: skip
        sp = res.options.spectrum_periods
        ax.set_ylabel(f"λ₁, λ₂ [1/s]\n(spectrum, {sp} periods)")
    else:
        ax.set_ylabel("λ₁ [1/s]\n(the lanes' median)")
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False, ncol=2)
    ax.grid(alpha=0.3)


def atlas_figure(res: Any, *, title: str = ""):
    """The atlas as a matplotlib Figure (see the module docstring); ``res``: an `AtlasResult`."""
    import matplotlib.pyplot as plt

    ds = res.continuation
    colour = dict(enumerate(_palette(ds.sizes["attractor"])))
    fig, axes = plt.subplots(3, 1, figsize=(13, 11), sharex=True, gridspec_kw=dict(height_ratios=[1.5, 1, 1]))
    _branch_panel(axes[0], res, colour)
    _fraction_panel(axes[1], res, colour)
    _lyapunov_panel(axes[2], res, colour)
    for w_read in READ_OFF:  # the paper's frequencies, where the section is read off
        if res.values[0] <= w_read <= res.values[-1]:
            for ax in axes:
                ax.axvline(w_read, color="0.35", lw=0.8, ls=":", zorder=0)
            axes[0].text(w_read, 0.985, f"{w_read:g}", transform=axes[0].get_xaxis_transform(), ha="center",
                         va="top", fontsize=8, color="0.3", bbox=dict(fc="white", ec="none", pad=0.5))  # fmt: skip
    for ax, letter in zip(axes, "abc", strict=True):
        ax.text(-0.07, 1.0, f"({letter})", transform=ax.transAxes, fontsize=12, fontweight="bold", va="top")
    w = res.values
    axes[2].set_xlim(w[0] - 0.02 * (w[-1] - w[0]), w[-1] + 0.02 * (w[-1] - w[0]))
    axes[2].set_xlabel("forcing frequency ω_π [rad/s]")
    o = res.options
    q = float(res.params.q_pi)
    axes[0].set_title(title or (
        f"Atlas of the wobblestone over ω_π, q_π = {q:g} m: {ds.sizes['lane']} fresh starts at rest + seeds per "
        f"value, {o.transient_periods} + {o.sample_periods} periods per lane"), fontsize=10)  # fmt: skip
    fig.tight_layout()
    return fig


def plot_atlas(res: Any, path: str | Path, *, title: str = "", dpi: int = 120) -> Path:
    """Draw `atlas_figure` of ``res`` (an `AtlasResult`) to ``path`` (PNG or any matplotlib format)."""
    import matplotlib.pyplot as plt

    fig = atlas_figure(res, title=title)
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
