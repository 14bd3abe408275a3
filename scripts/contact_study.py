"""Contact-law study: writes docs/contact/*.png|json and the scene table.

    .venv/bin/python scripts/contact_study.py [--short] [--skip-ladder]

1. quadrature convergence of the integral law (incl. the ICS inside / near the rim),
2. exact limits of MODEL.md section 7,
3. calibration of the Pade laws to the Hertz integral law, error maps,
4. Kane & Levinson rattleback without slip (energy, one-sided reversal),
5. the ladder of laws on the built-in scenes: table and cost-vs-error chart.
"""

from __future__ import annotations

import argparse
import pathlib
import time

import jax
import jax.numpy as jnp
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import jaxcelt as jc  # noqa: E402
from jaxcelt.integrate.noslip import simulate_noslip  # noqa: E402
from jaxcelt.physics.contact.calibrate import _with, calibrate, error_map, integral_reference, slip_samples  # noqa: E402
from jaxcelt.physics.contact.integral import HERTZ_S, patch_integrals  # noqa: E402
from jaxcelt.plotting.contact import plot_convergence, plot_cost_vs_error, plot_error_maps  # noqa: E402
from jaxcelt.provenance import load_average, write_result  # noqa: E402
from jaxcelt.studies.ladder import HERTZ_CALIBRATED, builtin_scenes, needed_state, recommend, results_table, run_ladder  # noqa: E402

OUT = pathlib.Path(__file__).resolve().parents[1] / "docs" / "contact"
B = 0.1813


def convergence():
    cases = {
        "ICS outside (0.3,-0.2,1), d=(0.2,0.3)": (0.3, -0.2, 1.0, 0.2, 0.3),
        "ICS inside (0.05,0.02,1)": (0.05, 0.02, 1.0, 0.0, 0.0),
        "ICS inside near rim (0.17,0,1)": (0.17, 0.0, 1.0, 0.0, 0.0),
        "pure spin (0,0,1)": (0.0, 0.0, 1.0, 0.0, 0.0),
    }
    sizes = [(4, 4), (8, 6), (12, 8), (16, 10), (24, 12), (32, 16), (48, 20)]
    data = {}
    for label, (vx, vy, w, dc, ds) in cases.items():
        ref = np.array(patch_integrals(vx, vy, w, B, dc, ds, n_angle=96, n_radial=40))
        errs = [
            np.abs(np.array(patch_integrals(vx, vy, w, B, dc, ds, n_angle=a, n_radial=r)) - ref).max() for a, r in sizes
        ]
        data[label] = (np.array([4 * a * r for a, r in sizes]), np.array(errs))
    fig = plot_convergence(data)
    fig.axes[0].set_title(
        "integral law (Hertz, b = 0.1813): error vs nodes\n(reference: 96 x 40 nodes per arc/ray)", fontsize=9
    )
    fig.savefig(OUT / "quadrature_convergence.png", dpi=110)
    plt.close(fig)
    return {k: {"nodes": v[0].tolist(), "err": v[1].tolist()} for k, v in data.items()}


def limits():
    K, E, G, H = (float(x) for x in jc.contact_integrals(B))
    S0, S2 = HERTZ_S["S0"], HERTZ_S["S2"]
    f = lambda *a: patch_integrals(*a, n_angle=24, n_radial=12)
    out = {}
    for w in (0.5, 2.0, -3.0):
        out[f"pure spin M_s(w={w}) - 4ES2 sign w"] = float(f(0.0, 0.0, w, B)[2]) - 4 * E * S2 * np.sign(w)
        out[f"dT_sx/dv_sx(w={w}) - 4GS0/|w|"] = float(
            jax.grad(lambda v, w=w: f(v, 0.0, w, B)[0])(0.0)
        ) - 4 * G * S0 / abs(w)
        out[f"dT_sy/dv_sy(w={w}) - 4HS0/|w|"] = float(
            jax.grad(lambda v, w=w: f(0.0, v, w, B)[1])(0.0)
        ) - 4 * H * S0 / abs(w)
    for beta in (0.0, 1.0, 2.5):
        T = f(np.cos(beta), np.sin(beta), 0.0, B)
        out[f"pure sliding |T - v/|v||, beta={beta}"] = float(np.hypot(T[0] - np.cos(beta), T[1] - np.sin(beta)))
    return out


