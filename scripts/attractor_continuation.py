"""Global continuation of the wobblestone's attractors over omega_pi in [10, 20] rad/s at q_pi = 0.04 m.

`jaxcelt.continue_attractors` with the paper's stone (`CeltParams.paper`), 64 fresh starts at rest
(`jaxcelt.attractor_starts`: 16 headings psi0 over a full turn x 4 tilts in +-0.1 rad), the same at every
value, plus 4 seeds from each attractor of the previous value; 200 transient periods, 16 section samples, the
largest Lyapunov exponent over 100 periods (labels non-periodic attractors chaotic / quasi-periodic /
uncertain); periodic attractors refined by `jaxcelt.periodic_orbit` (Floquet multipliers). Values: 10, 10.5, ..., 20 and
15.6 (the paper's frequency). Resumable: the per-value files go to ``--work`` (default
``out/attractor_continuation``); a rerun reads finished values back.

Then the known answer: the forced two-well Duffing oscillator x'' + 0.25 x' - x + x^3 = F cos t, F = 0.1 .. 0.25
(two period-1 attractors, one per well) continued by the same model-agnostic core from 10 x 10 starts, its basin
fractions against a plain scipy census on the same starts (`duffing_check`; the tests use these definitions).

Writes docs/orbits/attractor_continuation.json (through `jaxcelt.provenance.write_result`: the attractor
table per value, the attractor sets at 14, 15.6, 17 and 19 rad/s, times; the Duffing check) and
docs/orbits/attractor_continuation.png (stacked basin fractions with tipping over; the attractors' section
coordinates omega_2 and psi against omega_pi).

    python scripts/attractor_continuation.py [--starts 16 4] [--transient 200] [--sample 16] [--lyapunov 100]
        [--work DIR] [--plot-only]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "orbits"
READ_OFF = (14.0, 15.6, 17.0, 19.0)


def values() -> np.ndarray:
    return np.unique(np.round(np.concatenate([np.linspace(10.0, 20.0, 21), [15.6]]), 10))


# --- the known answer: the forced two-well Duffing oscillator, against a plain scipy census ---------------------

DELTA = 0.25
DUFFING_F = (0.1, 0.15, 0.2, 0.25)
T_DUFFING = 2 * np.pi


def duffing(t, y, a):
    """x'' + delta x' - x + x^3 = F cos t as a first-order system (JAX); a = (delta, F)."""
    import jax.numpy as jnp

    delta, F = a
    return jnp.stack([y[1], -delta * y[1] + y[0] - y[0] ** 3 + F * jnp.cos(t)])


def duffing_model(**kw):
    """The Duffing oscillator as a `SectionModel`, F continued (`jaxcelt.sweeps.continuation_ode.forced_ode_model`)."""
    from jaxcelt.sweeps.continuation_ode import forced_ode_model

    return forced_ode_model(duffing, lambda F: (DELTA, F), lambda F: T_DUFFING, key="duffing delta=0.25 omega=1", **kw)


def grid_starts(n: int) -> np.ndarray:
    """An n x n grid of (x, x') starts over [-2, 2]^2."""
    xs = np.linspace(-2.0, 2.0, n)
    X, V = np.meshgrid(xs, xs, indexing="ij")
    return np.stack([X.ravel(), V.ravel()], axis=1)


def scipy_wells(F: float, starts: np.ndarray, periods: int) -> np.ndarray:
    """x of every start's section point after ``periods`` forcing periods, by scipy alone (DOP853, rtol 1e-10)."""
    from scipy.integrate import solve_ivp

    n = len(starts)

    def rhs(t, Y):
        x, v = Y[:n], Y[n:]
        return np.concatenate([v, -DELTA * v + x - x**3 + F * np.cos(t)])

    y0 = np.concatenate([starts[:, 0], starts[:, 1]])
    s = solve_ivp(rhs, (0.0, periods * T_DUFFING), y0, method="DOP853", rtol=1e-10, atol=1e-12,
                  t_eval=[periods * T_DUFFING])  # fmt: skip
    if not s.success:
        raise RuntimeError(f"scipy census failed at F = {F}: {s.message}")
    return s.y[:n, -1]


