"""Figures of a parameter fit: fitted vs measured, loss histories, parameter traces,
correlations, coverage and the gradient-norm study. Each function returns a matplotlib Figure."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from jaxcelt.identify.observe import OBSERVABLES

_CHANNELS = {
    "state": ("v1", "v2", "v3", "ω1", "ω2", "ω3", "n1", "n2", "n3", "rC1", "rC2", "rC3", "ψ"),
    "omega": ("ω1 [rad/s]", "ω2 [rad/s]", "ω3 [rad/s]"),
    "orientation": ("n1", "n2", "n3", "ψ [rad]"),
    "centre": ("X1 of O [m]", "X2 of O [m]", "X3 of O [m]"),
}


def _val(true, n):
    return None if true is None else float(getattr(true, n)) if hasattr(true, n) else float(true[n])


def plot_fit(result, *, title: str = "", true=None, kind: str | None = None, channels: Sequence[int] | None = None):
    """Fitted (lines; windows of multiple shooting in alternating colours) vs measured (dots),
    plus the loss history and the relative parameter error per iteration."""
    import matplotlib.pyplot as plt

    from jaxcelt.identify.result import predict

    pred = predict(result)[0]
    kind = kind or next(iter(pred["data"]))
    chans = list(channels) if channels is not None else list(range(OBSERVABLES[kind]))[:4]
    fig, ax = plt.subplots(1, len(chans) + 1, figsize=(3.6 * (len(chans) + 1), 3.4), constrained_layout=True)
    ts, data, fitted = pred["ts"], pred["data"][kind], pred[kind]
    for j, c in enumerate(chans):
        a = ax[j]
        a.plot(ts.reshape(-1), data[..., c].reshape(-1), ".", ms=2.5, color="0.45", label="measured")
        for k in range(ts.shape[0]):
            a.plot(
                ts[k], fitted[k, :, c], lw=1.1, color=("tab:red", "tab:blue")[k % 2], label="fitted" if k == 0 else None
            )
        a.set(xlabel="t [s]", title=_CHANNELS[kind][c])
        if j == 0:
            a.legend(fontsize=8, loc="best")
    a = ax[-1]
    if true is not None:
        for n in result.free:
            err = [abs(h[n] - _val(true, n)) / abs(_val(true, n)) for h in result.param_history]
            a.semilogy(err, marker=".", label=n)
        a.axhline(0.01, color="k", ls=":", lw=0.8, label="1%")
        a.set(xlabel="iteration", ylabel="relative error", title="parameter error")
        a.legend(fontsize=8)
    else:
        a.semilogy(result.loss_history)
        a.set(xlabel="iteration", ylabel="loss", title="loss")
    fig.suptitle(title or f"{result.optimiser}, {result.windows} window(s)")
    return fig


def plot_loss_histories(results, labels: Sequence[str]):
    """Loss vs iteration and vs wall time for several fits of one problem."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for r, lab in zip(results, labels):
        h = np.maximum(np.asarray(r.loss_history), 1e-300)
        ax[0].semilogy(h, label=lab)
        t = np.linspace(0, r.wall_time, len(h))
        ax[1].semilogy(t, h, label=lab)
    ax[0].set(xlabel="iteration", ylabel="loss = ½|r|²", title="loss history")
    ax[1].set(xlabel="run time after compilation [s] (uniform per iteration)", ylabel="loss", title="loss vs time")
    for a in ax:
        a.legend(fontsize=8)
    return fig


def plot_parameter_traces(results, labels: Sequence[str], *, true=None):
    """Each free parameter against the iteration, one panel per parameter, one line per fit.

    With ``true``: the ratio fitted/true on a log axis clipped to [1/20, 20] (a diverging fit
    leaves the panel at the top or bottom edge instead of flattening the others)."""
    import matplotlib.pyplot as plt

    free = results[0].free
    fig, ax = plt.subplots(1, len(free), figsize=(3.4 * len(free), 3.4), constrained_layout=True)
    n_max = max(len(r.param_history) for r in results)
    for j, n in enumerate(free):
        a = np.atleast_1d(ax)[j]
        t = _val(true, n)
        for r, lab in zip(results, labels):
            v = np.asarray([h[n] for h in r.param_history], float)
            if t is not None:
                v = np.clip(np.nan_to_num(v / t, nan=20.0, posinf=20.0), 1 / 20, 20)
            a.plot(np.arange(1, len(v) + 1), v, label=lab, lw=1.2)
        if t is not None:
            a.axhline(1.0, color="k", ls="--", lw=0.8, label="true")
            a.set(yscale="log", ylim=(1 / 22, 22), ylabel="fitted / true" if j == 0 else None)
        a.set(xlabel="iteration + 1", title=n, xscale="log", xlim=(1, n_max))
        if j == 0:
            a.legend(fontsize=8)
    return fig


