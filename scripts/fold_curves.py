"""The wobblestone's fold in two parameters: how far the onset of the period-1 family moves -> docs/orbits/fold_curves.json
and docs/orbits/fold_curves.png.

Starts from the fold of the period-1 branch that `scripts/orbit_branches.py` found by continuation
(docs/orbits/branches.json, 14.8801 rad/s at the paper's parameters) and follows it with
`jaxcelt.continue_orbit_bifurcation` in (omega_pi, q_pi) over the 100 x 60 map's box q_pi in [0.02, 0.06] and, for
the paper's question (a periodic bounded motion at 14 rad/s), in (omega_pi, eps = eps_R), (omega_pi, mu) and
(omega_pi, k_r). Each curve's start is refined at the paper's value of its second parameter, so it must equal the
located one-parameter fold (docs/orbits/celt_fold_grad.json) -- the check recorded per curve. Every finished curve
is written at once (a rerun skips curves already in the file unless ``--force``). Timings are indicative (load
average recorded): "to the first step" includes the compilation of the curve's corrector.

    python scripts/fold_curves.py [--only q_pi eps mu k_r] [--force] [--plot-only]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import time

import numpy as np

import jaxcelt as jc
from jaxcelt.orbits.curves import curve_to_dict
from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.provenance import write_result
from jaxcelt.versions import versions

ROOT = pathlib.Path(__file__).resolve().parents[1]
OUT = ROOT / "docs/orbits/fold_curves.json"
OMEGA_PAPER = 14.0
CHECK_TOL = 1e-4

# key -> (second parameter name, bounds of it, scale of it, initial step, largest step, points at most)
CURVES = {
    # q_pi: the decreasing end is limited to its first 6 points: from the point at q_pi = 0.0300 the next corrector
    # did not return within minutes (twice), so the curve is not followed below it
    "q_pi": ("q_pi", (0.02, 0.06), 0.01, 0.1, 0.4, 14),
    "eps": ("eps=eps_R", (1e-5, 1e-3), 1e-4, 0.1, 0.8, 31),
    "mu": ("mu", (0.1, 0.4), 0.02, 0.1, 0.6, 31),
    "k_r": ("k_r", (0.2, 0.8), 0.04, 0.1, 0.6, 31),
    # the increasing-q_pi end of the q_pi curve, continued from its last point (it stopped at its point limit)
    "q_pi_upper": ("q_pi", (0.02, 0.06), 0.01, 0.2, 0.6, 16),
    "q_pi_upper2": ("q_pi", (0.02, 0.06), 0.01, 0.2, 0.6, 8),
}
START_FROM = {"q_pi_upper": ("q_pi", 1), "q_pi_upper2": ("q_pi_upper", -1)}
"""a curve started from the last point of another (it stopped at its point limit), followed one way only"""
NOTES = {
    "q_pi": "the decreasing-q_pi end is capped at 6 points: in two runs the corrector step from the point at "
    "q_pi = 0.0300 (omega_pi bounds 10-20 rad/s, up to 8 Newton iterations of variational solves) did not return "
    "within minutes, so the curve below q_pi = 0.030 is not computed; the increasing end stopped at its point "
    "limit and is continued by q_pi_upper",
}
OMEGA_BOUNDS = (10.0, 20.0)
MAX_STEPS = 20_000
"""solver steps per map evaluation (a period takes far fewer; a corrector iterate that needs more is a failed step,
halved, rather than a minutes-long solve)"""


def fold_start() -> tuple[np.ndarray, float]:
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    br = next(iter(d["branches"].values()))["branch"]
    b = next(b for b in br["bifurcations"] if b["kind"] == "fold")
    return np.array([b["state"][n] for n in STATE_NAMES]), float(b["value"])


def located_fold() -> float:
    return float(json.loads((ROOT / "docs/orbits/celt_fold_grad.json").read_text())["omega_fold"])


def timed_fold_curve(key, p, y, name, bounds, scale, ds, ds_max, max_points, direction):
    """The fold curve in (omega_pi, ``name``) from (p, y), each point's time printed: (curve, point times, total)."""
    times: list[float] = []
    t0 = time.perf_counter()

    def cb(n, v, ok):
        times.append(time.perf_counter() - t0)
        print(f"  [{key}] point {n} {name} = {v:.6g} {'ok' if ok else 'retry'} ({times[-1]:.0f} s)", flush=True)

    curve = jc.continue_orbit_bifurcation(
        p, y, ("omega_pi", name), (OMEGA_BOUNDS, bounds), scale=(1.0, scale), ds=ds, ds_max=ds_max,
        max_points=max_points, max_steps=MAX_STEPS, callback=cb, direction=direction,
    )  # fmt: skip
    return curve, times, time.perf_counter() - t0


