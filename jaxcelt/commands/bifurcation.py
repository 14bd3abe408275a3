"""``jaxcelt bifurcation``: a stroboscopic sweep -> dataset (netCDF) + figures (PNG) + summary (JSON).

Defaults are a coarse, laptop-sized version of the paper's Fig. 3 (60 frequencies; under a minute
on 2 CPU cores, most of it compilation: docs/bifurcation/README.md); the full benchmark size is
``--omega 10:20:400 --transient 200 --sample 100``.
Interrupting and rerunning the same command resumes from the finished chunks.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from jaxcelt.commands._sweep_flags import ENGINES as ENGINES
from jaxcelt.commands._sweep_flags import add_sweep_flags, lane_devices, run_settings
from jaxcelt.commands.args import UsageError, overrides, positive_int, value_range


def register(sub) -> None:
    p = sub.add_parser(
        "bifurcation",
        help="stroboscopic bifurcation diagram over omega_pi (or another parameter)",
        description=__doc__.splitlines()[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument(
        "--omega", type=value_range, default="10:20:60", help="omega_pi values [rad/s]: START:STOP:COUNT or a,b,c"
    )
    p.add_argument("--param", default="omega_pi", help="swept CeltParams field (values from --values)")
    p.add_argument(
        "--values",
        type=value_range,
        default=None,
        help="values of --param when it is not omega_pi (START:STOP:COUNT or list)",
    )
    add_sweep_flags(
        p,
        lyapunov_default=150,
        chunk_size_default=200,
        dtype=False,
        help={
            "lyapunov": "periods of tangent dynamics for the Lyapunov exponent (0: off); labels need a long window "
            "(the exponent's standard error shrinks roughly as 1/sqrt(periods))",
            "set": "override any CeltParams field, repeatable",
            "solver": "explicit Runge-Kutta method (adaptive, PID control, section times hit exactly). Dopri8 is "
            "the same 8th-order Dormand-Prince family as scipy's DOP853: at rtol 1e-8 about 25x more accurate "
            "than Tsit5, as fast per sweep, but it compiles longer",
            "chunk-size": "lanes per jitted pool launch (the unit of resumable writing); split over the devices",
            "width": "pool slots per device: lanes stepped side by side (vmap width; default "
            "jaxcelt.ensemble.DEFAULT_WIDTH)",
            "host-devices": "CPU only: split the CPU into this many JAX devices and shard lanes over them (one XLA "
            "CPU computation uses about one core); 'auto' = number of CPU cores, 1 = off. Ignored on GPU",
            "stop-on-invalid": "end a lane at its first invalid state (lift-off or n3 <= 0; the model does not hold "
            "past it): label 'invalid', later samples inf, no Lyapunov exponent. --no-stop-on-invalid integrates on",
        },
    )
    p.add_argument(
        "--orbits",
        type=value_range,
        default="14,15.6,17,19",
        help="omega_pi values for phase-plot figures ('' for none)",
    )
    p.add_argument("--orbit-periods", type=positive_int, default=40, help="periods shown in the phase plots")
    p.add_argument("--out", type=Path, default=Path("out/bifurcation"), help="output directory (resumable)")
    p.add_argument("--no-figures", action="store_true")
    p.add_argument(
        "--atlas",
        action="store_true",
        help="also draw the atlas over omega_pi (`jaxcelt atlas` at its default size, into OUT/atlas/: attractors, "
        "basin fractions, periodic branches, exponents) and start each phase plot on the attractor with the largest "
        "basin there, rather than from rest",
    )
    p.set_defaults(func=run)


def format_summary(ds, *, wall_seconds: float, out: Path, files: list[str], max_ranges: int = 30) -> str:
    """The short report printed at the end of ``jaxcelt bifurcation`` (everything from the dataset ``ds``)."""
    import collections

    import numpy as np

    from jaxcelt.integrate.solve import INVALID_KINDS

    name = ds.attrs["swept_parameter"]
    vals = ds[name].values
    unit = " rad/s" if name == "omega_pi" else ""
    cfg = json.loads(ds.attrs.get("config_json", "{}"))
    first = (lambda a: a[:, 0]) if ds["regime"].ndim == 2 else (lambda a: a)
    n = len(vals)
    lines = [
        f"{n} lanes, {name} {vals.min():g} .. {vals.max():g}{unit}; "
        f"{cfg.get('transient_periods', '?')} transient + {cfg.get('sample_periods', '?')} sampled periods, "
        f"{cfg.get('solver', '?')} rtol {cfg.get('rtol', '?')}; sweep {wall_seconds:.1f} s including compilation",
        f"regimes by {name}{' [rad/s]' if unit else ''}:",
    ]
    from jaxcelt.sweeps.regimes import regime_ranges

    ranges = regime_ranges(ds)
    for a, b, k, label in ranges[:max_ranges]:
        span = f"{a:8.3f}" if k == 1 else f"{a:8.3f} .. {b:.3f}"
        lines.append(f"  {span:<20} {k:4d} lane{'s' if k > 1 else ' '}  {label}")
    if len(ranges) > max_ranges:
        lines.append(f"  ... {len(ranges) - max_ranges} more ranges (all in summary.json)")
    counts = collections.Counter(label for *_, k, label in ranges for _ in range(k))
    lines.append("lanes per regime: " + ", ".join(f"{label} {c}" for label, c in counts.most_common()))
    valid = first(ds["valid"].values).astype(bool)
    kinds = first(ds["first_invalid_kind"].values)
    n_bad = int(np.sum(~valid))
    if n_bad:
        by_kind = collections.Counter(INVALID_KINDS.get(int(k), str(int(k))) for k in kinds[~valid])
        where = ", ".join(f"{a:.4g}" if k == 1 else f"{a:.4g}..{b:.4g}" for a, b, k, lb in ranges if lb == "invalid")
        lines.append(
            f"invalid lanes (left the model's validity): {n_bad} of {n}, at {name} = {where}; "
            + ", ".join(f"{c} {kind}" for kind, c in sorted(by_kind.items()))
        )
    else:
        lines.append(f"invalid lanes: none of {n}")
    status = first(ds["status"].values)
    n_failed = int(np.sum(np.isin(status, (1, 3))))
    if n_failed:
        lines.append(f"solver failures (max_steps or error): {n_failed} lanes")
    lam = ds["lyapunov"].values
    if np.isfinite(lam).any():
        lines.append(f"largest Lyapunov exponent: {np.nanmin(lam):.3g} .. {np.nanmax(lam):.3g} 1/s")
    lines.append(f"wrote {out}/: " + ", ".join(files))
    lines.append(
        f"load: from jaxcelt.sweeps.dataset import open_sweep; ds = open_sweep({str(out)!r})  "
        f"# xarray.Dataset: ds.section, ds.regime, ds.lyapunov over ds.{name}"
    )
    return "\n".join(lines)


def run(args) -> int:
    t_command = time.perf_counter()
    devices = lane_devices(args)
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.commands._warnings import one_line_warnings
    from jaxcelt.integrate.solvers import make_solver
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.sweeps.api import sweep
    from jaxcelt.sweeps.dataset import open_sweep
    from jaxcelt.sweeps.regimes import regime_runs
    from jaxcelt.versions import versions_string

    # bad input raises ValueError naming the parameter (jaxcelt.cli: one error line, exit 2), before any work
    params = jc.CeltParams.paper(**overrides(args.set))
    if args.param not in jc.PARAM_NAMES:
        raise UsageError(f"argument --param: unknown parameter {args.param!r}; known: {', '.join(jc.PARAM_NAMES)}")
    if args.param == "omega_pi":
        values = args.omega
    elif args.values is None:
        raise UsageError(f"argument --values: required with --param {args.param}")
    else:
        values = args.values
    if values.size == 0:
        raise UsageError("argument --omega/--values: no values to sweep")
    for v in values:  # each lane's parameters must be valid too
        params.replace(**{args.param: float(v)})
    if args.atlas and (args.param != "omega_pi" or set(overrides(args.set)) - {"q_pi"}):
        raise UsageError("argument --atlas: the atlas is over omega_pi at the paper's parameters (--set q_pi=... only)")
    omega0 = args.omega0
    print(versions_string(), flush=True)
    y0 = np.asarray(jc.initial_state(params, omega=omega0))
    args.out.mkdir(parents=True, exist_ok=True)
    solver = make_solver(args.solver)
    if _phase_plots(args):  # the phase plots' program: traced and compiled while the sweep leaves a core idle
        from jaxcelt.sweeps.dense import prepare_dense_trajectory

        pw = params.replace(omega_pi=float(args.orbits[0]))
        prepare_dense_trajectory(pw, jc.initial_state(pw, omega=omega0), **_orbit_settings(args, solver), defer=True)
    load = load_average()
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
            engine=args.engine,
            stop_on_invalid=args.stop_on_invalid,
            sort_by_cost=True,
            devices=devices,
            out=str(args.out),
            progress=True,
        )
    wall = time.perf_counter() - t0
    if devices is not None:
        devices.close()
    ds = open_sweep(args.out)
    summary = {
        "command": "jaxcelt bifurcation",
        "param": args.param,
        "n_values": int(values.size),
        **run_settings(args, wall, devices),
        "lanes_failed": int(np.sum(np.isin(ds["status"].values, (1, 3)))),  # status 2 = stopped invalid
        "lanes_invalid": int(np.sum(ds["valid"].values == 0)),
        "regimes": regime_runs(ds),
    }
    write_result(args.out / "summary.json", summary, load_at_start=load)
    starts = {}
    if args.atlas:
        starts = _atlas(args, params)
        summary["atlas"] = {"dir": "atlas", "phase_plot_starts": {f"{w:g}": v[1] for w, v in starts.items()}}
    if not args.no_figures:
        _figures(args, ds, params, omega0, solver, starts)
    # the whole command after its imports: the sweep, the figures and the phase plots, compilation included
    summary["command_seconds"] = round(time.perf_counter() - t_command, 2)
    write_result(args.out / "summary.json", summary, load_at_start=load)
    files = sorted(f.name for f in args.out.iterdir() if f.is_file() and f.name != "manifest.json")
    print(format_summary(ds, wall_seconds=wall, out=args.out, files=files), flush=True)
    return 0


def _phase_plots(args) -> bool:
    return bool(not args.no_figures and args.param == "omega_pi" and args.orbits.size)


def _orbit_settings(args, solver) -> dict:
    return dict(transient_periods=args.transient, periods=args.orbit_periods, solver=solver, rtol=args.rtol, atol=args.atol)


def _atlas(args, params) -> dict:
    """`jaxcelt atlas` at its default size (at this stone's q_pi) into OUT/atlas; for each phase-plot frequency
    that is one of its values, (the state of the attractor with the largest basin there, a label for it)."""
    import numpy as np
    import xarray as xr

    from jaxcelt.commands import atlas as atlas_command

    parser = argparse.ArgumentParser()
    atlas_command.register(parser.add_subparsers())
    a = parser.parse_args(["atlas", "--out", str(args.out / "atlas"), "--q-pi", repr(float(params.q_pi))])
    atlas_command.run(a)
    starts = {}
    with xr.open_dataset(args.out / "atlas" / "atlas.nc") as ds:
        vals = ds["omega_pi"].values
        for w in np.asarray(args.orbits, dtype=float):
            j = np.flatnonzero(np.abs(vals - w) < 1e-9)
            if j.size == 0:
                continue
            frac = np.where(ds["exists"].values[:, j[0]].astype(bool), ds["fraction"].values[:, j[0]], -1.0)
            i = int(np.argmax(frac))
            if frac[i] <= 0:
                starts[float(w)] = (None, "no attractor in the atlas: every start tipped over (shown from rest)")
                continue
            kind = str(ds["kind"].values[i, j[0]])
            period = int(ds["period"].values[i, j[0]])
            name = f"period-{period}" if kind == "periodic" and period > 0 else kind
            y = np.asarray(ds["section_point"].values[i, j[0]], dtype=float)
            starts[float(w)] = (y, f"attractor #{int(ds['attractor'].values[i])} of the atlas ({name}, basin {frac[i]:.2f})")
    return starts


def _figures(args, ds, params, omega0, solver, starts=None) -> None:
    import matplotlib
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.sweeps.dense import dense_trajectory, prepare_dense_trajectory

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from jaxcelt.plotting.bifurcation import bifurcation_figure, orbit_figure

    phase_plots = _phase_plots(args)
    orbit_settings = _orbit_settings(args, solver)
    if phase_plots:  # compiling on a worker thread (started now if the sweep did not) while the diagrams are drawn
        pw = params.replace(omega_pi=float(args.orbits[0]))
        prepare_dense_trajectory(pw, jc.initial_state(pw, omega=omega0), **orbit_settings)
    fig = bifurcation_figure(ds, color_by="regime")
    fig.savefig(args.out / "bifurcation_regime.png", dpi=150)
    plt.close(fig)
    if np.isfinite(ds["lyapunov"].values).any():
        fig = bifurcation_figure(ds, color_by="lyapunov")
        fig.savefig(args.out / "bifurcation_lyapunov.png", dpi=150)
        plt.close(fig)
    if phase_plots:
        for w in args.orbits:
            pw = params.replace(omega_pi=float(w))
            y_att, att_label = (starts or {}).get(float(w), (None, ""))
            # an attractor's section state drifts off the contact manifold by the integration error: projected back
            y0 = jc.initial_state(pw, omega=omega0) if y_att is None else jc.project_state(y_att, pw)
            o = dense_trajectory(pw, y0, **orbit_settings)
            label = att_label if o["valid"] else "; ".join(
                x for x in (att_label, "model left its validity (lift-off or n3 <= 0)") if x
            )
            fig = orbit_figure(o["ts"], o["ys"], o["r_O"], o["section_index"], omega_pi=float(w), label=label)
            fig.savefig(args.out / f"orbit_omega{w:g}.png", dpi=130)
            plt.close(fig)
