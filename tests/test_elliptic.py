"""Complete elliptic integrals (jaxcelt.physics.contact.elliptic) against scipy.special: values and b-derivatives."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import ellipe, ellipk, ellipkm1

import jaxcelt as jc

B_GRID = np.concatenate(
    [[1e-6, 1e-4, 1e-3, 0.01, 0.05], np.linspace(0.1, 0.95, 18), [0.99, 0.999, 0.9995, 0.99999, 1.0]]
)


def _G_quad(m):
    # G = (K - E)/m = int_0^{pi/2} sin^2 / sqrt(1 - m sin^2): no 0/0 cancellation as m -> 0.
    f = lambda th: np.sin(th) ** 2 / np.sqrt(1 - m * np.sin(th) ** 2)
    return quad(f, 0, np.pi / 2, epsabs=0, epsrel=2e-14, limit=200)[0]


def _scipy_KEGH(b):
    """Reference K, E, G, H. ellipkm1(b^2) = K(m = 1 - b^2) avoids the cancellation of 1 - b^2 at
    small b (scipy's ellipk(1 - 1e-12) is off by 7e-7 relative); G by quadrature avoids the 0/0
    of (K - E)/m as b -> 1 (the quadrature is used only for m <= 0.5, where it is smooth). H = (E + (m - 1) K)/m = K - G identically."""
    b = np.atleast_1d(np.asarray(b, float))
    m = 1.0 - b**2
    K, E = ellipkm1(b**2), ellipe(m)
    # closed form where it is well conditioned; quadrature where (K - E)/m cancels
    G = np.array([(k - e) / mi if mi > 0.5 else _G_quad(mi) for k, e, mi in zip(K, E, m)])
    return K, E, G, K - G


def test_model_md_values():
    # MODEL.md section 2 quotes 7 significant digits: K, E, G, H = 3.111402, 1.043046, 2.138654, 0.972749.
    K, E, G, H = (float(x) for x in jc.contact_integrals(0.1813))
    np.testing.assert_allclose([K, E, G, H], [3.111402, 1.043046, 2.138654, 0.972749], rtol=0, atol=6e-7)
    assert abs(K - ellipk(1 - 0.1813**2)) < 1e-14


def test_values_vs_scipy():
    # 14 AGM iterations reach machine precision for b >= 1e-6; the G series used for e^2 < 1e-3
    # is truncated after 5 terms (error ~ e^10 < 1e-15). Tolerance 1e-13 relative: a few hundred
    # ulps, the conditioning of (K - E)/e^2 just above the series switch (e^2 = 1e-3).
    K, E, G, H = (np.asarray(x) for x in jc.contact_integrals(jnp.asarray(B_GRID)))
    Ks, Es, Gs, Hs = _scipy_KEGH(B_GRID)
    for name, a, s in (("K", K, Ks), ("E", E, Es), ("G", G, Gs), ("H", H, Hs)):
        err = np.max(np.abs(a - s) / np.abs(s))
        assert err < 1e-13, (name, err)


def test_H_closed_form_matches_definition():
    b = 0.1813
    e2 = 1 - b**2
    K, E, G, H = (float(x) for x in jc.contact_integrals(b))
    assert abs(H - (E + (e2 - 1) * K) / e2) < 1e-14


@pytest.mark.parametrize("b", [0.05, 0.1813, 0.5, 0.9, 0.99, 0.9999, 1.0])
def test_derivatives_in_b(b):
    """d(K, E, G, H)/db: forward = reverse mode, and = the classical formulas / FD of scipy."""

    def f(bb):
        return jnp.stack(jc.contact_integrals(bb))

    jac = np.asarray(jax.jacfwd(f)(jnp.asarray(b)))
    rev = np.asarray(jax.jacrev(f)(jnp.asarray(b)))
    assert np.all(np.isfinite(jac))
    np.testing.assert_allclose(jac, rev, rtol=1e-12, atol=1e-14)
    if b == 1.0:
        # series at m = 0: dK/dm = pi/8, dE/dm = -pi/8, dG/dm = (pi/2)(3/16); dm/db = -2b = -2
        exact = np.array([-np.pi / 4, np.pi / 4, -3 * np.pi / 16, -np.pi / 4 + 3 * np.pi / 16])
        np.testing.assert_allclose(jac, exact, rtol=1e-12)
        return
    m = 1 - b * b
    if m > 1e-2:
        # dK/dm = (E - (1 - m) K) / (2 m (1 - m)), dE/dm = (E - K) / (2 m), dm/db = -2 b
        K, E = ellipk(m), ellipe(m)
        ref = np.array([(E - (1 - m) * K) / (2 * m * (1 - m)), (E - K) / (2 * m)]) * (-2 * b)
        np.testing.assert_allclose(jac[:2], ref, rtol=1e-11)
    h = 1e-4 * min(b, 1 - b)
    fd = (np.array(_scipy_KEGH(b + h)) - np.array(_scipy_KEGH(b - h)))[:, 0] / (2 * h)
    # central FD: truncation ~ h^2 f'''/6 and rounding ~ 1e-16 f/h, both below 1e-7 relative here.
    np.testing.assert_allclose(jac, fd, rtol=1e-7, atol=1e-9)
