"""Every change of the wobblestone's attractor set over omega_pi, with the evidence that explains it.

Reads the continuation of ``scripts/attractor_continuation.py`` (its resumable per-value files in ``--work``,
default ``out/attractor_continuation``: run that script first) and the period-1 branches' bifurcation points
(``docs/orbits/branches.json``). Between every two neighbouring values it lists what changed: an attractor id
appears or vanishes, or keeps its id but changes its label. Then it gathers evidence:

* **long runs**: every non-periodic set is run on from its lanes' last section states for ``--long`` more forcing
  periods at its value (`jaxcelt.sweep`, the lanes' engine, stopping where the model leaves its validity), with
  the largest Lyapunov exponent over the last ``--lyapunov`` periods. A set whose lanes all tip over is a chaotic
  transient, not an attractor; survivors tell whether the set is chaotic (lambda_1 > 0) or closes in on a
  periodic orbit (their distance to the orbit continued there by Newton);
* **the spectrum** (`jaxcelt.lyapunov_spectrum`, lambda_1 and lambda_2 with standard errors, ``--spectrum``
  periods) from a surviving lane past the Neimark-Sacker point: a 2-torus has lambda_1 = 0 and lambda_2 < 0;
* **seeds**: where the seeds of an attractor that vanishes went at the next value;
* **sampling**: the chance (1 - f)^N that N fresh starts miss a basin of fraction f.

Each change gets one explanation: a local bifurcation of the period-1 branch (fold, Neimark-Sacker, within the
interval), a named global event (boundary crisis: the set survives the long run at one value and its seeds tip
over at the next; a chaotic transient whose lanes tip over), a change of label only (the same set: lanes that
settle too slowly for the transient, or an exponent interval that crosses the threshold), sampling of a small
basin, or "not explained" where the evidence does not decide.

Writes docs/orbits/attractor_events.json through `jaxcelt.provenance.write_result`.

    python scripts/attractor_events.py [--work DIR] [--long 1000] [--lyapunov 300] [--spectrum 400]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "orbits"
PAD = 32  # lanes of a long run, padded to a multiple of this
MISS_P = 0.05  # a basin that N starts miss with a larger chance may be there unseen
TIP_TRANSIENT = 0.9  # share of a set's lanes that tip over in the long run for it to be a chaotic transient


def _continuation_script():
    spec = importlib.util.spec_from_file_location("attractor_continuation", ROOT / "scripts" / "attractor_continuation.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def load(work: Path):
    """The continuation dataset (read back from the resumable files, nothing recomputed) and the per-value seeds."""
    import xarray as xr

    import jaxcelt as jc
    from jaxcelt.sweeps.dataset import _ENGINE

    ac = _continuation_script()
    files = sorted((work / "values").glob("value_*.nc"))
    vals = ac.values()
    if len(files) != len(vals):
        raise SystemExit(f"{work}: {len(files)} of {len(vals)} values finished; run scripts/attractor_continuation.py")
    settings = json.loads((OUT / "attractor_continuation.json").read_text())["settings"]
    p = jc.CeltParams.paper(omega_pi=15.6, q_pi=settings["q_pi"])
    starts = jc.attractor_starts(p, psi0=(0.0, 2 * np.pi), tilt=(-0.1, 0.1), n=tuple(settings["starts"]))
    t0 = time.perf_counter()
    ds = jc.continue_attractors(
        p, "omega_pi", vals, starts=starts, transient_periods=settings["transient_periods"],
        sample_periods=settings["sample_periods"], seeds_per_attractor=settings["seeds_per_attractor"], refine=True,
        lyapunov_periods=settings["lyapunov_periods"], out=str(work), progress=False,
    )  # fmt: skip
    if time.perf_counter() - t0 > 120:
        print("warning: the continuation was (partly) recomputed, not read back", flush=True)
    seeds = []
    for f in files:
        with xr.open_dataset(f, engine=_ENGINE) as v:
            seeds.append((v["seed_origin"].values.copy(), v["seed_outcome"].values.copy()))
    return p, ds, seeds, settings


def bifurcations() -> list[dict]:
    """The period-1 branches' fold and Neimark-Sacker points (both mirror branches)."""
    d = json.loads((OUT / "branches.json").read_text())
    out = []
    for name, b in d["branches"].items():
        for x in b["branch"]["bifurcations"]:
            out.append(dict(kind=x["kind"], value=float(x["value"]), branch=name))
    return out