def calibration():
    s = slip_samples()
    ref = integral_reference(s, B)
    res = {}
    for law in ("generalised_pade", "pade"):
        for fit_S in (False, True):
            c = calibrate(law, samples=s, reference=ref, fit_S=fit_S)
            res[f"{law}{'+S' if fit_S else ''}"] = c._asdict()
    # error maps at d = 0 and one rolling state, calibrated constants (S_i Hertz)
    p = _with(jc.hertz_params(jc.CeltParams.paper()), eps=1e-14)
    laws = {
        "gen. Pade (Hertz-cal.)": (jc.GeneralisedPade(), HERTZ_CALIBRATED["generalised_pade"]),
        "Pade (Hertz-cal.)": (jc.Pade(), HERTZ_CALIBRATED["pade"]),
        "Coulomb + spin": (jc.CoulombSpin(), {}),
        "gen. Pade (paper constants)": (jc.GeneralisedPade(), {"S0": 0.1498, "S2": 0.1121, "S3": 0.0589}),
    }
    maps_summary = {}
    for d, tag in (((0.0, 0.0), "d0"), ((0.3, 0.35), "rolling")):
        maps = {k: error_map(law, _with(p, **ov), d=d, n_alpha=41, n_beta=36) for k, (law, ov) in laws.items()}
        fig = plot_error_maps(maps, title=f"error vs Hertz integral law, b = {B}, (d_c, d_s) = {d}")
        fig.savefig(OUT / f"error_maps_{tag}.png", dpi=100)
        plt.close(fig)
        maps_summary[tag] = {
            k: {"max": float(m["err"].max()), "rms": float(np.sqrt(np.mean(m["err"] ** 2)))} for k, m in maps.items()
        }
    return res, maps_summary


def kane_levinson():
    p = jc.CeltParams.paper(a1=0.2, a2=0.03, a3=0.02, m=1.0, B1=2e-4, B2=1.6e-3, B3=1.7e-3, B12=2e-5, k3=0.01, q_pi=0.0)
    ts = np.linspace(0, 20, 801)
    fig, ax = plt.subplots(figsize=(7, 3.6), layout="constrained")
    out = {}
    for w3 in (-5.0, 5.0):
        y0 = jc.initial_state(p, omega=(0, 0, w3), n=np.array([0.01, 0.01, 1.0]) / np.sqrt(1.0002))
        sol = simulate_noslip(p, y0, 20.0, ts=jnp.asarray(ts), rtol=1e-12, atol=1e-14)
        E = np.asarray(jax.vmap(jc.energy, in_axes=(0, None))(sol.ys, p))
        w = np.asarray(sol.ys[:, 5])
        rev = np.nonzero(np.sign(w) != np.sign(w3))[0]
        out[f"w3(0)={w3}"] = {
            "energy_rel_drift_max": float(np.max(np.abs(E / E[0] - 1))),
            "first_reversal_t": float(ts[rev[0]]) if len(rev) else None,
            "w3_final": float(w[-1]),
        }
        ax.plot(ts, w, label=f"omega3(0) = {w3:+.0f} rad/s")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("omega3 [rad/s]")
    ax.set_title("Kane & Levinson (1982) rattleback, rolling without slip (C 10 mm above O, B12 = +2e-5)", fontsize=9)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(OUT / "kane_levinson_noslip.png", dpi=110)
    plt.close(fig)
    return out


def ladder(short: bool, tol: float = 0.05):
    scenes = builtin_scenes(short=short)
    results, state = {}, {}
    for name, sc in scenes.items():
        t = time.time()
        results[name] = run_ladder(sc)
        state[name] = needed_state(sc)
        print(f"  ladder {name}: {time.time() - t:.0f} s", flush=True)
    table = results_table(results, tol)
    fig = plot_cost_vs_error(results, tol=tol)
    fig.axes[0].set_title("cost vs error of each law on each scene (reference: Hertz integral law)", fontsize=9)
    fig.savefig(OUT / "cost_vs_error.png", dpi=110)
    plt.close(fig)
    (OUT / "scene_table.md").write_text(table)
    return {
        "tol": tol,
        "table": table,
        "scenes": {
            n: {"description": s.description, "t1": s.t1, "observed": list(s.observed)} for n, s in scenes.items()
        },
        "results": {n: [r.as_dict() for r in rs] for n, rs in results.items()},
        "recommended": {n: recommend(rs, tol) for n, rs in results.items()},
        "state": state,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--short", action="store_true")
    ap.add_argument("--skip-ladder", action="store_true")
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    load0 = load_average()
    summary = {"jax": jax.__version__}
    for name, fn in (("convergence", convergence), ("limits", limits), ("kane_levinson", kane_levinson)):
        t = time.time()
        summary[name] = fn()
        print(f"{name}: {time.time() - t:.0f} s", flush=True)
    t = time.time()
    summary["calibration"], summary["error_maps"] = calibration()
    print(f"calibration: {time.time() - t:.0f} s", flush=True)
    write_result(OUT / "summary.json", summary, load_at_start=load0, default=float)
    if not args.skip_ladder:
        summary["ladder"] = ladder(args.short)
        write_result(OUT / "summary.json", summary, load_at_start=load0, default=float)
        print(summary["ladder"]["table"])


if __name__ == "__main__":
    main()
