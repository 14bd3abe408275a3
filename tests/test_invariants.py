"""Physical invariants along trajectories (MODEL.md section 10).

* mu = k_r = 0 on a fixed base: the contact force is normal (no work, no horizontal component,
  no moment about the vertical through C), so energy, horizontal momentum and (B omega) . n are
  conserved; the constraint v_A . n = 0 and the contact height hold.
* With friction on a fixed base the energy never increases (pointwise dE/dt <= 0 wherever the
  model is valid, N > 0; and along a trajectory).
* Static rest: N = m g, ydot = 0, and the stone stays at rest.

All solves share one compiled `simulate` (same ts length, float64); only values change.
"""

from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc

TS = jnp.linspace(0.0, 2.0, 201)
TH = np.radians(15.0)
N0 = (0.6 * np.sin(TH), 0.8 * np.sin(TH), np.cos(TH))  # tilted 15 deg, both rocking axes excited
OMEGA0 = (0.5, 1.0, 5.0)  # spin + rocking


@pytest.fixture(scope="module")
def conservative_run():
    p = jc.CeltParams.paper(mu=0.0, k_r=0.0, q_pi=0.0)
    y0 = jc.initial_state(p, omega=OMEGA0, n=N0, psi=0.3, position=(0.01, -0.02))
    sol = jc.simulate(p, y0, 2.0, ts=TS, rtol=1e-11, atol=1e-13)
    assert bool(sol.success) and bool(sol.valid), sol.summary()
    return p, sol, jc.diagnostics(sol.ts, sol.ys, p)


def test_conserved_energy(conservative_run):
    # Tolerance 1e-10 relative. Measured: 8.3e-12 over 2 s (3735 Tsit5 steps at rtol 1e-11).
    _, _, d = conservative_run
    E = np.asarray(d.energy)
    assert np.abs(E - E[0]).max() <= 1e-10 * abs(E[0])


def test_conserved_horizontal_momentum(conservative_run):
    # Relative to |P0| = 0.17 kg m/s (v_A = 0 but omega x rho gives C a horizontal velocity).
    # Measured: 1.1e-12 absolute = 6.6e-12 relative.
    _, _, d = conservative_run
    P = np.asarray(d.horizontal_momentum)
    assert np.linalg.norm(P[0]) > 0.1
    assert np.abs(P - P[0]).max() <= 1e-10 * np.linalg.norm(P[0])


def test_conserved_vertical_angular_momentum(conservative_run):
    # (B omega) . n about the vertical through C. Measured: 6.8e-12 relative.
    _, _, d = conservative_run
    S = np.asarray(d.spin_momentum)
    assert np.abs(S - S[0]).max() <= 1e-10 * abs(S[0])


def test_constraint_holds(conservative_run):
    # |v_A . n| <= 1e-10 m/s. Measured: 3.4e-11 m/s; contact height 3.3e-12 m; |n| - 1 4.4e-13.
    # The motion must be non-trivial for this to mean anything: tilt varies by degrees, N stays > 0.
    _, _, d = conservative_run
    assert np.abs(np.asarray(d.normal_velocity)).max() <= 1e-10
    assert np.abs(np.asarray(d.height_residual)).max() <= 1e-10
    assert np.abs(np.asarray(d.norm_residual)).max() <= 1e-10
    tilt = np.degrees(np.asarray(d.tilt))
    assert tilt.max() - tilt.min() > 5.0
    assert np.asarray(d.N).min() > 0


def test_energy_never_increases_along_trajectory():
    """Friction (paper mu, k_r) on a fixed base, spinning and tilted: E(t_{i+1}) <= E(t_i) + tol.

    tol = 1e-10 E0 covers the global error of the solve at rtol 1e-10 (the energy drop per
    saved interval is ~1e-4 J here, so the test still has teeth). Measured: every step
    decreases, the largest increment is -1.1e-5 J (E0 = 0.182 J, E(2 s) = 0.116 J).
    """
    p = jc.CeltParams.paper(q_pi=0.0)
    y0 = jc.initial_state(p, omega=OMEGA0, n=N0, psi=0.3)
    sol = jc.simulate(p, y0, 2.0, ts=TS, rtol=1e-10, atol=1e-12)
    assert bool(sol.success) and bool(sol.valid), sol.summary()
    E = np.asarray(jc.diagnostics(sol.ts, sol.ys, p).energy)
    assert np.all(np.diff(E) <= 1e-10 * E[0]), np.diff(E).max()
    assert E[-1] < 0.9 * E[0]  # friction does dissipate


@jax.jit
@partial(jax.vmap, in_axes=(None, 0, 0, 0, 0))
def _power_and_N(p, w, n, psi, vA):
    y = jc.initial_state(p, omega=w, n=n, psi=psi, v_A=vA)  # traced: n normalised, v_A projected
    P = jax.jvp(lambda z: jc.energy(z, p), (y,), (jc.vector_field(0.0, y, p),))[1]
    return P, jc.normal_force(0.0, y, p)


@pytest.mark.parametrize("derivative_exact", [0.0, 1.0])
def test_power_nonpositive_at_random_states(derivative_exact):
    """dE/dt = grad E . f(y) <= 0 at random valid states (N > 0) on a fixed base, both readings.

    Random tilts up to ~60 deg, spins from 0.01 to 10 rad/s, slips from 0 to 0.1 m/s. The power is
    computed exactly by jax.jvp. Tolerance 1e-12 W (rounding of the O(1e-3) J/s terms). Measured:
    max P = -9.4e-7 W over 732 valid states (the least dissipative are near rest).
    """
    p = jc.CeltParams.paper(q_pi=0.0, derivative_exact=derivative_exact)

    rng = np.random.default_rng(42)
    k = 750
    n = rng.normal(size=(k, 3)) * [0.5, 0.5, 0.1] + [0.0, 0.0, 1.0]
    w = rng.normal(size=(k, 3)) * rng.choice([0.01, 0.3, 3.0, 10.0], size=(k, 1))
    vA = rng.normal(size=(k, 3)) * rng.choice([0.0, 1e-4, 1e-2, 0.1], size=(k, 1))
    P, N = (np.asarray(x) for x in _power_and_N(p, w, n, rng.uniform(-3, 3, k), vA))
    count, worst = int(np.sum(N > 0)), P[N > 0].max()
    assert count > 650
    print(f"valid states {count}, max power {worst:.3g} W")
    assert worst <= 1e-12, worst


@pytest.mark.parametrize("psi,position", [(0.0, (0.0, 0.0)), (1.3, (0.2, -0.1))])
def test_static_rest(psi, position):
    """At rest on a fixed base: N = m g (to rounding), ydot = 0, and the solve stays at rest."""
    p = jc.CeltParams.paper(q_pi=0.0)
    y0 = jc.initial_state(p, psi=psi, position=position)
    mg = float(p.m * p.g)
    assert abs(float(jc.normal_force(0.0, y0, p)) - mg) <= 1e-14 * mg
    assert np.abs(np.asarray(jc.vector_field(0.0, y0, p))).max() <= 1e-15
    sol = jc.simulate(p, y0, 2.0, ts=TS)
    assert bool(sol.success)
    assert np.abs(np.asarray(sol.ys) - np.asarray(y0)).max() <= 1e-15
    d = jc.diagnostics(sol.ts, sol.ys, p)
    assert np.abs(np.asarray(d.N) - mg).max() <= 1e-14 * mg
    # r_O is a_3 above the contact point, which sits at `position`.
    np.testing.assert_allclose(np.asarray(d.r_O[-1]), [position[0], position[1], float(p.a3)], rtol=0, atol=1e-15)
