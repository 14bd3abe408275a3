"""Period-doubling cascade of the forced two-well Duffing oscillator by continuation and branch switching,
against a brute-force orbit diagram (scipy) -> docs/orbits/duffing_cascade.json and duffing_cascade.png.

x'' + 0.3 x' - x + x^3 = F cos(1.2 t), right-well orbits, F from 0.24. The period-1 branch is
continued in F (`continue_pseudo_arclength`); at each period doubling the period-2k branch is started
by `switch_at_period_doubling` and continued in turn, up to period 8. Independently, scipy DOP853
integrates the oscillator over a grid of F (each F started from the previous one's end state,
400 transient periods, 64 section points) and counts the distinct section points (1e-5). Each doubling
found by continuation must fall where that count doubles (within one grid step).

    python scripts/duffing_cascade.py [--grid 241]
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

from jaxcelt.orbit_continuation import continue_pseudo_arclength, switch_at_period_doubling
from jaxcelt.versions import versions

ROOT = pathlib.Path(__file__).resolve().parents[1]
W, D = 1.2, 0.3
T = 2 * np.pi / W
F0, F1 = 0.24, 0.29


def duffing(t, y, p):
    d, f = p
    return jnp.stack([y[1], -d * y[1] + y[0] - y[0] ** 3 + f * jnp.cos(W * t)])


def args_of(F):
    return jnp.stack([D, F])


def period_of(a):
    return 2 * jnp.pi / W


def _rhs(F):
    return lambda t, y: [y[1], -D * y[1] + y[0] - y[0] ** 3 + F * np.cos(W * t)]


def brute_force(Fs, y0, transient=400, sample=64, tol=1e-5):
    """Distinct section points per F (scipy DOP853, rtol 1e-10), each F from the previous end state."""
    counts, points, y = [], [], np.asarray(y0, float)
    for F in Fs:
        s = solve_ivp(_rhs(F), (0, transient * T), y, method="DOP853", rtol=1e-10, atol=1e-11)
        y = s.y[:, -1]
        ts = T * np.arange(transient, transient + sample + 1)
        s = solve_ivp(_rhs(F), (transient * T, ts[-1]), y, method="DOP853", rtol=1e-10, atol=1e-11, t_eval=ts)
        sec = s.y.T
        y = sec[-1]
        distinct = []
        for pt in sec:
            if not any(np.max(np.abs(pt - q)) < tol for q in distinct):
                distinct.append(pt)
        counts.append(len(distinct) if len(distinct) <= 16 else 0)  # 0: more than 16 (aperiodic)
        points.append(sec[:, 0])
    return np.asarray(counts), np.asarray(points)


def cascade(levels=3):
    y = np.array([1.0, 0.0])
    s = solve_ivp(_rhs(F0), (0, 100 * T), y, method="DOP853", rtol=1e-11, atol=1e-12)
    y, lam, k = s.y[:, -1], F0, 1
    out, branches = [], []
    for _ in range(levels):
        t = time.perf_counter()
        br = continue_pseudo_arclength(duffing, y, args_of, period_of, lam, F1, k=k, ds=0.005, ds_max=0.02)
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
    ap.add_argument("--grid", type=int, default=241, help="brute-force values of F in [0.24, 0.29]")
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "docs/orbits")
    a = ap.parse_args(argv)
    t = time.perf_counter()
    pds, branches = cascade()
    t_cont = time.perf_counter() - t
    Fs = np.linspace(F0, F1, a.grid)
    t = time.perf_counter()
    counts, points = brute_force(Fs, [1.0, 0.0])
    t_brute = time.perf_counter() - t
    h = Fs[1] - Fs[0]
    for r in pds:
        below = counts[(Fs < r["F_pd"] - h) & (Fs > r["F_pd"] - 2 * h)]
        above = counts[(Fs > r["F_pd"] + h) & (Fs < r["F_pd"] + 2 * h)]
        r["brute_force_count_below"] = int(below[0]) if len(below) else None
        r["brute_force_count_above"] = int(above[0]) if len(above) else None
        # first grid value at which the brute-force count exceeds k (the doubling seen by brute force)
        first = Fs[np.argmax((counts > r["k"]) | (counts == 0))]
        r["brute_force_first_F_above_k"] = float(first)
        r["agrees_within_grid_step"] = bool(abs(first - r["F_pd"]) <= h)
    res = {
        "system": "x'' + 0.3 x' - x + x^3 = F cos(1.2 t), right well, F in [0.24, 0.29]",
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
    (a.out / "duffing_cascade.json").write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps({k: v for k, v in res.items() if k not in ("versions", "branches")}, indent=2))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 5), constrained_layout=True)
    ax.plot(np.repeat(Fs, points.shape[1]), points.ravel(), ",", color="0.5", alpha=0.8)
    ax.plot([], [], ".", color="0.5", label="scipy brute force (section points)")
    for b, c in zip(branches, ("tab:blue", "tab:orange", "tab:green", "tab:red"), strict=False):
        F, x, st = np.asarray(b["F"]), np.asarray(b["x"]), np.asarray(b["stable"])
        ax.plot(np.where(st, F, np.nan), np.where(st, x, np.nan), "-", color=c, lw=1.6, label=f"period-{b['k']} branch")
        ax.plot(np.where(~st, F, np.nan), np.where(~st, x, np.nan), "--", color=c, lw=1.0)
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
