"""Periodic-orbit branches of the wobblestone over omega_pi in [10, 20] rad/s, on the brute-force diagram.

Starts from the periodic attractors of the census (docs/orbits/census.json: the mirror pair of
period-1 orbits at 15.6 rad/s; no period-2 attractor was found), refines each with
`jaxcelt.periodic_orbit` and follows it with `jaxcelt.continue_orbit` both ways until the branch
leaves the window; lists folds, period doublings and Neimark-Sacker points with their
multipliers; checks the mirror symmetry (psi -> psi + pi: the two branches must have the same
bifurcation values); solves the orbits at the paper's four frequencies from the nearest branch
points; and draws the branches over a brute-force stroboscopic diagram (from rest at
psi0 = 157.5 deg, `jaxcelt.bifurcation`). Writes docs/orbits/branches.json and
docs/orbits/branches/*.png; each finished branch is stored at once and reused by a rerun with
the same settings (``--force`` recomputes). Timings are indicative (load average recorded).

    python scripts/orbit_branches.py [--out docs/orbits] [--window 10 20] [--values 201]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import jax
import numpy as np

import jaxcelt as jc
from jaxcelt.orbits.branch import ArclengthBranch, branch_to_dict
from jaxcelt.orbits.points import Bifurcation
from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.provenance import write_result
from jaxcelt.versions import versions

ROOT = Path(__file__).resolve().parents[1]
PSI0_DEG = 157.5
PAPER_OMEGAS = (14.0, 15.6, 17.0, 19.0)


def _branch_from_dict(d: dict) -> ArclengthBranch:
    y = np.stack([np.asarray(d["state"][n]) for n in STATE_NAMES], axis=1)
    mu = np.asarray(d["multipliers"])
    bifs = [
        Bifurcation(
            b["kind"],
            b["value"],
            tuple(b["bracket"]),
            np.asarray(b["multipliers"])[:, 0] + 1j * np.asarray(b["multipliers"])[:, 1],
            np.asarray([b["state"][n] for n in STATE_NAMES]),
        )
        for b in d["bifurcations"]
    ]
    return ArclengthBranch(
        values=np.asarray(d["values"]),
        y=y,
        tangents=np.zeros((len(y), 9)),
        multipliers=mu[..., 0] + 1j * mu[..., 1],
        stable=np.asarray(d["stable"]),
        steps=np.zeros(len(y)),
        bifurcations=bifs,
        stopped=d["stopped"],
        start=d["start"],
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "orbits")
    ap.add_argument("--window", type=float, nargs=2, default=(10.0, 20.0))
    ap.add_argument("--values", type=int, default=201, help="brute-force frequencies")
    ap.add_argument("--transient", type=int, default=300, help="brute-force transient periods")
    ap.add_argument("--sample", type=int, default=50, help="brute-force section samples")
    ap.add_argument("--max-points", type=int, default=300)
    ap.add_argument("--force", action="store_true", help="recompute stored branches")
    args = ap.parse_args(argv)
    out_json = args.out / "branches.json"
    figdir = args.out / "branches"
    figdir.mkdir(parents=True, exist_ok=True)
    settings = {"window": list(args.window), "max_points": args.max_points}
    res: dict = {}
    if out_json.exists() and not args.force:
        res = json.loads(out_json.read_text())
        if res.get("settings") != settings:
            res = {}
    res.setdefault("branches", {})
    res.update(
        settings=settings,
        script="scripts/orbit_branches.py",
        versions=versions(),
        machine={"platform": platform.platform(), "processor": platform.processor(), "cpu_count": os.cpu_count()},
    )

    census = json.loads((args.out / "census.json").read_text())
    starts = []
    for om, r in census["results"].items():
        for i, a in enumerate(r["attractors"]):
            if a["kind"] == "periodic" and a["k"] in (1, 2):
                starts.append(
                    (f"period-{a['k']} at {om} rad/s, psi {np.degrees(a['state'][12]) % 360:.1f} deg", float(om), a, i)
                )
    print(f"{len(starts)} periodic attractors in the census: " + "; ".join(s[0] for s in starts))

    branches: dict[str, ArclengthBranch] = {}
    for label, om, a, _ in starts:
        if label in res["branches"]:
            branches[label] = _branch_from_dict(res["branches"][label]["branch"])
            print(f"{label}: stored")
            continue
        p = jc.CeltParams.paper(omega_pi=om)
        load0 = os.getloadavg()[0]
        t = time.perf_counter()
        orb = jax.block_until_ready(jc.periodic_orbit(p, np.asarray(a["state"]), k=a["k"], t0=a["t_section"]))
        t_first = time.perf_counter() - t
        t = time.perf_counter()
        orb = jax.block_until_ready(jc.periodic_orbit(p, np.asarray(a["state"]), k=a["k"], t0=a["t_section"]))
        t_solve = time.perf_counter() - t
        times: list[float] = []

        def tick(n, lam, ok, times=times):
            times.append(time.perf_counter())

        t = time.perf_counter()
        br = jc.continue_orbit(p, orb, "omega_pi", tuple(args.window), max_points=args.max_points, callback=tick)
        t_branch = time.perf_counter() - t
        steps = np.diff(np.r_[t, times])
        branches[label] = br
        res["branches"][label] = {
            "omega_pi": om,
            "k": a["k"],
            "start_status": int(orb.status),
            "start_multipliers_abs": [float(x) for x in np.abs(np.asarray(orb.multipliers))],
            "branch": branch_to_dict(br, STATE_NAMES),
            "seconds": {
                "newton_first_call_incl_compile": round(t_first, 2),
                "newton_solve": round(t_solve, 3),
                "branch_incl_compile": round(t_branch, 1),
                "first_corrector_incl_compile": round(float(steps[0]), 1),
                "median_corrector_attempt": round(float(np.median(steps[1:])), 3),
                "corrector_attempts": len(times),
            },
            "load_average": [round(load0, 2), round(os.getloadavg()[0], 2)],
        }
        write_result(out_json, res)
        print(f"{label}: {len(br.values)} points, {br.stopped}, {t_branch:.1f} s")
        for b in br.bifurcations:
            print(f"   {b.kind} at {b.value:.6f}: |mu| " + ", ".join(f"{x:.5f}" for x in np.abs(b.multipliers[:3])))

    # mirror symmetry: the two branches of a mirror pair have the same bifurcation values
    labels = list(branches)
    if len(labels) == 2:
        a, b = (sorted((x.kind, x.value) for x in branches[k].bifurcations) for k in labels)
        same_kinds = [x[0] for x in a] == [x[0] for x in b]
        diff = max((abs(x[1] - y[1]) for x, y in zip(a, b, strict=False)), default=float("nan"))
        res["mirror_check"] = {"same_kinds": same_kinds, "max_bifurcation_value_difference": diff}
        print(f"mirror check: same kinds {same_kinds}, max |difference| {diff:.2e}")

    # orbits at the paper's frequencies, from the nearest points of the first branch
    br = branches[labels[0]]
    at = {}
    for om in PAPER_OMEGAS:
        rows = []
        vals = np.asarray(br.values)
        # every sheet crossing om: a sign change of values - om between consecutive points
        idx = [i for i in range(len(vals) - 1) if (vals[i] - om) * (vals[i + 1] - om) <= 0]
        seen: list[np.ndarray] = []
        for i in idx:
            j = i if abs(vals[i] - om) <= abs(vals[i + 1] - om) else i + 1
            p = jc.CeltParams.paper(omega_pi=om)
            orb = jc.periodic_orbit(p, br.y[j], t0=0.0)
            if any(np.max(np.abs(np.asarray(orb.y) - y)) < 1e-6 for y in seen):
                continue  # the start point sits on om itself and is met by two brackets
            seen.append(np.asarray(orb.y))
            rows.append(
                {
                    "status": jc.orbits.ORBIT_STATUS[int(orb.status)],
                    "stable": bool(orb.stable),
                    "multipliers_abs": [float(x) for x in np.abs(np.asarray(orb.multipliers))],
                    "omega2": float(orb.y[4]),
                    "drift_m": [float(x) for x in np.asarray(orb.drift)],
                }
            )
        at[str(om)] = rows
        print(f"omega_pi = {om}: {len(rows)} period-1 orbits on the branch: " + "; ".join(
            f"{r['status']}, {'stable' if r['stable'] else 'unstable'}, |mu|max {r['multipliers_abs'][0]:.5f}" for r in rows
        ))  # fmt: skip
    res["paper_frequencies"] = at
    write_result(out_json, res)

    # brute force from rest at psi0 = 157.5 deg
    p = jc.CeltParams.paper()
    y0 = jc.initial_state(p, psi=np.radians(PSI0_DEG))
    t = time.perf_counter()
    sw = jc.bifurcation(
        p,
        np.linspace(args.window[0], args.window[1], args.values),
        transient_periods=args.transient,
        sample_periods=args.sample,
        y0=y0,
        stop_on_invalid=True,
    )
    res["brute_force"] = {
        "values": args.values,
        "transient_periods": args.transient,
        "sample_periods": args.sample,
        "psi0_deg": PSI0_DEG,
        "seconds_incl_compile": round(time.perf_counter() - t, 1),
        "lanes_invalid": int(np.sum(~np.asarray(sw.valid))),
    }
    write_result(out_json, res)

    import matplotlib

    matplotlib.use("Agg")
    from jaxcelt.plotting.orbits import branch_figure, multipliers_figure

    fig = branch_figure(
        [branches[k] for k in labels],
        labels=labels,
        sweep=sw,
        title=r"Period-1 branches of the paper's stone over the brute-force diagram (from rest, $\psi_0$ = 157.5$^\circ$)",
        xlim=tuple(args.window),
    )
    fig.savefig(figdir / "branches_omega2.png", dpi=130)
    fig = branch_figure(
        [branches[k] for k in labels],
        labels=labels,
        sweep=sw,
        title="Detail: the period-1 window between the fold and the Neimark-Sacker point",
        xlim=(14.5, 18.5),
        ylim=(-1.0, 1.0),
    )
    fig.savefig(figdir / "branches_omega2_detail.png", dpi=130)
    fig = multipliers_figure(branches[labels[0]], title=labels[0])
    fig.savefig(figdir / "multipliers.png", dpi=130)
    print(f"wrote {out_json} and {figdir}/*.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
