"""Basin maps of an attractor census (`jaxcelt.attractors`): the attractor reached from each
start over heading psi0 and tilt, one colour per attractor, basin fractions in the legend."""

from __future__ import annotations

from typing import Any

import numpy as np

from jaxcelt.plotting.bifurcation import REGIME_COLOURS

__all__ = ["plot_basins", "attractor_colours"]

# distinct periodic attractors; the other kinds keep the regime colours of the other figures
_PERIODIC = ("#08519c", "#ff7f0e", "#17becf", "#e377c2", "#bcbd22", "#8c564b", "#6baed6", "#ffbb78", "#98df8a")


def attractor_colours(rows: list[dict[str, Any]]) -> list[str]:
    """A colour per attractor row (dicts with ``kind``): periodic rows cycle through a palette."""
    out, j = [], 0
    for a in rows:
        if a["kind"] == "periodic":
            out.append(_PERIODIC[j % len(_PERIODIC)])
            j += 1
        else:
            out.append(REGIME_COLOURS.get(a["kind"], "#cccccc"))
    return out


def plot_basins(census: Any, *, title: str | None = None, ax: Any = None):
    """Basin map over (psi0, tilt) of a census (`AttractorCensus` or its ``to_dict()``).

    A grid census is drawn as cells (psi0 horizontal [deg], tilt vertical [deg]); random starts
    as points. Returns the figure.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    d = census if isinstance(census, dict) else census.to_dict()
    lanes = d.get("lanes")
    if not lanes or lanes.get("psi0") is None or lanes.get("tilt") is None:
        raise ValueError("plot_basins: 'census' has no start coordinates (psi0, tilt) per lane")
    rows = d["attractors"]
    label = np.asarray(lanes["label"])
    psi0 = np.degrees(np.asarray(lanes["psi0"], float))
    tilt = np.degrees(np.asarray(lanes["tilt"], float))
    colours = attractor_colours(rows)
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(len(rows) + 1) - 0.5, len(rows))
    if ax is None:
        fig, ax = plt.subplots(figsize=(8.5, 4.6), layout="constrained")
    else:
        fig = ax.figure
    shape = d.get("grid_shape")
    if shape is not None:
        a, b = shape
        P, T, L = psi0.reshape(a, b), tilt.reshape(a, b), label.reshape(a, b)

        def edges(c):
            c = np.asarray(c, float)
            if c.size == 1:
                return np.array([c[0] - 0.5, c[0] + 0.5])
            h = np.diff(c) / 2
            return np.concatenate([[c[0] - h[0]], c[:-1] + h, [c[-1] + h[-1]]])

        ax.pcolormesh(edges(P[:, 0]), edges(T[0]), L.T, cmap=cmap, norm=norm)
    else:
        ax.scatter(psi0, tilt, c=label, cmap=cmap, norm=norm, s=12)
    ax.set_xlabel(r"start heading $\psi_0$ [deg]")
    ax.set_ylabel("start tilt [deg]")
    handles = []
    for a, c in zip(rows, colours, strict=True):
        name = a.get("name") or (f"period-{a['k']}" if a["kind"] == "periodic" else a["kind"])
        psi = (a.get("state") or [None] * 13)[12]
        if a["kind"] == "periodic" and psi is not None:  # tells symmetric orbits apart
            name += rf" ($\psi$ = {np.degrees(psi) % 360:.0f}°)"
        handles.append(Patch(color=c, label=f"{name}: {a['fraction']:.3f} ({a['count']})"))
    ax.legend(handles=handles, loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=8, title="attractor: fraction")
    s = d.get("settings", {})
    ax.set_title(
        title
        or rf"$\omega_\pi$ = {d['omega_pi']:g} rad/s, {d['n_lanes']} starts at rest, "
        f"{s.get('transient_periods', '?')} + {s.get('sample_periods', '?')} periods"
    )
    return fig