def duffing_check(n: int = 10, values=DUFFING_F, transient: int = 150, sample: int = 16) -> dict:
    """Basin fractions of the two wells' period-1 attractors: the continuation against a scipy census on the same
    n x n starts (each start classified by the sign of x at its final section point)."""
    from jaxcelt.sweeps.continuation_core import continue_section_attractors

    starts = grid_starts(n)
    t0 = time.perf_counter()
    ds = continue_section_attractors(duffing_model(), "F", list(values), starts, transient_periods=transient,
                                     sample_periods=sample)  # fmt: skip
    wall = time.perf_counter() - t0
    t0 = time.perf_counter()
    xs = [scipy_wells(F, starts, transient + sample - 1) for F in values]
    wall_scipy = time.perf_counter() - t0
    rows = []
    for j, F in enumerate(values):
        present = [int(a) for a in np.flatnonzero(ds["exists"].values[:, j])]
        left = [a for a in present if ds["section_point"].values[a, j, 0] < 0]
        f = float(ds["fraction"].values[left[0], j]) if left else 0.0
        sig = float(ds["fraction_stderr"].values[left[0], j]) if left else 0.0
        f_sc = float(np.mean(xs[j] < 0))
        agree = float(np.mean((ds["outcome"].values[j] == (left[0] if left else -9)) == (xs[j] < 0)))
        rows.append(dict(
            F=float(F), attractors=[dict(id=a, kind=str(ds["kind"].values[a, j]), period=int(ds["period"].values[a, j]),
                                         fraction=float(ds["fraction"].values[a, j]),
                                         multiplier_max=float(ds["multiplier_max"].values[a, j]),
                                         x=float(ds["section_point"].values[a, j, 0])) for a in present],
            left_fraction=f, left_fraction_stderr=sig, scipy_left_fraction=f_sc,
            diff_over_sigma=abs(f - f_sc) / sig if sig > 0 else None, lane_agreement=agree,
        ))  # fmt: skip
    return dict(
        equation="x'' + 0.25 x' - x + x^3 = F cos t", starts=f"{n} x {n} grid over [-2, 2]^2", n_starts=n * n,
        transient_periods=transient, sample_periods=sample, values=rows,
        multiplier_analytic=float(np.exp(-DELTA * T_DUFFING / 2)), wall_s=round(wall, 1),
        scipy_wall_s=round(wall_scipy, 1), scipy="solve_ivp DOP853 rtol 1e-10 atol 1e-12",
    )  # fmt: skip


# --- the wobblestone ----------------------------------------------------------------------------------------------


