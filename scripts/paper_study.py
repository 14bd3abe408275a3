"""Does any reading of the paper reproduce its regimes at 14, 15.6, 17, 19 rad/s?

The paper (section 3, Figs. 4-7) reports for q_pi = 0.04 m:
  14 rad/s periodic, bounded;  15.6 periodic (locally), unbounded;  17 quasi-periodic, bounded;
  19 chaotic, (seemingly) unbounded.
Everything the text leaves open is swept in one vmapped batch of lanes (`jaxcelt.ensemble.run_lanes`):
the reading switches v_pi_sign and derivative_exact (MODEL.md section 9), the smoothing eps = eps_R,
initial conditions (rest at several headings psi0, small roll/pitch rocking, slow spin) and the
transient length; each lane is labelled with `jaxcelt.sweeps.regimes.classify` (section period, largest
Lyapunov exponent and its standard error, global drift of O) twice: with the model's validity enforced
(n3 <= 0 or lift-off -> "invalid") and with motion past n3 <= 0 allowed (labels ignore validity).

The labels follow the README's rule (`classify`'s defaults): period-k when the samples repeat; otherwise
lambda_1 -+ 2 standard errors against 0.02 1/s (chaotic / converging / quasi-periodic / uncertain). Study
files written before the standard error was stored keep their rows; ``--relabel`` re-labels the stored rows
of every study file by that rule (the point estimate decides where a row has no standard error, as
`classify` does) and rewrites their score tables, without integrating anything.

Chunks are cached under --out (an interrupted run resumes). Writes docs/paper-reproduction/*.json
and the table used by docs/paper-reproduction.md.

    python scripts/paper_study.py --quick          # small smoke version
    python scripts/paper_study.py                  # the study (tens of minutes on 2 CPU cores)
    python scripts/paper_study.py --relabel        # re-label the committed study files (seconds)
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import time
from pathlib import Path

import numpy as np

import jaxcelt as jc
from jaxcelt.ensemble import SweepConfig, run_lanes
from jaxcelt.provenance import write_result
from jaxcelt.sweeps.regimes import GLOBAL_MOTION, classify, regime_names
from jaxcelt.versions import versions

PAPER = {
    14.0: ("periodic", "bounded"),
    15.6: ("periodic", "unbounded"),
    17.0: ("quasi-periodic", "bounded"),
    19.0: ("chaotic", "unbounded"),
}
FREQS = tuple(PAPER)


def initial_conditions(p: jc.CeltParams) -> dict[str, np.ndarray]:
    """Named initial states (all on the contact manifold)."""
    d = np.radians(2.0)
    ics = {
        "rest psi0=0": jc.initial_state(p),
        "rest psi0=pi/4": jc.initial_state(p, psi=np.pi / 4),
        "rest psi0=pi/2": jc.initial_state(p, psi=np.pi / 2),
        "roll 2deg": jc.initial_state(p, n=(0.0, np.sin(d), np.cos(d))),
        "pitch 2deg": jc.initial_state(p, n=(np.sin(d), 0.0, np.cos(d))),
        "spin +1 rad/s": jc.initial_state(p, omega=(0.0, 0.0, 1.0)),
    }
    # headings: psi0 sweeps the angle between the long axis and the vibration; psi0 + pi with
    # v_pi_sign = +1 is the same motion as psi0 with v_pi_sign = -1 (tests/test_symmetry.py)
    for k in range(16):
        ics[f"rest psi0={22.5 * k:g}deg"] = jc.initial_state(p, psi=np.radians(22.5 * k))
    return {k: np.asarray(v) for k, v in ics.items()}


def local_class(name: str) -> str:
    return "periodic" if name.startswith("period-") else name


CHAOS_THRESHOLD = 0.02  # [1/s], the README's rule (`classify`'s default)
CONFIDENCE = 2.0  # half-width of the exponent's interval in standard errors (`classify`'s default)
RULE = "README: period-k if the samples repeat, else lambda_1 -+ 2 stderr against 0.02 1/s"


def relabel(name: str, lyapunov: float | None, stderr: float | None) -> str:
    """A stored label re-labelled by the README's rule: period-k, invalid and failed stay; a non-periodic
    lane's label follows from lambda_1 -+ 2 standard errors against 0.02 1/s (the point estimate alone
    where no standard error is stored)."""
    if name.startswith("period-") or name in ("invalid", "failed"):
        return name
    if lyapunov is None or not np.isfinite(lyapunov):
        return "aperiodic"
    se = 0.0 if stderr is None or not np.isfinite(stderr) else float(stderr)
    lo, hi = lyapunov - CONFIDENCE * se, lyapunov + CONFIDENCE * se
    if lo > CHAOS_THRESHOLD:
        return "chaotic"
    if hi < -CHAOS_THRESHOLD:
        return "converging"
    if lo >= -CHAOS_THRESHOLD and hi <= CHAOS_THRESHOLD:
        return "quasi-periodic"
    return "uncertain"


def score_table(rows: list[dict]) -> list[dict]:
    """One entry per (reading, eps, start): the labels and the score against the paper, 8 at most (one point
    per matching local label, periodic of any k counting as periodic, one per matching global label).
    ``score_strict`` counts a lane that left the model's validity as a miss; ``score_allowed`` labels it as
    if it were valid."""
    combos: dict[tuple, list[dict]] = {}
    for r in rows:
        combos.setdefault((r["v_pi_sign"], r["derivative_exact"], r["eps"], r["ic"]), []).append(r)
    table = []
    for (s, de, e, ic), sub in combos.items():
        entry = dict(v_pi_sign=s, derivative_exact=de, eps=e, ic=ic, labels={}, score_strict=0, score_allowed=0)
        for r in sub:
            want_local, want_global = PAPER[float(r["omega_pi"])]
            ok_global = r["global_motion"] == want_global
            for mode in ("strict", "allowed"):
                entry[f"score_{mode}"] += int(local_class(r[mode]) == want_local) + int(ok_global)
            entry["labels"][str(r["omega_pi"])] = (
                f"{r['allowed']}{'' if r['strict'] != 'invalid' else ' (invalid)'}, {r['global_motion']}, λ={r['lyapunov']:.3g}"
            )
        table.append(entry)
    table.sort(key=lambda x: (-x["score_strict"], -x["score_allowed"]))
    return table


def relabel_file(path: Path) -> dict:
    """Re-label a study file's stored rows by the README's rule and rewrite its score table (no integration)."""
    d = json.loads(path.read_text())
    for r in d["rows"]:
        se = r.get("lyapunov_stderr")
        r["strict"] = relabel(r["strict"], r["lyapunov"], se)
        r["allowed"] = relabel(r["allowed"], r["lyapunov"], se)
    d["table"] = score_table(d["rows"])
    d["chaos_threshold"] = CHAOS_THRESHOLD
    d["labelling_rule"] = RULE + (
        "" if all("lyapunov_stderr" in r for r in d["rows"]) else " (no standard error stored: the point estimate decides)"
    )
    # the rows were integrated earlier: keep that run's provenance beside the re-labelling's
    measured = d.pop("provenance", None)
    d["provenance_of_integration"] = d.get("provenance_of_integration") or measured or (
        "not recorded: the rows were integrated before result files recorded their provenance"
    )
    write_result(path, d, default=str)
    return d


def run(args) -> dict:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    base = jc.CeltParams.paper()
    ics = initial_conditions(base)
    if args.ics:
        unknown = set(args.ics) - set(ics)
        if unknown:
            raise SystemExit(f"unknown initial conditions {sorted(unknown)}; known: {sorted(ics)}")
        ics = {k: ics[k] for k in args.ics}
    if args.quick:
        ics = {k: ics[k] for k in ("rest psi0=0", "roll 2deg")}
    eps_values = [float(e) for e in args.eps]
    signs = [float(x) for x in args.signs]
    des = [float(x) for x in args.derivative_exact]
    combos = list(itertools.product(signs, des, eps_values, list(ics)))
    lanes = [(s, de, e, ic, w) for (s, de, e, ic) in combos for w in FREQS]
    print(f"{len(lanes)} lanes = {len(combos)} combinations x {len(FREQS)} frequencies; {versions()}")
    cfg = SweepConfig(
        transient_periods=args.transient,
        sample_periods=args.sample,
        lyapunov_periods=args.lyapunov,
        rtol=args.rtol,
        atol=args.rtol * 1e-2,
        max_steps=args.max_steps,
    )
    results: dict[str, list] = {}
    chunk = args.chunk
    t_start = time.perf_counter()
    load_at_start = list(os.getloadavg())
    for c0 in range(0, len(lanes), chunk):
        part = lanes[c0 : c0 + chunk]
        key = hashlib.sha1(repr(part).encode()).hexdigest()[:12]
        cache = out / f"T{args.transient}_S{args.sample}_L{args.lyapunov}_rtol{args.rtol:g}_{key}.npz"
        if cache.exists():
            r = dict(np.load(cache))
        else:
            fields = {k: np.asarray([getattr(base, k)] * len(part), dtype=float) for k in jc.PARAM_NAMES}
            fields["v_pi_sign"] = np.array([x[0] for x in part])
            fields["derivative_exact"] = np.array([x[1] for x in part])
            fields["eps"] = np.array([x[2] for x in part])
            fields["eps_R"] = np.array([x[2] for x in part])
            fields["omega_pi"] = np.array([x[4] for x in part])
            import jax

            pb = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(base), [fields[k] for k in jc.PARAM_NAMES])
            y0b = np.stack([ics[x[3]] for x in part])
            t = time.perf_counter()
            r = run_lanes(pb, y0b, cfg, pad_to=chunk)
            r = {
                k: r[k]
                for k in (
                    "samples",
                    "status",
                    "valid",
                    "r_O",
                    "lyapunov",
                    "lyapunov_stderr",
                    "first_invalid_kind",
                    "max_tilt",
                    "min_N",
                    "drift",
                    "num_steps",
                )
            }
            np.savez(cache, **r)
            print(f"chunk {c0 // chunk + 1}/{-(-len(lanes) // chunk)}: {time.perf_counter() - t:.1f} s", flush=True)
        for k, v in r.items():
            results.setdefault(k, []).append(v)
    R = {k: np.concatenate(v) for k, v in results.items()}
    # the README's rule: lambda_1 -+ 2 standard errors against 0.02 1/s (classify's defaults)
    thr = CHAOS_THRESHOLD
    se = R["lyapunov_stderr"]
    lab_strict = classify(R["samples"], R["status"], R["valid"], R["r_O"], R["lyapunov"], lyapunov_stderr=se)
    lab_free = classify(R["samples"], R["status"], np.ones_like(R["valid"]), R["r_O"], R["lyapunov"], lyapunov_stderr=se)
    names_strict = regime_names(lab_strict["regime"], lab_strict["period"])
    names_free = regime_names(lab_free["regime"], lab_free["period"])
    rows = []
    for i, (s, de, e, ic, w) in enumerate(lanes):
        rows.append(
            dict(
                v_pi_sign=s,
                derivative_exact=de,
                eps=e,
                ic=ic,
                omega_pi=w,
                strict=str(names_strict[i]),
                allowed=str(names_free[i]),
                global_motion=GLOBAL_MOTION[int(lab_free["global_motion"][i])],
                lyapunov=float(R["lyapunov"][i]),
                lyapunov_stderr=float(R["lyapunov_stderr"][i]),
                drift_m=float(R["drift"][i]),
                max_tilt_deg=float(np.degrees(R["max_tilt"][i])),
                first_invalid_t=float(R["first_invalid_t"][i]) if "first_invalid_t" in R else None,
                min_N=float(R["min_N"][i]),
                status=int(R["status"][i]),
                steps=int(R["num_steps"][i]),
            )
        )
    table = score_table(rows)
    summary = dict(
        config=dict(vars(args)),
        versions=versions(),
        wall_s=time.perf_counter() - t_start,
        chaos_threshold=thr,
        labelling_rule=RULE,
        paper=PAPER,
        rows=rows,
        table=table,
    )
    tag = args.tag or ("quick" if args.quick else f"T{args.transient}_rtol{args.rtol:g}")
    docs = Path(args.docs)
    docs.mkdir(parents=True, exist_ok=True)
    write_result(docs / f"study_{tag}.json", summary, load_at_start=load_at_start, default=str)
    print(f"max score 8 (4 local + 4 global). Best combinations ({tag}), strict then allowed:")
    for t in table[:10]:
        print(
            t["score_strict"], t["score_allowed"], t["v_pi_sign"], t["derivative_exact"], t["eps"], t["ic"], t["labels"]
        )
    return summary


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--relabel", action="store_true", help="re-label the study files in --docs by the README's rule")
    ap.add_argument("--transient", type=int, default=300)
    ap.add_argument("--sample", type=int, default=64)
    ap.add_argument("--lyapunov", type=int, default=60)
    ap.add_argument("--eps", nargs="+", default=["1e-2", "1e-4", "1e-6"])
    ap.add_argument("--ics", nargs="+", default=None, help="subset of initial conditions (names)")
    ap.add_argument("--signs", nargs="+", default=["1", "-1"], help="v_pi_sign values")
    ap.add_argument("--derivative-exact", nargs="+", default=["0", "1"], help="derivative_exact values")
    ap.add_argument("--tag", default=None, help="name of the output JSON (default from settings)")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--max-steps", type=int, default=2_000_000)
    ap.add_argument("--chunk", type=int, default=48)
    ap.add_argument("--out", default="runs/paper_study")
    ap.add_argument("--docs", default="docs/paper-reproduction")
    args = ap.parse_args(argv)
    if args.relabel:
        for f in sorted(Path(args.docs).glob("study_*.json")):
            t = relabel_file(f)["table"][0]
            print(f"{f.name}: best {t['score_strict']} strict / {t['score_allowed']} allowed ({t['ic']}, eps {t['eps']:g})")
        return
    if args.quick:
        args.transient, args.sample, args.lyapunov, args.eps, args.chunk = 20, 16, 8, ["1e-4"], 16
    run(args)


if __name__ == "__main__":
    main()
