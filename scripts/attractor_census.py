"""Attractor census of the wobblestone at omega_pi = 14, 15.6, 17, 19 rad/s (paper parameters).

Every frequency: a psi0 x tilt grid of starts at rest (`jaxcelt.attractor_starts`), each run as
one lane of `jaxcelt.sweeps.api.sweep` (`jaxcelt.attractors`): transient, then stroboscopic samples,
labelled periodic-k / quasi-periodic / chaotic / aperiodic / invalid / failed; periodic lanes
grouped into distinct attractors. Resumable per frequency: a frequency whose result (with the same grid, tilt and
periods) is in ``<out>/census/omega_<w>.json`` is skipped. Writes ``<out>/census.json`` (all frequencies:
attractor tables, fractions, wall time, first-chunk vs later-chunk time (compilation is in
the first), jax version, machine, load average) and basin maps ``<out>/census/basins_<w>.png``.
Timings are indicative (shared machine: load average recorded).

    python scripts/attractor_census.py [--out docs/orbits] [--grid 40 25] [--transient 200]
        [--sample 16] [--tilt 0.1] [--omega 14 15.6 17 19] [--refine] [--plot-only] [--refine-stored]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import jax
import numpy as np

import jaxcelt as jc
from jaxcelt.provenance import write_result

ROOT = Path(__file__).resolve().parents[1]
OMEGAS = (14.0, 15.6, 17.0, 19.0)


def _name(w: float) -> str:
    return f"{w:g}".replace(".", "p")


def run_one(w: float, args) -> dict:
    p = jc.CeltParams.paper(omega_pi=w)
    starts = jc.attractor_starts(p, psi0=(0.0, 2 * np.pi), tilt=(-args.tilt, args.tilt), n=tuple(args.grid))
    chunk_times: list[float] = []
    t_last = [time.perf_counter()]

    def on_chunk(i, _):
        t = time.perf_counter()
        chunk_times.append(t - t_last[0])
        t_last[0] = t

    load0 = os.getloadavg()
    t0 = time.perf_counter()
    c = jc.attractors(
        p,
        starts,
        transient_periods=args.transient,
        sample_periods=args.sample,
        lyapunov_periods=args.lyapunov,
        chunk_size=args.chunk,
        on_chunk=on_chunk,
        refine=args.refine,
    )
    wall = time.perf_counter() - t0
    d = c.to_dict()
    d.update(
        wall_s=round(wall, 1),
        chunk_wall_s=[round(x, 1) for x in chunk_times],
        chunk_lanes=args.chunk,
        load_average_start=[round(x, 2) for x in load0],
        load_average_end=[round(x, 2) for x in os.getloadavg()],
        tilt_axis="n = (sin tilt, 0, cos tilt), at rest",
    )
    return d


def refine_stored(w: float, d: dict) -> None:
    """Refine the stored periodic rows with `jaxcelt.periodic_orbit` (in place; timed)."""
    from jaxcelt.sweeps.census import Attractor, refine_attractor

    p = jc.CeltParams.paper(omega_pi=w)
    for row in d["attractors"]:
        if row["kind"] != "periodic" or row["refine_status"] != "not run":
            continue
        a = Attractor(**{k: v for k, v in row.items() if k in Attractor.__dataclass_fields__})
        a.state = np.asarray(a.state, float)
        a.lyapunov = float("nan") if a.lyapunov is None else a.lyapunov
        t = time.perf_counter()
        refine_attractor(p, a)
        row.update(
            refine_status=a.refine_status,
            residual=a.residual,
            multipliers=a.multipliers,
            stable=a.stable,
            refine_wall_s=round(time.perf_counter() - t, 1),
        )
        print(f"omega_pi = {w:g}: period-{a.k} ({a.count} lanes): {a.refine_status}, |mu| {a.multipliers}", flush=True)


def plot(d: dict, path: Path) -> None:
    from jaxcelt.plotting.attractors import plot_basins

    fig = plot_basins(d)
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt

    plt.close(fig)


def symmetry(d: dict) -> dict | None:
    """Agreement of the basin map with its image under (psi0, tilt) -> (psi0 + 180 deg, -tilt).

    ``kind``: fraction of grid cells whose kind equals that of the image cell; ``periodic_swap``:
    fraction of cells where "in the first periodic basin" equals "image in the second" (two
    periodic attractors only). Needs an even psi0 grid over a full turn and a tilt range
    symmetric about 0; else None.
    """
    shape, lanes = d.get("grid_shape"), d.get("lanes")
    if shape is None or shape[0] % 2 or lanes is None:
        return None
    a, b = shape
    psi = np.asarray(lanes["psi0"]).reshape(a, b)
    tilt = np.asarray(lanes["tilt"]).reshape(a, b)
    if not (np.allclose(psi[a // 2 :, 0] - psi[: a // 2, 0], np.pi) and np.allclose(tilt[0], -tilt[0, ::-1])):
        return None

    def image(x):
        return np.roll(x, a // 2, axis=0)[:, ::-1]

    kind = np.asarray(lanes["kind"], dtype=object).reshape(a, b)
    out = dict(kind=float(np.mean(kind == image(kind))))
    if sum(r["kind"] == "periodic" for r in d["attractors"]) == 2:
        lab = np.asarray(lanes["label"]).reshape(a, b)
        out["periodic_swap"] = float(np.mean((lab == 0) == (image(lab) == 1)))
    return out


def markdown_table(summary: dict) -> str:
    """The census table of docs/orbits/README.md from census.json (one row per frequency)."""
    lines = [
        "| ω_π [rad/s] | starts | periodic attractors: k, ψ on the section, fraction, max \\|μ\\| "
        "| aperiodic | invalid | wall time [s] |",
        "|---|---|---|---|---|---|",
    ]
    for w in summary["omega_pi"]:
        r = summary["results"][f"{w:g}"]
        per = []
        for a in r["attractors"]:
            if a["kind"] == "periodic":
                mu = f"{a['multipliers'][0]:.4f}" if a.get("multipliers") else a["refine_status"]
                per.append(f"period-{a['k']}, {np.degrees(a['state'][12]) % 360:.1f}°, {a['fraction']:.3f}, {mu}")
        frac = {a["kind"]: a["fraction"] for a in r["attractors"] if a["kind"] != "periodic"}
        lines.append(
            f"| {w:g} | {r['n_lanes']} | {'; '.join(per) or 'none'} | {frac.get('aperiodic', 0.0):.3f} "
            f"| {frac.get('invalid', 0.0):.3f} | {r['wall_s']:.0f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "orbits"))
    ap.add_argument("--omega", type=float, nargs="+", default=list(OMEGAS))
    ap.add_argument("--grid", type=int, nargs=2, default=[40, 25], metavar=("N_PSI0", "N_TILT"))
    ap.add_argument("--tilt", type=float, default=0.1, help="tilt range +-TILT [rad]")
    ap.add_argument("--transient", type=int, default=200)
    ap.add_argument("--sample", type=int, default=16)
    ap.add_argument("--lyapunov", type=int, default=0)
    ap.add_argument("--chunk", type=int, default=500)
    ap.add_argument("--refine", action="store_true")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--table", action="store_true", help="print the README table from <out>/census.json and exit")
    ap.add_argument(
        "--refine-stored", action="store_true", help="refine the stored periodic attractors (periodic_orbit)"
    )
    args = ap.parse_args(argv)
    out = Path(args.out)
    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)  # before the first JAX operation
    if args.table:
        print(markdown_table(json.loads((out / "census.json").read_text())))
        return
    (out / "census").mkdir(parents=True, exist_ok=True)
    for w in args.omega:
        f = out / "census" / f"omega_{_name(w)}.json"
        want = dict(grid=list(args.grid), tilt=args.tilt, transient=args.transient, sample=args.sample)
        d = json.loads(f.read_text()) if f.exists() else None
        if d is not None and d.get("request") == want:
            print(f"omega_pi = {w:g}: done ({f}), skipped", flush=True)
        elif args.plot_only or args.refine_stored:
            continue
        else:
            print(f"omega_pi = {w:g}: running", flush=True)
            d = run_one(w, args)
            d["request"] = want
            (out / "census" / f"basins_{_name(w)}.png").unlink(missing_ok=True)
            write_result(f, d, load_at_start=d["load_average_start"], indent=None)
            print(f"omega_pi = {w:g}: {d['wall_s']} s, " + ", ".join(
                f"{a['name']} {a['fraction']:.3f}" for a in d["attractors"]), flush=True)  # fmt: skip
        if args.refine_stored:
            refine_stored(w, d)
            write_result(f, d, indent=None)
        png = out / "census" / f"basins_{_name(w)}.png"
        if not png.exists():
            try:
                plot(d, png)
            except ImportError as e:
                print(f"no basin plot: {e}", flush=True)
    summary = dict(
        omega_pi=[],
        results={},
        jax_version=jax.__version__,
        jaxcelt_version=jc.__version__,
        machine=dict(platform=platform.platform(), processor=platform.machine(), cpu_count=os.cpu_count()),
        devices=[str(x) for x in jax.devices()],
        script="scripts/attractor_census.py",
    )
    for w in args.omega:
        f = out / "census" / f"omega_{_name(w)}.json"
        if f.exists():
            d = json.loads(f.read_text())
            d["symmetry"] = symmetry(d)
            d.pop("lanes", None)
            summary["omega_pi"].append(w)
            summary["results"][f"{w:g}"] = d
    write_result(out / "census.json", summary)


if __name__ == "__main__":
    main()
