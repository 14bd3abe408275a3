"""Why the float32 GPU map labels float64's period-3-16 cells aperiodic: precision or tolerance?

Picks cells (seeded) that the 400 x 400 GPU maps label "period 3-16" in float64 (rtol 1e-8) and
"aperiodic" in float32 (rtol 1e-6) (docs/performance/gpu_map_labels_*.npz), runs them again on
this machine over the maps' 270 + 30 periods as float64 at rtol 1e-8, float64 at rtol 1e-6 and
float32 at rtol 1e-6, and reports each run's label and how far its samples are from repeating at the
float64 period k: max |x[j+k] - x[j]| / (1 + max |x|) over omega and n (what `detect_period` tests
against its tolerance, 1e-4).

    python scripts/float32_periodic_check.py   # -> docs/performance/float32_periodic_check.json
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

DOCS = Path(__file__).resolve().parents[1] / "docs" / "performance"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=DOCS / "float32_periodic_check.json")
    a = ap.parse_args()

    import jaxcelt as jc
    from jaxcelt.plotting.map import map_categories
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.sweeps.api import sweep_lanes
    from jaxcelt.sweeps.regimes import REGIMES
    from jaxcelt.versions import versions

    names = [c[0] for c in map_categories(np.zeros(0, int), np.zeros(0, int))[1]]
    f64 = np.load(DOCS / "gpu_map_labels_float64.npz")
    f32 = np.load(DOCS / "gpu_map_labels_float32.npz")
    ix, iy = np.nonzero((f64["category"] == names.index("period 3-16")) & (f32["category"] == names.index("aperiodic")))
    pick = np.random.default_rng(a.seed).choice(len(ix), a.cells, replace=False)
    om, q = f64["omega_pi"][ix[pick]], f64["q_pi"][iy[pick]]
    p = jc.CeltParams.paper()
    kw = dict(transient_periods=270, sample_periods=30, stop_on_invalid=True)
    runs = {
        "float64_rtol1e-8": dict(rtol=1e-8, atol=1e-10),
        "float64_rtol1e-6": dict(rtol=1e-6, atol=1e-8),
        "float32_rtol1e-6": dict(rtol=1e-6, atol=1e-8, dtype="float32"),
    }
    res, secs = {}, {}
    load0 = load_average()
    for name, opts in runs.items():
        t = time.perf_counter()
        res[name] = sweep_lanes(p, {"omega_pi": om, "q_pi": q}, **kw, **opts)
        secs[name] = round(time.perf_counter() - t, 1)
    ref = res["float64_rtol1e-8"]
    cells = []
    for i in range(a.cells):
        k = int(ref["period"].values[i])
        row = {"omega_pi": float(om[i]), "q_pi": float(q[i]), "float64_period": k}
        for name, ds in res.items():
            s = ds["section"].values[i][:, 3:9]
            gap = float(np.max(np.abs(s[k:] - s[:-k])) / (1 + np.max(np.abs(s)))) if k > 0 else None
            row[name] = {
                "status": int(ds["status"].values[i]),
                "regime": REGIMES[int(ds["regime"].values[i])],
                "period": int(ds["period"].values[i]),
                "gap_at_float64_period": gap,
            }
        cells.append(row)
    out = {"about": __doc__.splitlines()[0], "versions": versions(), "seconds": secs, "cells": cells}
    write_result(a.out, out, load_at_start=load0)
    print(json.dumps(cells, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
