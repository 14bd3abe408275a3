"""Work-precision diagrams (issue 7): error at the stroboscopic times against wall time (compile
apart) and against right-hand-side evaluations, for diffrax explicit, implicit and fixed-step
methods over tolerance / dt ladders; float64 and float32; every contact law in jc.CONTACT_LAWS.

Reference per scene: diffrax Dopri8 at rtol = atol = 1e-13 (validated against scipy DOP853 on an
independent numba RHS by ``benchmarks/reference.py``). Error: max |y - y_ref| over the sample
times and the 13 state components (SI units). RHS evaluations: exact count for implicit methods
(counting contact law, Jacobian columns included), steps x stages for explicit ones.

    python benchmarks/work_precision.py [--quick] [--out docs/performance] [--parts scenes,float32,laws]
"""

from __future__ import annotations

import argparse
import json
import pathlib
import time

import jax
import numpy as np

import jaxcelt as jc
from jaxcelt import benchmarking as bm
from jaxcelt.versions import versions

EXPLICIT = ["Tsit5", "Dopri5", "Dopri8"]
IMPLICIT = ["Kvaerno3", "Kvaerno5", "Kvaerno3-Newton", "Kvaerno5-Newton"]
FIXED = ["RK4-fixed", "Heun-fixed"]


def _stages_per_step(name: str) -> int | None:
    s = bm.make_solver(name)
    s = getattr(s, "solver", s)
    tab = getattr(s, "tableau", None)
    if tab is None:
        return 1  # Euler
    return tab.num_stages - (1 if tab.fsal and bm.SOLVERS[name][1] != "fixed" else 0)


def reference_ys(scene: bm.Scene, law=None) -> np.ndarray:
    sol = jc.simulate(
        scene.params, scene.y0, scene.t1, ts=scene.ts, solver=bm.make_solver("Dopri8"), rtol=1e-13, atol=1e-13,
        exact_ts=True, contact_law=law, max_steps=2_000_000,
    )  # fmt: skip
    return np.asarray(jax.block_until_ready(sol.ys))


def ladder(scene, name, values, *, ys_ref, law=None, dtype=None, max_run_s=20.0, count_implicit=True, repeats=2):
    """Run one method down its ladder; stop when a run exceeds ``max_run_s`` or fails."""
    out = []
    kind = bm.SOLVERS[name][1]
    for v in values:
        kw = dict(dt0=v) if kind == "fixed" else dict(rtol=v)
        count = count_implicit and kind == "implicit"
        try:
            r = bm.run_diffrax(
                scene, name, ys_ref=ys_ref, law=law, dtype=dtype, repeats=repeats, count_evals=count, **kw
            )
        except Exception as e:  # a configuration diffrax rejects is a result, not a crash
            print(f"  {name} {kw}: ERROR {type(e).__name__}: {str(e)[:200]}", flush=True)
            out.append(dict(scene=scene.name, solver=name, kind=kind, error_message=str(e)[:500], **kw))
            break
        if "rhs_evals" not in r:
            r["rhs_evals"] = None if kind == "implicit" else r["steps"] * _stages_per_step(name)
        out.append(r)
        print(
            f"  {name:16s} {r['dtype']:8s} {str(kw):22s} err {r['error']:.2e}  run {r['run_s'] * 1e3:8.1f} ms  "
            f"compile {r['compile_s']:5.1f} s  steps {r['accepted']}+{r['rejected']}  nfe {r['rhs_evals']}  status {r['status']}",
            flush=True,
        )
        if r["status"] != 0 or r["run_s"] > max_run_s:
            break
    return out


def config(quick: bool):
    if quick:
        return dict(
            scenes=[("rest17", 2), ("stick_slip", 1)],
            rtols=[1e-5, 1e-7, 1e-9],
            rtols_implicit=[1e-5, 1e-7],
            dts=[2e-3, 5e-4],
            explicit=["Tsit5", "Dopri8"],
            implicit=["Kvaerno5-Newton"],
            fixed=["RK4-fixed"],
            f32_rtols=[1e-3, 1e-5],
            f32_solvers=["Tsit5"],
            laws=["generalised_pade", "pade"],
            max_run_s=5.0,
            repeats=1,
        )
    return dict(
        scenes=[("rest17", 5), ("stick_slip", 1), ("rest19", 5), ("spin_reversal", 5)],
        rtols=[1e-4, 1e-6, 1e-8, 1e-10, 1e-12],  # a ladder stops early past max_run_s
        rtols_implicit=[1e-4, 1e-6, 1e-8, 1e-10],
        dts=[4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4],
        explicit=EXPLICIT,
        implicit=["Kvaerno5", "Kvaerno3-Newton", "Kvaerno5-Newton"],
        fixed=FIXED,
        f32_rtols=[1e-2, 1e-3, 1e-4, 1e-5, 1e-6],
        f32_solvers=["Tsit5", "Dopri5"],
        laws=[k for k in jc.CONTACT_LAWS],
        max_run_s=20.0,
        repeats=2,
    )


