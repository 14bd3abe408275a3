"""The paper's periodic motion at 14 rad/s, asked of the fold of the period-1 family -> docs/orbits/paper_14.json and
docs/orbits/paper_14.png.

The period-1 family of the 15.6 rad/s orbit begins at its fold, 14.8798 rad/s with the paper's values
(docs/orbits/celt_fold_grad.json). A stable period-1 orbit lives on one side of the fold only, so it can reach
omega_pi = 14 rad/s only where the fold does. This script follows the fold (`jaxcelt.continue_orbit_bifurcation`,
with the start, bounds and solver limits of `scripts/fold_curves.py`) in omega_pi and each reading of MODEL.md
section 9 that is a continuous `CeltParams` field, from the default reading towards the alternative:

- ``B12`` (A5, the sign of the product of inertia) from +1.728e-4 towards -1.728e-4. The mirror x2 -> -x2 maps the
  stone with B12 onto the stone with -B12 (MODEL.md section 10), so omega_fold(B12) = omega_fold(-B12): the curve is
  followed from +B12 to 0, its other half is its mirror image.
- ``derivative_exact`` (A13a) from 0 (eq. 13 as printed) to 1: the contact law blends the two groupings linearly
  (fac = b_Ts (1 - de) + de), so every value between is a model.
- ``k_r`` (the rolling-resistance coefficient), both ways from the paper's value, as the remaining parameter of
  `scripts/fold_curves.py` that had no curve.

``v_pi_sign`` (A12) is not continued: the base velocity is s_pi q_pi omega_pi sin(omega_pi t) E1 and nothing else
depends on time, so s_pi = -1 is the same system shifted by half a forcing period (same orbits, same multipliers,
same fold), and a real s_pi between is the amplitude s_pi q_pi, i.e. the (omega_pi, q_pi) curve of fold_curves.json;
at s_pi = 0 there is no forcing at all.

Every computation runs as its own process writing a part file (``--part``), and the parts are merged (``--merge``):
``--curve KEY`` follows one fold curve (``B12_to_0`` continues the B12 curve from its end); ``--grad`` takes
d omega_fold / d theta by the implicit function theorem; ``--at14 CURVE SEGMENT`` solves the orbits at 14 rad/s
past a curve's crossing (a curve of this script's parts or of docs/orbits/fold_curves.json) and runs the motion
from each for `PERIODS` periods (drift of O); ``--walk PART`` follows the stable orbit of an ``--at14`` part in its
parameter at 14 rad/s; ``--at156 PARAMETER VALUE`` moves the 15.6 rad/s orbit and runs it likewise. Timings are
indicative (load average recorded; each process compiles its own solver). The committed file was made by

    python scripts/paper_14.py --curve B12 --part /tmp/p14/B12.json   # also derivative_exact, k_r, then B12_to_0
    python scripts/paper_14.py --grad --part /tmp/p14/grad.json
    python scripts/paper_14.py --at14 q_pi_upper2 5 --part /tmp/p14/at14_q_pi.json
    python scripts/paper_14.py --at14 B12 2 --offset 0.004 --part /tmp/p14/at14_B12_b.json
    python scripts/paper_14.py --at14 B12 1 --part /tmp/p14/at14_B12_c.json
    python scripts/paper_14.py --walk /tmp/p14/at14_B12_c.json --walk-to 1.728e-4 --walk-steps 12 --part /tmp/p14/walk2.json
    python scripts/paper_14.py --at156 q_pi 0.04599119520882185 --part /tmp/p14/at156_q_pi.json
    python scripts/paper_14.py --at156 B12 8.611814330421657e-05 --part /tmp/p14/at156_B12.json
    python scripts/paper_14.py --merge /tmp/p14/{B12,B12_to_0,derivative_exact,k_r,at14_q_pi,at14_B12_b,at14_B12_c,at156_q_pi,at156_B12,grad,walk2}.json
    python scripts/paper_14.py --plot-only
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import sys
import time

import numpy as np

import jaxcelt as jc
from jaxcelt.orbits.curves import curve_to_dict
from jaxcelt.provenance import write_result
from jaxcelt.versions import versions

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from fold_curves import MAX_STEPS, OMEGA_BOUNDS, fold_start, located_fold, timed_fold_curve  # noqa: E402

OUT = ROOT / "docs/orbits/paper_14.json"
OMEGA_PAPER = 14.0

# key -> (parameter, bounds, scale, direction (+1/-1 towards increasing/decreasing parameter, 0 both), ds, ds_max,
# points at most)
CURVES = {
    "B12": ("B12", (-2e-4, 2e-4), 1e-4, -1, 0.2, 0.5, 9),
    "derivative_exact": ("derivative_exact", (0.0, 1.0), 0.5, +1, 0.2, 0.5, 9),
    "k_r": ("k_r", (0.0, 1.2), 0.1, 0, 0.2, 1.0, 9),
    # the B12 curve stopped at its point limit at B12 = 5.2e-5: continued from that end towards 0
    "B12_to_0": ("B12", (-2e-4, 2e-4), 1e-4, -1, 0.3, 0.5, 7),
}
START_FROM = {"B12_to_0": "B12"}
"""a curve started from the lowest-parameter end of another (read from its part file beside ``--part``)"""


def crossing(omega: np.ndarray, p: np.ndarray, level: float = OMEGA_PAPER) -> list[dict]:
    """Where the piecewise-linear curve through (omega[i], p[i]) crosses omega = ``level``: linear interpolation
    between consecutive points on either side (a point exactly on the level counts once). Pure, for the curves'
    read-off and its test."""
    w, q = np.asarray(omega, float), np.asarray(p, float)
    if w.shape != q.shape or w.ndim != 1:
        raise ValueError(f"crossing: 'omega' and 'p' must be 1-d of one length, got {w.shape} and {q.shape}")
    out = []
    for i in range(len(w) - 1):
        a, b = w[i] - level, w[i + 1] - level
        if a == 0 or a * b < 0:
            s = 0.0 if a == 0 else a / (a - b)
            out.append({"segment": i, "p": float(q[i] + s * (q[i + 1] - q[i]))})
    if len(w) and w[-1] == level:
        out.append({"segment": len(w) - 1, "p": float(q[-1])})
    return out


def run_curve(key: str, part: pathlib.Path) -> dict:
    name, bounds, scale, direction, ds, ds_max, max_points = CURVES[key]
    y, w = fold_start()
    p = jc.CeltParams.paper(omega_pi=w)
    if key in START_FROM:
        cd = json.loads(part.with_name(START_FROM[key] + ".json").read_text())["curves"][START_FROM[key]]["curve"]
        j = int(np.argmin(cd[name]))
        y, w = np.asarray(cd["state"][j]), float(cd["omega_pi"][j])
        p = _params(name, float(cd[name][j]), w)
    p0 = float(getattr(p, name))
    curve, times, total = timed_fold_curve(key, p, y, name, bounds, scale, ds, ds_max, max_points, direction)
    om, pp = np.asarray(curve.p1), np.asarray(curve.p2)
    i0 = curve.start
    a, b = max(i0 - 1, 0), min(i0 + 1, len(om) - 1)
    return {
        "parameter": name,
        "paper_value": p0,
        "bounds": list(bounds),
        "scale": scale,
        "direction": direction,
        "ds": ds,
        "ds_max": ds_max,
        "max_points": max_points,
        "points": len(om),
        "start_minus_located_fold": float(om[i0] - located_fold()) if key not in START_FROM else None,
        "continues": START_FROM.get(key),
        "range_reached": [float(pp.min()), float(pp.max())],
        "omega_range": [float(om.min()), float(om.max())],
        "domega_dp_at_start": float((om[b] - om[a]) / (pp[b] - pp[a])) if b > a and pp[b] != pp[a] else None,
        "max_abs_multiplier_minus_1": float(np.max(np.min(np.abs(curve.multipliers - 1.0), axis=1))),
        "seconds": {
            "to_first_step_incl_compile": round(times[0], 1) if times else None,
            "total": round(total, 1),
            "corrector_attempts": len(times),
        },
        "curve": curve_to_dict(curve, ("omega_pi", name)),
    }


PERIODS = 300
"""forcing periods of the motion run from an orbit to judge its global motion"""
DRIFT_THRESHOLD = 0.05
"""[m] net displacement of O that counts as unbounded wandering (`jaxcelt.sweeps.regimes.classify`'s default)"""


def _params(name: str, value: float, omega: float) -> jc.CeltParams:
    """The paper's stone at omega_pi with ``name`` (a field or "a=b") set to value; set by `eqx.tree_at`, so a
    reading switch may take a value between its two readings (CeltParams' validation admits 0/1 and +-1 only)."""
    import equinox as eqx
    import jax.numpy as jnp

    fields = name.split("=")
    return eqx.tree_at(lambda q: [getattr(q, f) for f in fields], jc.CeltParams.paper(omega_pi=omega),
                       [jnp.asarray(value, float)] * len(fields))  # fmt: skip


def global_motion(params: jc.CeltParams, y0: np.ndarray, periods: int = PERIODS) -> dict:
    """Run ``periods`` forcing periods from the section state y0 (t0 = 0), sampled on the section: net drift and
    largest excursion of O, the classify rule's label, and how far the samples wander from y0 (a periodic orbit
    that holds stays at 0)."""
    import jax

    from jaxcelt.physics.diagnostics import centre_position

    T = 2 * np.pi / float(params.omega_pi)
    ts = T * np.arange(periods + 1)
    t = time.perf_counter()
    sol = jc.simulate(params, y0, ts[-1], ts=ts, rtol=1e-10, atol=1e-12, max_steps=20_000 * periods)
    ys = np.asarray(sol.ys)
    r_O = np.asarray(jax.vmap(centre_position, in_axes=(0, None))(sol.ys, params))
    d = r_O[:, :2] - r_O[0, :2]
    dist = np.linalg.norm(d, axis=-1)
    net, exc = float(dist[-1]), float(np.max(dist))
    dev = np.max(np.abs(ys[:, 3:9] - ys[0, 3:9]), axis=-1)
    return {
        "periods": periods,
        "status": int(sol.status),
        "valid": bool(np.all(np.asarray(sol.valid))),
        "net_drift_m": net,
        "max_excursion_m": exc,
        "drift_per_period_first_m": float(dist[1]),
        "global_motion": "unbounded" if (net > DRIFT_THRESHOLD and net >= 0.5 * exc) else "bounded",
        "max_section_deviation_omega_n": float(np.max(dev)),
        "left_orbit_at_period": int(np.argmax(dev > 1e-3)) if np.any(dev > 1e-3) else None,
        "seconds_incl_compile": round(time.perf_counter() - t, 1),
    }


STEPS_156 = 6
"""natural-parameter steps from the paper's value to the moved one for the 15.6 rad/s orbit"""


def _orbit_record(params, o) -> dict:
    return {
        "status": int(o.status),
        "residual": float(o.residual),
        "multipliers_abs": [float(a) for a in np.abs(np.asarray(o.multipliers))],
        "stable": bool(o.stable),
        "state": [float(v) for v in np.asarray(o.y)],
    }


def sheets_at_14(name: str, cd: dict, seg: int, offset: float = 0.02) -> dict:
    """Both orbits born at the fold, at omega_pi = 14: at fixed parameter value p of the curve point of segment
    ``seg`` whose fold lies below 14 rad/s, `jc.continue_orbit` in omega_pi from ``offset`` above that fold through it
    (both sheets) up to 14.05 rad/s; each sheet's point nearest 14 is polished by `jc.periodic_orbit` at exactly
    14 rad/s, and the motion from it is run `PERIODS` periods."""
    om = cd["omega_pi"]
    j = seg if om[seg] < OMEGA_PAPER else seg + 1
    wf, pv, y = float(om[j]), float(cd[name][j]), np.asarray(cd["state"][j])
    t = time.perf_counter()
    p = _params(name, pv, wf + offset)
    o = jc.periodic_orbit(p, y, max_steps=MAX_STEPS)
    out = {"curve_point": j, "fold_omega": wf, name: pv, "start_offset": offset, "start_status": int(o.status)}
    if int(o.status) != 0:
        return out
    br = jc.continue_orbit(p, o, "omega_pi", (wf - 0.3, OMEGA_PAPER + 0.05), ds=0.02, ds_max=0.15, max_points=60,
                           max_steps=MAX_STEPS)  # fmt: skip
    v = np.asarray(br.values)
    out["branch"] = {"omega_pi": v.tolist(), "stable": np.asarray(br.stable).tolist(),
                     "max_abs_multiplier": np.max(np.abs(np.asarray(br.multipliers)), axis=1).tolist(),
                     "stopped": str(getattr(br, "stopped", ""))}  # fmt: skip
    sheets = []
    for c in crossing(v, np.arange(len(v), dtype=float)):
        i = (
            c["segment"]
            if abs(v[c["segment"]] - 14) <= abs(v[min(c["segment"] + 1, len(v) - 1)] - 14)
            else c["segment"] + 1
        )
        p14 = _params(name, pv, OMEGA_PAPER)
        o14 = jc.periodic_orbit(p14, np.asarray(br.y[i]), max_steps=MAX_STEPS)
        rec = {"branch_point": int(i), **_orbit_record(p14, o14)}
        if int(o14.status) == 0:
            rec["motion"] = global_motion(p14, np.asarray(o14.y))
        sheets.append(rec)
    out["sheets_at_14"] = sheets
    out["seconds_incl_compile"] = round(time.perf_counter() - t, 1)
    return out


def orbit_156(name: str, end: float) -> dict:
    """The stable 15.6 rad/s orbit (docs/orbits/branches.json) at the paper's values and continued in ``name``
    to ``end`` in `STEPS_156` natural-parameter steps of `jc.periodic_orbit` at omega_pi = 15.6: its multipliers and global motion at both ends."""
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    br = next(iter(d["branches"].values()))["branch"]
    v = np.asarray(br["values"])
    i = int(np.argmin(np.abs(v - 15.6) + 100 * ~np.asarray(br["stable"])))
    from jaxcelt.physics.model import STATE_NAMES

    y = np.array([br["state"][n][i] for n in STATE_NAMES])
    t = time.perf_counter()
    p = jc.CeltParams.paper(omega_pi=float(v[i]))
    o = jc.periodic_orbit(p, y, max_steps=MAX_STEPS)
    out = {
        "parameter": name,
        "end_value": end,
        "default": {**_orbit_record(p, o), "motion": global_motion(p, np.asarray(o.y))},
    }
    p0, path, ok = float(getattr(p, name.split("=")[0])), [], True
    for val in np.linspace(p0, end, STEPS_156 + 1)[1:]:  # natural-parameter steps, each from the previous orbit
        pe = _params(name, float(val), float(v[i]))
        o2 = jc.periodic_orbit(pe, np.asarray(o.y), max_steps=MAX_STEPS)
        ok = int(o2.status) == 0
        path.append({name: float(val), "status": int(o2.status), "stable": bool(o2.stable),
                     "max_abs_multiplier": float(np.max(np.abs(np.asarray(o2.multipliers))))})  # fmt: skip
        if not ok:
            break
        o = o2
    out["path"] = path
    out["end"] = _orbit_record(pe, o2)
    if ok:
        out["end"]["motion"] = global_motion(pe, np.asarray(o2.y))
    out["seconds_incl_compile"] = round(time.perf_counter() - t, 1)
    return out


GRAD_FIELDS = ("B12", "derivative_exact", "k_r", "q_pi", "mu")
"""the fields d omega_fold / d theta is taken in by the implicit function theorem (one reverse pass)"""


def fold_gradient() -> dict:
    """d omega_fold / d theta at the paper's values for every field of `GRAD_FIELDS` at once: `jax.grad` of
    `jaxcelt.orbits.celt.locate_orbit_bifurcation`'s located value, as scripts/celt_fold_grad.py does for mu alone
    (that script's file records mu only, so the directions of the other readings are computed here)."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    from jaxcelt.orbits.celt import locate_orbit_bifurcation

    y, v = fold_start()
    p = jc.CeltParams.paper(omega_pi=v)

    def fold(vals):
        q = eqx.tree_at(lambda q: [getattr(q, f) for f in GRAD_FIELDS], p, list(vals))
        return locate_orbit_bifurcation(q, y, "omega_pi", v, kind="fold", wrt=GRAD_FIELDS).value

    t = time.perf_counter()
    g = jax.grad(fold)([jnp.asarray(float(getattr(p, f))) for f in GRAD_FIELDS])
    return {
        "domega_fold_d": {f: float(x) for f, x in zip(GRAD_FIELDS, g, strict=True)},
        "seconds_incl_compile": round(time.perf_counter() - t, 1),
    }


def walk_at_14(key: str, steps: int = 8, to: float | None = None) -> dict:
    """The stable sheet found at 14 rad/s by ``--at14`` (at_14 part ``key``) followed in its parameter towards the
    paper's value at omega_pi = 14 in natural steps of `jc.periodic_orbit` (each from the previous orbit) up to the
    other end of the curve's crossing segment (or to ``to``): if the orbit is the one born at the fold, it ends (or turns
    unstable through a multiplier at +1) where the fold crosses 14 rad/s."""
    part = json.loads(pathlib.Path(key).read_text())
    a = next(iter(part["at_14"].values()))
    name = a["parameter"]
    s = next(s for s in a["sheets_at_14"] if s["stable"])
    src = json.loads(pathlib.Path(key).with_name(a["curve"] + ".json").read_text())["curves"][a["curve"]]["curve"]
    (x,) = crossing(src["omega_pi"], src[name])
    hi = float(src[name][x["segment"] + 1]) if to is None else to
    y, path = np.asarray(s["state"]), []
    for val in np.linspace(a[name], hi, steps + 1)[1:]:
        o = jc.periodic_orbit(_params(name, float(val), OMEGA_PAPER), y, max_steps=MAX_STEPS)
        path.append({name: float(val), "status": int(o.status), "stable": bool(o.stable),
                     "multipliers_abs": [float(m) for m in np.abs(np.asarray(o.multipliers))[:3]]})  # fmt: skip
        if int(o.status) != 0:
            break
        y = np.asarray(o.y)
    return {"from": a[name], "to": hi, "crossing": x["p"], "path": path}


def summarise(res: dict) -> None:
    """Per curve: its crossings of 14 rad/s, lowest fold and slope at the paper's value; per orbit check: stable or
    saddle at 14 rad/s and the global motion; and the plain answer."""
    fold = located_fold()
    lines = []
    for c in res["curves"].values():
        name, cd = c["parameter"], c["curve"]
        om, pv = np.asarray(cd["omega_pi"]), np.asarray(cd[name])
        j = int(np.argmin(om))
        c["lowest_fold"] = {"omega_pi": float(om[j]), name: float(pv[j])}
        c["crossings_of_14"] = crossing(om, pv)
        c["closest_to_14_rad_s"] = float(om[j] - OMEGA_PAPER)
        lines.append(
            f"{name} over [{pv.min():.4g}, {pv.max():.4g}]: fold {om.min():.4f}-{om.max():.4f} rad/s, "
            + (f"crosses 14 rad/s at {name} = {', '.join(format(x['p'], '.4g') for x in c['crossings_of_14'])}"
               if c["crossings_of_14"] else f"nearest 14 rad/s: {om[j]:.4f} at {name} = {pv[j]:.4g}")
        )  # fmt: skip
    stable_bounded = []
    for a in res.get("at_14", {}).values():
        for s in a.get("sheets_at_14", []):
            s["bounded_and_stable"] = bool(s["stable"] and s.get("motion", {}).get("global_motion") == "bounded")
            if s["bounded_and_stable"]:
                stable_bounded.append(f"{a['parameter']} = {a[a['parameter']]:.4g}")
    res["located_fold_omega"] = fold
    res["stable_bounded_period1_at_14"] = stable_bounded
    res["answer"] = "; ".join(lines)


def plot(res: dict, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [k for k in res["curves"] if k not in START_FROM]
    fig, axes = plt.subplots(1, max(len(keys), 1), figsize=(4.2 * max(len(keys), 1), 3.8), squeeze=False)
    for ax, key in zip(axes[0], keys, strict=False):
        c = res["curves"][key]
        name = c["parameter"]
        parts = [res["curves"][k]["curve"] for k in res["curves"] if k == key or START_FROM.get(k) == key]
        w = np.concatenate([cd["omega_pi"] for cd in parts])
        pv = np.concatenate([cd[name] for cd in parts])
        order = np.argsort(pv)
        ax.plot(w[order], pv[order], ".-", lw=1, ms=3, color="C0", label="fold curve")
        if name == "B12":  # the mirror half: omega_fold(B12) = omega_fold(-B12)
            ax.plot(w[order], -pv[order], ".--", lw=1, ms=3, color="C0", alpha=0.5, label="mirror image (−B12)")
        for a in res.get("at_14", {}).values():
            if a["parameter"] == name:
                for sh in a.get("sheets_at_14", []):
                    ax.plot([OMEGA_PAPER], [a[name]], "o" if sh["stable"] else "x", color="g" if sh["stable"] else "m",
                            mfc="none", ms=8, label="stable orbit at 14" if sh["stable"] else "saddle at 14")  # fmt: skip
        cd = c["curve"]
        ax.plot([res["located_fold_omega"]], [c["paper_value"]], "r*", ms=10, label="paper's reading")
        ax.axvline(OMEGA_PAPER, color="k", ls="--", lw=0.8, label="ω_π = 14 rad/s")
        for pt in cd["points"]:
            ax.plot([pt["omega_pi"]], [pt[name]], "ks", mfc="none", ms=7)
            ax.annotate(pt["kind"], (pt["omega_pi"], pt[name]), fontsize=7)
        ax.set_xlabel("ω_π [rad/s]")
        ax.set_ylabel(name)
        ax.set_title(f"fold in (ω_π, {name})", fontsize=10)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle("wobblestone: the fold where the period-1 family begins, moved by each reading", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--curve", choices=list(CURVES))
    ap.add_argument("--part", type=pathlib.Path, help="where --curve writes its curve")
    ap.add_argument("--merge", nargs="*", type=pathlib.Path, default=[])
    ap.add_argument("--at14", nargs=2, metavar=("CURVE", "SEGMENT"), help="sheets at 14 rad/s from a curve's crossing")
    ap.add_argument("--grad", action="store_true", help="d omega_fold / d theta by the implicit function theorem")
    ap.add_argument("--walk", type=pathlib.Path, help="an --at14 part whose stable sheet is followed to the crossing")
    ap.add_argument("--walk-to", type=float, help="--walk: the end value (default: past the crossing)")
    ap.add_argument("--walk-steps", type=int, default=8)
    ap.add_argument("--offset", type=float, default=0.02, help="--at14: start this far above the fold [rad/s]")
    ap.add_argument("--at156", nargs=2, metavar=("PARAMETER", "VALUE"), help="the 15.6 rad/s orbit moved to VALUE")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--out", type=pathlib.Path, default=OUT)
    a = ap.parse_args(argv)
    if a.curve:
        load0 = list(os.getloadavg())
        part = {"curves": {a.curve: run_curve(a.curve, a.part)}, "load_average_start": load0}
        part["load_average_end"] = list(os.getloadavg())
        write_result(a.part, part, load_at_start=load0, indent=1)  # a part: merged by --merge
        return 0
    if a.walk:
        load0 = list(os.getloadavg())
        part = {"walk_at_14": walk_at_14(str(a.walk), a.walk_steps, a.walk_to), "load_average_start": load0}
        write_result(a.part, part, load_at_start=load0, indent=1)
        return 0
    if a.grad:
        load0 = list(os.getloadavg())
        write_result(a.part, {"gradient": fold_gradient(), "load_average_start": load0}, load_at_start=load0, indent=1)
        return 0
    if a.at156:
        load0 = list(os.getloadavg())
        part = {"at_15_6": {a.at156[0]: orbit_156(a.at156[0], float(a.at156[1]))}, "load_average_start": load0}
        write_result(a.part, part, load_at_start=load0, indent=1)
        return 0
    if a.at14:
        key, seg = a.at14[0], int(a.at14[1])
        load0 = list(os.getloadavg())
        src = json.loads((ROOT / "docs/orbits/fold_curves.json").read_text())["curves"]
        if key not in src:
            src = json.loads(a.part.with_name(key + ".json").read_text())["curves"]
        name = src[key]["parameter"]
        part = {"at_14": {f"{key}:{seg}:{a.offset:g}": {"curve": key, "parameter": name, **sheets_at_14(name, src[key]["curve"], seg, a.offset)}},
                "load_average_start": load0}  # fmt: skip
        write_result(a.part, part, load_at_start=load0, indent=1)
        return 0
    res = json.loads(a.out.read_text()) if a.out.exists() else {}
    res.pop("provenance", None)
    if a.merge:
        load0 = None
        res.setdefault("curves", {})
        res.pop("walk_at_14", None)
        res["walks_at_14"] = []
        for f in a.merge:
            part = json.loads(f.read_text())
            load0 = load0 or part["load_average_start"]
            for k in ("curves", "at_14", "at_15_6"):
                res.setdefault(k, {}).update(part.get(k, {}))
            if "walk_at_14" in part:
                res.setdefault("walks_at_14", []).append(part["walk_at_14"])
            if "gradient" in part:
                res["gradient_at_paper_values"] = part["gradient"]
        res.update(
            system="paper's stone (CeltParams.paper), fold of the period-1 family of the 15.6 rad/s orbit",
            omega_bounds=list(OMEGA_BOUNDS), max_steps=MAX_STEPS, periods_run=PERIODS,
            drift_threshold_m=DRIFT_THRESHOLD, merged_from_parallel_runs=len(a.merge),
            load_average_start=load0, load_average_end=list(os.getloadavg()), versions=versions(),
        )  # fmt: skip
        summarise(res)
        write_result(a.out, res, load_at_start=load0, indent=1)
    plot(res, a.out.with_suffix(".png"))
    print(json.dumps({k: v for k, v in res.items() if k not in ("curves", "versions", "provenance")}, indent=1)[:4000])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