def run(args) -> dict:
    import jaxcelt as jc
    from jaxcelt.sweeps.continuation_core import continuation_summary

    p = jc.CeltParams.paper(omega_pi=15.6, q_pi=0.04)
    starts = jc.attractor_starts(p, psi0=(0.0, 2 * np.pi), tilt=(-0.1, 0.1), n=tuple(args.starts))
    load0 = list(os.getloadavg())
    t0 = time.perf_counter()
    ds = jc.continue_attractors(
        p, "omega_pi", values(), starts=starts, transient_periods=args.transient, sample_periods=args.sample,
        seeds_per_attractor=4, refine=True, lyapunov_periods=args.lyapunov, out=args.work, progress=True,
    )  # fmt: skip
    wall = time.perf_counter() - t0
    summary = continuation_summary(ds)
    for row in summary["values"]:  # the section points of each attractor, for the figure
        for a in row["attractors"]:
            j = int(np.argmin(np.abs(ds["omega_pi"].values - row["value"])))
            pts = ds["section_points"].values[a["id"], j]
            pts = pts[np.all(np.isfinite(pts), axis=1)]
            a["omega2_points"] = pts[:, 4].tolist()
            a["psi_deg_points"] = (np.degrees(pts[:, 12]) % 360).tolist()
    read_off = {}
    for w in READ_OFF:
        row = next(r for r in summary["values"] if abs(r["value"] - w) < 1e-9)
        read_off[f"{w:g}"] = dict(
            attractors=[_name(a) for a in row["attractors"]],
            tipping_over=row["tipping_over"],
            tipping_over_stderr=row["tipping_over_stderr"],
        )
    return dict(
        summary=summary,
        read_off=read_off,
        settings=dict(
            q_pi=0.04,
            n_values=int(len(values())),
            starts=list(args.starts),
            n_starts=int(ds.sizes["lane"]),
            tilt=0.1,
            transient_periods=args.transient,
            sample_periods=args.sample,
            seeds_per_attractor=4,
            refine=True,
            lyapunov_periods=args.lyapunov,
            solver="default (SweepOptions)",
        ),  # fmt: skip
        wall_s=round(wall, 1),
        load_average_start=[round(x, 2) for x in load0],
        load_average_end=[round(x, 2) for x in os.getloadavg()],
        script="scripts/attractor_continuation.py",
    )


def _name(a: dict) -> dict:
    out = dict(id=a["id"], kind=a["kind"], period=a["period"], fraction=a["fraction"],
               fraction_stderr=a["fraction_stderr"], lanes=a["lanes"])  # fmt: skip
    if a["kind"] == "periodic":
        out.update(multiplier_max=a["multiplier_max"], stable=a["stable"], refine_status=a["refine_status"],
                   psi_deg=float(np.degrees(a["section_point"][12]) % 360), omega2=a["section_point"][4])  # fmt: skip
    else:
        out.update(lyapunov=a["lyapunov"], lyapunov_stderr=a["lyapunov_stderr"])
    return out


def _id_label(i: int, rows: list[dict]) -> str:
    """'#5 period-1 15–16, aperiodic 16.5–19': the kinds an attractor id takes, over its runs of values."""
    runs: list[list] = []
    for r in rows:
        a = next((a for a in r["attractors"] if a["id"] == i), None)
        if a is None:
            continue
        name = f"period-{a['period']}" if a["kind"] == "periodic" else a["kind"]
        if runs and runs[-1][0] == name:
            runs[-1][2] = r["value"]
        else:
            runs.append([name, r["value"], r["value"]])
    parts = [f"{n} {lo:g}" + (f"–{hi:g}" if hi > lo else "") for n, lo, hi in runs]
    return f"#{i} " + ", ".join(parts)