def _save(res, out, quick):
    # written after every part so that an interrupted long run keeps what it measured
    (out / f"work_precision{'_quick' if quick else ''}.json").write_text(json.dumps(res, indent=1))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--parts", default="scenes,float32,laws")
    args = ap.parse_args(argv)
    cfg = config(args.quick)
    parts = set(args.parts.split(","))
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    info = versions()
    info["device"] = bm.device_string()
    print("versions:", info, flush=True)
    res: dict = dict(versions=info, config={k: v for k, v in cfg.items()}, scenes=[], float32=[], laws=[])
    t_start = time.perf_counter()
    if "scenes" in parts:
        for name, periods in cfg["scenes"]:
            sc = bm.make_scene(name, periods)
            ref = reference_ys(sc)
            print(f"scene {name} ({sc.description})", flush=True)
            runs = []
            for s in cfg["explicit"]:
                runs += ladder(sc, s, cfg["rtols"], ys_ref=ref, max_run_s=cfg["max_run_s"], repeats=cfg["repeats"])
            for s in cfg["implicit"]:
                runs += ladder(
                    sc, s, cfg["rtols_implicit"], ys_ref=ref, max_run_s=cfg["max_run_s"], repeats=cfg["repeats"]
                )
            for s in cfg["fixed"]:
                runs += ladder(sc, s, cfg["dts"], ys_ref=ref, max_run_s=cfg["max_run_s"], repeats=cfg["repeats"])
            res["scenes"].append(dict(scene=name, description=sc.description, periods=periods, runs=runs))
            _save(res, out, args.quick)
    if "float32" in parts:
        sc = bm.make_scene("rest17", cfg["scenes"][0][1])
        ref = reference_ys(sc)
        print("float32 vs float64 on", sc.description, flush=True)
        runs = []
        for s in cfg["f32_solvers"]:
            runs += ladder(
                sc,
                s,
                cfg["f32_rtols"],
                ys_ref=ref,
                dtype=np.float32,
                max_run_s=cfg["max_run_s"],
                count_implicit=False,
                repeats=cfg["repeats"],
            )
        runs += ladder(
            sc,
            cfg["fixed"][0],
            cfg["dts"][:3],
            ys_ref=ref,
            dtype=np.float32,
            max_run_s=cfg["max_run_s"],
            repeats=cfg["repeats"],
        )
        res["float32"] = runs
        _save(res, out, args.quick)
    if "laws" in parts:
        sc = bm.make_scene("rest17", cfg["scenes"][0][1])
        for law in cfg["laws"]:
            print(f"contact law {law}", flush=True)
            try:
                ref = reference_ys(sc, law=law)
            except Exception as e:
                print("  reference failed:", e)
                continue
            runs = ladder(
                sc, "Tsit5", cfg["rtols"][:4], ys_ref=ref, law=law, max_run_s=cfg["max_run_s"], repeats=cfg["repeats"]
            )
            runs += ladder(
                sc,
                "Kvaerno5-Newton",
                cfg["rtols_implicit"][:3],
                ys_ref=ref,
                law=law,
                max_run_s=cfg["max_run_s"],
                count_implicit=False,
                repeats=cfg["repeats"],
            )
            res["laws"].append(dict(law=law, runs=runs))
            _save(res, out, args.quick)
    res["total_seconds"] = time.perf_counter() - t_start
    tag = "_quick" if args.quick else ""
    path = out / f"work_precision{tag}.json"
    path.write_text(json.dumps(res, indent=1))
    print("wrote", path, f"({res['total_seconds']:.0f} s)")
    from jaxcelt.plotting.performance import plot_work_precision

    for fig_name, fig in plot_work_precision(res).items():
        fig.savefig(out / f"wp_{fig_name}{tag}.png", dpi=100)
        print("wrote", out / f"wp_{fig_name}{tag}.png")
    return res


if __name__ == "__main__":
    main()
