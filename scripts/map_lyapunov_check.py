"""How far the map's labels depend on its short windows: lanes of docs/map/ run again with longer ones.

The map of docs/map/ labels each cell from 50 transient + 20 sampled periods and a largest Lyapunov
exponent over 10 periods. A finite-time exponent is O(1/t) away from its limit, and a slowly attracting
orbit is not yet periodic to the detector's tolerance after 50 periods. This script runs lanes of the
map's lower-left region (omega_pi 10-12 rad/s, q_pi 0.022-0.030 m, low forcing acceleration) and of its
strongly chaotic band (17.9-18.2 rad/s) four ways, and writes the exponents and labels of each to
docs/map/lyapunov_window_check.json:

* ``map``: the map's settings (50 + 20 periods, lambda_1 over 10);
* ``lyapunov_40``, ``long_lyapunov``: lambda_1 over 40 and 160 periods instead of 10;
* ``long_transient``: 300 transient periods before the 20 samples, lambda_1 over 10.

Each run's labels are recorded twice: ``label`` by the sweep's rule (the exponent's interval of
+-2 batch-means standard errors, `jaxcelt.sweeps.regimes.classify`) and ``label_point_estimate`` from the
exponent alone (no standard error), so the two rules can be compared on lanes whose long-window
answer is known.

The lanes found period-1 after the long transient are then refined with `jaxcelt.periodic_orbit`
(Newton on the stroboscopic map from the last sample, Tsit5 rtol 1e-9) for their Floquet exponent
log|mu_max| / T: the exact largest exponent of the orbit, against which the finite-time exponents
and their standard errors are checked (``floquet``).

    python scripts/map_lyapunov_check.py [--json docs/map/lyapunov_window_check.json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

LOW = [(w, q) for w in (10.0, 10.5, 11.0, 11.5, 12.0) for q in (0.022, 0.026, 0.030)]
CHAOTIC = [(w, q) for w in (17.9, 18.2) for q in (0.045, 0.055)]
RUNS = {
    "map": dict(transient_periods=50, sample_periods=20, lyapunov_periods=10),
    "lyapunov_40": dict(transient_periods=50, sample_periods=20, lyapunov_periods=40),
    "long_lyapunov": dict(transient_periods=50, sample_periods=20, lyapunov_periods=160),
    "long_transient": dict(transient_periods=300, sample_periods=20, lyapunov_periods=10),
}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, default=Path("docs/map/lyapunov_window_check.json"))
    a = ap.parse_args()

    import jaxcelt as jc
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.sweeps.regimes import classify, regime_names
    from jaxcelt.versions import versions

    load0 = load_average()
    p = jc.CeltParams.paper()
    pts = LOW + CHAOTIC
    lanes = {"omega_pi": np.array([w for w, _ in pts]), "q_pi": np.array([q for _, q in pts])}
    rec: dict = {
        "about": (
            "scripts/map_lyapunov_check.py: lanes of the omega_pi x q_pi map (docs/map/) from rest, Tsit5 rtol 1e-8, "
            "stop-on-invalid, run with the map's windows and with longer ones; chaos threshold 0.02 1/s."
        ),
        "versions": versions(),
        "lanes": [{"omega_pi": w, "q_pi": q, "group": "low" if (w, q) in LOW else "chaotic"} for w, q in pts],
        "runs": {},
    }
    datasets = {}
    for name, kw in RUNS.items():
        t = time.perf_counter()
        ds = jc.sweep_lanes(p, lanes, stop_on_invalid=True, max_steps=10_000_000, progress=True, **kw)
        datasets[name] = ds
        lam = ds["lyapunov"].values
        err = ds["lyapunov_stderr"].values
        point = classify(ds["section"].values, ds["status"].values, ds["valid"].values.astype(bool),
                         ds["r_O"].values, lam)  # fmt: skip
        rec["runs"][name] = {
            **kw,
            "seconds": round(time.perf_counter() - t, 1),
            "lyapunov_per_s": [None if not np.isfinite(x) else round(float(x), 4) for x in lam],
            "lyapunov_stderr_per_s": [None if not np.isfinite(x) else round(float(x), 4) for x in err],
            "label": [str(s) for s in regime_names(ds["regime"].values, ds["period"].values)],
            "label_point_estimate": [str(s) for s in regime_names(point["regime"], point["period"])],
            "status": [int(s) for s in ds["status"].values],
        }
        print(name, json.dumps(rec["runs"][name]), flush=True)
    import diffrax

    lt_ds = datasets["long_transient"]
    floquet = []
    t = time.perf_counter()
    for i, label in enumerate(rec["runs"]["long_transient"]["label"]):
        if label != "period-1":
            continue
        w, q = pts[i]
        o = jc.periodic_orbit(
            p.replace(omega_pi=w, q_pi=q), lt_ds["section"].values[i, -1], k=1,
            t0=float(lt_ds["t_section"].values[i, -1]), solver=diffrax.Tsit5(), rtol=1e-9, atol=1e-11,
            newton_tol=1e-6, max_steps=50_000,
        )  # fmt: skip
        lg_run = rec["runs"]["long_lyapunov"]
        lam, err = lg_run["lyapunov_per_s"][i], lg_run["lyapunov_stderr_per_s"][i]
        fe = float(o.floquet_exponent)
        floquet.append({
            "lane": i, "omega_pi": w, "q_pi": q, "status": int(o.status), "residual": float(o.residual),
            "max_multiplier": round(float(o.max_multiplier), 5), "floquet_exponent_per_s": round(fe, 4),
            "long_lyapunov_per_s": lam, "long_lyapunov_stderr_per_s": err,
            "within_2_stderr": bool(abs(lam - fe) <= 2 * err),
        })  # fmt: skip
        print("floquet", json.dumps(floquet[-1]), flush=True)
    rec["floquet"] = {"seconds": round(time.perf_counter() - t, 1), "orbits": floquet}
    low = [i for i, (w, q) in enumerate(pts) if (w, q) in LOW]
    m, lg, lt = (rec["runs"][k] for k in ("map", "long_lyapunov", "long_transient"))
    ch = range(len(low), len(pts))

    def med(run, idx):
        vals = [rec["runs"][run]["lyapunov_per_s"][i] for i in idx]
        return round(float(np.median([v for v in vals if v is not None])), 3)  # None: stopped invalid

    def counts(run, idx, key="label"):
        labels = [rec["runs"][run][key][i] for i in idx]
        return {k: labels.count(k) for k in sorted(set(labels))}

    rec["summary"] = {
        "low_lanes": len(low),
        "low_labels": {run: counts(run, low) for run in RUNS},
        "low_labels_point_estimate": {run: counts(run, low, "label_point_estimate") for run in RUNS},
        "chaotic_labels": {run: counts(run, ch) for run in RUNS},
        "chaotic_labels_point_estimate": {run: counts(run, ch, "label_point_estimate") for run in RUNS},
        "low_chaotic_with_map_windows": sum(m["label_point_estimate"][i] == "chaotic" for i in low),
        "low_chaotic_with_long_lyapunov": sum(lg["label_point_estimate"][i] == "chaotic" for i in low),
        "low_negative_long_lyapunov": sum((lg["lyapunov_per_s"][i] or 0) < 0 for i in low),
        "low_periodic_after_long_transient": sum(lt["label"][i].startswith("period") for i in low),
        "floquet_converged_stable": sum(f["status"] == 0 and f["max_multiplier"] < 1 for f in floquet),
        "floquet_within_2_stderr": sum(f["within_2_stderr"] for f in floquet),
        "floquet_orbits": len(floquet),
        "chaotic_lanes": len(CHAOTIC),
        "chaotic_chaotic_with_both_windows": sum(
            m["label_point_estimate"][i] == "chaotic" and lg["label_point_estimate"][i] == "chaotic" for i in ch
        ),
        "chaotic_median_lyapunov_per_s": {run: med(run, ch) for run in RUNS},
        "low_median_lyapunov_per_s": {run: med(run, low) for run in RUNS},
    }
    print(json.dumps(rec["summary"]), flush=True)
    write_result(a.json, rec, load_at_start=load0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
