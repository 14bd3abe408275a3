"""Check the Lyapunov spectrum (`jaxcelt.lyapunov_spectrum`, `jaxcelt.integrate.spectrum.lyapunov_spectrum`).

* Lorenz (sigma = 10, rho = 28, beta = 8/3): the 3 exponents over t = 1000 after a transient of 20,
  re-orthonormalised every time unit, against the reference values (0.9056, 0, -14.5723) (Sprott 2003);
  their sum against the trace -(sigma + 1 + beta).
* The wobblestone's stable period-1 orbit at omega_pi = 15.6 rad/s (paper parameters; reached from rest at
  psi0 = 157.5 deg after 300 periods and refined by `jaxcelt.periodic_orbit`, as scripts/orbit_check.py): the 8
  exponents from a start on the orbit against log|mu_i| / T of its Floquet multipliers, and the sum of all 13
  (8 physical + the 5 exact trivial ones) against the time average of the divergence of the vector field over
  one period (integrated with the orbit).

Each computation is timed twice: the first call (compilation included) and a second, compiled one. Writes
docs/orbits/lyapunov_spectrum.json.

    python scripts/lyapunov_spectrum_check.py [--out docs/orbits/lyapunov_spectrum.json] [--periods 400]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

import jaxcelt as jc
from jaxcelt.integrate.spectrum import lyapunov_spectrum
from jaxcelt.provenance import load_average, write_result

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

LORENZ = dict(sigma=10.0, rho=28.0, beta=8.0 / 3.0)
LORENZ_REFERENCE = (0.9056, 0.0, -14.5723)  # Sprott, Chaos and Time-Series Analysis (2003)
LORENZ_T, LORENZ_TRANSIENT, LORENZ_DT = 1000, 20, 1.0
OMEGA, TRANSIENT_PERIODS = 15.6, 20
RTOL, ATOL = 1e-10, 1e-10


def lorenz(t, y, a):
    s, r, b = a
    return jnp.stack([s * (y[1] - y[0]), y[0] * (r - y[2]) - y[1], y[0] * y[1] - b * y[2]])


def _timed(f, *args):
    t = time.perf_counter()
    first = jax.block_until_ready(f(*args))
    t_first = time.perf_counter() - t
    t = time.perf_counter()
    out = jax.block_until_ready(f(*args))
    return out, first, t_first, time.perf_counter() - t


def lorenz_spectrum(t_total: int = LORENZ_T) -> dict:
    a = (LORENZ["sigma"], LORENZ["rho"], LORENZ["beta"])

    @jax.jit
    def run(y0):
        return lyapunov_spectrum(
            lorenz,
            y0,
            a,
            segment=LORENZ_DT,
            n_segments=int(t_total / LORENZ_DT),
            n_transient_segments=int(LORENZ_TRANSIENT / LORENZ_DT),
            rtol=RTOL,
            atol=ATOL,
        )

    r, _, t_first, t_run = _timed(run, jnp.array([1.0, 1.0, 1.0]))
    lam = np.asarray(r.exponents)
    trace = -(a[0] + 1 + a[2])
    ref = np.asarray(LORENZ_REFERENCE)
    return dict(
        params=LORENZ,
        time=float(r.time),
        transient=LORENZ_TRANSIENT,
        reorth_interval=LORENZ_DT,
        n_reorth=int(r.n_reorth),
        rtol=RTOL,
        atol=ATOL,
        exponents=lam.tolist(),
        stderr=np.asarray(r.stderr).tolist(),
        reference=ref.tolist(),
        rel_diff_lambda1=float(abs(lam[0] - ref[0]) / ref[0]),
        rel_diff_lambda3=float(abs(lam[2] - ref[2]) / abs(ref[2])),
        sum=float(lam.sum()),
        trace=trace,
        sum_minus_trace=float(lam.sum() - trace),
        status=int(r.status),
        solver_steps=int(r.num_steps),
        seconds=dict(first_call_incl_compile=t_first, compiled=t_run),
    )


def mean_divergence(params, y0, t0, T):
    """(1/T) times the integral of div f = trace(df/dy) along the solution from y0 over [t0, t0 + T] (Dopri8)."""
    f = jc.vector_field

    def aug(t, z, p):
        y = z[:13]
        return jnp.concatenate([f(t, y, p), jnp.trace(jax.jacfwd(lambda yy: f(t, yy, p))(y))[None]])

    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(aug),
        diffrax.Dopri8(),
        t0,
        t0 + T,
        None,
        jnp.concatenate([jnp.asarray(y0), jnp.zeros(1)]),
        params,
        stepsize_controller=diffrax.PIDController(rtol=1e-11, atol=1e-12),
        max_steps=200_000,
    )
    return float(sol.ys[-1, 13]) / T


def orbit_spectrum(periods: int = 400) -> dict:
    import orbit_check  # the same start as scripts/orbit_check.py

    p = jc.CeltParams.paper(omega_pi=OMEGA)
    yg, t0 = orbit_check.guess(p)
    orb = jax.block_until_ready(jc.periodic_orbit(p, yg, t0=t0))
    T = float(orb.period)
    floquet = np.log(np.abs(np.asarray(orb.multipliers))) / T

    def run(y):
        return jc.lyapunov_spectrum(
            p, y, periods=periods, transient_periods=TRANSIENT_PERIODS, t0=t0, rtol=RTOL, atol=RTOL * 1e-2
        )

    r, _, t_first, t_run = _timed(run, orb.y)
    lam = np.asarray(r.exponents)
    div = mean_divergence(p, orb.y, t0, T)
    pairs = [(0, 1), (2, 3), (4, 5)]  # complex pairs of the orbit (multipliers come sorted by modulus)
    return dict(
        omega_pi=OMEGA,
        psi0_deg=orbit_check.PSI0_DEG,
        orbit_status=int(orb.status),
        orbit_residual=float(orb.residual),
        period_s=T,
        multipliers_abs=np.abs(np.asarray(orb.multipliers)).tolist(),
        multipliers_im=np.asarray(orb.multipliers).imag.tolist(),
        floquet_exponents=floquet.tolist(),
        transient_periods=TRANSIENT_PERIODS,
        periods=periods,
        time=float(r.time),
        n_reorth=int(r.n_reorth),
        rtol=RTOL,
        atol=RTOL * 1e-2,
        exponents=lam.tolist(),
        stderr=np.asarray(r.stderr).tolist(),
        trivial=np.asarray(r.trivial).tolist(),
        abs_diff=(lam - floquet).tolist(),
        max_abs_diff=float(np.max(np.abs(lam - floquet))),
        max_abs_diff_times_time=float(np.max(np.abs(lam - floquet)) * float(r.time)),
        pair_sum_abs_diff=[float(lam[i] + lam[j] - floquet[i] - floquet[j]) for i, j in pairs],
        real_abs_diff=[float(lam[i] - floquet[i]) for i in (6, 7)],
        sum_physical=float(lam.sum()),
        sum_floquet=float(floquet.sum()),
        sum_all_13=float(lam.sum() + np.asarray(r.trivial).sum()),
        mean_divergence=div,
        sum_all_13_minus_divergence=float(lam.sum() + np.asarray(r.trivial).sum() - div),
        status=int(r.status),
        solver_steps=int(r.num_steps),
        seconds=dict(first_call_incl_compile=t_first, compiled=t_run),
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "orbits" / "lyapunov_spectrum.json"))
    ap.add_argument("--periods", type=int, default=400)
    a = ap.parse_args(argv)
    load = load_average()
    out = dict(lorenz=lorenz_spectrum(), orbit_15_6=orbit_spectrum(a.periods), jax_backend=jax.default_backend())
    write_result(a.out, out, load_at_start=load)
    for k in ("lorenz", "orbit_15_6"):
        r = out[k]
        print(k, "exponents", np.round(r["exponents"], 5), "seconds", r["seconds"])
    print("orbit floquet", np.round(out["orbit_15_6"]["floquet_exponents"], 5))
    print("sum_all_13 - mean divergence", out["orbit_15_6"]["sum_all_13_minus_divergence"])


if __name__ == "__main__":
    main()
