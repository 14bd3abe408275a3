"""``jaxcelt atlas``: the wobblestone's attractors, basins, periodic branches and exponents over omega_pi -> one figure.

`jaxcelt.sweeps.atlas.atlas` over ``--values`` frequencies in ``--omega A B`` at base amplitude ``--q-pi``: the
brute-force section points from rest, the attractors continued from ``--starts`` fresh starts with their basin
fractions (tipping over included), the periodic branches through their orbits (stability, fold / period-doubling /
Neimark-Sacker points), lambda_1 (``--lyapunov-periods``) and lambda_1, lambda_2 (``--spectrum-periods``) per
attractor. Writes ``DIR/atlas.png`` (`jaxcelt.plotting.atlas.plot_atlas`), ``DIR/atlas.json`` (the continuation
summary, the branches, the exponents, the time of each part and of the whole command) and ``DIR/atlas.nc`` (the
continuation dataset with the exponents and the brute-force points). The continuation's per-value files go to
``DIR/continuation/``: rerunning the same command after a kill reads the finished values back. Example::

    jaxcelt atlas --out out/atlas
    jaxcelt atlas --out out/atlas_gpu --values 41 --starts 32 8 --transient 300 --lyapunov-periods 200
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from jaxcelt.commands.args import UsageError, nonnegative_int, positive_float, positive_int

READ_OFF = (14.0, 15.6, 17.0, 19.0)
"""the paper's frequencies [rad/s]: added to the values inside the window; atlas.json lists the attractors there"""


def register(sub) -> None:
    p = sub.add_parser(
        "atlas",
        help="attractors, basin fractions, periodic branches and Lyapunov exponents over omega_pi, one figure",
        description=__doc__.splitlines()[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--out", type=Path, required=True, help="output directory")
    p.add_argument("--omega", type=positive_float, nargs=2, default=(10.0, 20.0), metavar=("A", "B"),
                   help="omega_pi window [rad/s]")  # fmt: skip
    p.add_argument("--values", type=positive_int, default=11,
                   help="continuation values over the window (>= 2), plus 14, 15.6, 17, 19 where inside it")  # fmt: skip
    p.add_argument("--starts", type=positive_int, nargs=2, default=(8, 3), metavar=("N_PSI0", "N_TILT"),
                   help="fresh starts at rest: headings over a full turn x tilts in +-0.1 rad")  # fmt: skip
    p.add_argument("--transient", type=nonnegative_int, default=100, help="transient periods of every lane")
    p.add_argument("--sample", type=positive_int, default=16, help="sampled section periods of every lane")
    p.add_argument("--lyapunov-periods", type=nonnegative_int, default=40,
                   help="periods of lambda_1 on every lane (0: off)")  # fmt: skip
    p.add_argument("--spectrum-periods", type=nonnegative_int, default=20,
                   help="periods of the Lyapunov spectrum (lambda_1, lambda_2) per attractor and value (0: off)")  # fmt: skip
    p.add_argument("--brute-values", type=nonnegative_int, default=51, help="brute-force values over the window")
    p.add_argument("--brute-transient", type=nonnegative_int, default=100, help="brute-force transient periods")
    p.add_argument("--brute-sample", type=positive_int, default=24, help="brute-force sampled periods")
    p.add_argument("--branch-points", type=positive_int, default=120, help="points per periodic branch at most")
    p.add_argument("--no-branches", action="store_true", help="do not continue periodic branches")
    p.add_argument("--q-pi", type=positive_float, default=0.04, help="base amplitude q_pi [m]")
    p.set_defaults(func=run)


def _dataset(res):
    """The continuation dataset with the exponents and the brute-force section points (omega_2, psi) added."""
    import numpy as np

    ds = res.continuation.copy()
    dims = ("attractor", "omega_pi")
    for k in ("lambda1", "lambda1_stderr", "lambda2", "lambda2_stderr"):
        ds[f"spectrum_{k}"] = (dims, getattr(res, k))
    if res.brute is not None:
        ds = ds.assign_coords(brute_omega_pi=np.asarray(res.brute.values))
        s = np.asarray(res.brute.samples)
        ds["brute_omega2"] = (("brute_omega_pi", "brute_sample"), s[..., 4])
        ds["brute_psi"] = (("brute_omega_pi", "brute_sample"), s[..., 12])
    return ds


def run(args) -> int:
    t_command = time.perf_counter()
    lo, hi = args.omega
    if not lo < hi:
        raise UsageError(f"argument --omega: expected A < B, got {lo:g} {hi:g}")
    if args.values < 2:
        raise UsageError(f"argument --values: expected at least 2, got {args.values}")
    if args.sample < 2:
        raise UsageError(f"argument --sample: expected at least 2, got {args.sample}")
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.commands._warnings import one_line_warnings
    from jaxcelt.provenance import load_average, write_result
    from jaxcelt.sweeps.atlas import AtlasOptions, atlas

    params = jc.CeltParams.paper(q_pi=args.q_pi)
    opts = AtlasOptions(
        starts=tuple(args.starts), transient_periods=args.transient, sample_periods=args.sample,
        lyapunov_periods=args.lyapunov_periods, spectrum_periods=args.spectrum_periods,
        brute_values=args.brute_values, brute_transient=args.brute_transient, brute_sample=args.brute_sample,
        branches=not args.no_branches, branch_max_points=args.branch_points,
        out=str(args.out / "continuation"), progress=True,
    )  # fmt: skip
    # the paper's frequencies inside the window are values too (the figure and atlas.json read them off)
    values = np.unique(np.round(np.r_[np.linspace(lo, hi, args.values), [w for w in READ_OFF if lo < w < hi]], 10))
    args.out.mkdir(parents=True, exist_ok=True)
    load = load_average()
    with one_line_warnings("atlas"):
        res = atlas(params, values, options=opts)
    summary = res.summary()
    ds = _dataset(res)
    tmp = args.out / "atlas.nc.tmp"
    ds.to_netcdf(tmp)
    os.replace(tmp, args.out / "atlas.nc")  # atomic: a kill never leaves a damaged atlas.nc
    import matplotlib

    matplotlib.use("Agg")
    from jaxcelt.plotting.atlas import plot_atlas

    plot_atlas(res, args.out / "atlas.png")
    summary["seconds"]["command"] = round(time.perf_counter() - t_command, 2)
    summary["seconds_note"] = "each part's first calls include their compilation (the XLA cache may hold some)"
    summary["command"] = "jaxcelt atlas"
    summary["read_off"] = {
        f"{w:g}": next(r for r in summary["continuation"]["values"] if abs(r["value"] - w) < 1e-9)
        for w in READ_OFF if lo < w < hi
    }
    write_result(args.out / "atlas.json", summary, load_at_start=load, indent=None)
    for row in summary["continuation"]["values"]:
        parts = [f"#{a['id']} {a['kind']}{a['period'] or ''} {a['fraction']:.3f}" for a in row["attractors"]]
        print(f"omega_pi = {row['value']:g}: tipping over {row['tipping_over']:.3f}; " + "; ".join(parts))
    for b in summary["branches"]:
        print(f"{b['label']}: {b['n_points']} points; " + ", ".join(
            f"{x['kind']} {x['value']:.4f}" for x in b["bifurcations"]))  # fmt: skip
    print(f"seconds: {summary['seconds']}")
    print(f"wrote {args.out / 'atlas.png'}, {args.out / 'atlas.json'}, {args.out / 'atlas.nc'}")
    return 0
