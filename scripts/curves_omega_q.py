"""The wobblestone's fold and Neimark-Sacker curves in (omega_pi, q_pi), both mirror orbits, over the 100 x 60 map's
box -> docs/orbits/curves_omega_q.json and docs/orbits/curves_omega_q.png.

Starts from the fold and the Neimark-Sacker (NS) point of each of the two period-1 branches of
`scripts/orbit_branches.py` (docs/orbits/branches.json: the mirror pair psi and psi + pi of the 15.6 rad/s orbit)
and follows each with `jaxcelt.continue_orbit_bifurcation` in (omega_pi, q_pi) over the box of the committed map
(docs/map/map_omega_q_100x60.json: omega_pi 10-20 rad/s, q_pi 0.02-0.06 m). Each curve's start is refined at the
paper's q_pi = 0.04 m with omega_pi free, so it must equal the one-parameter point there: the located fold
(docs/orbits/celt_fold_grad.json, 14.8798 rad/s) and the bisected NS point of the branch (branches.json, 17.7475
rad/s); the difference is recorded per curve (tolerance `CHECK_TOL`). Curves are capped at a few points each (a
step costs tens of seconds of variational solves on a 2-core CPU); what is not reached is said in "not_done".
The fold curve is not followed below q_pi = 0.030 m: from its point there (q_pi = 0.03003 m) the next corrector did
not return within minutes, in two runs of scripts/fold_curves.py and in a run of this script (17-point fold curves,
stopped after 4 minutes on that step); the fold pieces here are capped above that point.

The figure draws the curves over the map's regime panel: the map's dataset (out/map_100x60/sweep.nc, not
committed) is made with the map's own command (its JSON "argv") when absent.

    python scripts/curves_omega_q.py [--only ns_a fold_a ...] [--out FILE] [--merge A.json B.json ...]
                                     [--plot-only]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

import jaxcelt as jc
from jaxcelt.orbits.curves import curve_to_dict
from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.provenance import write_result

ROOT = pathlib.Path(__file__).resolve().parents[1]
OUT = ROOT / "docs/orbits/curves_omega_q.json"
MAP_JSON = ROOT / "docs/map/map_omega_q_100x60.json"
MAP_NC = ROOT / "out/map_100x60/sweep.nc"
CHECK_TOL = 1e-4
BOUNDS = ((10.0, 20.0), (0.02, 0.06))
SCALE = (1.0, 0.01)
MAX_STEPS = 20_000
"""solver steps per map evaluation (a corrector iterate that needs more is a failed step, halved)"""

# key -> (kind, branch index in branches.json, points at most, initial step, largest step)
CURVES = {
    "ns_a": ("neimark-sacker", 0, 16, 0.1, 0.5),
    "ns_b": ("neimark-sacker", 1, 16, 0.1, 0.5),
    "fold_a": ("fold", 0, 7, 0.1, 0.4),
    "fold_b": ("fold", 1, 7, 0.1, 0.4),
    "ns_a_lower": ("neimark-sacker", 0, 12, 0.1, 0.5),
    "ns_b_lower": ("neimark-sacker", 1, 12, 0.1, 0.5),
    "fold_a_upper": ("fold", 0, 10, 0.2, 0.6),
    "fold_b_upper": ("fold", 1, 10, 0.2, 0.6),
}
START_FROM = {
    "ns_a_lower": ("ns_a", 0, -1),
    "ns_b_lower": ("ns_b", 0, -1),
    "fold_a_upper": ("fold_a", -1, 1),
    "fold_b_upper": ("fold_b", -1, 1),
}
"""a curve continued from an end point of another (which stopped at its point limit): (curve, point index,
direction in q_pi)"""
DETECT = {"neimark-sacker": None, "fold": ("1:1 resonance", "fold-flip")}
"""codimension-two points detected (None: all of CODIM2_TESTS; the fold's cusp is left out: its extra derivative
costs a second compilation)"""


def branch_points() -> list[dict]:
    """Per branch of branches.json: its name and the state and value of its fold and its NS point."""
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    out = []
    for name, b in d["branches"].items():
        bif = {x["kind"]: x for x in b["branch"]["bifurcations"]}
        out.append({
            "name": name,
            **{k: (np.array([bif[n]["state"][s] for s in STATE_NAMES]), float(bif[n]["value"]))
               for k, n in (("fold", "fold"), ("neimark-sacker", "Neimark-Sacker"))},
        })  # fmt: skip
    return out


def one_parameter_value(kind: str, branch: dict) -> tuple[float, str]:
    """The one-parameter point the curve must pass at q_pi = 0.04 and where it comes from."""
    if kind == "fold":
        v = float(json.loads((ROOT / "docs/orbits/celt_fold_grad.json").read_text())["omega_fold"])
        return v, "docs/orbits/celt_fold_grad.json omega_fold (Newton on the bordered system, branch psi 118.3 deg)"
    return branch["neimark-sacker"][1], "docs/orbits/branches.json: bisection on max |mu| - 1 on this branch"


def run_curve(key: str, res: dict) -> dict:
    kind, ib, max_points, ds, ds_max = CURVES[key]
    branch = branch_points()[ib]
    y, w = branch[kind]
    p, direction = jc.CeltParams.paper(omega_pi=w), 0
    if key in START_FROM:
        src, idx, direction = START_FROM[key]
        cd = res["curves"][src]["curve"]
        y, w = np.asarray(cd["state"][idx]), cd["omega_pi"][idx]
        p = jc.CeltParams.paper(omega_pi=w, q_pi=cd["q_pi"][idx])
    attempts, t0, first = [0], time.time(), [None]

    def cb(n, q, ok):
        attempts[0] += 1
        if first[0] is None:
            first[0] = time.time() - t0
        print(f"  {key}: point {n} q_pi {q:.5f} {'ok' if ok else 'retry'} ({time.time() - t0:.0f} s)", flush=True)

    c = jc.continue_orbit_bifurcation(
        p, y, ("omega_pi", "q_pi"), BOUNDS, kind=kind, direction=direction, scale=SCALE, ds=ds, ds_max=ds_max,
        max_points=max_points,
        detect=DETECT[kind], callback=cb, max_steps=MAX_STEPS,
    )  # fmt: skip
    total = time.time() - t0
    ref, source = one_parameter_value(kind, branch)
    i = c.start
    if key in START_FROM:  # a continuation: its start is the other curve's end point, refined again
        ref, source = w, f"{START_FROM[key][0]}'s end point (this curve continues it)"
    rec = {
        "kind": kind,
        "branch": branch["name"],
        "start_value_one_parameter": w,
        "one_parameter_point": ref,
        "one_parameter_source": source,
        "curve_at_q_0_04": float(c.p1[i]),
        "q_at_start": float(c.p2[i]),
        "continues": START_FROM.get(key, [None])[0],
        "curve_minus_one_parameter": float(c.p1[i] - ref),
        "passes_through_point": bool(
            abs(c.p1[i] - ref) < CHECK_TOL and (key in START_FROM or abs(c.p2[i] - 0.04) < 1e-12)
        ),
        "points": len(c.p1),
        "max_points": max_points,
        "ds": ds,
        "ds_max": ds_max,
        "q_range": [float(c.p2.min()), float(c.p2.max())],
        "omega_range": [float(c.p1.min()), float(c.p1.max())],
        "stopped": list(c.stopped),
        "located_points": [(pt.kind, pt.p1, pt.p2, pt.converged) for pt in c.points],
        "seconds": {
            "to_first_step_incl_compile": round(first[0] or total, 1),
            "total": round(total, 1),
            "corrector_attempts": attempts[0],
        },  # fmt: skip
        "curve": curve_to_dict(c, ("omega_pi", "q_pi")),
    }
    if kind == "neimark-sacker":
        mu = np.abs(c.multipliers)
        pair = np.sort(np.abs(mu - 1.0), axis=1)[:, :2]
        rec["max_abs_pair_modulus_minus_1"] = float(np.max(pair[np.abs(c.kappa) <= 1.0])) if np.any(
            np.abs(c.kappa) <= 1.0) else None  # fmt: skip
        rec["theta_range"] = [float(np.nanmin(c.theta)), float(np.nanmax(c.theta))]
        rec["max_other_modulus"] = float(np.max(np.sort(mu, axis=1)[:, :-2]))
    else:
        rec["max_abs_multiplier_minus_1"] = float(np.max(np.min(np.abs(c.multipliers - 1.0), axis=1)))
    return rec


def known_answers() -> dict:
    """The Neimark-Sacker continuation on two problems with answers we did not compute (as tests/test_ns_curves.py
    checks them): a linear oscillator (exact: zeta = 0, kappa = cos(w0 T), 1:k at w0 T = 2 pi m / k) and a forced
    van der Pol oscillator against scipy's integration of its variational equations."""
    import jax.numpy as jnp
    from scipy.integrate import solve_ivp

    def osc(t, y, a):
        zeta, w = a
        return jnp.stack([y[1], -2.0 * zeta * y[1] - y[0] + 0.3 * jnp.cos(w * t)])

    t0 = time.time()
    c = jc.continue_bifurcation(
        osc, jnp.zeros(2), lambda z, w: (z, w), lambda a: 2 * jnp.pi / a[1], (0.01, 1.3), ((-0.5, 0.5), (1.05, 4.5)),
        kind="neimark-sacker", ds=0.05, ds_max=0.25, max_points=120,
    )  # fmt: skip
    exact = {"1:3 resonance": (1.5, 3.0), "1:4 resonance": (4 / 3, 4.0)}
    lin = {
        "system": "x'' + 2 zeta x' + x = 0.3 cos(w t), curve in (zeta, w), w from 1.05 to 4.5",
        "points": len(c.p1),
        "max_abs_zeta": float(np.max(np.abs(c.p1))),
        "max_abs_kappa_minus_cos_2pi_over_w": float(np.max(np.abs(c.kappa - np.cos(2 * np.pi / c.p2)))),
        "resonances": [
            {
                "kind": pt.kind,
                "w": pt.p2,
                "exact": min(exact[pt.kind], key=lambda w: abs(w - pt.p2)),
                "converged": pt.converged,
            }
            for pt in c.points
        ],  # fmt: skip
        "seconds_incl_compile": round(time.time() - t0, 1),
    }
    lin["max_abs_resonance_error"] = max(abs(r["w"] - r["exact"]) for r in lin["resonances"])
    mu_v = 0.5

    def vdp(t, y, a):
        w, F = a
        return jnp.stack([y[1], mu_v * (1.0 - y[0] ** 2) * y[1] - y[0] + F * jnp.cos(w * t)])

    def scipy_monodromy(y0, w, F):
        def rhs(t, s):
            x, v = s[0], s[1]
            J = np.array([[0.0, 1.0], [-2.0 * mu_v * x * v - 1.0, mu_v * (1.0 - x**2)]])
            return np.concatenate(
                [[v, mu_v * (1 - x**2) * v - x + F * np.cos(w * t)], (J @ s[2:].reshape(2, 2)).ravel()]
            )

        sol = solve_ivp(rhs, (0.0, 2 * np.pi / w), np.concatenate([y0, np.eye(2).ravel()]), method="DOP853",
                        rtol=1e-11, atol=1e-12)  # fmt: skip
        return sol.y[:2, -1], sol.y[2:, -1].reshape(2, 2)

    t0 = time.time()
    c = jc.continue_bifurcation(
        vdp, jnp.array([-1.3383, -0.7657]), lambda w, F: (w, F), lambda a: 2 * jnp.pi / a[0], (1.27, 1.0),
        ((0.8, 2.5), (0.4, 2.2)), kind="neimark-sacker", ds=0.05, ds_max=0.2, max_points=60,
    )  # fmt: skip
    secs = round(time.time() - t0, 1)
    mod, ang, ret = [], [], []
    for i in np.nonzero(np.abs(c.kappa) < 1.0)[0]:
        y1, M = scipy_monodromy(c.y[i], c.p1[i], c.p2[i])
        mu = np.linalg.eigvals(M)
        ret.append(float(np.max(np.abs(y1 - c.y[i]))))
        mod.append(float(np.max(np.abs(np.abs(mu) - 1.0))))
        ang.append(float(abs(abs(np.angle(mu[0])) - np.arccos(c.kappa[i]))))
    res_pts = []
    for pt in c.points:
        if pt.kind in ("1:1 resonance", "1:3 resonance", "1:4 resonance"):
            k = int(pt.kind[2])
            _, M = scipy_monodromy(pt.y, pt.p1, pt.p2)
            theta = float(np.max(np.abs(np.angle(np.linalg.eigvals(M)))))
            res_pts.append({"kind": pt.kind, "w": pt.p1, "F": pt.p2, "converged": pt.converged, "scipy_theta": theta,
                            "theta_minus_2pi_over_k": theta - (2 * np.pi / k if k > 1 else 0.0)})  # fmt: skip
    vdp_rec = {
        "system": "x'' - 0.5 (1 - x^2) x' + x = F cos(w t), curve in (w, F) from w ~ 1.27, F = 1",
        "points": len(c.p1),
        "ns_points_checked": len(mod),
        "scipy_max_return_error": max(ret),
        "scipy_max_abs_modulus_minus_1": max(mod),
        "scipy_max_angle_minus_arccos_kappa": max(ang),
        "resonances": res_pts,
        "seconds_incl_compile": secs,
    }
    return {"linear_oscillator": lin, "forced_van_der_pol": vdp_rec}