def plot(d: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = d["summary"]["values"]
    w = np.array([r["value"] for r in rows])
    ids = sorted({a["id"] for r in rows for a in r["attractors"]})
    frac = {
        i: np.array([next((a["fraction"] for a in r["attractors"] if a["id"] == i), 0.0) for r in rows]) for i in ids
    }
    cmap = plt.get_cmap("tab20")
    palette = [cmap(k) for k in (0, 2, 4, 8, 10, 12, 16, 18, 14, 1, 5, 9, 11, 13, 17, 19)]  # red (6, 7): tipping
    colour = {i: palette[k % len(palette)] for k, i in enumerate(ids)}

    fig, axes = plt.subplots(3, 1, figsize=(13, 10), sharex=True, gridspec_kw=dict(height_ratios=[1.3, 1, 1]))
    ax = axes[0]
    base = np.zeros(len(w))
    for i in ids:
        ax.fill_between(
            w, base, base + frac[i], step="mid", color=colour[i], alpha=0.85, lw=0, label=_id_label(i, rows)
        )
        base = base + frac[i]
    tip = np.array([r["tipping_over"] for r in rows])
    ax.fill_between(w, base, base + tip, step="mid", facecolor="#f4cccc", edgecolor="#d62728", hatch="//", lw=0,
                    label="tipping over (left validity)")  # fmt: skip
    base = base + tip
    fail = np.array([r["failed"] for r in rows])
    if fail.any():
        ax.fill_between(w, base, base + fail, step="mid", color="k", lw=0, label="failed")
    ax.set_ylim(0, 1)
    ax.set_ylabel("basin fraction of the fresh starts")
    s = d["settings"]
    ax.set_title(
        f"Wobblestone attractors over ω_π, q_π = {s['q_pi']} m: {s['n_starts']} fresh starts + seeds per value, "
        f"{s['transient_periods']} + {s['sample_periods']} periods",
        fontsize=10,
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    for ax, key, lab in (
        (axes[1], "omega2_points", "ω₂ on the section [rad/s]"),
        (axes[2], "psi_deg_points", "ψ on the section [deg]"),
    ):
        for r in rows:
            for a in r["attractors"]:
                y = np.asarray(a[key])
                big = a["kind"] == "periodic"
                filled = big and a.get("stable") is True
                if not big and a.get("orbit_period"):  # the orbit continued by Newton, on a non-periodic attractor
                    c = a["orbit_point"][4] if key == "omega2_points" else np.degrees(a["orbit_point"][12]) % 360
                    ax.scatter([r["value"]], [c], s=70, marker="x" if a["orbit_multiplier_max"] >= 1 else "+",
                               color=colour[a["id"]], linewidths=1.8, zorder=4)  # fmt: skip
                ax.scatter(
                    np.full(len(y), r["value"]), y, s=55 if big else 7, marker="D" if big else "o",
                    facecolors=colour[a["id"]] if (filled or not big) else "white", edgecolors=colour[a["id"]],
                    linewidths=1.2 if big else 0, zorder=3 if big else 2,
                )  # fmt: skip
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[2].set_ylim(0, 360)
    axes[2].set_yticks(range(0, 361, 90))
    axes[2].set_xlabel("forcing frequency ω_π [rad/s]")
    axes[1].set_title(
        "section points: diamonds periodic attractors (filled: stable by their Floquet multipliers), dots the samples "
        "of non-periodic ones;\n+ / ×: the periodic orbit of a non-periodic attractor, continued by Newton, stable / "
        "unstable",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, nargs=2, default=[16, 4], metavar=("N_PSI0", "N_TILT"))
    ap.add_argument("--transient", type=int, default=200)
    ap.add_argument("--sample", type=int, default=16)
    ap.add_argument("--lyapunov", type=int, default=100, help="periods of the largest Lyapunov exponent (0: off)")
    ap.add_argument("--work", default=str(ROOT / "out" / "attractor_continuation"))
    ap.add_argument("--plot-only", action="store_true")
    args = ap.parse_args(argv)
    js, png = OUT / "attractor_continuation.json", OUT / "attractor_continuation.png"
    if not args.plot_only:
        import jax

        jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)  # before the first JAX operation
        from jaxcelt.provenance import write_result

        d = run(args)
        d["duffing"] = duffing_check()
        for r in d["duffing"]["values"]:
            print(f"Duffing F = {r['F']:g}: left well {r['left_fraction']:.3f} +- {r['left_fraction_stderr']:.3f}, "
                  f"scipy {r['scipy_left_fraction']:.3f}, lanes agree {r['lane_agreement']:.3f}", flush=True)  # fmt: skip
        write_result(js, d, load_at_start=d["load_average_start"], indent=None)
        for w, r in d["read_off"].items():
            print(f"omega_pi = {w}: tipping over {r['tipping_over']:.3f}; " + "; ".join(
                f"#{a['id']} {a['kind']}{a['period'] or ''} {a['fraction']:.3f}" for a in r["attractors"]), flush=True)  # fmt: skip
        print(f"wall {d['wall_s']} s", flush=True)
    plot(json.loads(js.read_text()), png)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
