"""Symmetries of the model (MODEL.md section 10 "Mirror").

Derivation (used by `transform_state`). Take a body relabelling/reflection Q (body components
x' = Q x, Q = diag(+-1, +-1, +-1)) and a global reflection/rotation M with M e3 = e3 (the base and
gravity are preserved) and M e1 = e1 (the base still vibrates along +X1, so v_pi is unchanged),
with det(M) det(Q) = +1 so that the new body->global map R' = M R Q^T is a rotation. Then

* polar vectors in body components (v, n, rho):  v' = Q v
* the angular velocity is axial:                 omega' = det(M) Q omega
* global positions:                              r_C' = M r_C
* psi' is read off E1' = R'^T e1 = Q E1 with the construction of MODEL.md section 4
  (E1 . w = cos psi, E1 . u = -sin psi, u, w from n')
* parameters: B' = Q B Q^T (so B12 -> -B12 for any single-axis reflection), k' = Q k.

Cases:
* x2 -> -x2 mirror: Q = M = diag(1, -1, 1): omega' = (-w1, w2, -w3), n' = (n1, -n2, n3),
  v' = (v1, -v2, v3), r_C' = (X, -Y, Z), psi' = -psi. omega2 is unchanged -- the statement of
  MODEL.md section 10 -- and it holds with the vibrating base, at all times, not only at sections.
* x1 -> -x1 mirror: Q = diag(-1, 1, 1), M = diag(1, -1, 1): omega' = (w1, -w2, -w3), psi' = pi - psi.
  Here omega2 flips: the two mirrors differ by the relabelling below.
* relabelling by a half turn about x3: Q = diag(-1, -1, 1), M = I: the same stone described in
  rotated axes (B12 unchanged), omega' = (-w1, -w2, w3), psi' = psi + pi.
The contact law is equivariant under these maps (v_sy, omega_s, d_s flip under a mirror; T_sy and
M_s are odd in them), which is what these tests check numerically along whole trajectories.
"""

import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc

T1 = 2 * 2 * np.pi / 17.0  # two forcing periods at omega_pi = 17
TS = jnp.linspace(0.0, T1, 41)
# Tight tolerances: where the two solves take different step sequences (psi and r_C enter the
# step-size control), their difference is the global solver error (~4e-9 at rtol 1e-10).
RTOL = 1e-12
ATOL = 1e-14
TOL = 1e-10  # on every component; measured <= 8e-13


def _u_w(n):
    u = np.array([0.0, 1.0, 0.0]) - n[1] * n
    u /= np.sqrt(1.0 - n[1] ** 2)
    return u, np.cross(u, n)


def _E1(n, psi):
    u, w = _u_w(n)
    return np.cos(psi) * w - np.sin(psi) * u


def transform_state(y, Q, M):
    """Image of state y (13,) under body map Q and global map M (see the module docstring)."""
    y = np.asarray(y, dtype=float)
    Q, M = np.diag(Q).astype(float), np.diag(M).astype(float)
    v, w, n, rC, psi = y[0:3], y[3:6], y[6:9], y[9:12], y[12]
    n2 = Q @ n
    E1 = Q @ _E1(n, psi)
    u2, w2 = _u_w(n2)
    psi2 = np.arctan2(-(E1 @ u2), E1 @ w2)
    return np.concatenate([Q @ v, np.linalg.det(M) * (Q @ w), n2, M @ rC, [psi2]])


def transform_params(p, Q):
    Qm = np.diag(Q).astype(float)
    B = Qm @ np.asarray(p.B) @ Qm
    k = Qm @ np.asarray(p.k)
    return p.replace(B12=-B[0, 1], B13=-B[0, 2], B23=-B[1, 2], k1=k[0], k2=k[1], k3=k[2])


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def _run(p, y0):
    sol = jc.simulate(p, jnp.asarray(y0), T1, ts=TS, rtol=RTOL, atol=ATOL)
    assert bool(sol.success) and bool(sol.valid), sol.summary()
    return np.asarray(sol.ys)


# a rocking, spinning, slipping state, tilted about both body axes; the base vibrates (paper defaults)
ROCKING = dict(omega=(0.7, -1.5, 3.0), n=(0.15, -0.1, 0.9835), psi=0.4, v_A=(0.01, 0.02, 0.0), position=(0.01, 0.02))


def _y0(p):
    n = np.array(ROCKING["n"])
    n /= np.linalg.norm(n)
    vA = np.array(ROCKING["v_A"])
    return jc.initial_state(
        p, omega=ROCKING["omega"], n=n, psi=ROCKING["psi"], v_A=vA - (vA @ n) * n, position=ROCKING["position"]
    )


@pytest.fixture(scope="module")
def base_run():
    p = jc.CeltParams.paper()
    y0 = _y0(p)
    return p, y0, _run(p, y0)


CASES = {
    "mirror_x2": ((1, -1, 1), (1, -1, 1)),
    "mirror_x1": ((-1, 1, 1), (1, -1, 1)),
    "half_turn_x3": ((-1, -1, 1), (1, 1, 1)),
}


