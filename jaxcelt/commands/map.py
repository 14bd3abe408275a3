"""``jaxcelt map``: a two-parameter regime / Lyapunov chart -> dataset (netCDF) + figure (PNG) + summary (JSON).

Every grid point is one lane of the sweep engine (stroboscopic sampling after a transient, regime
labels, optional largest Lyapunov exponent). Interrupting and rerunning the same command resumes
from the finished chunks. Example (the paper's forcing plane)::

    jaxcelt map --x omega_pi=10:20:100 --y q_pi=0.02:0.06:60 --out out/map

``--curves FILE`` draws bifurcation curves over both panels of the figure: a JSON result file with curves in the
map's two parameters as `jaxcelt.orbits.curves.curve_to_dict` writes them (e.g. docs/orbits/curves_omega_q.json
from scripts/curves_omega_q.py, docs/orbits/fold_curves.json). The curves are read, not computed: a curve takes
minutes of variational solves per point and needs a start on a located one-parameter bifurcation, which is the
curves script's job; the map command only draws them.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

from jaxcelt.commands._sweep_flags import add_sweep_flags, lane_devices, run_settings
from jaxcelt.commands.args import UsageError, overrides, value_range


def register(sub) -> None:
    p = sub.add_parser(
        "map",
        help="two-parameter map of regimes and the largest Lyapunov exponent (e.g. omega_pi x q_pi)",
        description=__doc__.splitlines()[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--x", default="omega_pi=10:20:40", metavar="NAME=RANGE",
                   help="horizontal axis: a CeltParams field and its values, START:STOP:COUNT or a,b,c")  # fmt: skip
    p.add_argument("--y", default="q_pi=0.02:0.06:24", metavar="NAME=RANGE", help="vertical axis, as --x")
    add_sweep_flags(
        p,
        lyapunov_default=30,
        chunk_size_default=600,
        dtype=True,
        help={
            "lyapunov": "periods of tangent dynamics for lambda_1 (0: off)",
            "set": "override any other CeltParams field, repeatable",
            "solver": "explicit Runge-Kutta method",
            "chunk-size": "lanes per jitted pool launch (unit of resumable writing)",
            "width": "pool slots per device (default jaxcelt.ensemble.DEFAULT_WIDTH)",
            "host-devices": "CPU only: split the CPU into this many JAX devices ('auto' = cores, 1 = off)",
            "stop-on-invalid": "end a lane at its first invalid state (lift-off or n3 <= 0): label 'invalid'",
        },
    )
    p.add_argument("--out", type=Path, default=Path("out/map"), help="output directory (resumable)")
    p.add_argument("--no-figures", action="store_true")
    p.add_argument("--curves", type=Path, default=None, metavar="FILE",
                   help="JSON file of bifurcation curves in the map's two parameters, drawn over both panels")  # fmt: skip
    p.set_defaults(func=run)


def parse_axis(spec: str, flag: str):
    """``"omega_pi=10:20:100"`` -> ("omega_pi", values); `UsageError` (a ValueError) naming the flag otherwise."""
    if "=" not in spec:
        raise UsageError(f"argument {flag}: expected NAME=START:STOP:COUNT (or NAME=a,b,c), got {spec!r}")
    name, rng = (s.strip() for s in spec.split("=", 1))
    try:
        values = value_range(rng)
    except argparse.ArgumentTypeError as e:
        raise UsageError(f"argument {flag}: {e}") from None
    if values.size == 0:
        raise UsageError(f"argument {flag}: no values in {rng!r}")
    return name, values


def read_curves(path: Path, x_name: str, y_name: str) -> dict:
    """The curves file of ``--curves``, checked to hold curves in the map's parameters; `UsageError` otherwise."""
    from jaxcelt.plotting.map import map_curve_lines

    try:
        data = json.loads(Path(path).read_text())
    except OSError as e:
        raise UsageError(f"argument --curves: cannot read {str(path)!r}: {e.strerror or e}") from None
    except json.JSONDecodeError as e:
        raise UsageError(f"argument --curves: {str(path)!r} is not JSON ({e.msg}, line {e.lineno})") from None
    try:
        map_curve_lines(data, x_name, y_name)
    except (ValueError, KeyError, TypeError) as e:
        raise UsageError(f"argument --curves: {str(path)!r}: {e}") from None
    return data


