"""Complete elliptic integrals in pure JAX, differentiable in the axis ratio b.

JAX has no ``ellipk``/``ellipe``. For the contact ellipse the modulus is the eccentricity
e = sqrt(1 - b^2) and the complementary modulus is b itself, so the arithmetic-geometric
mean (AGM) starting from (1, b) gives K(e) = pi / (2 AGM(1, b)) and, with Gauss's sum of
the squared half-differences, E(e). A fixed number of AGM iterations (converges
quadratically once a ~ g; 14 reach machine precision for b >= 1e-6) keeps the function jit/vmap/grad
friendly. Conventions are scipy's with m = e^2: ``K(e) == scipy.special.ellipk(e**2)``.
"""

import jax.numpy as jnp

from jaxcelt._types import Array, ArrayLike, Float

_AGM_ITERS = 14


def ellipke(b: Float[ArrayLike, "..."]) -> tuple[Float[Array, "..."], Float[Array, "..."]]:
    """Return (K(e), E(e)) for modulus e = sqrt(1 - b^2), 0 < b <= 1 (MODEL.md section 2)."""
    b = jnp.asarray(b)
    a = jnp.ones_like(b)
    g = b
    e2 = 1.0 - b * b
    # E = K * (1 - sum_n 2^(n-1) c_n^2), c_0 = e, c_{n+1} = (a_n - g_n)/2.
    acc = 0.5 * e2
    power = 1.0
    for _ in range(_AGM_ITERS):
        c = 0.5 * (a - g)
        a, g = 0.5 * (a + g), jnp.sqrt(a * g)
        acc = acc + power * c * c
        power = power * 2.0
    K = jnp.pi / (2.0 * a)
    E = K * (1.0 - acc)
    return K, E


# Maclaurin coefficients of G(e) = (K - E)/e^2 = pi/2 * sum_{n>=1} c_n 2n/(2n-1) e^(2n-2),
# c_n = (binom(2n, n)/4^n)^2, used where e^2 is tiny and the closed form is 0/0.
_G_SERIES = (1 / 4 * 2, 9 / 64 * 4 / 3, 25 / 256 * 6 / 5, 1225 / 16384 * 8 / 7, 3969 / 65536 * 10 / 9)


def contact_integrals(b: Float[ArrayLike, "..."]) -> tuple[Array, Array, Array, Array]:
    """K, E, G = (K - E)/e^2 and H = (E + (e^2 - 1) K)/e^2 (paper's eq. 13; MODEL.md section 2).

    Uses a series for e^2 < 1e-3 so that b -> 1 (circular contact) stays finite with finite
    gradients; H = K - G identically.
    """
    b = jnp.asarray(b)
    K, E = ellipke(b)
    e2 = 1.0 - b * b
    small = e2 < 1e-3
    e2_safe = jnp.where(small, 1.0, e2)
    G_closed = (K - E) / e2_safe
    G_series = 0.0
    for i, c in enumerate(_G_SERIES):
        G_series = G_series + c * e2**i
    G_series = jnp.pi / 2 * G_series
    G = jnp.where(small, G_series, G_closed)
    return K, E, G, K - G
