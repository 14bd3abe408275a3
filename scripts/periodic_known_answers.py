"""Known-answer numbers of `jaxcelt.orbits.shooting` (the cases of tests/test_periodic.py) as JSON.

Linear damped forced oscillator (analytic steady state and multipliers), Mathieu first
instability tongue against the Ince-Strutt series (truncated after q^5), forced Duffing against
a scipy DOP853 brute-force integration and Liouville's det M = exp(-d T). Writes
docs/orbits/known_answers.json.

    python scripts/periodic_known_answers.py [--out docs/orbits/known_answers.json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the shared compiled test program and its cases

import test_periodic as tp  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "orbits" / "known_answers.json"))
    a = ap.parse_args(argv)
    from jaxcelt.provenance import load_average, write_result

    load0 = load_average()
    r = {"load_average": os.getloadavg()[0]}
    d, w0, F, w = 0.3, 1.5, 0.7, 2.1
    T = 2 * np.pi / w
    t = time.perf_counter()
    o = tp.orbits([1.0, -1.0], [d, w0**2, 0, 0, F, w])
    r["seconds_compile_and_first_call"] = time.perf_counter() - t
    t = time.perf_counter()
    o = tp.orbits([1.0, -1.0], [d, w0**2, 0, 0, F, w])
    r["seconds_one_call_6_lanes"] = time.perf_counter() - t
    X = F / (w0**2 - w**2 + 1j * d * w)
    wd = np.sqrt(w0**2 - d**2 / 4)
    e = np.exp((-d / 2 + np.array([1j, -1j]) * wd) * T)
    r["linear"] = dict(
        orbit_max_error=float(np.max(np.abs(o.y[0] - [X.real, -w * X.imag]))),
        multiplier_max_error=float(np.max(np.abs(np.sort_complex(o.multipliers[0]) - np.sort_complex(e)))),
    )
    qs = np.array([0.1, 0.2, 0.4])
    q = np.repeat(qs, 2)
    mid = 1 - q**2 / 8
    even = np.arange(6) % 2 == 0
    lo, hi, sign_lo = np.where(even, mid - q - 0.1, mid), np.where(even, mid, mid + q + 0.1), np.where(even, 1.0, -1.0)
    for _ in range(45):
        am = 0.5 * (lo + hi)
        p = np.stack([np.zeros(6), am, -2 * q, np.zeros(6), np.zeros(6), 2 * np.ones(6)], 1)
        g = np.trace(tp.orbits(np.zeros((6, 2)), p).monodromy, axis1=1, axis2=2) + 2
        m = np.sign(g) == sign_lo
        lo, hi = np.where(m, am, lo), np.where(m, hi, am)
    am = 0.5 * (lo + hi)
    b1 = 1 - qs - qs**2 / 8 + qs**3 / 64 - qs**4 / 1536 - 11 * qs**5 / 36864
    a1 = 1 + qs - qs**2 / 8 - qs**3 / 64 - qs**4 / 1536 + 11 * qs**5 / 36864
    r["mathieu"] = dict(
        q=qs.tolist(),
        b1_found=am[0::2].tolist(),
        b1_minus_series=(am[0::2] - b1).tolist(),
        a1_minus_series=(am[1::2] - a1).tolist(),
        first_omitted_term_49q6_over_589824=(49 * qs**6 / 589824).tolist(),
    )
    dd, al, _, be, FF, ww = tp.DUFF
    TT = 2 * np.pi / ww
    ref = solve_ivp(
        lambda t, y: [y[1], -dd * y[1] - al * y[0] - be * y[0] ** 3 + FF * np.cos(ww * t)],
        (0, 80 * TT),
        [0.0, 0.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-13,
        t_eval=[80 * TT],
    ).y[:, -1]
    od = tp.orbits([[0.0, 0.0], [0.5, 0.2], [np.nan, 0.0]], tp.DUFF)
    r["duffing"] = dict(
        status=od.status.tolist(),
        orbit_max_error_vs_scipy=float(np.max(np.abs(od.y[:2] - ref))),
        det_minus_exp_dT=float(np.max(np.abs(np.prod(od.multipliers[:2], axis=1).real - np.exp(-dd * TT)))),
    )
    write_result(a.out, r, load_at_start=load0)
    print(json.dumps(r, indent=1))


if __name__ == "__main__":
    main()
