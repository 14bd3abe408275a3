"""Check `jaxcelt.periodic_orbit` on the wobblestone's period-1 orbit at omega_pi = 15.6 rad/s.

The stone starts at rest with psi0 = 157.5 deg (paper parameters, eps = eps_R = 1e-4) and runs
300 forcing periods; the section point is the Newton guess. The orbit's 8 Floquet multipliers
are compared with a central-difference monodromy of the independent numpy/scipy model
(tests/reference_numpy.py, DOP853 at rtol 1e-12; tests/orbit_fd_reference.py), and
log|mu_max| / T with `jaxcelt.celt_lyapunov` started on the orbit. Writes
docs/orbits/orbit_check.json (timings are indicative: load average recorded).

    python scripts/orbit_check.py [--out docs/orbits/orbit_check.json] [--periods 1000]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import linear_sum_assignment

import jaxcelt as jc
from jaxcelt.provenance import load_average, write_result

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the independent reference model lives with the tests

OMEGA, PSI0_DEG, TRANSIENT = 15.6, 157.5, 300


def guess(p, transient=TRANSIENT):
    """Section state after ``transient`` periods from rest at psi0 (Dopri8, rtol 1e-10)."""
    T = 2 * np.pi / float(p.omega_pi)
    y0 = jc.initial_state(p, psi=np.radians(PSI0_DEG))
    sol = jc.simulate(
        p,
        y0,
        transient * T,
        ts=jnp.array([transient * T]),
        rtol=1e-10,
        atol=1e-12,
        solver=diffrax.Dopri8(),
        exact_ts=True,
    )
    assert bool(sol.success), sol.summary()
    return np.asarray(sol.ys[-1]), transient * T


def match(mu, nu):
    """max |mu_i - nu_pi(i)| over the best one-to-one pairing."""
    cost = np.abs(mu[:, None] - nu[None, :])
    r, c = linear_sum_assignment(cost)
    return float(cost[r, c].max())


def check(periods: int = 1000, transient_lyap: int = 30) -> dict:
    import orbit_fd_reference as fd
    import reference_numpy as ref

    p = jc.CeltParams.paper(omega_pi=OMEGA)
    T = 2 * np.pi / OMEGA
    yg, t0 = guess(p)
    t = time.perf_counter()
    orb = jax.block_until_ready(jc.periodic_orbit(p, yg, t0=t0))
    t_first = time.perf_counter() - t
    t = time.perf_counter()
    orb = jax.block_until_ready(jc.periodic_orbit(p, yg, t0=t0))
    t_solve = time.perf_counter() - t
    mu = np.asarray(orb.multipliers)

    t = time.perf_counter()
    M_fd, defect = fd.fd_monodromy(np.asarray(orb.y), t0, T, ref.paper_params(omega_pi=OMEGA))
    t_fd = time.perf_counter() - t
    mu_fd = np.linalg.eigvals(M_fd)

    t = time.perf_counter()
    lyap = jc.celt_lyapunov(p, orb.y, periods=periods, transient_periods=transient_lyap, t0=t0, rtol=1e-10, atol=1e-12,
                           error_control="all", tangent="jvp")  # as its result file
    lam = float(lyap.exponent)
    t_lyap = time.perf_counter() - t
    lam_orbit = float(orb.floquet_exponent)
    return dict(
        omega_pi=OMEGA,
        psi0_deg=PSI0_DEG,
        eps=float(p.eps),
        transient_periods=TRANSIENT,
        t0=t0,
        status=int(orb.status),
        newton_steps=int(orb.newton_steps),
        residual=float(orb.residual),
        y=np.asarray(orb.y).tolist(),
        guess_distance=float(np.max(np.abs(np.asarray(orb.y) - yg))),
        multipliers_re=mu.real.tolist(),
        multipliers_im=mu.imag.tolist(),
        multipliers_abs=np.abs(mu).tolist(),
        trivial_multipliers_abs=np.abs(np.asarray(orb.trivial_multipliers)).tolist(),
        stable=bool(orb.stable),
        drift_m=np.asarray(orb.drift).tolist(),
        psi_turns=int(orb.psi_turns),
        reference_fd_defect=float(np.max(np.abs(defect))),
        reference_fd_multipliers_abs=np.sort(np.abs(mu_fd))[::-1].tolist(),
        multiplier_max_abs_diff_vs_scipy_fd=match(mu, mu_fd),
        floquet_exponent=lam_orbit,
        lyapunov_periods=periods,
        lyapunov_lambda1=lam,
        lyapunov_rel_diff=abs(lam - lam_orbit) / abs(lam_orbit),
        seconds=dict(first_call_incl_compile=t_first, newton_solve=t_solve, scipy_fd_monodromy=t_fd, lyapunov=t_lyap),
        load_average=os.getloadavg()[0],
        jax_backend=jax.default_backend(),
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "orbits" / "orbit_check.json"))
    ap.add_argument("--periods", type=int, default=1000, help="periods of the Lyapunov average")
    a = ap.parse_args(argv)
    load0 = load_average()
    r = check(a.periods)
    write_result(a.out, r, load_at_start=load0)
    print(json.dumps({k: v for k, v in r.items() if k != "y"}, indent=1))


if __name__ == "__main__":
    main()
