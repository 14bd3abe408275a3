"""Figs. 3-7 analogues for one reading of the paper: diagram + four regime panels.

    python scripts/paper_figures.py --psi0-deg 90 --eps 1e-4 --out docs/paper-reproduction

Writes ``fig3_<tag>.png`` (omega_2 at the section against omega_pi, coloured by regime) and
``fig4-7_<tag>_w<omega>.png`` (local phase plot omega_1-omega_3, global path of O, section) for
omega_pi = 14, 15.6, 17, 19, plus ``figures_<tag>.json`` with the labels shown. Uses only the
library (`jaxcelt.bifurcation`, `jaxcelt.sweeps.dense.dense_trajectory`, `jaxcelt.plotting.bifurcation`).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402

import jaxcelt as jc  # noqa: E402
from jaxcelt.ensemble import SweepConfig  # noqa: E402
from jaxcelt.plotting.bifurcation import bifurcation_figure, orbit_figure  # noqa: E402
from jaxcelt.provenance import write_result  # noqa: E402
from jaxcelt.sweeps.dataset import to_dataset  # noqa: E402
from jaxcelt.sweeps.dense import dense_trajectory  # noqa: E402
from jaxcelt.sweeps.regimes import GLOBAL_MOTION, classify, regime_names  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402

PAPER = {
    14.0: "periodic, bounded",
    15.6: "periodic (local), unbounded",
    17.0: "quasi-periodic, bounded",
    19.0: "chaotic, unbounded",
}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--psi0-deg", type=float, default=0.0)
    ap.add_argument("--eps", type=float, default=1e-4, help="eps = eps_R")
    ap.add_argument("--v-pi-sign", type=float, default=1.0)
    ap.add_argument("--derivative-exact", type=float, default=0.0)
    ap.add_argument("--omega", default="10:20:41", help="START:STOP:COUNT for the diagram ('' to skip)")
    ap.add_argument("--transient", type=int, default=300)
    ap.add_argument("--sample", type=int, default=48)
    ap.add_argument("--lyapunov", type=int, default=60)
    ap.add_argument("--orbit-periods", type=int, default=40)
    ap.add_argument("--stop-on-invalid", action="store_true")
    ap.add_argument("--out", default="docs/paper-reproduction")
    ap.add_argument("--tag", default=None)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tag = args.tag or f"psi{args.psi0_deg:g}_eps{args.eps:g}"
    p = jc.CeltParams.paper(
        eps=args.eps, eps_R=args.eps, v_pi_sign=args.v_pi_sign, derivative_exact=args.derivative_exact
    )
    y0 = jc.initial_state(p, psi=np.radians(args.psi0_deg))
    info = {"reading": vars(args), "versions": versions(), "orbits": {}}
    t = time.perf_counter()
    if args.omega:
        a, b, n = args.omega.split(":")
        omegas = np.linspace(float(a), float(b), int(n))
        kw = dict(transient_periods=args.transient, sample_periods=args.sample, lyapunov_periods=args.lyapunov)
        if args.stop_on_invalid:
            kw["stop_on_invalid"] = True
        res = jc.bifurcation(p, omegas, y0=y0, progress=True, **kw)
        cfg = SweepConfig(transient_periods=args.transient, sample_periods=args.sample, lyapunov_periods=args.lyapunov)
        # the README's rule, as paper_study.py: lambda_1 -+ 2 standard errors against 0.02 1/s
        ds = to_dataset(res, p, cfg)
        info["chaos_threshold"] = 0.02
        fig = bifurcation_figure(
            ds,
            color_by="regime",
            title=rf"$\omega_2$ at the section, $\psi_0$ = {args.psi0_deg:g}°, $\varepsilon$ = {args.eps:g}",
        )
        fig.savefig(out / f"fig3_{tag}.png", dpi=110)
        info["diagram_wall_s"] = time.perf_counter() - t
    for w in PAPER:
        q = p.replace(omega_pi=w)
        o = dense_trajectory(q, y0, transient_periods=args.transient, periods=args.orbit_periods, points_per_period=40)
        si = np.asarray(o["section_index"])
        samples = np.asarray(o["ys"])[si][None]
        lab = classify(samples, np.array([o["status"]]), np.array([True]), np.asarray(o["r_O"])[si][None])
        name = str(regime_names(lab["regime"], lab["period"])[0])
        glob = GLOBAL_MOTION[int(lab["global_motion"][0])]
        label = f"ours: {name if name != 'aperiodic' else 'not periodic'}, {glob}" + (
            "" if o["valid"] else " (INVALID: n3<=0 or lift-off)"
        )
        info["orbits"][str(w)] = {"ours": label, "paper": PAPER[w], "valid": bool(o["valid"])}
        fig = orbit_figure(o["ts"], o["ys"], o["r_O"], si, omega_pi=w, label=f"{label} | paper: {PAPER[w]}")
        fig.savefig(out / f"fig4-7_{tag}_w{w:g}.png", dpi=100)
        print(w, label, flush=True)
    info["wall_s"] = time.perf_counter() - t
    write_result(out / f"figures_{tag}.json", info, default=str)


if __name__ == "__main__":
    main()
