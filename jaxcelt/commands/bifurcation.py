"""``jaxcelt bifurcation``: a stroboscopic sweep -> dataset (netCDF) + figures (PNG) + summary (JSON).

Defaults are a coarse, laptop-sized version of the paper's Fig. 3 (a few minutes on 2 CPU
cores); the full benchmark size is ``--omega 10:20:400 --transient 200 --sample 100``.
Interrupting and rerunning the same command resumes from the finished chunks.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

SWEEP_SOLVERS = ("Tsit5", "Dopri5", "Dopri8")  # names in jaxcelt.benchmarking.SOLVERS


def register(sub) -> None:
    p = sub.add_parser(
        "bifurcation",
        help="stroboscopic bifurcation diagram over omega_pi (or another parameter)",
        description=__doc__.splitlines()[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--omega", default="10:20:60", help="omega_pi values [rad/s]: START:STOP:COUNT or a,b,c")
    p.add_argument("--param", default="omega_pi", help="swept CeltParams field (values from --values)")
    p.add_argument(
        "--values", default=None, help="values of --param when it is not omega_pi (START:STOP:COUNT or list)"
    )
    p.add_argument("--transient", type=int, default=100, help="transient forcing periods discarded")
    p.add_argument("--sample", type=int, default=30, help="stroboscopic samples (periods) kept")
    p.add_argument(
        "--lyapunov", type=int, default=30, help="periods of tangent dynamics for the Lyapunov exponent (0: off)"
    )
    p.add_argument(
        "--set", action="append", default=[], metavar="NAME=VALUE", help="override any CeltParams field, repeatable"
    )
    p.add_argument("--omega0", default="0,0,0", help="initial omega (body) [rad/s]")
    p.add_argument(
        "--solver",
        default="Tsit5",
        choices=SWEEP_SOLVERS,
        help="explicit Runge-Kutta method (adaptive, PID control, section times hit exactly). Dopri8 is the same "
        "8th-order Dormand-Prince family as scipy's DOP853: at rtol 1e-8 about 25x more accurate than Tsit5, "
        "as fast per sweep, but it compiles longer",
    )
    p.add_argument("--rtol", type=float, default=1e-8)
    p.add_argument("--atol", type=float, default=1e-10)
    p.add_argument("--max-steps", type=int, default=1_000_000)
    p.add_argument(
        "--chunk-size",
        type=int,
        default=200,
        help="lanes per jitted pool launch (the unit of resumable writing); split over the devices",
    )
    p.add_argument(
        "--width",
        type=int,
        default=None,
        help="pool slots per device: lanes stepped side by side (vmap width; default jaxcelt.sweep.DEFAULT_WIDTH)",
    )
    p.add_argument(
        "--host-devices",
        default="auto",
        help="CPU only: split the CPU into this many JAX devices and shard lanes over them (one XLA CPU "
        "computation uses about one core); 'auto' = number of CPU cores, 1 = off. Ignored on GPU",
    )
    p.add_argument(
        "--stop-on-invalid",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="end a lane at its first invalid state (lift-off or n3 <= 0; the model does not hold past it): "
        "label 'invalid', later samples inf, no Lyapunov exponent. --no-stop-on-invalid integrates on",
    )
    p.add_argument("--orbits", default="14,15.6,17,19", help="omega_pi values for phase-plot figures ('' for none)")
    p.add_argument("--orbit-periods", type=int, default=40, help="periods shown in the phase plots")
    p.add_argument("--out", type=Path, default=Path("out/bifurcation"), help="output directory (resumable)")
    p.add_argument("--no-figures", action="store_true")
    p.set_defaults(func=run)


def _ranges(ds, key: str = "regime") -> list[dict]:
    """Contiguous runs of equal (regime label, global motion) along the swept axis."""
    import numpy as np

    from jaxcelt.regimes import GLOBAL_MOTION, regime_names

    name = ds.attrs["swept_parameter"]
    vals = ds[name].values
    reg = ds["regime"].values
    per = ds["period"].values
    glob = ds["global_motion"].values
    if reg.ndim == 2:  # multi-start: first start
        reg, per, glob = reg[:, 0], per[:, 0], glob[:, 0]
    labels = [f"{n}, {GLOBAL_MOTION[int(g)]}" for n, g in zip(regime_names(reg, per), glob)]
    out = []
    start = 0
    for i in range(1, len(vals) + 1):
        if i == len(vals) or labels[i] != labels[start]:
            out.append({"from": float(vals[start]), "to": float(vals[i - 1]), "n": i - start, "label": labels[start]})
            start = i
    lam = ds["lyapunov"].values
    if np.isfinite(lam).any():
        out.append({"lyapunov_range_per_s": [float(np.nanmin(lam)), float(np.nanmax(lam))]})
    return out


def _set_host_devices(spec: str) -> int:
    """Ask JAX for ``spec`` CPU devices (before the backend starts); returns the count asked for."""
    import os

    import jax

    n = (os.cpu_count() or 1) if spec == "auto" else int(spec)
    if n < 1:
        raise SystemExit(f"--host-devices must be >= 1 or 'auto', got {spec!r}")
    try:
        jax.config.update("jax_num_cpu_devices", n)
    except RuntimeError:  # backend already started (e.g. called from Python after JAX work)
        pass
    return n


def run(args) -> int:
    _set_host_devices(args.host_devices)
    import jax
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.benchmarking import make_solver
    from jaxcelt.commands._warnings import one_line_warnings
    from jaxcelt.commands.simulate import parse_overrides
    from jaxcelt.dataset import open_sweep
    from jaxcelt.sweep import DEFAULT_WIDTH, orbit, parse_range, sweep
    from jaxcelt.versions import versions_string

    print(versions_string(), flush=True)
    params = jc.CeltParams.paper(**parse_overrides(args.set))
    values = parse_range(args.omega if args.param == "omega_pi" else (args.values or ""))
    if values.size == 0:
        raise SystemExit("no values to sweep (use --omega, or --values with --param)")
    omega0 = [float(x) for x in args.omega0.split(",")]
    y0 = np.asarray(jc.initial_state(params, omega=omega0))
    args.out.mkdir(parents=True, exist_ok=True)
    solver = make_solver(args.solver)
    t0 = time.perf_counter()
    with one_line_warnings("bifurcation"):  # e.g. a damaged chunk file recomputed on resume
        sweep(
            params,
            args.param,
            values,
            transient_periods=args.transient,
            sample_periods=args.sample,
            lyapunov_periods=args.lyapunov,
            y0=y0,
            solver=solver,
            rtol=args.rtol,
            atol=args.atol,
            max_steps=args.max_steps,
            chunk_size=args.chunk_size,
            width=args.width,
            stop_on_invalid=args.stop_on_invalid,
            sort_by_cost=True,
            out=str(args.out),
            progress=True,
        )
    wall = time.perf_counter() - t0
    ds = open_sweep(args.out)
    summary = {
        "command": "jaxcelt bifurcation",
        "param": args.param,
        "n_values": int(values.size),
        "transient_periods": args.transient,
        "sample_periods": args.sample,
        "lyapunov_periods": args.lyapunov,
        "solver": args.solver,
        "rtol": args.rtol,
        "atol": args.atol,
        "stop_on_invalid": bool(args.stop_on_invalid),
        "devices": [str(d) for d in jax.local_devices()],
        "chunk_size": args.chunk_size,
        "width_per_device": args.width or DEFAULT_WIDTH,
        "wall_seconds_including_compile": round(wall, 2),
        "lanes_failed": int(np.sum(np.isin(ds["status"].values, (1, 3)))),  # status 2 = stopped invalid
        "lanes_invalid": int(np.sum(ds["valid"].values == 0)),
        "regimes": _ranges(ds),
    }
    (args.out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary, indent=1))
    if args.no_figures:
        return 0
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from jaxcelt.plotting.bifurcation import bifurcation_figure, orbit_figure

    fig = bifurcation_figure(ds, color_by="regime")
    fig.savefig(args.out / "bifurcation_regime.png", dpi=150)
    plt.close(fig)
    if np.isfinite(ds["lyapunov"].values).any():
        fig = bifurcation_figure(ds, color_by="lyapunov")
        fig.savefig(args.out / "bifurcation_lyapunov.png", dpi=150)
        plt.close(fig)
    if args.param == "omega_pi" and args.orbits.strip():
        for w in parse_range(args.orbits):
            pw = params.replace(omega_pi=float(w))
            o = orbit(
                pw,
                jc.initial_state(pw, omega=omega0),
                transient_periods=args.transient,
                periods=args.orbit_periods,
                solver=solver,
                rtol=args.rtol,
                atol=args.atol,
            )
            label = "" if o["valid"] else "model left its validity (lift-off or n3 <= 0)"
            fig = orbit_figure(o["ts"], o["ys"], o["r_O"], o["section_index"], omega_pi=float(w), label=label)
            fig.savefig(args.out / f"orbit_omega{w:g}.png", dpi=130)
            plt.close(fig)
    print(f"wrote {args.out}", flush=True)
    return 0