def summarize(ds) -> dict:
    """Counts of each regime category and the Lyapunov range (for summary.json)."""
    import numpy as np

    from jaxcelt.plotting.map import map_categories

    sel = {"start": 0} if "start" in ds.dims else {}
    d = ds.isel(**sel)
    cat, cats = map_categories(d["regime"].values, d["period"].values)
    counts = {label: int(np.sum(cat == i)) for i, (label, _) in enumerate(cats) if np.any(cat == i)}
    lam = d["lyapunov"].values
    fin = np.isfinite(lam)
    out = {
        "cells": int(cat.size),
        "regime_counts": counts,
        "unbounded_wandering_cells": int(np.sum(d["global_motion"].values == 1)),
        "lyapunov_cells": int(fin.sum()),
    }
    if fin.any():
        out["lyapunov_per_s"] = {
            "min": round(float(lam[fin].min()), 4),
            "median": round(float(np.median(lam[fin])), 4),
            "max": round(float(lam[fin].max()), 4),
            "positive_above_0.02": int(np.sum(lam[fin] > 0.02)),
        }
    return out


def run(args) -> int:
    devices = lane_devices(args)
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.commands._warnings import one_line_warnings
    from jaxcelt.integrate.solvers import make_solver
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions_string

    # bad input raises ValueError naming the parameter (jaxcelt.cli: one error line, exit 2), before any work
    x = parse_axis(args.x, "--x")
    y = parse_axis(args.y, "--y")
    params = jc.CeltParams.paper(**overrides(args.set))
    for name in (x[0], y[0]):
        if name not in jc.PARAM_NAMES:
            raise UsageError(f"argument --x/--y: unknown parameter {name!r}; known: {', '.join(jc.PARAM_NAMES)}")
    for name, values in (x, y):  # each lane's parameters must be valid too
        for v in values:
            params.replace(**{name: float(v)})
    curves = None if args.curves is None else read_curves(args.curves, x[0], y[0])
    y0 = np.asarray(jc.initial_state(params, omega=args.omega0))
    print(versions_string(), flush=True)
    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    t0 = time.perf_counter()
    with one_line_warnings("map"):
        ds = jc.parameter_map(
            params, x=x, y=y, y0=y0, transient_periods=args.transient, sample_periods=args.sample,
            lyapunov_periods=args.lyapunov, solver=make_solver(args.solver), rtol=args.rtol, atol=args.atol,
            max_steps=args.max_steps, chunk_size=args.chunk_size, width=args.width, engine=args.engine,
            stop_on_invalid=args.stop_on_invalid, dtype=args.dtype, sort_by_cost=True, devices=devices,
            out=str(args.out), progress=True,
        )  # fmt: skip
    wall = time.perf_counter() - t0
    if devices is not None:
        devices.close()
    summary = {
        "command": "jaxcelt map",
        "x": {"name": x[0], "from": float(x[1][0]), "to": float(x[1][-1]), "n": int(x[1].size)},
        "y": {"name": y[0], "from": float(y[1][0]), "to": float(y[1][-1]), "n": int(y[1].size)},
        "set": args.set,
        "curves": None if args.curves is None else str(args.curves),
        **run_settings(args, wall, devices),
        "dtype": args.dtype,
        "engine": args.engine,
        "load_average_at_start": None if load is None else [round(v, 2) for v in load],
        **summarize(ds),
    }
    write_result(args.out / "summary.json", summary, load_at_start=load)
    print(json.dumps(summary, indent=1), flush=True)
    if not args.no_figures:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from jaxcelt.plotting.map import map_figure

        title = f"{x[0]} x {y[0]} map: {args.transient} transient + {args.sample} sampled periods"
        fig = map_figure(ds, title=title, curves=curves)
        fig.savefig(args.out / "map.png", dpi=150)
        plt.close(fig)
    print(f"wrote {args.out}", flush=True)
    return 0