def run_curve(key: str, res: dict) -> dict:
    name, bounds, scale, ds, ds_max, max_points = CURVES[key]
    y, w = fold_start()
    p = jc.CeltParams.paper(omega_pi=w)
    direction, prev_end = 0, None
    if key in START_FROM:
        cd = res["curves"][START_FROM[key][0]]["curve"]
        j = len(cd[name]) - 1
        y, w, prev_end = np.asarray(cd["state"][j]), cd["omega_pi"][j], (cd["omega_pi"][j], cd[name][j])
        p = jc.CeltParams.paper(omega_pi=w, **{f: cd[name][j] for f in name.split("=")})
        direction = START_FROM[key][1]
    p0 = float(getattr(p, name.split("=")[0]))
    curve, times, total = timed_fold_curve(key, p, y, name, bounds, scale, ds, ds_max, max_points, direction)
    d = curve_to_dict(curve, ("omega_pi", name))
    i0 = curve.start
    om = np.asarray(curve.p1)
    lo = int(np.argmin(om))
    attempts = len(times)
    fold = located_fold()
    out = {
        "parameter": name,
        "paper_value": p0,
        "bounds": list(bounds),
        "scale": scale,
        "ds": ds,
        "ds_max": ds_max,
        "max_points": max_points,
        "points": len(om),
        "start_omega": float(om[i0]),
        "start_minus_located_fold": float(om[i0] - fold),
        "passes_through_fold": bool(abs(om[i0] - fold) <= CHECK_TOL),
        "range_reached": [float(np.min(curve.p2)), float(np.max(curve.p2))],
        "omega_range": [float(np.min(om)), float(np.max(om))],
        "lowest_fold": {"omega_pi": float(om[lo]), name: float(curve.p2[lo])},
        "fold_below_14": bool(np.min(om) <= OMEGA_PAPER),
        "max_abs_multiplier_minus_1": float(np.max(np.min(np.abs(curve.multipliers - 1.0), axis=1))),
        "seconds": {
            "to_first_step_incl_compile": round(times[0], 1) if times else None,
            "continuation_after_first_step": round(total - times[0], 1) if times else None,
            "total": round(total, 1),
            "corrector_attempts": attempts,
        },
        "curve": d,
    }
    if prev_end is not None:
        out["continues"] = START_FROM[key][0]
        out["start_minus_end_of_continued_curve"] = float(om[i0] - prev_end[0])
    return out


def stability_check(res: dict) -> dict:
    """The orbit past the fold at the paper's parameters: `jc.periodic_orbit` from the stable-sheet point of
    docs/orbits/branches.json nearest omega_fold + 0.1 rad/s, at that point's omega_pi."""
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    br = next(iter(d["branches"].values()))["branch"]
    fold = located_fold()
    cand = [i for i, st in enumerate(br["stable"]) if st and br["values"][i] < fold + 1.0]
    i = min(cand, key=lambda i: abs(br["values"][i] - fold - 0.1))
    w = float(br["values"][i])
    y = np.array([br["state"][n][i] for n in STATE_NAMES])
    t = time.perf_counter()
    o = jc.periodic_orbit(jc.CeltParams.paper(omega_pi=w), y, max_steps=MAX_STEPS)
    return {
        "omega_pi": w,
        "omega_minus_fold": w - fold,
        "status": int(o.status),
        "residual": float(o.residual),
        "multipliers_abs": [float(a) for a in np.abs(np.asarray(o.multipliers))],
        "stable": bool(o.stable),
        "seconds_incl_compile": round(time.perf_counter() - t, 1),
    }