@pytest.mark.parametrize("case", list(CASES))
def test_mirror_and_relabelling(base_run, case):
    """Trajectory of the transformed problem = transform of the trajectory, vibrating base, 2 periods.

    Tolerance 1e-10 absolute on every component (states are O(0.01-10)); solves at rtol 1e-12.
    Measured: mirror_x2 1.1e-13, mirror_x1 and half_turn_x3 2.1e-13 (1.3e-11 at rtol 1e-10).
    """
    p, y0, ys = base_run
    Q, M = CASES[case]
    p2 = transform_params(p, Q)
    if case == "half_turn_x3":
        assert float(p2.B12) == float(p.B12)
    else:
        assert float(p2.B12) == -float(p.B12)
    y0_2 = transform_state(y0, Q, M)
    jc.check_state(y0_2, p2)  # the image of a manifold state is on the manifold
    ys2 = _run(p2, y0_2)
    expected = np.stack([transform_state(y, Q, M) for y in ys])
    err = np.abs(ys2 - expected)
    err[:, 12] = np.abs(_wrap(ys2[:, 12] - expected[:, 12]))
    assert err.max() <= TOL, (case, err.max(axis=0))
    # the motion is not trivially symmetric: the mirror image differs from the original
    assert np.abs(ys2[:, 3:6] - ys[:, 3:6]).max() > 0.1
    if case == "mirror_x2":
        # MODEL.md section 10: omega2 unchanged under B12 -> -B12 with mirrored initial conditions.
        np.testing.assert_allclose(ys2[:, 4], ys[:, 4], rtol=0, atol=TOL)


def test_mirror_x2_fig3_section():
    """MODEL.md section 10 as stated: omega2 at the section times t = k 2 pi / omega_pi unchanged,
    from rest (the mirror of rest is rest with psi = 0), B12 -> -B12. Tolerance 1e-10 rad/s."""
    p = jc.CeltParams.paper()
    p2 = transform_params(p, (1, -1, 1))
    y0 = jc.initial_state(p)
    ts = jnp.arange(41) * (T1 / 40)
    a = jc.simulate(p, y0, T1, ts=ts, rtol=RTOL, atol=ATOL)
    b = jc.simulate(p2, jc.initial_state(p2), T1, ts=ts, rtol=RTOL, atol=ATOL)
    wa, wb = np.asarray(a.ys[::20, 4]), np.asarray(b.ys[::20, 4])  # t = 0, T, 2T
    np.testing.assert_allclose(wb, wa, rtol=0, atol=TOL)
    assert abs(wa[-1]) > 0.01  # the base has set the stone rocking
    # and omega1, omega3 flip sign
    np.testing.assert_allclose(np.asarray(b.ys[:, [3, 5]]), -np.asarray(a.ys[:, [3, 5]]), rtol=0, atol=TOL)


@pytest.mark.parametrize("alpha", [0.7, -2.0, np.pi])
def test_heading_rotation_fixed_base(alpha):
    """Fixed base: psi0 -> psi0 + alpha (whole scene turned about the vertical) leaves omega, n and
    psi - alpha unchanged, and turns r_C by alpha. Tolerance 1e-10 (rtol 1e-12 solves whose step
    sequences differ). Measured: 8.1e-13 (omega, n, v), 3e-14 (psi), 5e-16 m (r_C)."""
    p = jc.CeltParams.paper(q_pi=0.0)
    y0 = _y0(p)
    ys = _run(p, y0)
    y0b = np.asarray(y0).copy()
    y0b[12] += alpha
    c, s = np.cos(alpha), np.sin(alpha)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    y0b[9:12] = Rz @ y0b[9:12]
    jc.check_state(y0b, p)
    ysb = _run(p, y0b)
    np.testing.assert_allclose(ysb[:, 0:9], ys[:, 0:9], rtol=0, atol=TOL)
    np.testing.assert_allclose(_wrap(ysb[:, 12] - alpha - ys[:, 12]), 0.0, rtol=0, atol=TOL)
    np.testing.assert_allclose(ysb[:, 9:12], ys[:, 9:12] @ Rz.T, rtol=0, atol=TOL)
    assert np.abs(ys[:, 12] - ys[0, 12]).max() > 0.05  # the stone does precess


def test_heading_half_turn_equals_base_sign_switch():
    """Vibrating base: turning the scene by pi reverses the base velocity in body axes, so
    (psi0 + pi, v_pi_sign = +1) equals (psi0, v_pi_sign = -1) in omega, n, v (reading switch A12). Measured 6.4e-13; tolerance 1e-10."""
    p = jc.CeltParams.paper()
    y0 = _y0(p)
    y0b = np.asarray(y0).copy()
    y0b[12] += np.pi
    y0b[9:11] *= -1
    a = _run(p.replace(v_pi_sign=-1.0), y0)
    b = _run(p, y0b)
    np.testing.assert_allclose(b[:, 0:9], a[:, 0:9], rtol=0, atol=TOL)
    c = _run(p, y0)
    assert np.abs(c[:, 3:6] - a[:, 3:6]).max() > 0.01  # and the sign does matter
