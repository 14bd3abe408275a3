"""The pool's drain: what one pool iteration costs at a given width, and drain schedules A/B.

1. The lanes of the 400 x 300 sweep (omega_pi in [10, 20] from rest, rtol 1e-8) that run to
   ``max_steps`` when integrated on (with none, as for a small ``--n-freq``, the 6 with the most
   steps), run alone (no queue, so no drain) at 3 slots per device and in pools of 4, 6 and 16
   slots per device (padding lanes): seconds per pool iteration. Pools of at most
   `jaxcelt.ensemble.pool.SEQUENTIAL_WIDTH` slots step in the inner loop whose kernels XLA runs
   one after the other.
2. The whole sweep, stopping at invalid states and integrating on, with the drain dividing the
   width by 4 down to 6 slots (96, 24, 6: every width steps once per iteration) and down to 4 slots
   (96, 24, 4: the library's default; the last width steps in the inner loop): compile apart, run
   time, iterations, step slots paid. Both schedules run their drain whatever the lanes left are predicted to
   cost (``drain_min_steps=0``).

    .venv/bin/python benchmarks/bench_drain.py --out docs/bifurcation
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import jax
import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--tail-max-steps", type=int, default=300_000, help="step budget of the lone-lane runs")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)
    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig
    from jaxcelt.ensemble import stroboscopic as sb
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    V = versions()
    print(" ".join(f"{k}={v}" for k, v in V.items()), flush=True)
    res: dict = dict(versions=V, cpu_count=os.cpu_count(), load_average_at_start=os.getloadavg())
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (len(vals), 1))

    def run(v, cfg, reps=1, **kw):
        pb = sb.lanes_params(p, "omega_pi", v)
        t = time.perf_counter()
        sb.run_lanes(pb, y0[: len(v)], cfg, compile_only=True, varying=("omega_pi",), stats=True, **kw)
        tc = time.perf_counter() - t
        runs = []
        for _ in range(reps):
            t = time.perf_counter()
            out, st = sb.run_lanes(pb, y0[: len(v)], cfg, varying=("omega_pi",), stats=True, **kw)
            runs.append(time.perf_counter() - t)
        status = {int(k): int(c) for k, c in zip(*np.unique(out["status"], return_counts=True))}
        return out, dict(
            compile_s=tc, run_s=float(np.median(runs)), runs_s=runs, iterations=st.iterations,
            slot_steps=st.slot_steps, steps=int(out["num_steps"].sum()), status_counts=status,
        )  # fmt: skip

    schedules = {"quarter_to_6": (6, 4), "quarter_to_4": (4, 4)}
    res["schedules"] = {}
    long = None
    for name, (md, fac) in schedules.items():
        res["schedules"][name] = dict(min_drain_width=md, drain_factor=fac)
        for stop in (True, False):
            cfg = SweepConfig(transient_periods=200, sample_periods=100, stop_on_invalid=stop)
            out, r = run(vals, cfg, reps=3 if stop else 1, min_drain_width=md, drain_factor=fac, drain_min_steps=0)
            assert r["compile_s"] > 1.0, "a compiled program of another schedule was reused"
            res["schedules"][name]["stop_on_invalid" if stop else "integrate_on"] = r
            print(name, "stop" if stop else "on", r, flush=True)
            if not stop and long is None:
                # the lanes at max_steps; with none (a small --n-freq), the 6 with the most steps
                long = np.flatnonzero(out["status"] == 1)
                if long.size == 0:
                    long = np.sort(np.argsort(-out["num_steps"], kind="stable")[:6])

    # 1. per-iteration cost against the width, on the lanes that run longest
    lv = vals[long]
    cfg = SweepConfig(transient_periods=200, sample_periods=100, stop_on_invalid=False, max_steps=a.tail_max_steps)
    ndev = len(jax.devices())
    res["lone_lanes"] = dict(omega_pi=lv.tolist(), max_steps=a.tail_max_steps, widths={})
    for pad in (None, 4 * ndev, 6 * ndev, 16 * ndev):
        _, r = run(lv, cfg, pad_to=pad)
        w = -(-max(len(lv), pad or 0) // ndev)
        r["us_per_iteration"] = 1e6 * r["run_s"] / r["iterations"]
        res["lone_lanes"]["widths"][str(w)] = r
        print("lone lanes, width", w, r, flush=True)
    res["load_average_at_end"] = os.getloadavg()
    if a.out:
        write_result(a.out / "drain.json", res, load_at_start=res["load_average_at_start"])
        print("wrote", a.out / "drain.json")


if __name__ == "__main__":
    main()
