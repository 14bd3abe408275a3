"""``jaxcelt simulate``: one trajectory, data (.npz) and a figure (.png)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from jaxcelt.commands.args import add_set_flag, finite_float, floats, overrides, positive_float, positive_int


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="integrate one trajectory and write data + figure",
        description="Integrate the stone on the vibrating base (paper's parameters unless overridden).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--omega-pi", type=finite_float, default=17.0, help="base frequency omega_pi [rad/s]")
    p.add_argument("--q-pi", type=finite_float, default=0.04, help="base amplitude q_pi [m]")
    p.add_argument("--periods", type=positive_float, default=20.0, help="duration in forcing periods 2 pi/omega_pi")
    p.add_argument("--samples-per-period", type=positive_int, default=50, help="saved states per period")
    p.add_argument("--omega0", type=floats(3), default=[0.0, 0.0, 0.0], help="initial omega (body) [rad/s], 'w1,w2,w3'")
    p.add_argument("--n0", type=floats(3), default=[0.0, 0.0, 1.0], help="initial vertical in body axes (normalised)")
    p.add_argument("--psi0", type=finite_float, default=0.0, help="initial heading psi [rad]")
    add_set_flag(p)
    p.add_argument("--rtol", type=positive_float, default=1e-8)
    p.add_argument("--atol", type=positive_float, default=1e-10)
    p.add_argument("--stop-on-invalid", action="store_true", help="stop at lift-off or n3 <= 0")
    p.add_argument("--out", type=Path, default=Path("out/simulate"), help="output directory")
    p.add_argument("--no-plot", action="store_true")
    p.set_defaults(func=run)


def run(args) -> int:
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.integrate.io import save_trajectory
    from jaxcelt.provenance import write_result

    # a bad value raises ValueError naming the parameter: jaxcelt.cli prints it as one error line, exit 2
    params = jc.CeltParams.paper(**(dict(omega_pi=args.omega_pi, q_pi=args.q_pi) | overrides(args.set)))
    y0 = jc.initial_state(params, omega=args.omega0, n=args.n0, psi=args.psi0, normalize=True)
    T = 2 * np.pi / args.omega_pi if args.omega_pi > 0 else 1.0
    t1 = args.periods * T
    ts = np.linspace(0.0, t1, int(round(args.periods * args.samples_per_period)) + 1)
    t = time.perf_counter()
    sol = jc.simulate(
        params, y0, t1, ts=ts, rtol=args.rtol, atol=args.atol, stop_on_invalid=args.stop_on_invalid, progress=True
    )
    sol.ys.block_until_ready()
    wall = time.perf_counter() - t
    print(sol.summary())
    print(f"wall time {wall:.2f} s (includes compilation)")
    finite = np.all(np.isfinite(np.asarray(sol.ys)), axis=1)
    diag = jc.diagnostics(sol.ts[finite], sol.ys[finite], params)
    args.out.mkdir(parents=True, exist_ok=True)
    stem = f"celt_w{args.omega_pi:g}"
    meta = {
        "command": "simulate",
        "status": int(sol.status),
        "summary": sol.summary(),
        "rtol": args.rtol,
        "atol": args.atol,
        "first_invalid_t": float(sol.validity.first_invalid_t),
        "first_invalid_kind": jc.INVALID_KINDS[int(sol.validity.first_invalid_kind)],
    }
    path = save_trajectory(
        args.out / f"{stem}.npz", sol.ts, sol.ys, params, meta=meta, extra={"N": diag.N, "r_O": diag.r_O}
    )
    write_result(args.out / f"{stem}.json", meta, indent=2)
    print(f"wrote {path}")
    if not args.no_plot:
        import matplotlib

        matplotlib.use("Agg")
        from jaxcelt.plotting.trajectory import trajectory_figure

        title = rf"$\omega_\pi$ = {args.omega_pi:g} rad/s, $q_\pi$ = {args.q_pi:g} m, {args.periods:g} periods"
        if not bool(sol.valid):
            title += f" — INVALID from t = {float(sol.validity.first_invalid_t):.3f} s"
        fig = trajectory_figure(sol.ts[finite], sol.ys[finite], diag, title=title)
        png = args.out / f"{stem}.png"
        fig.savefig(png, dpi=130)
        print(f"wrote {png}")
    return 0 if bool(sol.success) else 1
