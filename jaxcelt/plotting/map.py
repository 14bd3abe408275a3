"""Two-parameter maps (`jaxcelt.parameter_map`): local regime and largest Lyapunov exponent over
a grid of two parameters, side by side, optionally with bifurcation curves drawn over both panels.

Curves come from a result dict as `jaxcelt.orbits.curves.curve_to_dict` writes them (one curve: its two
parameters under their names, ``"kind"``, optionally ``"kappa"`` and ``"points"``) or a dict with such curves under
``"curves"`` (each either a curve dict or a record with the curve under ``"curve"``, as
``scripts/curves_omega_q.py`` and ``scripts/fold_curves.py`` write); `map_curve_lines` picks those in the map's two
parameters."""

from __future__ import annotations

import numpy as np

from jaxcelt.plotting.bifurcation import REGIME_COLOURS
from jaxcelt.sweeps.regimes import REGIMES

__all__ = ["map_figure", "map_categories", "map_curve_lines", "draw_map_curves", "PARAM_LABELS", "CURVE_STYLES"]

PARAM_LABELS = {
    "omega_pi": r"forcing frequency $\omega_\pi$ [rad/s]",
    "q_pi": r"forcing amplitude $q_\pi$ [m]",
    "mu": r"friction coefficient $\mu$ [-]",
    "k_r": r"rolling-resistance coefficient $k_r$ [-]",
    "b_r": r"rolling-resistance parameter $b_r$ [-]",
    "a_hat": r"contact radius $\hat a$ [m]",
    "b": r"contact-ellipse axis ratio $b$ [-]",
    "eps": r"friction smoothing $\varepsilon$ [s$^{-2}$]",
    "eps_R": r"rolling smoothing $\varepsilon_R$ [s$^{-2}$]",
}

CURVE_STYLES = {
    "fold": ("black", "-"),
    "period-doubling": ("#1b7837", "-."),
    "neimark-sacker": ("#7b3294", "--"),
}
"""curve kind -> (colour, line style) of its line over a map"""

# (label, colour) in legend order; periodic lanes split by their period
_CATEGORIES = (
    ("period-1", "#08519c"),
    ("period-2", "#4292c6"),
    ("period 3-16", "#9ecae1"),
    ("converging", REGIME_COLOURS["converging"]),
    ("quasi-periodic", REGIME_COLOURS["quasi-periodic"]),
    ("chaotic", REGIME_COLOURS["chaotic"]),
    ("aperiodic", REGIME_COLOURS["aperiodic"]),
    ("uncertain", REGIME_COLOURS["uncertain"]),
    ("invalid", "#bdbdbd"),
    ("failed", REGIME_COLOURS["failed"]),
)
_REGIME_CATEGORY = {code: name for code, name in REGIMES.items() if name != "periodic"}


def map_categories(regime: np.ndarray, period: np.ndarray) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """Category index per cell (into the returned (label, colour) list) from regime codes."""
    names = [c[0] for c in _CATEGORIES]
    regime, period = np.asarray(regime), np.asarray(period)
    cat = np.empty(regime.shape, dtype=int)
    for idx in np.ndindex(regime.shape):
        r, k = int(regime[idx]), int(period[idx])
        label = ("period-1" if k == 1 else "period-2" if k == 2 else "period 3-16") if r == 2 else _REGIME_CATEGORY[r]
        cat[idx] = names.index(label)
    return cat, list(_CATEGORIES)


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around grid values (midpoints; the ends extended by half a step)."""
    v = np.asarray(v, dtype=float)
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def map_figure(ds, *, title: str | None = None, curves: dict | None = None):
    """Figure with two panels over the map's grid (x horizontal, y vertical): the local regime
    (categorical, legend; dots mark unbounded wandering of the centre O) and the largest
    Lyapunov exponent lambda_1 [1/s] (diverging colour scale centred on 0, colour bar; grey:
    no exponent -- invalid, failed or not computed). Multi-start maps show the first start.
    ``curves``: bifurcation curves drawn over both panels (`draw_map_curves`; a ValueError naming ``curves``
    if none lies in the map's two parameters)."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap, TwoSlopeNorm
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    xn, yn = ds.attrs["x_parameter"], ds.attrs["y_parameter"]
    sel = {"start": 0} if "start" in ds.dims else {}
    d = ds.isel(**sel)
    xs, ys = d[xn].values, d[yn].values
    X, Y = _edges(xs), _edges(ys)
    cat, cats = map_categories(d["regime"].values, d["period"].values)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13.5, 5.4), constrained_layout=True)
    cmap = ListedColormap([c for _, c in cats])
    norm = BoundaryNorm(np.arange(len(cats) + 1) - 0.5, len(cats))
    a1.pcolormesh(X, Y, cat.T, cmap=cmap, norm=norm, shading="flat", rasterized=True)
    glob = d["global_motion"].values
    ix, iy = np.nonzero(glob == 1)
    if ix.size:
        a1.plot(xs[ix], ys[iy], ".", color="k", ms=1.6, alpha=0.7)
    present = sorted(set(cat.ravel().tolist()))
    handles = [Patch(facecolor=cats[i][1], edgecolor="0.3", lw=0.4, label=cats[i][0]) for i in present]
    if ix.size:
        handles.append(Line2D([], [], ls="", marker=".", color="k", label="O wanders (unbounded)"))
    a1.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8.5, title="local regime",
              title_fontsize=9, frameon=False)  # fmt: skip
    a1.set_title("Local regime (stroboscopic section)", fontsize=11)
    lam = d["lyapunov"].values.astype(float)
    fin = np.isfinite(lam)
    lmap = plt.get_cmap("RdBu_r").with_extremes(bad="0.85")
    if fin.any():
        lo, hi = float(np.min(lam[fin])), float(np.max(lam[fin]))
        lo, hi = min(lo, -1e-3), max(hi, 1e-3)
        m = a2.pcolormesh(X, Y, np.ma.masked_invalid(lam).T, cmap=lmap, norm=TwoSlopeNorm(0.0, lo, hi),
                          shading="flat", rasterized=True)  # fmt: skip
        fig.colorbar(m, ax=a2, label=r"largest Lyapunov exponent $\lambda_1$ [1/s]", pad=0.01)
        a2.set_title(r"Largest Lyapunov exponent $\lambda_1$ (grey: none)", fontsize=11)
    else:
        a2.pcolormesh(X, Y, np.ma.masked_all(lam.shape).T, cmap=lmap, shading="flat")
        a2.set_title(r"$\lambda_1$ not computed", fontsize=11)
    for a in (a1, a2):
        a.set_xlabel(PARAM_LABELS.get(xn, xn))
        a.set_ylabel(PARAM_LABELS.get(yn, yn))
        a.set_xlim(X[0], X[-1])
        a.set_ylim(Y[0], Y[-1])
    if curves is not None:
        lines = map_curve_lines(curves, xn, yn)
        for a in (a1, a2):
            draw_map_curves(a, lines, legend=a is a2)
    if title:
        fig.suptitle(title, fontsize=12)
    return fig


