"""``jaxcelt fit data.npz ...`` or ``jaxcelt fit rec1.csv rec2.csv --guess mu=0.2``: identify
contact parameters from measured records.

A thin layer over `jaxcelt.fit` and `jaxcelt.identify.records.load_data` / `load_csv`: parses options, shows a progress
bar with the loss, prints the fitted values with 95% intervals, writes a JSON result and figures.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from jaxcelt.commands.args import UsageError, override, overrides, positive_float, positive_int


def floats_list(text: str) -> list[float]:
    """``"0.3,1"`` -> [0.3, 1.0], positive values (argparse type)."""
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        vals = []
    if not vals or any(not (v > 0) for v in vals):
        raise argparse.ArgumentTypeError(f"expected positive numbers separated by commas, got {text!r}")
    return vals


def register(sub) -> None:
    p = sub.add_parser(
        "fit",
        help="fit contact parameters to a measured-data file (.npz or .nc)",
        description="Fit parameters of the model to measured trajectories (file format: jaxcelt.identify.records).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument(
        "data",
        type=Path,
        nargs="+",
        help="data file written by jaxcelt.identify.records.save_data (.npz or .nc), or one CSV per record "
        "(columns t, omega1..3, ...: jaxcelt.identify.records.load_csv, docs/identification.md)",
    )
    p.add_argument(
        "--guess",
        default="",
        metavar="NAME=VALUE,...",
        help="initial guess, e.g. mu=0.2,k_r=0.4 (same as --set; applied after it)",
    )
    p.add_argument("--omega-pi", type=positive_float, default=None, help="base frequency [rad/s] for CSV records without one")
    p.add_argument("--q-pi", type=positive_float, default=None, help="base amplitude [m] for CSV records without one")
    p.add_argument("--free", nargs="+", default=["mu", "k_r", "b_Ts", "m_Ts"], help="parameters to fit")
    p.add_argument(
        "--set",
        action="append",
        type=override,
        default=[],
        metavar="NAME=VALUE",
        help="starting/fixed value of any CeltParams field (default: paper)",
    )
    p.add_argument(
        "--kinds", nargs="+", default=None, help="use only these observation kinds (state omega orientation centre)"
    )
    p.add_argument("--optimiser", choices=("lm", "gn", "gn-damped", "adam", "lbfgs"), default="lm")
    p.add_argument(
        "--windows", type=positive_int, default=1, help="multiple-shooting windows per record (1 = single shooting)"
    )
    p.add_argument("--window-states", choices=("optimise", "data"), default="optimise")
    p.add_argument("--fit-y0", action="store_true", help="also optimise the first initial state")
    p.add_argument("--fit-rotation", action="store_true",
                   help="also fit the sensor-to-body rotation of the gyro/accelerometer axes (3 angles)")  # fmt: skip
    p.add_argument("--fit-time-offset", action="store_true",
                   help="also fit each record's time offset (the base's phase at the record's t = 0)")  # fmt: skip
    p.add_argument("--spans", type=floats_list, default=None, metavar="S1,S2,...",
                   help="fit the first S1 seconds of every record, then S2, ... (jaxcelt.identify.strategies.fit_staged)")  # fmt: skip
    p.add_argument("--starts", type=positive_int, default=1,
                   help="fit from this many starts (jaxcelt.identify.strategies.multistart: vmapped on a GPU): the guess and "
                   "starts drawn within a factor 2 of it (jaxcelt.identify.strategies.random_guesses); reports the best fit and "
                   "the spread")  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="seed of the random starts")
    p.add_argument("--max-iter", type=positive_int, default=100)
    p.add_argument("--learning-rate", type=positive_float, default=0.02, help="Adam step size")
    p.add_argument("--out", type=Path, default=Path("out/fit"), help="output directory (fit.json, fit.png)")
    p.add_argument("--no-plot", action="store_true")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args) -> int:
    from tqdm import tqdm

    import jaxcelt as jc
    from jaxcelt.identify.api import fit
    from jaxcelt.identify.records import MeasuredData, load_csv, load_data
    from jaxcelt.identify.strategies import fit_staged, multistart, random_guesses

    # bad input raises ValueError naming the parameter (jaxcelt.cli: one error line, exit 2)
    params0 = jc.CeltParams.paper(**overrides(args.set))
    try:
        if all(p.suffix.lower() == ".csv" for p in args.data):
            data = MeasuredData(tuple(load_csv(p, omega_pi=args.omega_pi, q_pi=args.q_pi) for p in args.data))
        elif len(args.data) == 1:
            data = load_data(args.data[0])
        else:
            raise UsageError("argument data: several files must all be CSV records (one .npz/.nc holds several records)")
    except (OSError, KeyError) as e:
        raise UsageError(f"argument data: cannot read {', '.join(map(str, args.data))!r}: {e}") from e
    except UsageError:
        raise
    except ValueError as e:
        raise UsageError(f"argument data: {', '.join(map(str, args.data))!r}: {e}") from e
    if args.kinds:
        data = data.subset(args.kinds)
    try:
        guess = [override(g) for g in args.guess.split(",") if g.strip()]
    except argparse.ArgumentTypeError as e:
        raise UsageError(f"argument --guess: {e}") from None
    params0 = jc.CeltParams.paper(**overrides(list(args.set) + guess))
    if args.starts > 1 and args.spans is not None:
        raise UsageError("argument --starts: cannot be combined with --spans")
    summary = None
    desc = f"fit ({args.optimiser})" if args.starts == 1 else f"fit ({args.optimiser}, {args.starts} starts)"
    # several starts: iterations of all of them, no fixed total
    bar = tqdm(total=args.max_iter if args.starts == 1 else None, disable=args.quiet, desc=desc, unit="it")

    def progress(it, loss, values):
        bar.update(1)
        bar.set_postfix(loss=f"{loss:.4g}", **{k: f"{v:.4g}" for k, v in values.items()})

    try:
        kw = dict(fit_rotation=args.fit_rotation, fit_time_offset=args.fit_time_offset)
        kw |= dict(
            free=tuple(args.free),
            optimiser=args.optimiser,
            windows=args.windows,
            window_states=args.window_states,
            fit_y0=args.fit_y0,
            max_iter=args.max_iter,
            learning_rate=args.learning_rate,
            callback=progress,
        )
        if args.starts > 1:
            guesses = random_guesses(params0, args.starts, free=tuple(args.free), seed=args.seed)
            res, summary = multistart(data, params0, guesses, **kw)
        elif args.spans is not None:
            res = fit_staged(data, params0, args.spans, **kw)
        else:
            res = fit(data, params0, **kw)
    finally:
        bar.close()
    print(res.summary())
    if summary is not None:
        print(f"{summary['n_at_best']} of {args.starts} starts reached the best loss; spread over them:")
        for n, (lo, hi) in summary["spread"].items():
            print(f"  {n:>8s} in [{lo:.6g}, {hi:.6g}]")
    args.out.mkdir(parents=True, exist_ok=True)
    from jaxcelt.provenance import write_result

    write_result(
        args.out / "fit.json",
        res.to_dict()
        | {"data": [str(p) for p in args.data]}
        | ({"multistart": summary} if summary is not None else {}),
    )
    print(f"wrote {args.out / 'fit.json'}")
    if not args.no_plot:
        import matplotlib

        matplotlib.use("Agg")
        from jaxcelt.plotting.fit import plot_fit

        true = data.meta.get("true_params")
        plot_fit(res, true=true).savefig(args.out / "fit.png", dpi=110)
        print(f"wrote {args.out / 'fit.png'}")
    return 0
