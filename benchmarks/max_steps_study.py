"""Why do some lanes exhaust ``max_steps`` when integrated on past the model's validity?

The 400 x 300 sweep (omega_pi in [10, 20], from rest, rtol 1e-8, atol 1e-10, integrating every
lane on) sends a few lanes to ``max_steps = 1e6`` with jaxcelt's default Tsit5, while a
hand-written Dormand-Prince 5(4) with an I-controller finishes them. Both controllers are the same
(I-control, safety 0.9, factor in [0.2, 10], RMS error norm scaled by atol + rtol max(|y0|, |y1|)).
This script separates the method from the implementation: the *same* numba loop
(``_numba_model._dopri_lane``) is run with Dormand-Prince's tableau and with Tsitouras' (taken
from diffrax), and jaxcelt's pool is run with ``diffrax.Tsit5`` and ``diffrax.Dopri5`` on the
lanes that are expensive for any of them. Steps per lane and statuses go to a JSON file.

    .venv/bin/python benchmarks/max_steps_study.py --out docs/bifurcation
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import _numba_model as nm  # noqa: E402
import diffrax  # noqa: E402

import jaxcelt as jc  # noqa: E402
from jaxcelt.provenance import load_average, write_result  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402


def tsit5_tableau():
    """Tsitouras 5(4) in the numba loop's layout (C, A (7x7, row 6 = b), B5, E)."""
    # the public coefficients, as diffrax ships them (diffrax.Tsit5's ButcherTableau)
    import diffrax

    t = diffrax.Tsit5.tableau  # public class attribute: the ButcherTableau

    C = np.r_[0.0, t.c]
    A = np.zeros((7, 7))
    for i, row in enumerate(t.a_lower):
        A[i + 1, : len(row)] = row
    B5 = np.asarray(t.b_sol, float)
    A[6, :6] = B5[:6]
    return C, A, B5, np.asarray(t.b_error, float)


def numba_lanes(Y0, TS, PP, B, Bi, rtol, atol, max_steps, tableau):
    C, A, B5, E = tableau
    L, S = TS.shape
    steps = np.zeros(L, np.int64)
    status = np.zeros(L, np.int64)
    for k in range(L):
        ys = np.full((S, 13), np.inf)
        steps[k], _, status[k] = nm._dopri_lane(Y0[k], 0.0, TS[k], PP[k], B, Bi, rtol, atol, max_steps, ys, C, A, B5, E)
    return steps, status


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=300)
    ap.add_argument("--sample", type=int, default=100)
    ap.add_argument("--max-steps", type=int, default=10**6)
    ap.add_argument("--top", type=int, default=24, help="lanes re-run with jaxcelt: the costliest for numba DP5")
    ap.add_argument("--out", default=None)
    ap.add_argument("--name", default="max_steps_study.json", help="result file name in --out")
    ap.add_argument("--lanes-from", default=None, help="re-run the omega_pi values of this earlier result file")
    a = ap.parse_args()
    load0 = load_average()
    rtol, atol = 1e-8, 1e-10
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    P, B, Bi = nm.pack(p)
    PP = np.tile(P, (len(vals), 1))
    PP[:, nm.WPI] = vals
    tr = a.periods - a.sample
    TS = np.stack([2 * np.pi / w * np.arange(tr, a.periods) for w in vals])
    Y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))
    res = {"versions": versions(), "config": vars(a) | {"rtol": rtol, "atol": atol}}
    t0 = time.perf_counter()
    _, st_dp, _, status_dp = nm.dopri_ensemble(Y0, TS, PP, B, Bi, rtol, atol, a.max_steps, False)
    res["numba_dp5_seconds"] = time.perf_counter() - t0
    top = np.argsort(-st_dp)[: a.top]
    # lanes the numba loop ended on a non-finite state (status 3) are costly for diffrax too
    top = np.unique(np.r_[top, np.flatnonzero(status_dp == 3)])
    if a.lanes_from:  # the same lanes as an earlier study (e.g. before a rule changed)
        earlier = [r["omega_pi"] for r in json.loads(Path(a.lanes_from).read_text())["lanes"]]
        top = np.array([int(np.argmin(np.abs(vals - w))) for w in earlier])
    st_ts, status_ts = numba_lanes(Y0[top], TS[top], PP[top], B, Bi, rtol, atol, a.max_steps, tsit5_tableau())
    lanes = {}
    for solver in ("Tsit5", "Dopri5"):
        r = jc.bifurcation(
            p, vals[top], transient_periods=tr, sample_periods=a.sample, rtol=rtol, atol=atol,
            max_steps=a.max_steps, solver=getattr(diffrax, solver)(),
        )  # fmt: skip
        lanes[solver] = (np.asarray(r.num_steps).ravel(), np.asarray(r.status).ravel())
    rows = []
    for j, k in enumerate(top):
        rows.append(
            {
                "omega_pi": float(vals[k]),
                "numba_dp5": [int(st_dp[k]), int(status_dp[k])],
                "numba_tsit5": [int(st_ts[j]), int(status_ts[j])],
                "jaxcelt_tsit5": [int(lanes["Tsit5"][0][j]), int(lanes["Tsit5"][1][j])],
                "jaxcelt_dopri5": [int(lanes["Dopri5"][0][j]), int(lanes["Dopri5"][1][j])],
            }
        )
    res["lanes"] = rows
    res["note"] = (
        "each entry: [accepted+rejected steps, status] (0 ok, 1 max_steps, 3 non-finite error or collapsed step, "
        "4 past validity on its side: jaxcelt.integrate.solve.HEADING_GAP)"
    )
    print(f"{'omega_pi':>9} {'nb DP5':>14} {'nb Tsit5':>14} {'jc Tsit5':>14} {'jc Dopri5':>14}")
    for r in rows:
        print(f"{r['omega_pi']:9.4f} " + " ".join(f"{s:>11d}/{c}" for s, c in (r["numba_dp5"], r["numba_tsit5"], r["jaxcelt_tsit5"], r["jaxcelt_dopri5"])))  # fmt: skip
    if a.out:
        write_result(Path(a.out) / a.name, res, load_at_start=load0)


if __name__ == "__main__":
    main()
