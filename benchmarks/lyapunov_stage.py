"""The sweep's Lyapunov stage: how its groups are formed and dealt over the devices, side by side.

The main job's sweep (``jaxcelt bifurcation``'s defaults: 60 values of omega_pi in [10, 20] rad/s, 100 transient
periods, 30 samples, the largest Lyapunov exponent over 150 periods, stopping at invalid states, rtol 1e-8,
atol 1e-10) on all CPU cores as devices. The main solve runs once; then the Lyapunov stage over its successful lanes,
costliest first (`jaxcelt.ensemble.run_lanes`' order), is run as groups of a fixed width, in these layouts:

* ``contiguous``: groups of the pool's width per device, each device holding a contiguous block of the group
  (the layout before `jaxcelt.ensemble.stroboscopic.lyapunov_groups`);
* ``round-robin``: groups of ``--widths`` lanes per device, the group's lanes dealt over the devices round-robin
  (`lyapunov_groups`, with `LYAPUNOV_GROUP_WIDTH` the library's default).

Each layout's program is traced and lowered, then compiled by XLA, each timed apart (JAX's persistent cache is not
used here; a width compiled before in the process is found compiled), then the stage is timed ``--reps`` times in
turn with the others (medians). Reports the groups, the padding positions, and the speed and exponents of each
layout against the first one (``speedup_vs_contiguous``, ``max_abs_lyapunov_difference_vs_contiguous``: the
contiguous layout, or with ``--no-contiguous`` the first of ``--widths``); the exponents differ (another compiled
program: rounding differs, and a finite-time exponent of a chaotic lane amplifies it).

    .venv/bin/python benchmarks/lyapunov_stage.py --out docs/bifurcation/lyapunov_stage.json
    .venv/bin/python benchmarks/lyapunov_stage.py --widths 16 --no-contiguous --out /tmp/stage.json   # one layout

``--error-control state|all``: what the stage's step-size control measures (`jaxcelt.SweepOptions`'
``lyapunov_error_control``; default the library's); ``--tangent difference|jvp``: how it forms the tangent vector's
derivative (``lyapunov_tangent``; default the library's). The per-lane exponents and their standard errors are
written for comparing two runs.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import jax
import numpy as np


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-freq", type=int, default=60)
    ap.add_argument("--lyapunov", type=int, default=150, help="periods of the exponent's window")
    ap.add_argument("--widths", default="8,12,16,24", help="round-robin group widths per device, comma-separated")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--no-contiguous", action="store_true", help="leave out the contiguous layout")
    ap.add_argument("--error-control", default=None, choices=("state", "all"),
                    help="what the stage's step-size control measures (default: the library's)")  # fmt: skip
    ap.add_argument("--tangent", default=None, choices=("difference", "jvp"),
                    help="how the stage forms the tangent's derivative (default: the library's)")  # fmt: skip
    ap.add_argument("--out", type=Path, default=Path("docs/bifurcation/lyapunov_stage.json"))
    a = ap.parse_args()
    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)
    import jaxcelt as jc
    from jaxcelt.ensemble import SweepConfig, device_mesh, lanes_params, run_lanes
    from jaxcelt.ensemble import stroboscopic as sb
    from jaxcelt.ensemble.pool import DEFAULT_WIDTH
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.versions import versions, versions_string

    print(versions_string(), flush=True)
    load0 = load_average()
    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    cfg = SweepConfig(transient_periods=100, sample_periods=30, lyapunov_periods=0, rtol=1e-8, atol=1e-10,
                      max_steps=10**6, stop_on_invalid=True)  # fmt: skip
    pb = lanes_params(p, "omega_pi", vals)
    out = run_lanes(pb, np.tile(np.asarray(jc.initial_state(p)), (a.n_freq, 1)), cfg, varying=("omega_pi",))
    ok = np.flatnonzero(out["status"] == 0)
    ok = ok[np.argsort(-out["num_steps"][ok], kind="stable")]
    ndev = len(jax.local_devices())
    mesh = device_mesh(None)
    ec = {} if a.error_control is None else {"lyapunov_error_control": a.error_control}
    ec |= {} if a.tangent is None else {"lyapunov_tangent": a.tangent}
    lcfg = SweepConfig(transient_periods=0, sample_periods=30, lyapunov_periods=a.lyapunov, rtol=1e-8, atol=1e-10,
                       max_steps=10**6, stop_on_invalid=True, **ec)  # fmt: skip
    pb_np = jax.tree_util.tree_map(np.asarray, pb)
    lyap = sb._lyap_chunk(jax.default_backend())
    pool_per_device = min(DEFAULT_WIDTH, -(-a.n_freq // ndev))

    def contiguous(per_device):
        G = per_device * ndev
        return [(sb.pad_lanes(ok[i : i + G], G), np.arange(G) < len(ok[i : i + G])) for i in range(0, len(ok), G)]

    layouts = {} if a.no_contiguous else {f"contiguous {pool_per_device}": contiguous(pool_per_device)}
    for w in (int(x) for x in a.widths.split(",")):
        layouts[f"round-robin {w}"] = sb.lyapunov_groups(ok, w, ndev)

    def args(idx):
        return jax.tree_util.tree_map(lambda v: v[idx], pb_np), out["samples"][idx, 0], out["t_samples"][idx, 0]

    def run(program, groups):
        lam, err = np.full(a.n_freq, np.nan), np.full(a.n_freq, np.nan)
        for idx, own in groups:
            x, e = program(*args(idx), lcfg, mesh)
            lam[idx[own]], err[idx[own]] = np.asarray(x)[own], np.asarray(e)[own]
        return lam, err

    rows, programs = {}, {}
    for name, groups in layouts.items():
        t = time.perf_counter()
        lowered = lyap.lower(*args(groups[0][0]), lcfg, mesh)
        t_lower = time.perf_counter() - t
        programs[name] = lowered.compile()
        t_compile = time.perf_counter() - t - t_lower
        t = time.perf_counter()
        lam, err = run(programs[name], groups)
        rows[name] = {"groups": len(groups), "lanes_per_device": int(groups[0][0].size // ndev),
                      "padding_positions": int(sum((~own).sum() for _, own in groups)),
                      "trace_and_lower_s": t_lower, "xla_compile_s": t_compile,
                      "first_call_s": t_lower + t_compile + time.perf_counter() - t, "warm_each_s": [],
                      "lyapunov": lam, "lyapunov_stderr": err}  # fmt: skip
    for _ in range(a.reps):
        for name, groups in layouts.items():
            t = time.perf_counter()
            run(programs[name], groups)
            rows[name]["warm_each_s"].append(time.perf_counter() - t)
    base = next(iter(rows.values()))  # the contiguous layout, unless left out
    print(f"\n{len(ok)} successful lanes of {a.n_freq}, {ndev} devices, the pool's width {pool_per_device} per device")
    print(f"{'layout':<18}{'groups':>7}{'padding':>9}{'lower':>8}{'XLA':>8}{'first call':>12}{'warm':>9}"
          f"{'vs first row':>14}{'max |dlambda|':>15}")
    base_lam = np.asarray(base["lyapunov"])
    for name, r in rows.items():
        r["warm_s"] = float(np.median(r["warm_each_s"]))
        r["speedup_vs_contiguous"] = float(np.median(base["warm_each_s"]) / r["warm_s"])
        d = np.abs(np.asarray(r["lyapunov"])[ok] - base_lam[ok])
        r["max_abs_lyapunov_difference_vs_contiguous"] = float(np.max(d)) if d.size else 0.0
        for k in ("lyapunov", "lyapunov_stderr"):
            r[k] = [None if not np.isfinite(v) else float(v) for v in r[k]]
        print(f"{name:<18}{r['groups']:>7}{r['padding_positions']:>9}{r['trace_and_lower_s']:>7.2f}s"
              f"{r['xla_compile_s']:>7.2f}s{r['first_call_s']:>11.2f}s{r['warm_s']:>8.2f}s"
              f"{r['speedup_vs_contiguous']:>14.2f}x{r['max_abs_lyapunov_difference_vs_contiguous']:>15.2e}")  # fmt: skip
    res = {"config": {"n_freq": a.n_freq, "transient_periods": 100, "sample_periods": 30, "lyapunov_periods": a.lyapunov,
                      "rtol": 1e-8, "atol": 1e-10, "stop_on_invalid": True, "reps": a.reps,
                      "lyapunov_error_control": lcfg.lyapunov_error_control, "lyapunov_tangent": lcfg.lyapunov_tangent},
           "devices": ndev, "successful_lanes": int(len(ok)), "pool_lanes_per_device": pool_per_device,
           "library_default_lanes_per_device": sb.LYAPUNOV_GROUP_WIDTH, "layouts": rows, "versions": versions()}  # fmt: skip
    write_result(a.out, res, load_at_start=load0)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
