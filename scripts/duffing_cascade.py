"""Period-doubling cascade of the forced two-well Duffing oscillator by continuation and branch switching,
against a brute-force orbit diagram (scipy) -> docs/orbits/duffing_cascade.json and duffing_cascade.png.

x'' + 0.3 x' - x + x^3 = F cos(1.2 t), right-well orbits, F from 0.24 to 0.293. The period-1 branch is
continued in F (`continue_arclength`); at each period doubling the period-2k branch is started
by `switch_at_period_doubling` and continued in turn, up to period 8. Independently, scipy DOP853
integrates the oscillator over a grid of F (1000 transient periods, 64 section points, all F as one
vectorised system) and finds each orbit's period (1e-6). At each doubling found by continuation the
brute-force period must be k ten grid steps below and 2k above, and the brute-force onset of the
period-2k splitting (|x_{n+k} - x_n|^2 linear in F past a supercritical doubling, extrapolated to
zero) must agree with the located F_pd.

    python scripts/duffing_cascade.py [--grid 383]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import time

import jax.numpy as jnp
import numpy as np
from scipy.integrate import solve_ivp

from jaxcelt.orbits.branch import continue_arclength
from jaxcelt.orbits.switching import switch_at_period_doubling
from jaxcelt.provenance import load_average, write_result
from jaxcelt.versions import versions

ROOT = pathlib.Path(__file__).resolve().parents[1]
W, D = 1.2, 0.3
T = 2 * np.pi / W
F0, F1 = 0.24, 0.293


def duffing(t, y, p):
    d, f = p
    return jnp.stack([y[1], -d * y[1] + y[0] - y[0] ** 3 + f * jnp.cos(W * t)])


def args_of(F):
    return jnp.stack([D, F])


def period_of(a):
    return 2 * jnp.pi / W


def _rhs(F):
    return lambda t, y: [y[1], -D * y[1] + y[0] - y[0] ** 3 + F * np.cos(W * t)]


def brute_force(Fs, y0, transient=1000, sample=64, tol=1e-6):
    """Section points of every F after ``transient`` periods (scipy DOP853, rtol 1e-10, all F as one
    vectorised system started from ``y0``) and the smallest period p in (1, 2, 4, 8, 16) with
    max |x_{n+p} - x_n| < tol over the samples (0: none, i.e. aperiodic or not yet converged)."""
    Fs = np.asarray(Fs, float)
    n = len(Fs)

    def rhs(t, y):
        x, v = y[:n], y[n:]
        return np.concatenate([v, -D * v + x - x**3 + Fs * np.cos(W * t)])

    ts = T * np.arange(transient, transient + sample + 1)
    y = np.concatenate([np.full(n, y0[0]), np.full(n, y0[1])])
    s = solve_ivp(rhs, (0.0, ts[-1]), y, method="DOP853", rtol=1e-10, atol=1e-11, t_eval=ts)
    x = s.y[:n].T  # (samples, n)
    periods = np.zeros(n, int)
    for p in (16, 8, 4, 2, 1):
        ok = np.max(np.abs(x[p:] - x[:-p]), axis=0) < tol
        periods = np.where(ok, p, periods)
    return periods, x.T


def split_onset(Fs, x, k, lo, hi):
    """F where the period-2k splitting amplitude of the brute-force orbits vanishes: A = |x_{n+k} - x_n|
    grows like sqrt(F - F_pd) past a supercritical doubling, so A^2 is fitted linearly in F over the
    grid points in (lo, hi) and extrapolated to zero."""
    sel = (Fs > lo) & (Fs < hi)
    A2 = np.max(np.abs(x[sel, k:] - x[sel, :-k]), axis=1) ** 2
    c1, c0 = np.polyfit(Fs[sel], A2, 1)
    return float(-c0 / c1), int(sel.sum())


def cascade(levels=3):
    y = np.array([1.0, 0.0])
    s = solve_ivp(_rhs(F0), (0, 100 * T), y, method="DOP853", rtol=1e-11, atol=1e-12)
    y, lam, k = s.y[:, -1], F0, 1
    out, branches = [], []
    for _ in range(levels):
        t = time.perf_counter()
        br = continue_arclength(duffing, y, args_of, period_of, lam, F1, k=k, ds=0.005, ds_max=0.02)
        pd = [b for b in br.bifurcations if b.kind == "period-doubling"]
        branches.append({"k": k, "F": br.values.tolist(), "x": br.y[:, 0].tolist(), "stable": br.stable.tolist()})
        if not pd:
            break
        b = pd[0]
        out.append(
            {
                "k": k,
                "F_pd": float(b.value),
                "multiplier_nearest_minus_one": float(np.min(np.abs(b.multipliers + 1))),
                "seconds_branch_incl_compile": round(time.perf_counter() - t, 1),
            }
        )
        orb = switch_at_period_doubling(duffing, b, args_of, period_of, k=k, lam=b.value + 1e-4, eps=0.02)
        if int(orb.status) != 0:
            break
        y, lam, k = np.asarray(orb.y), b.value + 1e-4, 2 * k
    return out, branches


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=383, help="brute-force values of F in [0.255, 0.2932]")
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "docs/orbits")
    a = ap.parse_args(argv)
    load0 = load_average()
    t = time.perf_counter()
    pds, branches = cascade()
    t_cont = time.perf_counter() - t
    Fs = np.linspace(0.255, 0.2932, a.grid)
    t = time.perf_counter()
    periods, points = brute_force(Fs, [1.0, 0.0])
    t_brute = time.perf_counter() - t
    h = Fs[1] - Fs[0]
    for i, r in enumerate(pds):
        k, F = r["k"], r["F_pd"]
        # ten grid steps from the doubling (slow convergence next to it), fewer where the period-2k
        # window is narrow (its width estimated with Feigenbaum's 4.669 from the previous doubling)
        gap = (F - pds[i - 1]["F_pd"]) / 4.669 if i else 1.0
        d = max(2, min(10, int(gap / 3 / h))) * h
        r["brute_force_distance"] = float(d)
        below = periods[(Fs < F - d)][-3:]
        above = periods[(Fs > F + d)][:3]
        r["brute_force_periods_below"] = below.tolist()
        r["brute_force_periods_above"] = above.tolist()
        r["period_k_below_2k_above"] = bool(len(below) and len(above) and np.all(below == k) and np.all(above == 2 * k))
        nxt = pds[i + 1]["F_pd"] if i + 1 < len(pds) else Fs[-1]
        # the splitting fit over the first third of the period-2k window, skipping ten grid steps (slow convergence at the doubling)
        lo, hi = F + 10 * h, F + (nxt - F) / 3
        if hi - lo > 4 * h:
            onset, m = split_onset(Fs, points, k, lo, hi)
            r["brute_force_onset"] = onset
            r["brute_force_onset_points"] = m
            r["onset_difference"] = abs(onset - F)
    res = {
        "system": "x'' + 0.3 x' - x + x^3 = F cos(1.2 t), right well, continuation from F = 0.24 to 0.293",
        "period_doublings": pds,
        "ratios": [
            (pds[i]["F_pd"] - pds[i - 1]["F_pd"]) / (pds[i + 1]["F_pd"] - pds[i]["F_pd"])
            for i in range(1, len(pds) - 1)
        ],
        "grid_step": float(h),
        "seconds": {"continuation_incl_compile": round(t_cont, 1), "brute_force_scipy": round(t_brute, 1)},
        "load_average": list(os.getloadavg()),
        "versions": versions(),
        "branches": branches,
    }
    write_result(a.out / "duffing_cascade.json", res, load_at_start=load0)
    print(json.dumps({k: v for k, v in res.items() if k not in ("versions", "branches")}, indent=2))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 5), constrained_layout=True)
    ax.plot(np.repeat(Fs, points.shape[1]), points.ravel(), ",", color="0.5", alpha=0.8)
    ax.plot([], [], ".", color="0.5", label="scipy brute force (section points)")
    for b, c in zip(branches, ("tab:blue", "tab:orange", "tab:green", "tab:red"), strict=False):
        F, x, st = np.asarray(b["F"]), np.asarray(b["x"]), np.asarray(b["stable"])
        cut = np.flatnonzero(np.diff(st.astype(int))) + 1  # runs of equal stability, sharing end points
        for a0, a1 in zip(np.r_[0, cut], np.r_[cut, len(F) - 1], strict=True):
            seg = slice(a0, max(a1, a0 + 1) + 1)
            ax.plot(F[seg], x[seg], "-" if st[a0] else "--", color=c, lw=1.6 if st[a0] else 1.0)
        ax.plot([], [], "-", color=c, lw=1.6, label=f"period-{b['k']} branch (one section point)")
    for r in pds:
        ax.axvline(r["F_pd"], color="tab:red", lw=0.7, ls=":")
        ax.annotate(f"PD {r['F_pd']:.5f}", (r["F_pd"], ax.get_ylim()[1]), xytext=(2, -12), textcoords="offset points",
                    fontsize=7, rotation=90, va="top")  # fmt: skip
    ax.set(
        xlabel="forcing amplitude F",
        ylabel="x at t = kT",
        title="Duffing period-doubling cascade: continuation vs brute force",
    )
    ax.legend(fontsize=8, loc="lower left")
    fig.savefig(a.out / "duffing_cascade.png", dpi=130)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
