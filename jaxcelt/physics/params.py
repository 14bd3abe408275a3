"""Parameters of the stone, the contact and the base forcing (MODEL.md section 2).

`CeltParams` is an `equinox.Module` whose leaves are float arrays, so one object can be
vmapped (a batch of parameter sets is the same class with a leading axis on its leaves)
and differentiated (``jax.grad`` with respect to any field). Everything is SI.

Field names follow the paper where it has a symbol. Geometry/inertia names chosen here:

=============  ===============================================================
``a1,a2,a3``   semi-axes of the ellipsoid along body x1, x2, x3 [m]
``m``          mass [kg]
``B1,B2,B3``   moments of inertia about C along x1, x2, x3 [kg m^2]
``B12,B13,B23`` products of inertia; the tensor holds -B12 etc. (MODEL.md section 9 A5)
``k1,k2,k3``   k = O->C in body components [m]; k3 < 0: C below the centre O
``g``          gravitational acceleration [m/s^2]
=============  ===============================================================

Reading switches (MODEL.md section 9): ``v_pi_sign`` (s_pi = +1 or -1, eq. 17) and
``derivative_exact`` (0/False: eq. 13 as printed; 1/True: the variant that has the exact
derivative with respect to the spin). Both are float leaves (0./1. and +-1.), so a sweep
can vmap over readings; the constructor accepts bools.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401  (float64 on)
from jaxcelt._types import Array, Mat3

__all__ = ["CeltParams", "PARAM_NAMES", "inertia_tensor"]


def _f(x: Any) -> Array:
    return jnp.asarray(x, dtype=float) if not isinstance(x, jax.Array) else x


def _field(**kw):
    return eqx.field(converter=_f, **kw)


def _concrete(x) -> np.ndarray | None:
    """Return a numpy view of x, or None if x is traced (checks then happen elsewhere)."""
    if isinstance(x, jax.core.Tracer):
        return None
    try:
        return np.asarray(x, dtype=float)
    except Exception:  # pragma: no cover - non-numeric leaves are rejected by the converter
        return None


class CeltParams(eqx.Module):
    """All numbers of the wobblestone model; see the module docstring for the names.

    Build with `CeltParams.paper(**overrides)` for section 3 of the paper, or
    ``params.replace(mu=0.3)`` for a modified copy. Both validate: every value is finite,
    ``m > 0``, semi-axes ``> 0``, the inertia tensor symmetric positive definite and
    physically realisable, ``0 < b <= 1``, ``mu, k_r >= 0``, smoothing ``eps, eps_R > 0``,
    and so on; a bad value raises ``ValueError`` naming the parameter.
    """

    # geometry and mass
    a1: Array = _field()
    a2: Array = _field()
    a3: Array = _field()
    m: Array = _field()
    B1: Array = _field()
    B2: Array = _field()
    B3: Array = _field()
    B12: Array = _field()
    B13: Array = _field()
    B23: Array = _field()
    k1: Array = _field()
    k2: Array = _field()
    k3: Array = _field()
    g: Array = _field()
    # contact patch and contact law (eqs. 9-15)
    a_hat: Array = _field()
    b: Array = _field()
    mu: Array = _field()
    k_r: Array = _field()
    b_r: Array = _field()
    S0: Array = _field()
    S2: Array = _field()
    S3: Array = _field()
    b_Ts: Array = _field()
    b_Ms: Array = _field()
    m_Ts: Array = _field()
    m_Ms: Array = _field()
    eps: Array = _field()
    eps_R: Array = _field()
    # base forcing (eq. 17) and constraint stabilisation
    q_pi: Array = _field()
    omega_pi: Array = _field()
    kappa: Array = _field()
    # reading switches (MODEL.md section 9)
    v_pi_sign: Array = _field()
    derivative_exact: Array = _field()

    @classmethod
    def paper(cls, **overrides) -> CeltParams:
        """Section 3 of Awrejcewicz & Kudra (2014) in SI units, with ``overrides`` applied.

        eps = eps_R = 1e-4 s^-2 and omega_pi = 17 rad/s are not in the paper's parameter list
        (MODEL.md section 9 A16); they are the documented defaults.
        """
        values = dict(
            a1=0.110, a2=0.025, a3=0.025, m=0.5436,
            B1=2.463e-4, B2=1.3589e-3, B3=1.3747e-3, B12=1.728e-4, B13=0.0, B23=0.0,
            k1=0.0, k2=0.0, k3=-4.29e-3, g=9.81,
            a_hat=6.192e-3, b=0.1813, mu=0.2241, k_r=0.4345, b_r=1.196,
            S0=0.1498, S2=0.1121, S3=0.0589,
            b_Ts=0.5305, b_Ms=0.2476, m_Ts=0.8161, m_Ms=0.5366,
            eps=1e-4, eps_R=1e-4,
            q_pi=0.04, omega_pi=17.0, kappa=0.0,
            v_pi_sign=1.0, derivative_exact=0.0,
        )  # fmt: skip
        unknown = set(overrides) - set(values)
        if unknown:
            raise ValueError(f"unknown parameter name(s) {sorted(unknown)}; known: {sorted(values)}")
        values.update(overrides)
        return cls(**values)

    def replace(self, **changes) -> CeltParams:
        """A validated copy with some fields changed."""
        unknown = set(changes) - set(PARAM_NAMES)
        if unknown:
            raise ValueError(f"unknown parameter name(s) {sorted(unknown)}")
        return dataclasses.replace(self, **changes)

    def __check_init__(self):
        _validate(self)

    @property
    def B(self) -> Mat3:
        """Inertia tensor about C in body axes, off-diagonals -B12, -B13, -B23."""
        return inertia_tensor(self)

    @property
    def k(self) -> Array:
        """k = O -> C in body components [m]."""
        return jnp.stack([self.k1, self.k2, self.k3], axis=-1)

    @property
    def semi_axes(self) -> Array:
        return jnp.stack([self.a1, self.a2, self.a3], axis=-1)

    def as_dict(self) -> dict[str, float | list]:
        """Plain-python view (for dataset attributes and JSON)."""
        return {k: np.asarray(getattr(self, k)).tolist() for k in PARAM_NAMES}


PARAM_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(CeltParams))


def inertia_tensor(p: CeltParams) -> Mat3:
    """B = [[B1, -B12, -B13], [-B12, B2, -B23], [-B13, -B23, B3]] (MODEL.md section 8)."""
    return jnp.stack(
        [
            jnp.stack([p.B1, -p.B12, -p.B13], -1),
            jnp.stack([-p.B12, p.B2, -p.B23], -1),
            jnp.stack([-p.B13, -p.B23, p.B3], -1),
        ],
        -2,
    )


_POSITIVE = ("a1", "a2", "a3", "m", "g", "a_hat", "eps", "eps_R", "b_r", "b_Ts", "b_Ms", "m_Ts", "m_Ms", "S0")
_NONNEGATIVE = ("mu", "k_r", "q_pi", "omega_pi", "kappa", "S2", "S3")


def _validate(p: CeltParams) -> None:
    vals = {}
    for name in PARAM_NAMES:
        v = _concrete(getattr(p, name))
        if v is None:
            return  # traced: values are checked where they are concrete
        if not np.all(np.isfinite(v)):
            raise ValueError(f"parameter {name!r} must be finite, got {v}")
        vals[name] = v
    for name in _POSITIVE:
        if np.any(vals[name] <= 0):
            raise ValueError(f"parameter {name!r} must be > 0, got {vals[name]}")
    for name in _NONNEGATIVE:
        if np.any(vals[name] < 0):
            raise ValueError(f"parameter {name!r} must be >= 0, got {vals[name]}")
    if np.any(vals["b"] <= 0) or np.any(vals["b"] > 1):
        raise ValueError(f"parameter 'b' (contact-ellipse axis ratio) must lie in (0, 1], got {vals['b']}")
    for name in ("m_Ts", "m_Ms"):
        if np.any(vals[name] > 2):
            raise ValueError(f"parameter {name!r} must lie in (0, 2], got {vals[name]}")
    if not np.all(np.isin(vals["v_pi_sign"], (-1.0, 1.0))):
        raise ValueError(f"parameter 'v_pi_sign' must be +1 or -1, got {vals['v_pi_sign']}")
    if not np.all(np.isin(vals["derivative_exact"], (0.0, 1.0))):
        raise ValueError(f"parameter 'derivative_exact' must be False/True (0 or 1), got {vals['derivative_exact']}")
    # `inertia_tensor` in numpy (eager jnp would compile a program per operation)
    B1, B2, B3, B12, B13, B23 = np.broadcast_arrays(*(vals[k] for k in ("B1", "B2", "B3", "B12", "B13", "B23")))
    B = np.stack([np.stack([B1, -B12, -B13], -1), np.stack([-B12, B2, -B23], -1), np.stack([-B13, -B23, B3], -1)], -2)
    eig = np.linalg.eigvalsh(B)
    if np.any(eig <= 0):
        raise ValueError(f"inertia tensor 'B' (B1, B2, B3, B12, B13, B23) must be positive definite; eigenvalues {eig}")
    # Principal moments of a real body satisfy the triangle inequality I_i <= I_j + I_k.
    s = eig.sum(-1, keepdims=True)
    if np.any(2 * eig > s * (1 + 1e-12)):
        raise ValueError(f"inertia tensor 'B' violates the triangle inequality of a real body; principal moments {eig}")
    k = np.stack([vals["k1"], vals["k2"], vals["k3"]], -1)
    ax = np.stack([vals["a1"], vals["a2"], vals["a3"]], -1)
    if np.any(np.sum((k / ax) ** 2, -1) >= 1):
        raise ValueError(f"mass centre 'k' = {k} must lie inside the ellipsoid with semi-axes {ax}")
