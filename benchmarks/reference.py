"""Reference-solution protocol: two different integrators at tolerance <= 1e-13 must agree.

For each scene (`jaxcelt.studies.benchmarking.make_scene`) and horizon:

* A: diffrax ``Dopri8`` (jaxcelt.simulate, rtol = atol = 1e-13, samples stepped onto exactly);
* B: scipy ``solve_ivp(DOP853)`` (Hairer's code, a different implementation and step-size
  controller) at rtol = atol = 1e-13, restarted on every sample interval so samples are solver
  states; its right-hand side is the numba port in ``benchmarks/_numba_model.py`` (an independent
  implementation of MODEL.md) when numba is available, else the jitted JAX field.

Agreement = max |y_A - y_B| over components at each sample time (SI units). The "trusted horizon"
is the last sample time up to which the agreement stays below ``--trust`` (1e-8); the work-precision
errors use only samples inside it. In chaotic scenes the two references separate like e^{lambda t}
however tight the tolerance: that is reported, not hidden.

    python benchmarks/reference.py [--quick] [--out docs/performance]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import jax
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import jaxcelt as jc  # noqa: E402
from jaxcelt.integrate import solvers  # noqa: E402
from jaxcelt.provenance import write_result  # noqa: E402
from jaxcelt.studies import benchmarking as bm  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402

TOL = 1e-13


def scipy_dop853(scene: bm.BenchmarkScene, tol: float = TOL, rhs: str = "numba"):
    """scipy DOP853 restarted on each sample interval; returns (ys, nfev, seconds, rhs_name)."""
    from scipy.integrate import solve_ivp

    f, name = None, "jax"
    if rhs == "numba":
        try:
            import _numba_model

            f, name = _numba_model.numba_rhs(scene.params), "numba"
        except ImportError:
            f = None
    if f is None:
        g = jax.jit(lambda t, y: jc.vector_field(t, y, scene.params))
        g(0.0, scene.y0).block_until_ready()

        def f(t, y):
            return np.asarray(g(t, y))

    ys = [np.asarray(scene.y0, float)]
    nfev = 0
    t0 = time.perf_counter()
    for a, b in zip(scene.ts[:-1], scene.ts[1:]):
        s = solve_ivp(f, (a, b), ys[-1], method="DOP853", rtol=tol, atol=tol)
        if s.status != 0:
            ys.extend([np.full(13, np.nan)] * (len(scene.ts) - len(ys)))
            break
        ys.append(s.y[:, -1])
        nfev += s.nfev
    return np.array(ys), nfev, time.perf_counter() - t0, name


def diffrax_dopri8(scene: bm.BenchmarkScene, tol: float = TOL):
    t0 = time.perf_counter()
    sol = jc.simulate(
        scene.params, scene.y0, scene.t1, ts=scene.ts, solver=solvers.make_solver("Dopri8"),
        rtol=tol, atol=tol, exact_ts=True, max_steps=2_000_000,
    )  # fmt: skip
    ys = np.asarray(jax.block_until_ready(sol.ys))
    return ys, int(sol.num_steps), time.perf_counter() - t0, int(sol.status)


def reference(scene: bm.BenchmarkScene, *, tol: float = TOL, trust: float = 1e-8, rhs: str = "numba") -> dict:
    """Both references on one scene and their agreement per sample time."""
    ya, steps_a, sec_a, status_a = diffrax_dopri8(scene, tol)
    yb, nfev_b, sec_b, rhs_name = scipy_dop853(scene, tol, rhs)
    agree_t = np.max(np.abs(ya - yb), axis=1)
    agree_t = np.where(np.isfinite(agree_t), agree_t, np.inf)
    ok = agree_t < trust
    trusted = int(np.argmin(ok)) - 1 if not ok.all() else len(ok) - 1
    return dict(
        scene=scene.name,
        description=scene.description,
        periods=len(scene.ts) - 1,
        tol=tol,
        ts=scene.ts.tolist(),
        agreement=agree_t.tolist(),
        max_agreement=float(np.max(agree_t)),
        trusted_index=trusted,
        trusted_until=float(scene.ts[max(trusted, 0)]),
        trust=trust,
        A=dict(solver="diffrax Dopri8", steps=steps_a, seconds_incl_compile=sec_a, status=status_a, ys=ya.tolist()),
        B=dict(solver=f"scipy DOP853 ({rhs_name} RHS)", nfev=nfev_b, seconds=sec_b, ys=yb.tolist()),
        params=scene.params.as_dict(),
    )


def scene_list(quick: bool) -> list[tuple[str, int]]:
    if quick:
        return [("rest17", 2), ("spin_reversal", 2), ("stick_slip", 1)]
    return [(f"rest{w}", n) for w in (14, 17, 19) for n in (5, 50)] + [("spin_reversal", 10), ("stick_slip", 3)]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="short horizons (minutes on 2 CPU cores)")
    ap.add_argument("--out", default="docs/performance", help="output folder")
    ap.add_argument("--tol", type=float, default=TOL)
    ap.add_argument("--rhs", choices=("numba", "jax"), default="numba", help="RHS of the scipy reference")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    info = versions()
    info["device"] = bm.device_string()
    print("versions:", info, flush=True)
    results = []
    for name, periods in scene_list(args.quick):
        sc = bm.make_scene(name, periods)
        r = reference(sc, tol=args.tol, rhs=args.rhs)
        results.append(r)
        print(
            f"{name:14s} {periods:3d} per.: max |A-B| = {r['max_agreement']:.2e}, trusted until t = {r['trusted_until']:.3g} s "
            f"({r['trusted_index']}/{r['periods']}); A {r['A']['steps']} steps {r['A']['seconds_incl_compile']:.1f}s, "
            f"B {r['B']['nfev']} nfev {r['B']['seconds']:.1f}s",
            flush=True,
        )
    tag = "_quick" if args.quick else ""
    path = out / f"reference{tag}.json"
    write_result(path, dict(versions=info, results=results))
    print("wrote", path)
    try:
        from jaxcelt.plotting.performance import plot_reference_agreement

        fig = plot_reference_agreement(results)
        fig.savefig(out / f"reference_agreement{tag}.png", dpi=110)
        print("wrote", out / f"reference_agreement{tag}.png")
    except ImportError as e:  # plotting is optional for the protocol itself
        print("no plot:", e)
    return results


if __name__ == "__main__":
    main()
