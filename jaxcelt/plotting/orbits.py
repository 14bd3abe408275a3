"""Figures of periodic-orbit branches (`jaxcelt.continue_orbit`): the combined bifurcation diagram
(brute-force section points with the continued branches on top; stable solid, unstable dashed,
bifurcation points marked and labelled) and the Floquet multipliers along a branch."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["branch_figure", "multipliers_figure", "BIFURCATION_MARKERS"]

BIFURCATION_MARKERS = {
    "fold": ("s", "LP", "tab:green"),
    "period-doubling": ("^", "PD", "tab:red"),
    "Neimark-Sacker": ("D", "NS", "tab:purple"),
}
"""kind -> (marker, short label, colour)"""

_BRANCH_COLOURS = ("#08519c", "#ff7f0e", "#2ca02c", "#e377c2", "#8c564b", "#17becf")
_LABELS = {
    "omega_pi": r"forcing frequency $\omega_\pi$ [rad/s]",
    "omega1": r"$\omega_1$ at $t_k = k\,2\pi/\omega_\pi$ [rad/s]",
    "omega2": r"$\omega_2$ at $t_k = k\,2\pi/\omega_\pi$ [rad/s]",
    "omega3": r"$\omega_3$ at $t_k = k\,2\pi/\omega_\pi$ [rad/s]",
}


def _component_index(component: str) -> int:
    from jaxcelt.physics.model import STATE_NAMES

    if component not in STATE_NAMES:
        raise ValueError(f"component must be one of {STATE_NAMES}, got {component!r}")
    return STATE_NAMES.index(component)


def _runs(flags: np.ndarray) -> list[tuple[int, int, bool]]:
    """Maximal runs [i, j] (inclusive, overlapping by one point) of equal ``flags``."""
    out, i = [], 0
    for j in range(1, len(flags) + 1):
        if j == len(flags) or flags[j] != flags[i]:
            out.append((i, min(j, len(flags) - 1), bool(flags[i])))
            i = j
    return out


def branch_figure(
    branches: Sequence[Any],
    *,
    labels: Sequence[str] | None = None,
    sweep: Any = None,
    component: str = "omega2",
    name: str = "omega_pi",
    title: str = "",
    xlim: tuple[float, float] | None = None,
    ylim: tuple[float, float] | None = None,
):
    """Combined diagram: brute-force section points with continued orbit branches on top.

    Args:
        branches: `jaxcelt.orbits.branch.ArclengthBranch` objects (``values``, ``y``,
            ``stable``, ``bifurcations``). A period-k branch may be given once per section point
            (the same branch with ``y`` of the j-th iterate), with the same label.
        labels: legend label of each branch (default "branch i").
        sweep: optional `jaxcelt.SweepResult` over the same parameter whose section points
            (``samples``) are drawn underneath in grey (the brute-force diagram).
        component: state component on the vertical axis (`jaxcelt.STATE_NAMES`).
        name: the continued parameter (horizontal axis label).
        xlim, ylim: axis ranges (default: the data's).

    Returns the matplotlib Figure.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    j = _component_index(component)
    labels = list(labels) if labels is not None else [f"branch {i}" for i in range(len(branches))]
    if len(labels) != len(branches):
        raise ValueError(f"labels: expected {len(branches)} labels, got {len(labels)}")
    fig, ax = plt.subplots(figsize=(10, 6), constrained_layout=True)
    handles = []
    if sweep is not None:
        sec = np.asarray(sweep.samples)[..., j]
        x = np.broadcast_to(np.asarray(sweep.values)[:, None], sec.shape)
        ok = np.isfinite(sec)
        ax.scatter(x[ok], sec[ok], s=1.5 if ok.sum() > 5000 else 4, color="0.65", linewidths=0, zorder=1)
        handles.append(Line2D([], [], ls="", marker="o", ms=4, color="0.65", label="section points from rest"))
    colour_of: dict[str, str] = {}
    marked: set[str] = set()
    texts: set[tuple[str, str]] = set()  # a symmetric pair of branches shares its labels
    for br, lab in zip(branches, labels, strict=True):
        c = colour_of.setdefault(lab, _BRANCH_COLOURS[len(colour_of) % len(_BRANCH_COLOURS)])
        lam, y = np.asarray(br.values), np.asarray(br.y)[:, j]
        for a, b, stable in _runs(np.asarray(br.stable)):
            ax.plot(
                lam[a : b + 1], y[a : b + 1], ls="-" if stable else "--", lw=2.0 if stable else 1.4, color=c, zorder=3
            )
        if lab not in {h.get_label() for h in handles}:
            handles.append(Line2D([], [], color=c, lw=2, label=lab))
        for bif in br.bifurcations:
            m, short, mc = BIFURCATION_MARKERS[bif.kind]
            yb = float(np.asarray(bif.y)[j])
            ax.plot([bif.value], [yb], ls="", marker=m, ms=8, mfc=mc, mec="k", zorder=5)
            text = f"{short} {bif.value:.3f}"
            if (text, f"{abs(yb):.2f}") not in texts:
                texts.add((text, f"{abs(yb):.2f}"))
                ax.annotate(text, (bif.value, yb), xytext=(6, 6), textcoords="offset points", fontsize=8)
            marked.add(bif.kind)
    handles.append(Line2D([], [], color="k", lw=2.0, label="stable"))
    handles.append(Line2D([], [], color="k", lw=1.4, ls="--", label="unstable"))
    for kind in BIFURCATION_MARKERS:
        if kind in marked:
            m, short, mc = BIFURCATION_MARKERS[kind]
            handles.append(Line2D([], [], ls="", marker=m, ms=8, mfc=mc, mec="k", label=f"{kind} ({short})"))
    ax.legend(handles=handles, loc="best", fontsize=8, framealpha=0.9)
    ax.set_xlabel(_LABELS.get(name, name))
    ax.set_ylabel(_LABELS.get(component, component))
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.grid(alpha=0.3)
    ax.set_title(title or "Periodic-orbit branches over the brute-force diagram", fontsize=12)
    return fig


def multipliers_figure(branch: Any, *, name: str = "omega_pi", title: str = ""):
    """Floquet multipliers along a branch: (a) |mu| against the parameter, (b) the multipliers in
    the complex plane against the unit circle, coloured by the parameter.

    Returns the matplotlib Figure.
    """
    import matplotlib.pyplot as plt

    lam = np.asarray(branch.values)
    mu = np.asarray(branch.multipliers)
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
    # a branch through a fold comes back in lam: the moduli are drawn along it, so the sheets
    # show as the curve folding back
    for i in range(mu.shape[1]):
        a.plot(lam, np.abs(mu[:, i]), ".-", ms=2.5, lw=0.8)
    a.axhline(1.0, color="k", lw=0.8)
    for bif in branch.bifurcations:
        mk, short, mc = BIFURCATION_MARKERS[bif.kind]
        a.axvline(bif.value, color=mc, lw=0.9, ls=":")
        a.annotate(f"{short} {bif.value:.3f}", (bif.value, 1.0), xytext=(3, 4), textcoords="offset points", fontsize=8)
    a.set_yscale("log")
    a.set(xlabel=_LABELS.get(name, name), ylabel=r"$|\mu|$", title="(a) multiplier moduli along the branch")
    a.grid(alpha=0.3)
    th = np.linspace(0, 2 * np.pi, 400)
    b.plot(np.cos(th), np.sin(th), color="k", lw=0.8)
    sc = b.scatter(mu.real.ravel(), mu.imag.ravel(), c=np.repeat(lam, mu.shape[1]), s=6, cmap="viridis")
    fig.colorbar(sc, ax=b, label=_LABELS.get(name, name))
    b.set(xlabel=r"Re $\mu$", ylabel=r"Im $\mu$", title="(b) multipliers and the unit circle")
    b.set_aspect("equal")
    b.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig
