"""The smoothing taken to zero: the period-1 family's fold and Neimark-Sacker point as eps = eps_R -> 0
-> docs/orbits/eps_limit.json and docs/orbits/eps_limit.png.

The friction law is smoothed by eps (V = sqrt(|v_s|^2 + eps), MODEL.md eq. 15) and the rolling resistance by
eps_R (D_R = sqrt(v_rx^2 + (b b_r)^-2 v_ry^2 + eps_R)). At q_pi = 0.04 m the fold of the period-1 family
(14.8798 rad/s at eps = eps_R = 1e-4) and its Neimark-Sacker point (17.7475 rad/s) are refined at each eps of
``EPS`` by `jaxcelt.continue_orbit_bifurcation` (``max_points=1``: only its start, the bifurcation refined at
fixed eps with omega_pi free), each from the point at the neighbouring eps (a continuation in eps by steps). For
each critical orbit the script records what decides the solvers' work: the smallest V^2 - eps and D_R^2 - eps_R
over one period (when both stay far above eps the law is smooth along the orbit and the sticking stiffness
~355/sqrt(eps) 1/s of MODEL.md never arises), and the steps, time and closure of one period with Dopri8, Tsit5
and Kvaerno5 (a work-precision table against a Dopri8 rtol 1e-13 reference). The fold at eps in [1.9e-5, 1e-3]
is checked against the arclength-continued fold curve of docs/orbits/fold_curves.json (interpolated). The limit
is fitted as omega(eps) = omega_0 + c eps^alpha (`fit_limit`, scipy.optimize.curve_fit with covariance) and with
alpha = 1 fixed.

    python scripts/eps_limit.py [--plot-only | --summarise]
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import pathlib
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
OUT = ROOT / "docs/orbits/eps_limit.json"
EPS = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8]
"""eps = eps_R of the located points (1e-4 is the start; the others by steps from it, both ways)"""
EPS_ORBIT_ONLY = [1e-10, 1e-12]
"""eps where only the one-period solves are timed (at the 1e-8 critical orbit): how far the explicit solvers go"""
Q_PI = 0.04
MAX_STEPS = 20_000
WP_SOLVERS = [("Dopri8", 1e-8), ("Dopri8", 1e-10), ("Dopri8", 1e-12), ("Tsit5", 1e-8), ("Tsit5", 1e-10),
              ("Kvaerno5", 1e-6), ("Kvaerno5", 1e-8), ("Kvaerno5", 1e-10)]  # fmt: skip
"""(solver, rtol) of the one-period work-precision table (atol = rtol / 10)"""
EXPLODE = 2.0
"""an explicit solver stops serving at an eps where its steps per period exceed EXPLODE x its steps at eps = 1e-3
(the stiffness taking over the step size) or its solve fails (status != 0 within max_steps = 200 000)"""


def power_law(eps, omega_0, c, alpha):
    return omega_0 + c * np.asarray(eps, float) ** alpha


def fit_limit(eps, omega, sigma=None, p0=None) -> dict:
    """omega(eps) = omega_0 + c eps^alpha by scipy.optimize.curve_fit (absolute sigma when given).

    Returns the parameters, their one-sigma errors from the covariance, the covariance, and the residuals."""
    from scipy.optimize import curve_fit

    eps, omega = np.asarray(eps, float), np.asarray(omega, float)
    if eps.shape != omega.shape or eps.size < 4 or np.any(eps <= 0):
        raise ValueError("fit_limit: 'eps' must be >= 4 positive values, as many as 'omega'")
    if p0 is None:
        j = int(np.argmax(eps))
        p0 = (float(omega[np.argmin(eps)]), float((omega[j] - omega[np.argmin(eps)]) / eps[j]), 1.0)
    popt, pcov = curve_fit(
        power_law, eps, omega, p0=p0, sigma=sigma, absolute_sigma=sigma is not None, maxfev=20_000
    )  # fmt: skip
    err = np.sqrt(np.diag(pcov))
    res = omega - power_law(eps, *popt)
    return {
        "omega_0": float(popt[0]), "c": float(popt[1]), "alpha": float(popt[2]),
        "omega_0_err": float(err[0]), "c_err": float(err[1]), "alpha_err": float(err[2]),
        "covariance": pcov.tolist(), "max_abs_residual": float(np.max(np.abs(res))),
    }  # fmt: skip


def fit_linear(eps, omega) -> dict:
    """omega_0 + c eps (alpha = 1) by least squares with covariance (np.polyfit, cov='unscaled' x residual var)."""
    eps, omega = np.asarray(eps, float), np.asarray(omega, float)
    coef, cov = np.polyfit(eps, omega, 1, cov=True)
    res = omega - np.polyval(coef, eps)
    return {"omega_0": float(coef[1]), "c": float(coef[0]), "omega_0_err": float(np.sqrt(cov[1, 1])),
            "c_err": float(np.sqrt(cov[0, 0])), "max_abs_residual": float(np.max(np.abs(res)))}  # fmt: skip


def _solver(name):
    import diffrax

    return {"Dopri8": diffrax.Dopri8, "Tsit5": diffrax.Tsit5, "Kvaerno5": diffrax.Kvaerno5}[name]()


def starts():
    """(omega, y) of the fold (fold_curves.json's start, eps = 1e-4) and of the NS point (branches.json)."""
    from jaxcelt.physics.model import STATE_NAMES

    c = json.loads((ROOT / "docs/orbits/fold_curves.json").read_text())["curves"]["eps"]["curve"]
    i = c["start"]
    br = next(iter(json.loads((ROOT / "docs/orbits/branches.json").read_text())["branches"].values()))["branch"]
    b = next(b for b in br["bifurcations"] if b["kind"] == "Neimark-Sacker")
    return {
        "fold": (float(c["omega_pi"][i]), np.asarray(c["state"][i])),
        "neimark-sacker": (float(b["value"]), np.array([b["state"][n] for n in STATE_NAMES])),
    }


def params(omega, eps):
    import jaxcelt as jc

    return jc.CeltParams.paper(omega_pi=omega, q_pi=Q_PI, eps=eps, eps_R=eps)


@functools.lru_cache(maxsize=1)
def _base():
    return params(14.88, 1e-4)


def args_of(omega, log10_eps):
    """(omega_pi, log10 eps) -> CeltParams with eps = eps_R = 10^log10_eps (one function object: its jitted
    corrector is compiled once and kept by `jaxcelt.continue_bifurcation`)."""
    import equinox as eqx
    import jax.numpy as jnp

    e = 10.0**log10_eps
    return eqx.tree_at(lambda p: (p.omega_pi, p.eps, p.eps_R), _base(), (jnp.asarray(omega, float), e, e))


def period_of(p):
    return 2 * np.pi / p.omega_pi


@functools.lru_cache(maxsize=1)
def _field():
    from jaxcelt.physics.contact.registry import get_contact_law
    from jaxcelt.physics.model import CeltField

    return CeltField(get_contact_law(None))


def refine(kind, omega, y, eps) -> dict:
    """The bifurcation point at this eps (omega_pi free), from (omega, y) found at a neighbouring eps.

    `jaxcelt.continue_bifurcation` with ``max_points=1`` (its start only: Newton at fixed p2 = log10 eps) in the
    chart of the contact manifold, as `jaxcelt.continue_orbit_bifurcation` does; called with module-level
    ``args_of``/``period_of`` so that one compiled corrector serves every eps (continue_orbit_bifurcation builds
    a new closure per call and compiles again)."""
    import diffrax
    import jax.numpy as jnp

    import jaxcelt as jc
    from jaxcelt.orbits.celt import celt_chart, celt_embed
    from jaxcelt.orbits.celt_curves import CURVE_DEFAULTS

    t = time.perf_counter()
    le = float(np.log10(eps))
    cur = jc.continue_bifurcation(
        _field(), jnp.asarray(y, float), args_of, period_of, (float(omega), le), ((10.0, 20.0), (-14.0, 0.0)),
        kind=kind, max_points=1, embed=celt_embed, chart=celt_chart, options=CURVE_DEFAULTS,
        solver=diffrax.Dopri8(), max_steps=MAX_STEPS,
    )  # fmt: skip
    mu = np.asarray(cur.multipliers[0])
    out = {"omega": float(cur.p1[0]), "eps": float(10.0 ** cur.p2[0]), "seconds": round(time.perf_counter() - t, 1),
           "y": np.asarray(cur.y[0]).tolist(), "multipliers_abs": np.sort(np.abs(mu))[::-1].tolist()}  # fmt: skip
    if kind == "fold":
        out["min_abs_multiplier_minus_1"] = float(np.min(np.abs(mu - 1)))
    else:
        out["kappa"] = float(cur.kappa[0])
        out["pair_abs_minus_1"] = float(np.min(np.abs(np.abs(mu[np.abs(mu.imag) > 1e-8]) - 1)))
    return out


def orbit_work(omega, y, eps, solvers) -> dict:
    """One period of the critical orbit: margins of the smoothing and each solver's steps, time, closure, error."""
    import jax
    import jax.numpy as jnp

    import jaxcelt as jc
    from jaxcelt.physics.model import kinematics

    p = params(omega, eps)
    T = 2 * np.pi / omega
    ts = np.linspace(0.0, T, 4001)
    ref = jc.simulate(p, y, T, ts=ts, solver=_solver("Dopri8"), rtol=1e-13, atol=1e-14, max_steps=200_000)
    k = jax.vmap(lambda t, yy: kinematics(t, yy, p).contact)(jnp.asarray(ts), ref.ys)
    v2 = np.asarray(k.vsx**2 + k.vsy**2)
    dr2 = np.asarray(k.vrx**2 + k.vry**2 / (p.b * p.b_r) ** 2)
    out = {"min_V2_minus_eps": float(v2.min()), "min_DR2_minus_epsR": float(dr2.min()),
           "omega_s_sign_changes": int(np.sum(np.diff(np.sign(np.asarray(k.omega_s))) != 0)),
           "reference_closure": float(np.max(np.abs(np.asarray(ref.ys[-1]) - y))), "solvers": []}  # fmt: skip
    y_ref = np.asarray(ref.ys[-1])
    for name, rtol in solvers:

        def run(name=name, rtol=rtol):
            return jc.simulate(p, y, T, solver=_solver(name), rtol=rtol, atol=rtol / 10, max_steps=200_000)

        jax.block_until_ready(run().ys)  # compiled (cached across eps: eps is a traced leaf)
        t = time.perf_counter()
        s = run()
        jax.block_until_ready(s.ys)
        out["solvers"].append({
            "solver": name, "rtol": rtol, "status": int(s.status), "steps": int(s.num_steps),
            "rejected": int(s.num_rejected_steps), "seconds": round(time.perf_counter() - t, 4),
            "error_vs_reference": float(np.max(np.abs(np.asarray(s.ys[-1]) - y_ref))),
            "closure": float(np.max(np.abs(np.asarray(s.ys[-1]) - y))),
        })  # fmt: skip
    return out


def fold_curve_check(eps, omega) -> float | None:
    """omega at eps from fold_curves.json's arclength curve (linear interpolation), minus ours; None outside it."""
    c = json.loads((ROOT / "docs/orbits/fold_curves.json").read_text())["curves"]["eps"]["curve"]
    e, w = np.asarray(c["eps=eps_R"]), np.asarray(c["omega_pi"])
    order = np.argsort(e)
    e, w = e[order], w[order]
    if not e[0] <= eps <= e[-1]:
        return None
    return float(np.interp(eps, e, w) - omega)


def ladder(kind, omega, y, log) -> list[dict]:
    """The point at each eps of EPS: 1e-4 from the seed, then down and up by steps from the previous point."""
    i0 = EPS.index(1e-4)
    try:
        rows = {i0: refine(kind, omega, y, EPS[i0])}
    except ValueError as e:
        return [{"eps": EPS[i0], "failed": str(e)[:200]}]
    log(kind, rows[i0])
    for path in (range(i0 + 1, len(EPS)), range(i0 - 1, -1, -1)):
        prev = rows[i0]
        for i in path:
            try:
                rows[i] = refine(kind, prev["omega"], np.asarray(prev["y"]), EPS[i])
            except ValueError as e:  # no point found from the previous one: the ladder ends here
                rows[i] = {"eps": EPS[i], "failed": str(e)[:200]}
                log(kind, rows[i])
                break
            log(kind, rows[i])
            prev = rows[i]
    return [rows[i] for i in sorted(rows)]


def explicit_limit(res) -> dict:
    """Where the explicit solvers (rtol 1e-10) stop serving on each critical orbit (the EXPLODE criterion)."""
    out = {}
    for kind, rows in res["orbits"].items():
        if not rows:
            continue
        for name in ("Dopri8", "Tsit5"):
            runs = [next(s for s in r["work"]["solvers"] if s["solver"] == name and s["rtol"] == 1e-10) for r in rows]
            base = runs[0]["steps"]
            bad = [(r, s) for r, s in zip(rows, runs, strict=True) if s["status"] != 0 or s["steps"] > EXPLODE * base]
            out[f"{kind}/{name}"] = {
                "stops_at_eps": bad[0][0]["eps"] if bad else None,
                "smallest_eps": rows[-1]["eps"],
                "steps_range": [min(s["steps"] for s in runs), max(s["steps"] for s in runs)],
            }
    return out


def fits(res) -> dict:
    out = {}
    for kind in ("fold", "neimark-sacker"):
        pts = [r for r in res["points"][kind] if "omega" in r]
        e, w = np.array([r["eps"] for r in pts]), np.array([r["omega"] for r in pts])
        if len(pts) < 3:
            out[kind] = {"n_points": len(pts)}
            continue
        f = {"n_points": len(pts), "eps_range": [float(e.min()), float(e.max())]}
        try:
            f["power_law"] = fit_limit(e, w)
        except (RuntimeError, ValueError) as err:
            f["power_law"] = {"failed": str(err)[:200]}
        f["linear"] = fit_linear(e, w)
        small = e <= 1e-6
        f["linear_eps_le_1e-5"] = fit_linear(e[e <= 1e-5], w[e <= 1e-5]) if np.sum(e <= 1e-5) >= 3 else None
        f["change_over_last_two_decades"] = float(w[small].max() - w[small].min()) if small.sum() >= 2 else None
        f["change_1e-3_to_smallest"] = float(w[np.argmax(e)] - w[np.argmin(e)])
        out[kind] = f
    return out


def plot(res, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, kind, label in zip(axes[:2], ("fold", "neimark-sacker"), ("fold", "Neimark–Sacker"), strict=True):
        if "linear" not in res["fits"][kind]:
            continue
        pts = [r for r in res["points"][kind] if "omega" in r]
        e, w = np.array([r["eps"] for r in pts]), np.array([r["omega"] for r in pts])
        f = res["fits"][kind]["linear"]
        ax.semilogx(e, (w - f["omega_0"]) * 1e6, "o", label=f"{label}: located")
        ee = np.logspace(np.log10(e.min()), np.log10(e.max()), 100)
        ax.semilogx(ee, f["c"] * ee * 1e6, "-", lw=1, label=f"ω₀ + c ε, ω₀ = {f['omega_0']:.7f}")
        if kind == "fold":
            c = json.loads((ROOT / "docs/orbits/fold_curves.json").read_text())["curves"]["eps"]["curve"]
            ce, cw = np.asarray(c["eps=eps_R"]), np.asarray(c["omega_pi"])
            m = ce > 0
            ax.semilogx(ce[m], (cw[m] - f["omega_0"]) * 1e6, "x", ms=5, color="C2", label="fold_curves.json")
        ax.set_xlabel("ε = ε_R [s⁻²]")
        ax.set_ylabel("ω − ω₀ [µrad/s]")
        ax.set_title(f"{label} at q_π = {Q_PI} m", fontsize=10)
        ax.legend(fontsize=7)
    ax = axes[2]
    for kind, mk in (("fold", "o"), ("neimark-sacker", "s")):
        rows = res["orbits"][kind]
        for name, col in (("Dopri8", "C0"), ("Tsit5", "C1"), ("Kvaerno5", "C3")):
            rt = 1e-8 if name == "Kvaerno5" else 1e-10
            e = [r["eps"] for r in rows]
            st = [
                next(s for s in r["work"]["solvers"] if s["solver"] == name and s["rtol"] == rt)["steps"] for r in rows
            ]
            ax.loglog(e, st, mk + "-", color=col, ms=4, lw=1, label=f"{name} rtol {rt:g} ({kind[:4]})")
    ax.set_xlabel("ε = ε_R [s⁻²]")
    ax.set_ylabel("steps per period")
    ax.set_title("one period of the critical orbit", fontsize=10)
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--summarise", action="store_true", help="recompute the limits and fits of the file, rewrite it")
    args = ap.parse_args()
    if args.plot_only:
        plot(json.loads(OUT.read_text()), OUT.with_suffix(".png"))
        return
    from jaxcelt.provenance import write_result

    if args.summarise:
        res = json.loads(OUT.read_text())
        res.pop("provenance", None)
        res["explicit_limit"], res["fits"] = explicit_limit(res), fits(res)
        write_result(OUT, res, load_at_start=list(os.getloadavg()))
        plot(res, OUT.with_suffix(".png"))
        return

    load = list(os.getloadavg())
    t_all = time.perf_counter()
    log = lambda kind, r: print(
        f"  [{kind}] eps {r['eps']:.3g}: "
        + (  # noqa: E731
            f"omega {r['omega']:.10f} ({r['seconds']} s)" if "omega" in r else f"failed: {r['failed']}"
        ),
        flush=True,
    )
    res: dict = {"q_pi": Q_PI, "eps_values": EPS, "max_steps": MAX_STEPS, "explode_factor": EXPLODE,
                 "work_precision_solvers": WP_SOLVERS, "points": {}, "orbits": {}}  # fmt: skip
    for kind, (omega, y) in starts().items():
        res["points"][kind] = ladder(kind, omega, y, log)
        rows = []
        for r in res["points"][kind]:
            if "omega" not in r:
                continue
            r["fold_curves_minus_this"] = fold_curve_check(r["eps"], r["omega"]) if kind == "fold" else None
            rows.append({"eps": r["eps"], "work": orbit_work(r["omega"], np.asarray(r["y"]), r["eps"], WP_SOLVERS)})
            print(
                f"  [{kind}] orbit work at eps {r['eps']:.3g}: min V^2 {rows[-1]['work']['min_V2_minus_eps']:.3g}",
                flush=True,
            )
        found = [r for r in res["points"][kind] if "omega" in r]
        for e in EPS_ORBIT_ONLY if found else []:
            last = found[-1]
            rows.append(
                {
                    "eps": e,
                    "orbit_of_eps": last["eps"],
                    "work": orbit_work(last["omega"], np.asarray(last["y"]), e, WP_SOLVERS),
                }
            )
        res["orbits"][kind] = rows
    res["explicit_limit"] = explicit_limit(res)
    res["fits"] = fits(res)
    res["seconds_total"] = round(time.perf_counter() - t_all, 1)
    res["load_average_end"] = list(os.getloadavg())
    write_result(OUT, res, load_at_start=load)
    plot(res, OUT.with_suffix(".png"))
    print(json.dumps({k: res[k] for k in ("explicit_limit", "fits", "seconds_total")}, indent=1))


if __name__ == "__main__":
    main()
