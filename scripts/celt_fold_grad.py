"""The fold of the wobblestone's period-1 branch in omega_pi and d(omega_fold)/d(mu): IFT gradient vs
central finite differences of the located point -> docs/orbits/celt_fold_grad.json.

Starts from the fold that `scripts/orbit_branches.py` found by continuation (docs/orbits/branches.json),
refines it with `jaxcelt.orbits.celt.locate_orbit_bifurcation` (Newton on periodicity + bordered
det(M - I) in the chart of the contact manifold) and differentiates the located omega_pi in the
friction coefficient mu. Timings are indicative (load average recorded; each call compiles).

    python scripts/celt_fold_grad.py [--h 1e-4]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import time

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxcelt as jc
from jaxcelt.orbits.celt import locate_orbit_bifurcation
from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.provenance import write_result
from jaxcelt.versions import versions

ROOT = pathlib.Path(__file__).resolve().parents[1]


def fold_start() -> tuple[np.ndarray, float]:
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    br = next(iter(d["branches"].values()))["branch"]
    b = next(b for b in br["bifurcations"] if b["kind"] == "fold")
    return np.array([b["state"][n] for n in STATE_NAMES]), float(b["value"])


def check(h: float = 1e-4) -> dict:
    y, v = fold_start()
    p = jc.CeltParams.paper(omega_pi=v)
    mu0 = float(p.mu)

    def locate(mu):
        return locate_orbit_bifurcation(eqx.tree_at(lambda q: q.mu, p, mu), y, "omega_pi", v, kind="fold", wrt=("mu",))

    load0 = list(os.getloadavg())
    t = time.perf_counter()
    bp = jax.block_until_ready(locate(jnp.asarray(mu0)))
    t_locate = time.perf_counter() - t
    t = time.perf_counter()
    g = float(jax.grad(lambda m: locate(m).value)(jnp.asarray(mu0)))
    t_grad = time.perf_counter() - t
    t = time.perf_counter()
    fp, fm = (locate(jnp.asarray(mu0 + s * h)) for s in (1, -1))
    t_fd = time.perf_counter() - t
    fd = (float(fp.value) - float(fm.value)) / (2 * h)
    return {
        "system": "paper's stone (CeltParams.paper), period-1 branch of the 15.6 rad/s orbit, fold in omega_pi",
        "omega_fold_continuation": v,
        "omega_fold": float(bp.value),
        "status": int(bp.status),
        "fd_status": [int(fp.status), int(fm.status)],
        "newton_steps": int(bp.newton_steps),
        "residual": float(bp.residual),
        "test_function": float(bp.test),
        "multipliers_abs": [float(a) for a in np.abs(np.asarray(bp.multipliers))],
        "mu": mu0,
        "domega_fold_dmu_grad": g,
        "domega_fold_dmu_fd": fd,
        "fd_step": h,
        "relative_difference": abs(g - fd) / abs(fd),
        "seconds": {
            "locate_incl_compile": round(t_locate, 1),
            "grad_incl_compile": round(t_grad, 1),
            "two_fd_locates_incl_compile": round(t_fd, 1),
        },  # fmt: skip
        "load_average_start": load0,
        "load_average_end": list(os.getloadavg()),
        "versions": versions(),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=1e-4, help="central-difference step in mu")
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "docs/orbits/celt_fold_grad.json")
    a = ap.parse_args(argv)
    out = check(a.h)
    write_result(a.out, out, load_at_start=out["load_average_start"], indent=2)
    print(json.dumps({k: v for k, v in out.items() if k != "versions"}, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
