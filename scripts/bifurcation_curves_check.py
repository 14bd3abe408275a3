"""Check two-parameter continuation of bifurcation points (`jaxcelt.continue_bifurcation`) on known answers.

* Mathieu x'' + (a - 2 q cos 2t) x = 0 (period pi): the period-doubling curve of the trivial orbit (a multiplier
  -1 of the pi-map) is the lower edge a = b1(q) of the first instability tongue. Continued in (a, q) from
  q = 0.1 both ways until q leaves [0.02, 5.2]; a along the curve against `scipy.special.mathieu_b(1, q)` at the
  curve points, and at 101 values of q in [0.02, 5] by cubic interpolation along the curve.
* Forced Duffing x'' + 0.2 x' + x + x^3 = F cos(w t): the fold curve of period-1 orbits in (w, F), from the upper
  fold at F = 0.3, through its cusp (the zero of the fold's normal-form coefficient) and back up the other fold
  branch. Checked with scipy only (solve_ivp DOP853, no JAX, no Newton): at points in the middle of the fold wedge
  two distinct stable period-1 orbits are reached from a grid of starts, at points outside it one.

Times: the first call (compilation included) and a second, compiled one. Writes
docs/orbits/curves_known_answers.json and docs/orbits/curves_known_answers.png.

    python scripts/bifurcation_curves_check.py [--out docs/orbits/curves_known_answers.json]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import jax.numpy as jnp
import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline
from scipy.special import mathieu_b

import jaxcelt as jc
from jaxcelt.provenance import load_average, write_result

ROOT = Path(__file__).resolve().parents[1]

MATHIEU_Q0, MATHIEU_Q = 0.1, (0.02, 5.2)
MATHIEU_COMPARE = (0.02, 5.0)
DELTA, F_START = 0.2, 0.3
DUFFING_BOUNDS = ((0.5, 3.0), (0.02, 0.5))
STEP = dict(ds=0.05, ds_max=0.2)
STEP_DUFFING = dict(ds=0.02, ds_max=0.05)
CENSUS_F = (0.25, 0.35, 0.45)
CENSUS_STARTS = [(x, v) for x in (-1.5, -0.5, 0.5, 1.5) for v in (-1.0, 1.0)]
CENSUS_PERIODS = 500


def mathieu(t, y, p):
    a, q = p
    return jnp.stack([y[1], -(a - 2 * q * jnp.cos(2 * t)) * y[0]])


def duffing(t, y, p):
    w, F = p
    return jnp.stack([y[1], -DELTA * y[1] - y[0] - y[0] ** 3 + F * jnp.cos(w * t)])


def mathieu_args(a, q):
    return (a, q)


def duffing_args(w, F):
    return (w, F)


def pi_period(p):
    return jnp.pi


def duffing_period(p):
    return 2 * jnp.pi / p[0]


def _timed(f):
    t = time.perf_counter()
    first = f()
    t_first = time.perf_counter() - t
    t = time.perf_counter()
    f()
    return first, t_first, time.perf_counter() - t


def mathieu_curve():
    q0 = MATHIEU_Q0

    def run():
        return jc.continue_bifurcation(
            mathieu, jnp.zeros(2), mathieu_args, pi_period, (1 - q0 - q0**2 / 8, q0),
            ((-10.0, 2.0), MATHIEU_Q), kind="period-doubling", detect=("fold-flip",), **STEP,
        )  # fmt: skip

    c, t_first, t_run = _timed(run)
    inside = (c.p2 >= MATHIEU_COMPARE[0]) & (c.p2 <= MATHIEU_COMPARE[1])
    ref = mathieu_b(1, c.p2)
    dev_points = np.abs(c.p1 - ref)[inside]
    order = np.argsort(c.p2)
    spline = CubicSpline(c.p2[order], c.p1[order])
    qs = np.linspace(*MATHIEU_COMPARE, 101)
    dev_interp = np.abs(spline(qs) - mathieu_b(1, qs))
    return c, dict(
        start_q=q0,
        q_range=list(MATHIEU_COMPARE),
        points=int(len(c.p1)),
        points_compared=int(inside.sum()),
        max_abs_deviation_at_points=float(dev_points.max()),
        max_rel_deviation_at_points=float((dev_points / np.abs(ref[inside])).max()),
        max_abs_deviation_interpolated=float(dev_interp.max()),
        max_multiplier_distance_from_minus_1=float(np.min(np.abs(c.multipliers + 1), axis=1).max()),
        fold_flip_points=len(c.points),
        stopped=list(c.stopped),
        status_counts={str(s): int((c.status == s).sum()) for s in (0, 1, 2)},
        time_first_s=t_first,
        time_compiled_s=t_run,
        q=c.p2.tolist(),
        a=c.p1.tolist(),
    )


def _hb_fold(F):
    """A fold of the period-1 response by harmonic balance (x = a cos wt + b sin wt): the start guess."""
    A = np.linspace(0.3, 3.0, 200001)
    K = 1 + 0.75 * A**2
    disc = (2 * K - DELTA**2) ** 2 - 4 * (K**2 - F**2 / A**2)
    w = np.sqrt(((2 * K - DELTA**2) + np.sqrt(np.maximum(disc, 0.0))) / 2)
    w = np.where(disc > 0, w, np.nan)
    i = int(np.nanargmax(w))  # the upper (jump-down) fold: the largest w on the large-amplitude sheet
    a_, w_ = A[i], w[i]
    r = 1 - w_**2 + 0.75 * a_**2
    a, b = np.linalg.solve([[r, DELTA * w_], [-DELTA * w_, r]], [F, 0.0])
    return float(w_), np.array([a, w_ * b])


def duffing_curve():
    w0, y0 = _hb_fold(F_START)

    def run():
        return jc.continue_bifurcation(
            duffing, jnp.asarray(y0), duffing_args, duffing_period, (w0, F_START),
            DUFFING_BOUNDS, kind="fold", **STEP_DUFFING,
        )  # fmt: skip

    return _timed(run)


def fold_branches(c):
    """The two fold branches of the curve (either side of the cusp), each as F -> w (increasing F)."""
    cusp = [p for p in c.points if p.kind == "cusp"][0]
    i = cusp.bracket[1]
    a = (c.p2[:i][::-1], c.p1[:i][::-1])
    b = (c.p2[i:], c.p1[i:])
    return cusp, a, b


def census(w, F):
    """Distinct stable period-1 orbits reached from `CENSUS_STARTS` (scipy DOP853, all starts as one system)."""
    T = 2 * np.pi / w
    n = len(CENSUS_STARTS)

    def rhs(t, Y):
        x, v = Y[:n], Y[n:]
        return np.concatenate([v, -DELTA * v - x - x**3 + F * np.cos(w * t)])

    y0 = np.concatenate([[s[0] for s in CENSUS_STARTS], [s[1] for s in CENSUS_STARTS]])
    ts = T * np.array([CENSUS_PERIODS - 1, CENSUS_PERIODS])
    sol = solve_ivp(rhs, (0, ts[-1]), y0, method="DOP853", rtol=1e-10, atol=1e-11, t_eval=ts)
    last, prev = sol.y[:, -1].reshape(2, n).T, sol.y[:, -2].reshape(2, n).T
    settled = np.max(np.abs(last - prev), axis=1) < 1e-6
    orbits: list[np.ndarray] = []
    for y in last[settled]:
        if not any(np.max(np.abs(y - o)) < 1e-4 for o in orbits):
            orbits.append(y)
    return len(orbits), int(settled.sum()), [o.tolist() for o in orbits]


def census_points(c):
    cusp, (Fa, wa), (Fb, wb) = fold_branches(c)
    rows = []
    for F in CENSUS_F:
        w1, w2 = sorted((float(np.interp(F, Fa, wa)), float(np.interp(F, Fb, wb))))
        width = w2 - w1
        for where, w in (("inside", 0.5 * (w1 + w2)), ("outside", w1 - 0.5 * width), ("outside", w2 + 0.5 * width)):
            count, settled, ys = census(w, F)
            rows.append(dict(where=where, omega=w, F=F, folds=[w1, w2], orbits=count, settled=settled, states=ys))
    # below the cusp: one orbit
    for w in (cusp.p1 - 0.05, cusp.p1, cusp.p1 + 0.05):
        count, settled, ys = census(w, 0.8 * cusp.p2)
        rows.append(dict(where="outside", omega=w, F=0.8 * cusp.p2, folds=None, orbits=count, settled=settled,
                         states=ys))  # fmt: skip
    return rows


def figure(path, mc, dc, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    qs = np.linspace(0.0, 5.2, 300)
    ax1.plot(qs, mathieu_b(1, qs), "k-", lw=3, alpha=0.3, label="scipy mathieu_b(1, q)")
    ax1.plot(mc.p2, mc.p1, "C0.-", ms=4, lw=1, label="period-doubling curve (continue_bifurcation)")
    ax1.set_xlabel("q")
    ax1.set_ylabel("a")
    ax1.set_title("Mathieu: lower edge of the first tongue")
    ax1.set_xlim(0, 5.3)
    ax1.legend(fontsize=9)
    ax1.grid(alpha=0.3)

    ax2.plot(dc.p1, dc.p2, "C0.-", ms=4, lw=1, label="fold curve of period-1 orbits")
    for p in dc.points:
        if p.kind == "cusp":
            ax2.plot(p.p1, p.p2, "r*", ms=14, label=f"cusp (w = {p.p1:.4f}, F = {p.p2:.4f})")
    for two, marker, label in ((True, "s", "scipy: 2 stable period-1 orbits"), (False, "o", "scipy: 1 stable orbit")):
        pts = [(r["omega"], r["F"]) for r in rows if (r["orbits"] == 2) == two]
        if pts:
            ax2.plot(*np.array(pts).T, marker, mfc="none", ms=8, color="C2" if two else "C1", ls="", label=label)
    ax2.set_xlabel("forcing frequency w")
    ax2.set_ylabel("forcing amplitude F")
    ax2.set_title(f"Duffing x'' + {DELTA} x' + x + x³ = F cos wt")
    ax2.set_xlim(1.0, 2.0)
    ax2.set_ylim(0.0, 0.5)
    ax2.legend(fontsize=8, loc="upper left")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(ROOT / "docs/orbits/curves_known_answers.json"))
    args = ap.parse_args()
    load = load_average()
    mc, mathieu_result = mathieu_curve()
    print({k: v for k, v in mathieu_result.items() if k not in ("q", "a")})
    dc, t_first, t_run = duffing_curve()
    cusp = [p for p in dc.points if p.kind == "cusp"]
    print("duffing:", len(dc.p1), dc.stopped, [(p.kind, p.p1, p.p2, p.test, p.converged) for p in dc.points])
    t = time.perf_counter()
    rows = census_points(dc)
    t_census = time.perf_counter() - t
    for r in rows:
        print(r["where"], round(r["omega"], 4), round(r["F"], 4), r["orbits"], r["settled"])
    inside = [r["orbits"] for r in rows if r["where"] == "inside"]
    outside = [r["orbits"] for r in rows if r["where"] == "outside"]
    duffing_result = dict(
        params=dict(delta=DELTA, alpha=1.0, beta=1.0),
        start=dict(F=F_START),
        points=int(len(dc.p1)),
        stopped=list(dc.stopped),
        status_counts={str(s): int((dc.status == s).sum()) for s in (0, 1, 2)},
        cusp=[
            dict(
                omega=p.p1,
                F=p.p2,
                test=p.test,
                converged=p.converged,
                multipliers=[float(m.real) for m in p.multipliers],
            )
            for p in cusp
        ],  # fmt: skip
        other_points=[dict(kind=p.kind, omega=p.p1, F=p.p2) for p in dc.points if p.kind != "cusp"],
        min_F_on_curve=float(dc.p2.min()),
        max_multiplier_distance_from_1=float(np.min(np.abs(dc.multipliers - 1), axis=1).max()),
        time_first_s=t_first,
        time_compiled_s=t_run,
        census=dict(
            starts=CENSUS_STARTS,
            periods=CENSUS_PERIODS,
            rows=rows,
            inside_counts=inside,
            outside_counts=outside,
            time_s=t_census,
        ),  # fmt: skip
        omega=dc.p1.tolist(),
        F=dc.p2.tolist(),
        cusp_test=dc.tests["cusp"].tolist(),
    )
    out = Path(args.out)
    write_result(out, dict(mathieu=mathieu_result, duffing=duffing_result), load_at_start=load)
    figure(out.with_suffix(".png"), mc, dc, rows)
    print("wrote", out, out.with_suffix(".png"))


if __name__ == "__main__":
    main()