def map_curve_lines(data: dict, x_name: str, y_name: str) -> list[dict]:
    """The curves of ``data`` in the map's parameters: one dict per curve with ``key``, ``kind``, ``x``, ``y``
    (arrays), ``ns`` (bool array: a Neimark-Sacker point, |kappa| <= 1; True on other kinds) and ``points``
    (located codimension-two points: (kind, x, y)). ValueError naming ``curves`` if ``data`` has none in
    (``x_name``, ``y_name``)."""
    if not isinstance(data, dict):
        raise ValueError(f"curves: expected a JSON object, got {type(data).__name__}")
    items = data["curves"].items() if isinstance(data.get("curves"), dict) else [("curve", data)]
    out = []
    for key, rec in items:
        c = rec.get("curve", rec) if isinstance(rec, dict) else None
        if not isinstance(c, dict) or x_name not in c or y_name not in c:
            continue
        x, y = np.asarray(c[x_name], dtype=float), np.asarray(c[y_name], dtype=float)
        if x.shape != y.shape or x.ndim != 1:
            raise ValueError(f"curves: curve {key!r} has {x_name} and {y_name} of different lengths")
        kappa = np.asarray(c["kappa"], dtype=float) if "kappa" in c else np.zeros_like(x)
        points = [(p["kind"], float(p[x_name]), float(p[y_name])) for p in c.get("points", [])]
        out.append(dict(key=str(key), kind=str(c.get("kind", "")), x=x, y=y, ns=np.abs(kappa) <= 1.0, points=points))
    if not out:
        raise ValueError(f"curves: no curve in the map's parameters ({x_name}, {y_name})")
    return out


_CURVE_LABELS = {"fold": "fold curve", "period-doubling": "period-doubling curve",
                 "neimark-sacker": "Neimark-Sacker (torus) curve"}  # fmt: skip
_POINT_MARKERS = {"1:1": "s", "1:2": "D", "1:3": "^", "1:4": "v", "cusp": "P", "fold-flip": "X"}


def draw_map_curves(ax, lines: list[dict], *, legend: bool = True) -> None:
    """Draw `map_curve_lines`' curves on ``ax``: one line style per kind (`CURVE_STYLES`); the neutral-saddle
    stretches of a Neimark-Sacker curve (|kappa| > 1, not a bifurcation) thin and dotted; located codimension-two
    points as markers; one legend entry per kind (and point kind) when ``legend``."""
    from matplotlib import patheffects
    from matplotlib.lines import Line2D

    halo = [patheffects.withStroke(linewidth=4.5, foreground="white", alpha=0.9)]
    seen: dict[str, Line2D] = {}
    for ln in lines:
        colour, style = CURVE_STYLES.get(ln["kind"], ("0.2", ":"))
        x, y, ns = ln["x"], ln["y"], ln["ns"]
        ax.plot(x, np.where(ns, y, np.nan), color=colour, ls=style, lw=2.2, path_effects=halo)
        if not np.all(ns):
            ax.plot(x, y, color=colour, ls=":", lw=0.8)
        label = _CURVE_LABELS.get(ln["kind"], f"{ln['kind']} curve")
        seen.setdefault(ln["kind"], Line2D([], [], color=colour, ls=style, lw=2.0, label=label))
        for kind, px, py in ln["points"]:
            m = next((v for k, v in _POINT_MARKERS.items() if kind.startswith(k)), "o")
            ax.plot(px, py, marker=m, color=colour, mec="white", ms=7, ls="")
            seen.setdefault(kind, Line2D([], [], marker=m, color=colour, mec="white", ls="", label=kind))
    if legend and seen:
        ax.legend(handles=list(seen.values()), loc="best", fontsize=8, framealpha=0.85)