def plot(res: dict, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [k for k in CURVES if k in res["curves"] and k not in START_FROM]
    fig, axes = plt.subplots(1, max(len(keys), 1), figsize=(4.2 * max(len(keys), 1), 3.8), squeeze=False)
    fold = res["located_fold_omega"]
    for ax, key in zip(axes[0], keys, strict=False):
        c = res["curves"][key]
        name = c["parameter"]
        cd = c["curve"]
        ax.plot(cd["omega_pi"], cd[name], ".-", lw=1, ms=3, color="C0", label="fold curve")
        for k2 in START_FROM:
            if res["curves"].get(k2, {}).get("parameter") == name:
                c2 = res["curves"][k2]["curve"]
                ax.plot(c2["omega_pi"], c2[name], ".-", lw=1, ms=3, color="C0")
                for pt in c2["points"]:
                    ax.plot([pt["omega_pi"]], [pt[name]], "ks", mfc="none", ms=7)
        ax.plot([fold], [c["paper_value"]], "r*", ms=10, label=f"one-parameter fold {fold:.4f}")
        ax.axvline(OMEGA_PAPER, color="k", ls="--", lw=0.8, label="ω_π = 14 rad/s")
        for pt in cd["points"]:
            ax.plot([pt["omega_pi"]], [pt[name]], "ks", mfc="none", ms=7)
            ax.annotate(pt["kind"], (pt["omega_pi"], pt[name]), fontsize=7)
        ax.axhspan(*c["bounds"], color="0.93", zorder=0)
        if name.startswith("eps"):
            ax.set_yscale("log")
        ax.set_xlabel("ω_π [rad/s]")
        ax.set_ylabel({"eps=eps_R": "ε = ε_R [s⁻²]", "q_pi": "q_π [m]"}.get(name, name))
        ax.set_title(f"fold in (ω_π, {name.split('=')[0]})", fontsize=10)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(
        "wobblestone: the fold of the period-1 family (a stable orbit and a saddle meet on it; squares: cusps)",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def summarise(res: dict) -> None:
    done = [k for k in CURVES if k in res["curves"]]
    below = {k: res["curves"][k]["fold_below_14"] for k in done}
    res["not_done"] = [k for k in CURVES if k not in done]
    res["fold_below_14_anywhere"] = any(below.values())
    lines = []
    for k in done:
        c = res["curves"][k]
        # an end that left the box is stored one step outside it: the ranges count the points inside the box only
        name, (b_lo, b_hi) = c["parameter"], c["bounds"]
        w_all, p_all = np.asarray(c["curve"]["omega_pi"]), np.asarray(c["curve"][name])
        inside = (p_all >= b_lo) & (p_all <= b_hi) & (w_all >= OMEGA_BOUNDS[0]) & (w_all <= OMEGA_BOUNDS[1])
        w_in, p_in = w_all[inside], p_all[inside]
        j = int(np.argmin(w_in))
        c["note"] = NOTES.get(k, "")
        if "continues" in c:  # started from another curve's end, not from the one-parameter fold
            c["passes_through_fold"] = None
        c["points_in_bounds"] = int(inside.sum())
        c["range_reached"] = [float(p_in.min()), float(p_in.max())]
        c["omega_range"] = [float(w_in.min()), float(w_in.max())]
        c["lowest_fold"] = {"omega_pi": float(w_in[j]), name: float(p_in[j])}
        c["fold_below_14"] = bool(w_in.min() <= OMEGA_PAPER)
        # d omega_fold / d p at the paper's value: central secant through the start's two neighbours on the curve
        om, pp, i = c["curve"]["omega_pi"], c["curve"][c["parameter"]], c["curve"]["start"]
        a, b = max(i - 1, 0), min(i + 1, len(om) - 1)
        c["domega_dp_at_start"] = (om[b] - om[a]) / (pp[b] - pp[a]) if b > a and pp[b] != pp[a] else None
        c["domega_dp_secant_points"] = [a, b]
        lo = c["lowest_fold"]
        lines.append(
            f"{c['parameter']} over [{c['range_reached'][0]:g}, {c['range_reached'][1]:g}]: lowest fold "
            f"{lo['omega_pi']:.4f} rad/s at {c['parameter']} = {lo[c['parameter']]:g}"
        )
    cusps = [
        f"the {res['curves'][k]['parameter']} curve has a cusp at omega_pi = {pt['omega_pi']:.4f}, "
        f"{res['curves'][k]['parameter']} = {pt[res['curves'][k]['parameter']]:.4f} (two folds meet, the curve turns back in "
        f"{res['curves'][k]['parameter']})"
        for k in done
        for pt in res["curves"][k]["curve"]["points"]
        if pt["kind"] == "cusp"
    ]
    if "orbits_near_the_q_curve_at_14" in res:
        stable = [o for o in res["orbits_near_the_q_curve_at_14"]["orbits"] if o["stable"]]
        res["stable_period1_orbit_at_14_established"] = bool(stable)
        res["stable_period1_orbit_at_14_note"] = (
            "folds of the (omega_pi, q_pi) curve lie below 14 rad/s for q_pi of about 0.046-0.049 m, with all other "
            "multipliers inside the unit circle; Newton from the fold orbits at 14 rad/s found "
            + (
                "a stable orbit"
                if stable
                else "saddles only, so a stable period-1 orbit at 14 rad/s is not established"
            )
        )
    res["answer"] = (
        ("a fold at or below 14 rad/s is reached" if res["fold_below_14_anywhere"] else
         "no fold on the computed curves lies at or below 14 rad/s")
        + "; " + "; ".join(lines + cusps)
    )  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", default=list(CURVES), choices=list(CURVES))
    ap.add_argument("--force", action="store_true")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--out", type=pathlib.Path, default=OUT)
    ap.add_argument("--no-stability", action="store_true", help="skip the orbit solve past the fold")
    ap.add_argument("--merge", nargs="*", type=pathlib.Path, default=[], help="result files of parallel runs")
    a = ap.parse_args(argv)
    res = json.loads(a.out.read_text()) if a.out.exists() else {}
    res.setdefault("curves", {})
    res.pop("provenance", None)
    if a.merge:
        load0 = None
        for f in a.merge:
            part = json.loads(f.read_text())
            load0 = load0 or part["load_average_start"]
            for k, v in part.items():
                if k == "curves":
                    res["curves"].update(v)
                elif k != "provenance":
                    res[k] = v
        res["load_average_start"] = load0
        res["merged_from_parallel_runs"] = len(a.merge)
        summarise(res)
        write_result(a.out, res, load_at_start=load0, indent=1)
    elif not a.plot_only:
        load0 = list(os.getloadavg())
        res.update(
            system="paper's stone (CeltParams.paper), fold of the period-1 family of the 15.6 rad/s orbit",
            located_fold_omega=located_fold(),
            check_tolerance=CHECK_TOL,
            omega_bounds=list(OMEGA_BOUNDS),
            max_steps=MAX_STEPS,
            load_average_start=load0,
        )
        for key in a.only:
            if key in res["curves"] and not a.force:
                continue
            print(f"curve {key}", flush=True)
            res["curves"][key] = run_curve(key, res)
            summarise(res)
            write_result(a.out, res, load_at_start=load0, indent=1)
            res.pop("provenance", None)
        if not a.no_stability and ("stability_past_fold" not in res or a.force):
            res["stability_past_fold"] = stability_check(res)
        res["load_average_end"] = list(os.getloadavg())
        res["versions"] = versions()
        summarise(res)
        write_result(a.out, res, load_at_start=load0, indent=1)
    plot(res, a.out.with_suffix(".png"))
    print(json.dumps({k: v for k, v in res.items() if k not in ("curves", "versions", "provenance")}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