def _sets(ds, j: int) -> dict[int, dict]:
    out = {}
    for a in np.flatnonzero(ds["exists"].values[:, j]):
        a = int(a)
        out[a] = dict(
            kind=str(ds["kind"].values[a, j]), period=int(ds["period"].values[a, j]),
            fraction=float(ds["fraction"].values[a, j]), count=int(ds["count"].values[a, j]),
            n_lanes=int(ds["n_lanes"].values[a, j]), orbit_period=int(ds["orbit_period"].values[a, j]),
            orbit_mu=_f(ds["orbit_multiplier_max"].values[a, j]), lyapunov=_f(ds["lyapunov"].values[a, j]),
            lyapunov_stderr=_f(ds["lyapunov_stderr"].values[a, j]),
        )  # fmt: skip
    return out


def _f(x) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


def long_runs(p, ds, j: int, sets: dict[int, dict], a_long: int, a_lyap: int) -> dict[int, dict]:
    """Run every non-periodic set at value j on from its lanes' last section states."""
    import jax

    import jaxcelt as jc
    from jaxcelt.sweeps.api import sweep
    from jaxcelt.sweeps.continuation import celt_section_coords
    from jaxcelt.sweeps.regimes import detect_period

    w = float(ds["omega_pi"].values[j])
    ids, y0 = [], []
    for a, s in sets.items():
        if s["kind"] == "periodic":
            continue
        lanes = np.flatnonzero(ds["outcome"].values[j] == a)
        ys = ds["lane_final"].values[j, lanes] if lanes.size else ds["section_point"].values[a, j][None]
        ids += [a] * len(ys)
        y0.append(ys)
    if not ids:
        return {}
    y0 = np.concatenate(y0)
    ids = np.asarray(ids)
    L = len(ids)
    Lp = -(-L // PAD) * PAD  # few batch sizes, few compilations
    opts = jc.SweepOptions(transient_periods=a_long, sample_periods=16, lyapunov_periods=a_lyap, stop_on_invalid=True)
    r = sweep(p.replace(omega_pi=w), "omega_pi", [w], y0=np.concatenate([y0, np.repeat(y0[-1:], Lp - L, 0)]),
              options=opts)  # fmt: skip
    r = jax.tree_util.tree_map(lambda x: np.asarray(x)[:, :L], r)
    status, valid = np.asarray(r.status)[0], np.asarray(r.valid)[0]
    tipped = np.isin(status, (2, 4)) | ~valid
    failed = (status != 0) & ~np.isin(status, (2, 4))
    samples = np.asarray(r.samples)[0]
    ly, lse = np.asarray(r.lyapunov, float)[0], np.asarray(r.lyapunov_stderr, float)[0]
    C = celt_section_coords(samples)
    out = {}
    for a in np.unique(ids):
        m = ids == a
        ok = m & ~tipped & ~failed
        per = [detect_period(C[i], max_period=8, tol=1e-4) for i in np.flatnonzero(ok)]
        rec = dict(lanes=int(m.sum()), tipped=int((m & tipped).sum()), failed=int((m & failed).sum()),
                   periodic=int(sum(k > 0 for k in per)), periods=sorted({int(k) for k in per if k > 0}))  # fmt: skip
        if ok.any():
            rec["lyapunov_median"] = float(np.median(ly[ok]))
            rec["lyapunov_stderr_median"] = float(np.median(lse[ok]))
            rec["lyapunov_min"], rec["lyapunov_max"] = float(np.min(ly[ok])), float(np.max(ly[ok]))
        orbit = ds["orbit_point"].values[a, j]
        if ok.any() and np.all(np.isfinite(orbit)):
            y = celt_section_coords(orbit)
            d_end = np.linalg.norm(C[ok][:, -1] - y, axis=-1) / (1 + np.max(np.abs(y)))
            d_start = np.linalg.norm(celt_section_coords(y0[ok]) - y, axis=-1) / (1 + np.max(np.abs(y)))
            rec["orbit_distance_start_median"] = float(np.median(d_start))
            rec["orbit_distance_end_median"] = float(np.median(d_end))
        rec["survivor_state"] = samples[np.flatnonzero(ok)[0], -1].tolist() if ok.any() else None
        out[int(a)] = rec
    return out


def spectrum(p, w: float, y: list, periods: int) -> dict:
    import jaxcelt as jc
    from jaxcelt.sweeps.regimes import REGIMES, spectrum_regime

    t = time.perf_counter()
    s = jc.lyapunov_spectrum(p.replace(omega_pi=w), np.asarray(y), periods=periods, transient_periods=20, rtol=1e-8,
                             atol=1e-10)
    ex, se = np.asarray(s.exponents, float), np.asarray(s.stderr, float)
    code = int(np.asarray(spectrum_regime(ex[:1], se[:1], ex[1:2], se[1:2], chaos_threshold=0.02, confidence=2.0))[0])
    return dict(periods=periods, lambda1=float(ex[0]), lambda2=float(ex[1]), lambda1_stderr=float(se[0]),
                lambda2_stderr=float(se[1]), label=REGIMES[code], seconds=round(time.perf_counter() - t, 1))  # fmt: skip


def explain(ev: dict, bif: list[dict], N: int, present: dict[float, set]) -> tuple[str, str]:
    """(class, sentence) for one change; ``present``: the ids at each value."""
    lo, hi = ev["from"], ev["to"]
    inside = [b for b in bif if lo < b["value"] <= hi]
    kinds_in = {b["kind"] for b in inside}
    before, after = ev.get("before"), ev.get("after")
    lb, la = ev.get("long_before"), ev.get("long_after")
    settled = ("periodic", "converging")
    if ev["change"] == "appears" and after["kind"] in settled and "fold" in kinds_in:
        x = next(b["value"] for b in inside if b["kind"] == "fold")
        return "fold", f"born at the fold of the period-1 branch at ω_π = {x:.4f} rad/s (a stable orbit and its saddle)"
    if ev["change"] == "relabelled" and before["kind"] in settled and after["kind"] not in settled:
        if "Neimark-Sacker" in kinds_in:
            x = next(b["value"] for b in inside if b["kind"] == "Neimark-Sacker")
            return "Neimark-Sacker", f"the orbit loses stability at the Neimark-Sacker point ω_π = {x:.4f} rad/s"
    if ev["change"] == "relabelled" and {before["kind"], after["kind"]} <= set(settled):
        return "label only", (
            f"the same orbit (|μ| {before['orbit_mu']:.4f} → {after['orbit_mu']:.4f}): lanes settle as |μ|^n, "
            f"too slowly to be periodic within the transient"
        )
    if ev["change"] == "relabelled" and {before["kind"], after["kind"]} <= {"chaotic", "uncertain", "quasi-periodic"}:
        return "label only", "the same set: its λ₁ interval crosses the chaos threshold (see the long runs)"
    if ev["change"] == "becomes transient":
        return "boundary crisis", (
            f"{_tips(lb)} at {lo:g}, {_tips(la)} at {hi:g}: no longer an attractor"
        )
    if ev["change"] == "vanishes":
        if _state(lb) == "transient":
            return "chaotic transient", f"not an attractor at {lo:g}: {_tips(lb)}"
        seeds = ev.get("seeds_next", {})
        n = sum(seeds.values())
        if n and seeds.get("-1", 0) == n and lb and lb["tipped"] < lb["lanes"]:
            return "boundary crisis", f"at {lo:g} {_tips(lb)}; all {n} of its seeds tip over at {hi:g}"
        if n and seeds.get("-1", 0) < n:
            to = sorted(int(k) for k in seeds if k != "-1")
            return "merged", f"its seeds land on {', '.join('#' + str(k) for k in to)} at {hi:g}"
        p_miss = (1 - before["fraction"]) ** N if before["fraction"] > 0 else 1.0
        if p_miss > MISS_P:
            return "sampling", f"{N} starts miss a basin of fraction {before['fraction']:.3f} with chance {p_miss:.2f}"
    if ev["change"] == "appears":
        if _state(la) == "transient":
            return "chaotic transient", f"not an attractor at {hi:g}: {_tips(la)}"
        src = ev.get("from_seeds") or []
        if src:
            names = ", ".join("#" + str(k) for k in src)
            still = [k for k in src if k in present[hi]]
            if still:
                return "split", (
                    f"holds seeds of {names}, still there at {hi:g}: the lanes of one set fall into two groups of "
                    f"section points that do not interleave ({ev.get('samples', 16)} per lane)"
                )
            if len(src) >= 2:
                return "merging crisis", f"the sets {names} of {lo:g} merge into one: the seeds of each land on it"
            return "re-identified", f"the set {names} of {lo:g} under a new id: its seeds land on it"
        p_miss = (1 - after["fraction"]) ** N if after["fraction"] > 0 else 1.0
        if p_miss > MISS_P:
            return "sampling", f"{N} starts miss a basin of fraction {after['fraction']:.3f} with chance {p_miss:.2f}"
        if la and la["tipped"] < la["lanes"]:
            return "crisis", (
                f"a set appears ({_tips(la)}) with a basin that {N} starts at {lo:g} would miss with chance "
                f"{p_miss:.3f} only"
            )
    return "not explained", "the evidence does not decide"


def find_events(vals, sets, longs, seeds) -> list[dict]:
    """The changes between neighbouring values (before explanation)."""
    events = []
    for j in range(len(vals) - 1):
        lo, hi = float(vals[j]), float(vals[j + 1])
        A, B = sets[j], sets[j + 1]
        origin, outcome = seeds[j + 1]
        for a in sorted(set(A) | set(B)):
            ev = dict(**{"from": lo, "to": hi}, id=a, before=A.get(a), after=B.get(a),
                      long_before=_strip(longs[j].get(a)), long_after=_strip(longs[j + 1].get(a)))  # fmt: skip
            lb, la = ev["long_before"], ev["long_after"]
            if a in A and a not in B:
                ev["change"] = "vanishes"
                went = outcome[origin == a]
                ev["seeds_next"] = {str(int(k)): int(v) for k, v in zip(*np.unique(went, return_counts=True))}
            elif a in B and a not in A:
                ev["change"] = "appears"
                ev["from_seeds"] = sorted({int(o) for o, x in zip(origin, outcome) if x == a and o in A})
            elif A[a]["kind"] != B[a]["kind"] or A[a]["period"] != B[a]["period"]:
                ev["change"] = "relabelled"
            elif _state(lb) in ("attractor", "leaky") and _state(la) == "transient":
                ev["change"] = "becomes transient"
            else:
                continue
            events.append(ev)
    return events


def _state(r: dict | None) -> str | None:
    """What a long run says of a set: "attractor" (at most 10 % of its lanes tip over), "transient" (at least
    `TIP_TRANSIENT` of at least 3 lanes tip over), "leaky" (in between: chaotic transients as long as the run),
    None (too few lanes to tell)."""
    if r is None or r["lanes"] == 0:
        return None
    if r["tipped"] <= 0.1 * r["lanes"]:
        return "attractor"
    if r["lanes"] >= 3 and r["tipped"] >= TIP_TRANSIENT * r["lanes"]:
        return "transient"
    return "leaky" if r["lanes"] >= 3 else None


def _tips(r: dict) -> str:
    return f"{r['tipped']} of its {r['lanes']} lanes tip over within the long run"


def _strip(r: dict | None) -> dict | None:
    return None if r is None else {k: v for k, v in r.items() if k != "survivor_state"}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, default=ROOT / "out" / "attractor_continuation")
    ap.add_argument("--long", type=int, default=1000, help="extra forcing periods of the long runs")
    ap.add_argument("--lyapunov", type=int, default=300, help="periods of lambda_1 in the long runs")
    ap.add_argument("--spectrum", type=int, default=400, help="periods of the spectrum past the NS point (0: off)")
    ap.add_argument("--explain-only", action="store_true",
                    help="recompute only the events and explanations from the committed result's evidence")  # fmt: skip
    args = ap.parse_args(argv)
    import jax

    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)
    from jaxcelt.provenance import write_result

    load0 = list(os.getloadavg())
    t0 = time.perf_counter()
    p, ds, seeds, settings = load(args.work)
    bif = bifurcations()
    ns = min(b["value"] for b in bif if b["kind"] == "Neimark-Sacker")
    vals = ds["omega_pi"].values
    N = int(ds.sizes["lane"])
    sets = [_sets(ds, j) for j in range(len(vals))]
    if args.explain_only:
        old = json.loads((OUT / "attractor_events.json").read_text())
        longs = [{int(a): r for a, r in old["long_runs"][f"{w:g}"].items()} for w in vals]
        spectra = old["spectra"]
        args.long, args.lyapunov, args.spectrum = old["long_periods"], old["long_lyapunov_periods"], old["spectrum_periods"]
        wall_gather = old["wall_s"]
    else:
        longs = []
        for j in range(len(vals)):
            longs.append(long_runs(p, ds, j, sets[j], args.long, args.lyapunov))
            print(f"ω_π = {vals[j]:g}: long runs of {len(longs[-1])} sets", flush=True)
        spectra = {}
        if args.spectrum > 0:
            for j, w in enumerate(vals):
                if w <= ns:
                    continue
                for a, rec in longs[j].items():
                    if rec.get("survivor_state") is not None and sets[j][a]["orbit_period"] > 0:
                        spectra[f"{w:g}/{a}"] = spectrum(p, float(w), rec["survivor_state"], args.spectrum)
                        print(f"spectrum ω_π = {w:g} #{a}: {spectra[f'{w:g}/{a}']}", flush=True)
        wall_gather = None
    events = find_events(vals, sets, longs, seeds)
    present = {float(v): set(sets[j]) for j, v in enumerate(vals)}
    for ev in events:
        ev["class"], ev["explanation"] = explain(ev, bif, N, present)
        print(f"{ev['from']:g} → {ev['to']:g} #{ev['id']} {ev['change']}: {ev['class']}: {ev['explanation']}", flush=True)
    counts: dict[str, int] = {}
    for ev in events:
        counts[ev["class"]] = counts.get(ev["class"], 0) + 1
    d = dict(
        continuation="docs/orbits/attractor_continuation.json", settings=settings, n_starts=N,
        long_periods=args.long, long_lyapunov_periods=args.lyapunov, spectrum_periods=args.spectrum,
        bifurcations=bif, events=events, classes=counts,
        long_runs={f"{vals[j]:g}": {str(a): _strip(r) for a, r in longs[j].items()} for j in range(len(vals))},
        spectra=spectra, wall_s=wall_gather if wall_gather is not None else round(time.perf_counter() - t0, 1),
        load_average_start=[round(x, 2) for x in load0], script="scripts/attractor_events.py",
    )  # fmt: skip
    write_result(OUT / "attractor_events.json", d, load_at_start=load0, indent=None)
    print(json.dumps(counts), f"wall {d['wall_s']} s", flush=True)


if __name__ == "__main__":
    main()
