"""Gradients of trajectory losses w.r.t. contact parameters against finite differences (must-show 5).

Loss: sum of squares of omega and 100 (n1^2 + n2^2) at 8 save times over one forcing period
(omega_pi = 17, vibrating base), so every parameter acts through the whole trajectory.
Parameters theta = (mu, k_r, b_Ts, m_Ts). Solves at rtol 1e-12, atol 1e-14 (Tsit5).

Finite differences: central, relative step h = 1e-4 (dtheta_i = h theta_i). Truncation error
~ h^2 = 1e-8 relative; the solve error (~1e-12 relative, and it jumps when a parameter change
alters the adaptive step sequence) is amplified by 1/h to ~1e-8. Measured convergence:
h = 1e-3: worst 2.4e-5 (m_Ts; truncation), h = 1e-4: worst 1.5e-6, h = 1e-5: worst 2.2e-5
(b_Ts from rest, whose gradient is tiny, -3.6e-5: noise) -- h = 1e-4 sits at the minimum.

`jax.grad` here differentiates the discretised solve (diffrax RecursiveCheckpointAdjoint); at
rtol 1e-12 that equals the derivative of the exact flow to far below the 1e-5 bound.

Exact rest (omega = 0, v_A = 0, t0 = 0 where the base velocity is zero) is the case where
|omega_s|^p, sqrt(.) and 0/0 would give NaN gradients; it is one of the lanes.
"""

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc

NAMES = ("mu", "k_r", "b_Ts", "m_Ts")
P0 = jc.CeltParams.paper()
THETA0 = np.array([float(getattr(P0, k)) for k in NAMES])
T1 = 2 * np.pi / 17.0
TS = jnp.linspace(0.0, T1, 9)[1:]
H = 1e-4
GRAD_RTOL = 1e-5


def _loss(theta, y0):
    p = P0.replace(**{k: theta[i] for i, k in enumerate(NAMES)})
    sol = jc.simulate(p, y0, T1, ts=TS, rtol=1e-12, atol=1e-14, max_steps=8192)
    ys = sol.ys
    return jnp.sum(ys[:, 3:6] ** 2) + 100.0 * jnp.sum(ys[:, 6:8] ** 2)


_batched_value_and_grad = jax.jit(jax.vmap(jax.value_and_grad(_loss)))


def _loss_eager(theta, y0):
    # Not wrapped in an extra jit: `simulate`'s own compiled solve is reused for every FD point,
    # which is far cheaper to build than a second (vmapped) compilation of the loss.
    return float(_loss(jnp.asarray(theta), jnp.asarray(y0)))


def _y0_rest():
    return np.asarray(jc.initial_state(P0))


def _y0_rocking():
    n = np.array([0.15, -0.1, 0.9835])
    return np.asarray(jc.initial_state(P0, omega=(0.7, -1.5, 3.0), n=n / np.linalg.norm(n), psi=0.4))


def _fd(theta, y0):
    """Central differences of the loss in each parameter, relative step H."""
    out = np.empty(len(NAMES))
    for i in range(len(NAMES)):
        d = np.zeros(len(NAMES))
        d[i] = H * abs(theta[i])
        out[i] = (_loss_eager(theta + d, y0) - _loss_eager(theta - d, y0)) / (2 * d[i])
    return out


@pytest.fixture(scope="module")
def batch():
    """Lanes: (rest, paper), (rocking, paper), (rest, other parameter values)."""
    thetas = np.stack([THETA0, THETA0, THETA0 * np.array([1.3, 0.7, 1.2, 1.1])])
    y0s = np.stack([_y0_rest(), _y0_rocking(), _y0_rest()])
    vals, grads = _batched_value_and_grad(jnp.asarray(thetas), jnp.asarray(y0s))
    return thetas, y0s, np.asarray(vals), np.asarray(grads)


def test_vmap_of_grad_matches_finite_differences(batch):
    """Tolerance 1e-5 relative per component. Measured: worst 1.5e-6 (b_Ts from rest,
    where dL/db_Ts = -3.6e-5 is four orders below the other components); typical 1e-9..1e-7."""
    thetas, y0s, vals, grads = batch
    assert np.all(np.isfinite(vals)) and np.all(np.isfinite(grads))
    fd = np.stack([_fd(t, y) for t, y in zip(thetas, y0s)])
    rel = np.abs(grads - fd) / np.abs(fd)
    assert np.all(rel <= GRAD_RTOL), (rel, grads, fd)
    # every parameter matters in every lane (so the comparison has teeth)
    assert np.all(np.abs(grads) > 1e-6)