def plot(res: dict, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import xarray as xr

    from jaxcelt.plotting.map import map_figure

    if not MAP_NC.exists():
        argv = json.loads(MAP_JSON.read_text())["argv"]
        cmd = [sys.executable, "-m", "jaxcelt", *argv[1:], "--no-figures", "--out", str(MAP_NC.parent)]
        print("making the map:", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
    ds = xr.open_dataset(MAP_NC)
    title = "Fold and Neimark-Sacker curves of the period-1 orbit pair over the 100 x 60 map (docs/map)"
    fig = map_figure(ds, title=title, curves=res)
    marks = []
    for ax in fig.axes[:2]:  # the one-parameter points the curves pass at the paper's q_pi
        pts = {c["kind"]: c["one_parameter_point"] for c in res["curves"].values() if c.get("continues") is None}
        ax.axhline(0.04, color="0.3", lw=0.6, ls=":")
        marks += ax.plot(list(pts.values()), [0.04] * len(pts), "o", ms=7, mfc="white", mec="black", zorder=5,
                         label=r"one-parameter points at $q_\pi$ = 0.04 m")  # fmt: skip
    ax = fig.axes[1]
    handles = [*ax.get_legend().legend_handles, marks[-1]]
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    fig.savefig(path, dpi=130)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=sorted(CURVES))
    ap.add_argument("--out", default=str(OUT))
    ap.add_argument("--merge", nargs="*", help="merge the curves of these partial result files into --out")
    ap.add_argument("--plot-only", action="store_true")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    load = list(os.getloadavg())
    if a.plot_only:
        plot(json.loads(out.read_text()), out.with_suffix(".png"))
        return
    res = json.loads(out.read_text()) if out.exists() else {}
    res.setdefault("curves", {})
    if a.merge:
        for f in a.merge:
            res["curves"].update(json.loads(pathlib.Path(f).read_text())["curves"])
        res["known_answers"] = known_answers()
    else:
        for key in a.only or list(CURVES):
            print(f"{key} ...", flush=True)
            res["curves"][key] = run_curve(key, res)
            write_result(out, _summary(res), load_at_start=load)
    write_result(out, _summary(res), load_at_start=load)
    if out == OUT:
        plot(res, out.with_suffix(".png"))


def _summary(res: dict) -> dict:
    curves = res["curves"]
    res.update({
        "system": "paper's stone (CeltParams.paper), period-1 orbits of the 15.6 rad/s family and their mirror",
        "parameters": ["omega_pi", "q_pi"],
        "bounds": [list(b) for b in BOUNDS],
        "scale": list(SCALE),
        "check_tolerance": CHECK_TOL,
        "max_steps": MAX_STEPS,
        "map": "docs/map/map_omega_q_100x60.json",
        "all_pass_through_one_parameter_points": all(c["passes_through_point"] for c in curves.values()),
        "max_abs_curve_minus_one_parameter": max(abs(c["curve_minus_one_parameter"]) for c in curves.values()),
        "not_done": [
            f"{k}: reached q_pi {c['q_range'][0]:.4f}-{c['q_range'][1]:.4f} m (ends: {', '.join(c['stopped'])})"
            for k, c in curves.items() if "left the bounds" not in c["stopped"] or c["stopped"].count(
                "left the bounds") < 2
        ],
    })  # fmt: skip
    return res


if __name__ == "__main__":
    main()
