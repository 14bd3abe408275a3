"""``jaxcelt orbits``: a periodic orbit, its Floquet multipliers and its branch -> JSON + figures.

The stone starts at rest with heading ``--psi0`` and runs ``--transient`` forcing periods; the
state at the last section time is the Newton guess of `jaxcelt.periodic_orbit` (period ``--k``).
With ``--continue LO:HI`` the orbit is followed in ``--param`` by pseudo-arclength continuation
(`jaxcelt.continue_orbit`) both ways until the branch leaves [LO, HI], and its folds, period
doublings and Neimark-Sacker points are listed. Example (the period-1 orbit of the paper's
stone at 15.6 rad/s)::

    jaxcelt orbits --omega-pi 15.6 --psi0 2.748893571891069 --continue 10:20 --out out/orbits
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from jaxcelt.commands.args import (
    UsageError,
    finite_float,
    nonnegative_int,
    override,
    overrides,
    positive_float,
    positive_int,
)


def _window(s: str) -> tuple[float, float]:
    parts = s.split(":")
    try:
        lo, hi = (float(x) for x in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO:HI, got {s!r}") from None
    if not lo < hi:
        raise argparse.ArgumentTypeError(f"expected LO < HI, got {s!r}")
    return lo, hi


def register(sub) -> None:
    p = sub.add_parser(
        "orbits",
        help="periodic orbit with Floquet multipliers, and its continued branch",
        description=__doc__.splitlines()[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--omega-pi", type=positive_float, default=15.6, help="base frequency omega_pi [rad/s]")
    p.add_argument("--q-pi", type=positive_float, default=0.04, help="base amplitude q_pi [m]")
    p.add_argument("--psi0", type=finite_float, default=2.748893571891069, help="initial heading psi [rad] (157.5 deg)")
    p.add_argument("--transient", type=nonnegative_int, default=300, help="forcing periods from rest to the guess")
    p.add_argument("--k", type=positive_int, default=1, help="forcing periods per return of the orbit")
    p.add_argument("--continue", dest="window", type=_window, default=None, metavar="LO:HI",
                   help="follow the branch in --param until it leaves [LO, HI]")  # fmt: skip
    p.add_argument("--param", default="omega_pi", help="continued CeltParams field")
    p.add_argument("--max-points", type=positive_int, default=300, help="branch points at most")
    p.add_argument("--set", action="append", type=override, default=[], metavar="NAME=VALUE",
                   help="override any other CeltParams field, repeatable")  # fmt: skip
    p.add_argument("--out", type=Path, default=Path("out/orbits"), help="output directory")
    p.add_argument("--no-plot", action="store_true")
    p.set_defaults(func=run)


def _complex_list(mu) -> list[list[float]]:
    import numpy as np

    mu = np.asarray(mu)
    return [[float(z.real), float(z.imag)] for z in mu]


def run(args) -> int:
    import jax
    import numpy as np
    from tqdm.auto import tqdm

    import jaxcelt as jc
    from jaxcelt.orbits.branch import branch_to_dict
    from jaxcelt.orbits.celt import ORBIT_STATUS
    from jaxcelt.physics.model import STATE_NAMES
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    params = jc.CeltParams.paper(**(dict(omega_pi=args.omega_pi, q_pi=args.q_pi) | overrides(args.set)))
    if args.window is not None:
        if args.param not in jc.PARAM_NAMES:
            raise UsageError(f"argument --param: unknown CeltParams field {args.param!r}")
        lam0 = float(getattr(params, args.param))
        if not args.window[0] < lam0 < args.window[1]:
            raise UsageError(f"argument --continue: the window must contain {args.param} = {lam0:g}")
    T = 2 * np.pi / args.omega_pi
    t_sec = args.transient * T
    t = time.perf_counter()
    y0 = jc.initial_state(params, psi=args.psi0)
    if args.transient > 0:
        sol = jc.simulate(params, y0, t_sec, ts=np.array([t_sec]), rtol=1e-10, atol=1e-12, exact_ts=True)
        if not bool(sol.success) or not bool(sol.valid):
            print(f"the transient from rest did not stay valid: {sol.summary()}")
            return 1
        guess = np.asarray(sol.ys[-1])
    else:
        guess = np.asarray(y0)
    t_transient = time.perf_counter() - t
    t = time.perf_counter()
    orb = jax.block_until_ready(jc.periodic_orbit(params, guess, k=args.k, t0=t_sec))
    t_orbit = time.perf_counter() - t
    status = ORBIT_STATUS[int(orb.status)]
    mu = np.asarray(orb.multipliers)
    print(f"period-{args.k} orbit: {status}, residual {float(orb.residual):.2e}, Newton steps {int(orb.newton_steps)}")
    print(
        "multipliers |mu|: "
        + ", ".join(f"{a:.4f}" for a in np.abs(mu))
        + ("  (stable)" if bool(orb.stable) else "  (unstable)")
    )
    args.out.mkdir(parents=True, exist_ok=True)
    result: dict = {
        "command": "orbits",
        "params": {n: float(getattr(params, n)) for n in jc.PARAM_NAMES},
        "psi0": args.psi0,
        "transient_periods": args.transient,
        "k": args.k,
        "orbit": {
            "status": status,
            "residual": float(orb.residual),
            "y": dict(zip(STATE_NAMES, map(float, np.asarray(orb.y)), strict=True)),
            "multipliers": _complex_list(mu),
            "multipliers_abs": [float(a) for a in np.abs(mu)],
            "stable": bool(orb.stable),
            "drift_m": [float(x) for x in np.asarray(orb.drift)],
            "psi_turns": int(orb.psi_turns),
        },
        "seconds": {"transient": round(t_transient, 2), "orbit_incl_compile": round(t_orbit, 2)},
        "versions": versions(),
    }
    code = 0 if int(orb.status) == 0 else 1
    branch = None
    if args.window is not None and code == 0:
        bar = tqdm(desc=f"continuing in {args.param}", unit="pt", total=args.max_points)

        def progress(n, lam, accepted):
            if accepted:
                bar.update(1)
                bar.set_postfix_str(f"{args.param}={lam:.4f}")

        t = time.perf_counter()
        # the orbit at t0 = transient T is the section point at t0 = 0 (the field depends on t only
        # through the base's phase)
        branch = jc.continue_orbit(params, orb, args.param, args.window, max_points=args.max_points, callback=progress)
        bar.close()
        result["seconds"]["branch_incl_compile"] = round(time.perf_counter() - t, 2)
        result["branch"] = branch_to_dict(branch, STATE_NAMES)
        print(f"branch: {len(branch.values)} points, {branch.stopped}")
        for b in branch.bifurcations:
            print(
                f"  {b.kind} at {args.param} = {b.value:.6f}, |mu| = "
                + ", ".join(f"{a:.4f}" for a in np.abs(b.multipliers[:3]))
            )
    path = args.out / "orbits.json"
    write_result(path, result)
    print(f"wrote {path}")
    if branch is not None and not args.no_plot:
        import matplotlib

        matplotlib.use("Agg")
        from jaxcelt.plotting.orbits import branch_figure, multipliers_figure

        fig = branch_figure([branch], labels=[f"period-{args.k}"], name=args.param)
        fig.savefig(args.out / "branch.png", dpi=130)
        fig = multipliers_figure(branch, name=args.param)
        fig.savefig(args.out / "multipliers.png", dpi=130)
        print(f"wrote {args.out / 'branch.png'}, {args.out / 'multipliers.png'}")
    return code