def test_gradient_from_exact_rest_is_finite():
    """Gradients of the right-hand side at exact rest (zero spin, zero slip, zero base speed) with
    respect to the state and every parameter are finite (the smoothed law is gradient-safe)."""
    p = jc.CeltParams.paper()
    y0 = jc.initial_state(p)
    w = jnp.asarray(np.random.default_rng(0).normal(size=13))

    @jax.jit
    def derivatives(y, pp):
        # d f/d y (13 x 13); d/d params of a scalar mixing all outputs with N and the energy
        jy = jax.jacfwd(jc.vector_field, argnums=1)(0.0, y, pp)
        scalar = lambda q: jnp.dot(w, jc.vector_field(0.0, y, q)) + jc.normal_force(0.0, y, q) + jc.energy(y, q)
        dN_dm = jax.grad(lambda q: jc.normal_force(0.0, y, q))(pp).m
        return jy, jax.grad(scalar)(pp), dN_dm

    jy, g, dN_dm = derivatives(y0, p)
    assert np.all(np.isfinite(np.asarray(jy)))
    for name in jc.PARAM_NAMES:
        assert np.all(np.isfinite(np.asarray(getattr(g, name)))), name
    # at rest N = m g, so dN/dm = g exactly
    assert abs(float(dN_dm) - float(p.g)) < 1e-12


@pytest.mark.slow
def test_plain_grad_equals_vmapped_lane(batch):
    """The unbatched jax.grad gives the same numbers as the vmapped lane (1e-10 relative to the gradient).

    vmap reorders floating-point operations, so each component carries round-off of the order of the
    largest component: components ~1e6 times smaller than the largest (measured: 1.65e-5 next to 15.1)
    can differ by 4.5e-10 relative (7e-15 absolute). Tolerance: 1e-10 of the gradient's max norm.
    """
    thetas, y0s, _, grads = batch
    for i in range(2):
        g = np.asarray(jax.jit(jax.grad(_loss))(jnp.asarray(thetas[i]), jnp.asarray(y0s[i])))
        np.testing.assert_allclose(g, grads[i], rtol=1e-10, atol=1e-10 * np.max(np.abs(grads[i])))


@pytest.mark.slow
def test_grad_with_implicit_solver():
    """Reverse mode through an implicit solver (Kvaerno5) from rest: finite, and agrees with Tsit5's
    gradient to 1e-5 relative (both at rtol 1e-10)."""

    def loss(theta, solver):
        p = P0.replace(mu=theta[0], k_r=theta[1])
        sol = jc.simulate(p, jc.initial_state(p), T1 / 2, ts=TS[:4] / 2, solver=solver, rtol=1e-10, atol=1e-12)
        return jnp.sum(sol.ys[:, 3:6] ** 2)

    th = jnp.asarray(THETA0[:2])
    g_imp = np.asarray(jax.grad(loss)(th, diffrax.Kvaerno5()))
    g_exp = np.asarray(jax.grad(loss)(th, diffrax.Tsit5()))
    assert np.all(np.isfinite(g_imp))
    np.testing.assert_allclose(g_imp, g_exp, rtol=1e-5)


def test_grad_wrt_one_traced_leaf_under_jit(paper_params):
    # only mu traced (params rebuilt inside the jitted function): state checks must not try
    # to concretise the traced leaf (found by the stability study, part d)
    y0 = jc.initial_state(paper_params)

    @jax.jit
    def loss(mu):
        sol = jc.simulate(paper_params.replace(mu=mu), y0, 0.05, ts=jnp.linspace(0.01, 0.05, 5))
        return jnp.sum(sol.ys[:, 3:6] ** 2)

    g = jax.grad(loss)(paper_params.mu)
    assert np.isfinite(g)


def test_unmonitored_forward_mode_solve_matches_the_monitored_one():
    """``monitor=False`` (the fit's solves) drops the validity monitor and nothing else: the same trajectory,
    status and forward-mode tangents as the monitored solve. Two different compiled programs: they may round
    differently, and a rounding can flip one step's acceptance, so they are compared to the solve's accuracy
    (rtol 1e-8: 1e-7 of the largest state, 1e-6 of the largest tangent) rather than bitwise."""
    y0 = jnp.asarray(_y0_rocking())

    def ys(theta, monitor):
        p = P0.replace(**{k: theta[i] for i, k in enumerate(NAMES)})
        sol = jc.simulate(p, y0, T1, ts=TS, adjoint=diffrax.ForwardMode(), monitor=monitor)
        return sol.ys, sol

    (J0, s0), (J1, s1) = (
        jax.jacfwd(lambda th, m=m: ys(th, m), has_aux=True)(jnp.asarray(THETA0)) for m in (True, False)
    )
    y_0, y_1 = s0.ys, s1.ys
    assert s1.validity is None and int(s0.validity.first_invalid_kind) == 0
    assert int(s1.status) == int(s0.status) == 0
    scale = np.max(np.abs(np.asarray(y_0)))
    assert np.max(np.abs(np.asarray(y_1) - np.asarray(y_0))) <= 1e-7 * scale
    jscale = np.max(np.abs(np.asarray(J0)))
    assert np.max(np.abs(np.asarray(J1) - np.asarray(J0))) <= 1e-6 * jscale
    with pytest.raises(ValueError, match="validity"):
        _ = s1.valid
    assert "not monitored" in s1.summary()
