"""Work-precision diagrams: error at the stroboscopic times against wall time (compile
apart) and against right-hand-side evaluations, for diffrax explicit, implicit and fixed-step
methods over tolerance / dt ladders; float64 and float32; every contact law in jc.CONTACT_LAWS.

Reference per scene (and per contact law): diffrax Dopri8 at rtol = atol = 1e-13 (validated
against scipy DOP853 on an independent numba RHS by ``benchmarks/reference.py``). Error: max
|y - y_ref| over the sample times and the 13 state components (SI units). RHS evaluations: exact
count of vector-field calls for implicit methods (counting contact law; the Jacobian's batched
columns are not included, so implicit points understate their work), steps x stages for
explicit and fixed-step ones.

Incremental and resumable: the JSON is rewritten after every ladder (one method on one scene),
ladders already in the JSON are skipped on a re-run, each ladder stops at a wall-time budget
(compile included) or at the first run slower than ``max_run_s`` or failing, and ``--deadline-min``
stops starting new ladders after that many minutes.

    python benchmarks/work_precision.py [--quick] [--out docs/performance]
        [--parts scenes,float32,laws] [--deadline-min 60] [--fresh]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import time

import diffrax
import jax
import numpy as np
import optimistix as optx

import jaxcelt as jc
from jaxcelt.integrate import solvers
from jaxcelt.provenance import load_average, write_result
from jaxcelt.studies import benchmarking as bm
from jaxcelt.versions import versions

EXPLICIT = ["Tsit5", "Dopri5", "Dopri8"]
IMPLICIT = ["Kvaerno3-Newton", "Kvaerno5-Newton"]
FIXED = ["RK4-fixed", "Heun-fixed"]


def _stages_per_step(name: str) -> int:
    """RHS evaluations per step (accepted or rejected) of an explicit / fixed-step method."""
    s = solvers.make_solver(name)
    s = getattr(s, "solver", s)
    tab = getattr(s, "tableau", None)
    if tab is None:
        return 1  # Euler
    return tab.num_stages - (1 if tab.fsal and solvers.SOLVERS[name][1] != "fixed" else 0)


def reference_ys(scene: bm.BenchmarkScene, law=None) -> tuple[np.ndarray, dict]:
    t = time.perf_counter()
    sol = jc.simulate(
        scene.params, scene.y0, scene.t1, ts=scene.ts, solver=solvers.make_solver("Dopri8"), rtol=1e-13, atol=1e-13,
        exact_ts=True, contact_law=law, max_steps=2_000_000,
    )  # fmt: skip
    ys = np.asarray(jax.block_until_ready(sol.ys))
    info = dict(steps=int(sol.num_steps), status=int(sol.status), seconds=time.perf_counter() - t)
    return ys, info


def _register_chord(rtol: float, atol: float) -> None:
    """``Kvaerno5-chord``: diffrax's default root finder (VeryChord: one Jacobian per step, reused by
    every stage and iteration) with the tolerances diffeqsolve would give it (the controller's
    rtol/atol, RMS norm). Given explicitly, because `jaxcelt.simulate` replaces the *default*
    VeryChord by full Newton since commit ed5e6fc; an explicit root finder is kept as it is."""
    solvers.SOLVERS["Kvaerno5-chord"] = (
        lambda: diffrax.Kvaerno5(root_finder=diffrax.VeryChord(rtol=rtol, atol=atol, norm=optx.rms_norm)),
        "implicit",
    )


def ladder(scene, name, values, *, ys_ref, law=None, dtype=None, max_run_s=10.0, budget_s=240.0, repeats=2):
    """Run one method down its ladder.

    Stops at the first failed run, at a run slower than ``max_run_s``, or when the ladder has
    used ``budget_s`` of wall time (compile included). Repeats drop to 1 for runs over 2 s.
    """
    out = []
    if name == "Kvaerno5-chord":
        _register_chord(values[0], values[0] * 1e-2)
    kind = solvers.SOLVERS[name][1]
    t_ladder = time.perf_counter()
    count = kind == "implicit"
    for v in values:
        if time.perf_counter() - t_ladder > budget_s:
            print(f"  {name}: ladder budget {budget_s:.0f} s used, stopping before {v:g}", flush=True)
            out.append(dict(scene=scene.name, solver=name, kind=kind, skipped=f"ladder budget {budget_s:.0f} s"))
            break
        kw = dict(dt0=v) if kind == "fixed" else dict(rtol=v)
        if name == "Kvaerno5-chord":
            _register_chord(v, v * 1e-2)  # atol as run_diffrax's default
        try:
            r = bm.run_diffrax(
                scene, name, ys_ref=ys_ref, law=law, dtype=dtype, repeats=repeats, count_evals=count, **kw
            )
        except Exception as e:  # a configuration diffrax rejects is a result, not a crash
            print(f"  {name} {kw}: ERROR {type(e).__name__}: {str(e)[:200]}", flush=True)
            out.append(dict(scene=scene.name, solver=name, kind=kind, error_message=str(e)[:500], **kw))
            break
        if "rhs_evals" not in r:
            r["rhs_evals"] = r["steps"] * _stages_per_step(name) + 1
            r["rhs_evals_how"] = "steps x stages + 1"
        else:
            r["rhs_evals_how"] = "counted"
        r["loadavg_1min"] = os.getloadavg()[0]
        r.pop("final_state", None)
        out.append(r)
        print(
            f"  {name:16s} {r['dtype']:8s} {str(kw):22s} err {r['error']:.2e}  run {r['run_s'] * 1e3:8.1f} ms  "
            f"compile {r['compile_s']:5.1f} s  steps {r['accepted']}+{r['rejected']}  nfe {r['rhs_evals']}  "
            f"status {r['status']}  load {r['loadavg_1min']:.1f}",
            flush=True,
        )
        if r["run_s"] > 2.0:
            repeats = 1
        if r["status"] != 0 or not np.isfinite(r["error"]) or r["run_s"] > max_run_s:
            break
    return out


TARGETS = (1e-4, 1e-6, 1e-8, 1e-10)


def _fmt_int(n) -> str:
    return "" if n is None else f"{int(n):,}".replace(",", " ")


def _cheapest(runs, target, key):
    """Per solver the cheapest (by ``key``) successful run with error <= target; all solvers sorted by ``key``."""
    best: dict = {}
    for r in runs:
        if "run_s" not in r or r["status"] != 0 or r.get("error") is None or not np.isfinite(r["error"]):
            continue
        if r["error"] <= target and r.get(key) is not None:
            if r["solver"] not in best or r[key] < best[r["solver"]][key]:
                best[r["solver"]] = r
    return sorted(best.values(), key=lambda r: r[key])


def _ladder_label(r) -> str:
    return f"rtol {r['rtol']:.0e}" if r.get("rtol") is not None else f"dt {r['dt0']:g} s"


def report(res: dict) -> str:
    """Markdown tables from a work_precision.json dict (docs/performance.md section 2)."""
    lines = []
    for sc in res.get("scenes", []):
        runs = [r for r in sc["runs"] if "run_s" in r]
        lines.append(f"\n**{sc['description']}** — cheapest run reaching each target error\n")
        lines.append("| target error | fastest (run time) | runner-up | fewest RHS evaluations (explicit / fixed) |")
        lines.append("|---|---|---|---|")
        for t in TARGETS:
            by_t = _cheapest(runs, t, "run_s")
            by_n = _cheapest([r for r in runs if r["kind"] != "implicit"], t, "rhs_evals")
            cell = lambda r: f"{r['solver']} {_ladder_label(r)}: {r['run_s'] * 1e3:.0f} ms, err {r['error']:.1e}"  # noqa: E731
            f = cell(by_t[0]) if by_t else "none reached it"
            ru = cell(by_t[1]) if len(by_t) > 1 else ""
            n = f"{by_n[0]['solver']} {_ladder_label(by_n[0])}: {_fmt_int(by_n[0]['rhs_evals'])}" if by_n else "none"
            lines.append(f"| {t:.0e} | {f} | {ru} | {n} |")
        lines.append("\n<details><summary>all runs of this scene</summary>\n")
        lines.append("| solver | rtol / dt | error | steps acc+rej | RHS evals | run [ms] | compile [s] | status |")
        lines.append("|---|---|---|---|---|---|---|---|")
        for r in sc["runs"]:
            if "run_s" not in r:
                lines.append(f"| {r['solver']} | | {r.get('skipped') or r.get('error_message', '')[:80]} | | | | | |")
                continue
            ev = _fmt_int(r["rhs_evals"]) + ("*" if r["rhs_evals_how"] == "counted" else "")
            lines.append(
                f"| {r['solver']} | {_ladder_label(r)} | {r['error']:.2e} | {r['accepted']}+{r['rejected']} | {ev} | "
                f"{r['run_s'] * 1e3:.1f} | {r['compile_s']:.1f} | {r['status']} |"
            )
        lines.append("\n</details>\n")
    if res.get("float32"):
        lines.append("\n**float32 vs float64** (error at each rtol; atol = 1e-2 rtol)\n")
        lines.append("| scene | solver | " + " | ".join(f"{t:.0e}" for t in res["config"]["f32_rtols"]) + " |")
        lines.append("|---|---|" + "---|" * len(res["config"]["f32_rtols"]))
        for f in res["float32"]:
            f64 = [r for sc in res["scenes"] if sc["scene"] == f["scene"] for r in sc["runs"] if "run_s" in r]
            for s in dict.fromkeys(r["solver"] for r in f["runs"]):
                for dt, rr in (("float32", f["runs"]), ("float64", f64)):
                    errs = {r["rtol"]: r for r in rr if r["solver"] == s and "run_s" in r}
                    cells = []
                    for t in res["config"]["f32_rtols"]:
                        r = errs.get(t)
                        cells.append("" if r is None else f"{r['error']:.1e}" + ("" if r["status"] == 0 else " (fail)"))
                    lines.append(f"| {f['scene']} | {s} {dt} | " + " | ".join(cells) + " |")
    if res.get("laws"):
        lines.append("\n**Contact laws** (rest17, 5 periods; error against the law's own Dopri8 1e-13 reference)\n")
        lines.append("| law | solver | rtol | error | steps acc+rej | RHS evals | run [ms] | compile [s] |")
        lines.append("|---|---|---|---|---|---|---|---|")
        for L in res["laws"]:
            if L.get("error_message") and not L.get("runs"):
                lines.append(f"| {L['law']} | | | {L['error_message'][:80]} | | | | |")
            for r in L.get("runs", []):
                if "run_s" not in r:
                    lines.append(
                        f"| {L['law']} | {r['solver']} | | {r.get('skipped') or r.get('error_message', '')[:80]} | | | | |"
                    )
                    continue
                lines.append(
                    f"| {L['law']} | {r['solver']} | {r['rtol']:.0e} | {r['error']:.2e} | {r['accepted']}+{r['rejected']} "
                    f"| {_fmt_int(r['rhs_evals'])} | {r['run_s'] * 1e3:.1f} | {r['compile_s']:.1f} |"
                )
    return "\n".join(lines)


def config(quick: bool):
    if quick:
        return dict(
            scenes=[("rest17", 2), ("stick_slip", 1)],
            rtols=[1e-5, 1e-7, 1e-9],
            rtols_implicit=[1e-5, 1e-7],
            dts=[2e-3, 5e-4],
            explicit=["Tsit5", "Dopri8"],
            implicit=["Kvaerno5-Newton"],
            chord=[],
            fixed=["RK4-fixed"],
            f32_scenes=["rest17"],
            f32_rtols=[1e-3, 1e-5],
            f32_solvers=["Tsit5"],
            laws=["generalised_pade", "pade"],
            law_solvers=["Tsit5"],
            max_run_s=5.0,
            budget_s=120.0,
            repeats=1,
        )
    return dict(
        scenes=[("rest17", 5), ("stick_slip", 1), ("rest19", 5), ("rest14", 5), ("spin_reversal", 5)],
        rtols=[1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
        rtols_implicit=[1e-4, 1e-6, 1e-8],
        rtols_k3=[1e-4, 1e-6],  # 3rd order: 1e-8 took 25 600 steps, 20 s on rest17
        # fixed steps: dt = (sample interval) / n, so that every sample is a step end (no interpolation)
        steps_per_sample=[100, 200, 400, 800, 1600, 3200, 6400],
        explicit=EXPLICIT,
        implicit=IMPLICIT,
        chord=dict(scenes=["rest17", "stick_slip"], solver="Kvaerno5-chord", rtols=[1e-4, 1e-6]),
        fixed=FIXED,
        f32_scenes=["rest17", "stick_slip"],
        f32_rtols=[1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8],
        f32_solvers=["Tsit5", "Dopri8"],
        laws=list(jc.CONTACT_LAWS),
        law_solvers=["Tsit5", "Dopri8"],
        law_rtols=[1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
        max_run_s=10.0,
        budget_s=300.0,
        repeats=2,
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--parts", default="scenes,float32,laws")
    ap.add_argument("--deadline-min", type=float, default=1e9, help="start no new ladder after this many minutes")
    ap.add_argument(
        "--scenes",
        default=None,
        help="scenes (in order) of the scenes part; 'a,b;c' = groups for repeated scenes parts",
    )
    ap.add_argument("--periods", default=None, help="override periods per scene, e.g. 'spin_reversal=10'")
    ap.add_argument("--solvers", default=None, help="comma list: run only these methods")
    ap.add_argument("--fresh", action="store_true", help="ignore an existing JSON (default: resume)")
    ap.add_argument("--plot-only", action="store_true", help="only redraw the charts from the JSON")
    ap.add_argument("--report", action="store_true", help="print Markdown tables from the JSON and exit")
    args = ap.parse_args(argv)
    cfg = config(args.quick)
    if args.periods:
        over = {k: int(v) for k, v in (kv.split("=") for kv in args.periods.split(","))}
        cfg["scenes"] = [(n, over.get(n, p)) for n, p in cfg["scenes"]]
    parts = args.parts.split(",")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tag = "_quick" if args.quick else ""
    path = out / f"work_precision{tag}.json"
    if args.report:
        print(report(json.loads(path.read_text())))
        return None
    load0 = load_average()
    info = versions()
    info["device"] = bm.device_string()
    print("versions:", info, flush=True)
    if path.exists() and not args.fresh:
        res = json.loads(path.read_text())
        print(f"resuming {path}: {len(res.get('done', []))} ladders done", flush=True)
    else:
        res = dict(scenes=[], float32=[], laws=[], done=[], references={})
    res["config"] = {k: v for k, v in cfg.items()}
    if not args.plot_only:
        if "sessions" in res:  # files written before the key was named "runs"
            res["runs"] = res.pop("sessions")
        res.setdefault("runs", []).append(
            dict(versions=info, started=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()))
        )
    res["versions"] = info
    t_start = time.perf_counter()
    refs: dict = {}

    def save():
        write_result(path, res, load_at_start=load0)

    def out_of_time():
        return (time.perf_counter() - t_start) / 60 > args.deadline_min

    def get_ref(scene_name, periods, law=None):
        key = f"{scene_name}/{periods}/{law}"
        if key not in refs:
            sc = bm.make_scene(scene_name, periods)
            ys, rinfo = reference_ys(sc, law)
            print(f"reference {key}: {rinfo}", flush=True)
            res["references"][key] = rinfo
            refs[key] = (sc, ys)
        return refs[key]

    def entry(lst, key, val, **extra):
        for e in lst:
            if e[key] == val:
                return e
        e = {key: val, **extra, "runs": []}
        lst.append(e)
        return e

    def run_ladder(lkey, lst, key, val, extra, scene_name, periods, solver, values, law=None, dtype=None):
        if lkey in res["done"] or args.plot_only or (args.solvers and solver not in args.solvers.split(",")):
            return
        if out_of_time():
            print(f"deadline: skipping {lkey}", flush=True)
            return
        sc, ys_ref = get_ref(scene_name, periods, law)
        e = entry(lst, key, val, description=sc.description, periods=periods, **extra)
        print(f"[{lkey}] {sc.description}", flush=True)
        t = time.perf_counter()
        runs = ladder(
            sc, solver, values, ys_ref=ys_ref, law=law, dtype=dtype, max_run_s=cfg["max_run_s"],
            budget_s=cfg["budget_s"], repeats=cfg["repeats"],
        )  # fmt: skip
        for r in runs:
            r["law_name"] = law or "generalised_pade"
        e["runs"] = [r for r in e["runs"] if not (r["solver"] == solver and r.get("dtype", "float64") == (
            "float32" if dtype is np.float32 else "float64"))] + runs  # fmt: skip
        res["done"].append(lkey)
        res.setdefault("ladder_seconds", {})[lkey] = time.perf_counter() - t
        save()

    n_scene_parts = 0
    for part in parts:
        if part == "scenes":
            scene_list = cfg["scenes"]
            if args.scenes:  # "a,b;c,d": the i-th "scenes" part runs the i-th group
                group = args.scenes.split(";")[min(n_scene_parts, len(args.scenes.split(";")) - 1)]
                scene_list = [(n, dict(cfg["scenes"])[n]) for n in group.split(",")]
            n_scene_parts += 1
            for name, periods in scene_list:
                for s in cfg["explicit"]:
                    run_ladder(f"scenes/{name}/{s}", res["scenes"], "scene", name, {}, name, periods, s, cfg["rtols"])
                for s in cfg["implicit"]:
                    vals = (
                        cfg.get("rtols_k3", cfg["rtols_implicit"])
                        if s.startswith("Kvaerno3")
                        else cfg["rtols_implicit"]
                    )
                    run_ladder(f"scenes/{name}/{s}", res["scenes"], "scene", name, {}, name, periods, s, vals)
                for s in cfg["fixed"]:
                    if "steps_per_sample" in cfg:
                        ts = bm.make_scene(name, periods).ts
                        dts = [float(ts[1] - ts[0]) / n for n in cfg["steps_per_sample"]]
                    else:
                        dts = cfg["dts"]
                    run_ladder(f"scenes/{name}/{s}", res["scenes"], "scene", name, {}, name, periods, s, dts)
                ch = cfg["chord"]
                if ch and name in ch["scenes"]:
                    run_ladder(
                        f"scenes/{name}/{ch['solver']}", res["scenes"], "scene", name, {}, name, periods,
                        ch["solver"], ch["rtols"],
                    )  # fmt: skip
        elif part == "float32":
            periods = dict(cfg["scenes"])
            for name in cfg["f32_scenes"]:
                for s in cfg["f32_solvers"]:
                    run_ladder(
                        f"float32/{name}/{s}", res["float32"], "scene", name, {}, name, periods[name], s,
                        cfg["f32_rtols"], dtype=np.float32,
                    )  # fmt: skip
        elif part == "laws":
            name, periods = "rest17", dict(cfg["scenes"])["rest17"]
            for law in cfg["laws"]:
                for s in cfg["law_solvers"]:
                    try:
                        run_ladder(
                            f"laws/{law}/{s}", res["laws"], "law", law, dict(scene=name), name, periods, s,
                            cfg.get("law_rtols", cfg["rtols"]), law=law,
                        )  # fmt: skip
                    except Exception as ex:  # e.g. a reference that does not finish
                        print(f"  law {law}: {type(ex).__name__}: {ex}", flush=True)
                        entry(res["laws"], "law", law, scene=name)["error_message"] = str(ex)[:500]
                        save()
                        break
        else:
            raise ValueError(f"unknown part {part!r}")
    if not args.plot_only:
        res["total_seconds_last_session"] = time.perf_counter() - t_start
        save()
    print("wrote", path, f"({res.get('total_seconds_last_session', 0):.0f} s)", flush=True)
    from jaxcelt.plotting.performance import plot_work_precision

    for fig_name, fig in plot_work_precision(res).items():
        fig.savefig(out / f"wp_{fig_name}{tag}.png", dpi=100)
        print("wrote", out / f"wp_{fig_name}{tag}.png")
    return res


if __name__ == "__main__":
    main()
