"""Elementwise maths the right-hand side needs, where XLA's CPU defaults are slow.

`sincos`: float64 sine and cosine of one argument from one range reduction and two short
polynomials (Cephes' ``sin.c`` coefficients and its three-part Cody-Waite reduction by pi/4).
XLA's CPU backend lowers float64 ``sin``/``cos`` to scalar libm calls (~9.5 ns per element on
this project's CPU, ``benchmarks/bench_step_parts.py``) and its fusion pass repeats them in
every consumer kernel; this version is plain vectorisable arithmetic (~2.4 ns for both) and
accurate to 2 ulp for |x| < 1e5 (tests against numpy over 2e5 random arguments; the reduction
loses accuracy only beyond |x| ~ 1e9, far past any angle or phase a run reaches). Derivatives
are exact (custom JVP: d sin = cos dx, d cos = -sin dx). Other dtypes use ``jnp.sin``/``jnp.cos``.

`log`: float64 natural logarithm, fdlibm's ``e_log.c`` (exponent split by bit operations,
mantissa in [sqrt(1/2), sqrt(2)), a degree-14 polynomial in s = f / (2 + f)), < 1 ulp. XLA's CPU
backend lowers float64 ``log`` to one scalar libm call per element; the Pade laws take four per
evaluation, and in their ``wide_batch`` form (``vector_log=True``, what the lane pool's wide pools
run) they use this version, so that the right-hand side calls no libm function at all
(``benchmarks/roofline.py`` lists the calls left in the compiled code). Its polynomial is inlined
at every use, which lengthens XLA's compilation of many-stage programs. Special values as
``jnp.log``: log 0 = -inf, log of a negative number or NaN = NaN, log inf = inf; subnormal
arguments are scaled into range first where the backend keeps them (XLA's CPU backend flushes
them to zero, for ``jnp.log`` as here). Derivative d log = dx / x (custom JVP). ``log(x, normal=True)``
leaves out the special values and the subnormal scaling (five selects and five comparisons an element),
for arguments known to be positive normal numbers (the Pade laws' denominators).

`matvec3`, `cross3`: 3x3 matrix times 3-vector and the cross product as explicit multiply-adds.
Under ``jax.vmap`` a product of a lane-constant matrix (the inertia tensor B, its adjugate) with
a per-lane vector becomes an XLA ``dot``, which XLA's CPU backend runs as a library
matrix-vector kernel of its own (never fused): 11 such kernels per evaluation of the right-hand
side. Written out, the products fuse with their neighbours, and the vmapped right-hand side and
the lane pool's step run about a fifth faster (``benchmarks/bench_step_parts.py``). ``jnp.cross``
moves the vector axis to the end and back (transposes under vmap); `cross3` is component-wise.
Dot products of two per-lane vectors mostly stay ``jnp.dot``: XLA lowers them to a
multiply-reduce, which ends a kernel and so keeps shared terms from being recomputed in every
consumer; written out, those of the contact kinematics made the pool's step 1.6-3x slower. The
one exception measured to pay is the body-to-global rotation of the velocity (``Frame``).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._types import Array, ArrayLike

__all__ = ["cross3", "log", "matvec3", "sincos"]

# Cephes sin.c: sin(z) = z + z^3 P(z^2), cos(z) = 1 - z^2/2 + z^4 Q(z^2) on |z| <= pi/4.
_SIN = (
    1.58962301576546568060e-10,
    -2.50507477628578072866e-8,
    2.75573136213857245213e-6,
    -1.98412698295895385996e-4,
    8.33333333332211858878e-3,
    -1.66666666666666307295e-1,
)
_COS = (
    -1.13585365213876817300e-11,
    2.08757008419747316778e-9,
    -2.75573141792967388112e-7,
    2.48015872888517045348e-5,
    -1.38888888888730564116e-3,
    4.16666666666665929218e-2,
)
# pi/4 in three parts (the first two exact in few bits, so y * DP1, y * DP2 are exact)
_DP1, _DP2, _DP3 = 7.85398125648498535156e-1, 3.77489470793079817668e-8, 2.69515142907905952645e-15


def _horner(z: Array, coeffs: tuple[float, ...]) -> Array:
    r = jnp.full_like(z, coeffs[0])
    for a in coeffs[1:]:
        r = r * z + a
    return r


def _sincos_f64(x: Array) -> tuple[Array, Array]:
    ax = jnp.abs(x)
    y = jnp.floor(ax * (4 / np.pi))  # octant (inf and NaN stay so: z is NaN, so are sine and cosine)
    j = y.astype(jnp.int64)
    odd = j & 1
    j = j + odd  # round odd octants up: z in [-pi/4, pi/4]
    y = y + odd.astype(x.dtype)
    z = ((ax - y * _DP1) - y * _DP2) - y * _DP3
    zz = z * z
    ps = z + z * zz * _horner(zz, _SIN)
    pc = 1.0 - 0.5 * zz + zz * zz * _horner(zz, _COS)
    # j mod 8 in {0, 2, 4, 6} (quadrant 0..3), read from its bits: 2 swaps sine and cosine, 4 negates
    # the sine, and the cosine is negative in quadrants 1 and 2 (bit 4 of j + 2)
    swap = (j & 2) != 0
    s = jnp.where(swap, pc, ps)
    c = jnp.where(swap, ps, pc)
    s = jnp.where(((j & 4) != 0) != (x < 0), -s, s)
    c = jnp.where(((j + 2) & 4) != 0, -c, c)
    return s, c


@jax.custom_jvp
def _sincos64(x: Array) -> tuple[Array, Array]:
    return _sincos_f64(x)


@_sincos64.defjvp
def _sincos64_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    s, c = _sincos64(x)
    return (s, c), (c * dx, -s * dx)


def sincos(x: ArrayLike) -> tuple[Array, Array]:
    """(sin x, cos x), elementwise; fast vectorised float64 path (see the module docstring)."""
    x = jnp.asarray(x)
    if x.dtype == jnp.float64:
        return _sincos64(x)
    return jnp.sin(x), jnp.cos(x)


# fdlibm e_log.c: log(1 + f) = 2s + s R(s^2), s = f / (2 + f), |s| <= 0.1716
_LG = (
    6.666666666666735130e-01,
    3.999999999940941908e-01,
    2.857142874366239149e-01,
    2.222219843214978396e-01,
    1.818357216161805012e-01,
    1.531383769920937332e-01,
    1.479819860511658591e-01,
)
_LN2_HI, _LN2_LO = 6.93147180369123816490e-01, 1.90821492927058770002e-10
_SQRT_HALF_BITS = 0x3FE6A09E667F3BCD  # bits of sqrt(1/2): mantissas are mapped to [sqrt(1/2), sqrt(2))
_EXP_ONE = 0x3FF0000000000000
_TINY = 2.2250738585072014e-308  # smallest normal float64


def _log_f64(x: Array, special: bool = True) -> Array:
    if special:
        sub = x < _TINY
        xs = jnp.where(sub, x * 18014398509481984.0, x)  # 2**54: subnormals into the normal range
    else:
        xs = x
    bits = jax.lax.bitcast_convert_type(xs, jnp.int64) + (_EXP_ONE - _SQRT_HALF_BITS)
    k = (bits >> 52) - 1023
    if special:
        k = k - jnp.where(sub, 54, 0)
    m = jax.lax.bitcast_convert_type((bits & 0x000FFFFFFFFFFFFF) + _SQRT_HALF_BITS, jnp.float64)
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    r = z * (_LG[0] + w * (_LG[2] + w * (_LG[4] + w * _LG[6]))) + w * (_LG[1] + w * (_LG[3] + w * _LG[5]))
    hfsq = 0.5 * f * f
    dk = k.astype(jnp.float64)
    out = dk * _LN2_HI - ((hfsq - (s * (hfsq + r) + dk * _LN2_LO)) - f)
    if not special:
        return out
    # special values as jnp.log: 0 -> -inf, negative or NaN -> NaN, inf -> inf
    out = jnp.where(x == 0, -jnp.inf, out)
    out = jnp.where((x < 0) | jnp.isnan(x), jnp.nan, out)
    return jnp.where(x == jnp.inf, jnp.inf, out)


@jax.custom_jvp
def _log64(x: Array) -> Array:
    return _log_f64(x)


@_log64.defjvp
def _log64_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    return _log64(x), dx / x


@jax.custom_jvp
def _log64_normal(x: Array) -> Array:
    return _log_f64(x, special=False)


@_log64_normal.defjvp
def _log64_normal_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    return _log64_normal(x), dx / x


def log(x: ArrayLike, *, normal: bool = False) -> Array:
    """Natural logarithm, elementwise; fast vectorised float64 path (see the module docstring).

    ``normal=True``: for arguments known to be positive normal numbers (or NaN, which gives an
    unspecified value): no special-value or subnormal handling, a few operations fewer per element."""
    x = jnp.asarray(x)
    if x.dtype == jnp.float64:
        return _log64_normal(x) if normal else _log64(x)
    return jnp.log(x)


def matvec3(m: ArrayLike, x: Array) -> Array:
    """m @ x for a 3x3 matrix and a 3-vector, as multiply-adds (see the module docstring)."""
    m = jnp.asarray(m)
    return m[:, 0] * x[0] + m[:, 1] * x[1] + m[:, 2] * x[2]


def cross3(a: Array, b: Array) -> Array:
    """a x b for two 3-vectors, component-wise (see the module docstring)."""
    return jnp.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
