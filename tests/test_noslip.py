"""Rolling without slip: reduced equations vs an independent 9x9 linear solve, energy, Kane & Levinson reversal."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.integrate.noslip import noslip_contact_force, noslip_vector_field, simulate_noslip
from jaxcelt.physics.model import contact_geometry


def kl_params(**kw):
    # Kane & Levinson (1982): semi-axes 0.20, 0.03, 0.02 m, h = 0.01 m (C between O and the top,
    # k3 = +h), per-unit-mass inertia A, B, C and D = -2e-5 as the tensor entry (our B12 = +2e-5).
    return jc.CeltParams.paper(
        a1=0.2, a2=0.03, a3=0.02, m=1.0, B1=2e-4, B2=1.6e-3, B3=1.7e-3, B12=2e-5, k3=0.01, q_pi=0.0, **kw
    )


def test_reduced_equations_match_direct_linear_solve():
    # unknowns (v_dot, w_dot, F): Newton, Euler and the differentiated constraint, solved by numpy
    p = kl_params()
    w = np.array([0.3, -0.7, 2.0])
    n = np.array([0.1, -0.2, 1.0])
    n /= np.linalg.norm(n)
    z = jnp.concatenate([jnp.asarray(w), jnp.asarray(n), jnp.zeros(3), jnp.asarray([0.4])])
    g = contact_geometry(jnp.asarray(n), jnp.asarray(w), p)
    rho, rdot = np.asarray(g.rho), np.asarray(g.r_dot)
    Bm, m = np.asarray(p.B), 1.0
    v = -np.cross(w, rho)
    X = lambda a: np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    A = np.zeros((9, 9))
    rhs = np.zeros(9)
    A[0:3, 0:3], A[0:3, 6:9], rhs[0:3] = m * np.eye(3), -np.eye(3), -m * np.cross(w, v) - m * 9.81 * n
    A[3:6, 3:6], A[3:6, 6:9], rhs[3:6] = Bm, -X(rho), -np.cross(w, Bm @ w)
    A[6:9, 0:3], A[6:9, 3:6], rhs[6:9] = np.eye(3), -X(rho), -np.cross(w, rdot)
    sol = np.linalg.solve(A, rhs)
    np.testing.assert_allclose(np.asarray(noslip_vector_field(0.0, z, p))[0:3], sol[3:6], rtol=1e-10)
    np.testing.assert_allclose(np.asarray(noslip_contact_force(0.0, z, p).F), sol[6:9], rtol=1e-10)


def test_rest_gives_mg():
    p = kl_params()
    z = jnp.asarray([0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0.0])
    f = noslip_contact_force(0.0, z, p)
    assert abs(float(f.N) - 9.81) < 1e-12 and float(f.friction_ratio) < 1e-12
    assert np.max(np.abs(np.asarray(noslip_vector_field(0.0, z, p)))) < 1e-14


def test_energy_conserved_10s():
    # no dissipation: relative energy drift <= 1e-10 over 10 s (Tsit5 at rtol 1e-12)
    p = kl_params()
    y0 = jc.initial_state(p, omega=(0, 0, -5.0), n=np.array([0.01, 0.01, 1.0]) / np.sqrt(1.0002))
    ts = jnp.linspace(0, 10, 101)
    sol = simulate_noslip(p, y0, 10.0, ts=ts, rtol=1e-12, atol=1e-14)
    E = np.asarray(jax.vmap(jc.energy, in_axes=(0, None))(sol.ys, p))
    assert int(sol.status) == 0
    assert np.max(np.abs(E / E[0] - 1)) <= 1e-10
    # contact point at rest: v_A = v + w x rho = 0 along the solution
    vA = [np.asarray(y[0:3] + jnp.cross(y[3:6], contact_geometry(y[6:9], y[3:6], p).rho)) for y in sol.ys[::20]]
    assert np.max(np.abs(vA)) < 1e-14


@pytest.mark.slow
def test_kane_levinson_reversal_one_direction_only():
    # omega3(0) = -5 rad/s reverses (first at ~3 s); +5 rad/s does not within 20 s
    p = kl_params()
    ts = jnp.linspace(0, 20, 401)
    out = {}
    for w3 in (-5.0, 5.0):
        y0 = jc.initial_state(p, omega=(0, 0, w3), n=np.array([0.01, 0.01, 1.0]) / np.sqrt(1.0002))
        w = np.asarray(simulate_noslip(p, y0, 20.0, ts=ts, rtol=1e-10, atol=1e-12).ys[:, 5])
        out[w3] = np.any(np.sign(w) != np.sign(w3))
    assert out[-5.0] and not out[5.0]