def plot_correlation(results, labels: Sequence[str]):
    """Correlation matrices of the free parameters (Gauss-Newton, at the optimum)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, len(results), figsize=(3.4 * len(results), 3.4), constrained_layout=True)
    for a, r, lab in zip(np.atleast_1d(ax), results, labels):
        c = np.asarray(r.corr)
        im = a.imshow(c, vmin=-1, vmax=1, cmap="RdBu_r")
        a.set_xticks(range(len(r.free)), r.free, rotation=45)
        a.set_yticks(range(len(r.free)), r.free)
        for i in range(c.shape[0]):
            for j in range(c.shape[1]):
                a.text(
                    j,
                    i,
                    f"{c[i, j]:.2f}",
                    ha="center",
                    va="center",
                    fontsize=8,
                    color="w" if abs(c[i, j]) > 0.6 else "k",
                )
        a.set_title(lab)
    fig.colorbar(im, ax=ax, shrink=0.8, label="correlation")
    return fig


def plot_coverage(rows, true, free: Sequence[str]):
    """95% intervals of every seed, centred on the true value, per parameter."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, len(free), figsize=(3.3 * len(free), 3.6), constrained_layout=True)
    for j, n in enumerate(free):
        a = ax[j]
        t = _val(true, n)
        for i, r in enumerate(rows):
            v, se = r["values"][n], r["stderr"][n]
            ok = abs(v - t) <= 1.96 * se
            a.errorbar(
                i, (v - t) / t * 100, yerr=1.96 * se / t * 100, fmt="o", ms=3, color="tab:blue" if ok else "tab:red"
            )
        a.axhline(0, color="k", lw=0.8)
        inside = np.mean([abs(r["values"][n] - t) <= 1.96 * r["stderr"][n] for r in rows])
        a.set(xlabel="seed", ylabel="(fit − true)/true [%]", title=f"{n}: {inside * 100:.0f}% inside")
    return fig


def plot_gradient_norm(T, grad_norm, lam, ts=None, log_tangent=None, *, window=None, lam_label="λ"):
    """|dL/dθ| vs window length with e^{λT} (matched at the median T), the multiple-shooting
    window length (``window`` [s], optional) and the tangent growth behind λ."""
    import matplotlib.pyplot as plt

    T, g = np.asarray(T), np.asarray(grad_norm)
    ncol = 2 if ts is not None else 1
    fig, ax = plt.subplots(1, ncol, figsize=(5.2 * ncol, 3.9), constrained_layout=True)
    a = np.atleast_1d(ax)[0]
    a.semilogy(T, g, "-", lw=1.4, label=r"$|\partial L/\partial\theta|$, single shooting on $[0, T]$")
    m = len(T) // 2
    a.semilogy(
        T,
        g[m] * np.exp(lam * (T - T[m])),
        "k--",
        lw=1,
        label=rf"$\propto e^{{\lambda T}}$, {lam_label} = {lam:.2f} 1/s",
    )
    if window is not None:
        a.axvline(window, color="tab:green", ls=":", label=f"multiple-shooting window ({window:.2f} s)")
    a.set(xlabel="record length T [s]", ylabel="gradient norm", title="gradient norm vs window length")
    a.legend(fontsize=8)
    if ts is not None:
        a = ax[1]
        a.plot(ts, log_tangent, label="log |δy(t)|")
        h = len(ts) // 2
        a.plot(
            ts[h:],
            log_tangent[h] + lam * (np.asarray(ts[h:]) - ts[h]),
            "k--",
            label=f"slope λ (2nd half) = {lam:.2f} 1/s",
        )
        a.set(xlabel="t [s]", ylabel="log |δy| (scaled)", title="tangent growth (finite-time Lyapunov)")
        a.legend(fontsize=8)
    return fig
