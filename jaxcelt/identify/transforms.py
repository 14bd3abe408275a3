"""Parameter transforms: the map from an unconstrained unknown z to a physical parameter value theta.

A fit optimises z, not theta. Each free parameter has a transform with ``forward(z, theta0) -> theta`` and its
``inverse(theta, theta0) -> z``, both differentiable, with z = 0 at the starting value theta0:

* `Positive`: theta = theta0 exp(z) (z is the log relative change; the default),
* `Bounded(lo, hi)`: a scaled logistic, lo < theta < hi,
* `Affine(scale)`: theta = theta0 + scale z, for signed parameters.

`DEFAULT_TRANSFORMS` names the transform of each parameter that is not `Positive`; `jaxcelt.identify.options.FitOptions`
``transforms`` overrides it per parameter.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp

from jaxcelt import _config  # noqa: F401

__all__ = ["Positive", "Bounded", "Affine", "DEFAULT_TRANSFORMS", "transform_of"]


class Positive(eqx.Module):
    """theta = theta0 exp(z): keeps theta > 0; z is the log relative change."""

    def forward(self, z, theta0):
        return theta0 * jnp.exp(z)

    def inverse(self, theta, theta0):
        return jnp.log(theta / theta0)


class Bounded(eqx.Module):
    """lo < theta < hi via theta = lo + (hi - lo) sigmoid(z + logit((theta0 - lo)/(hi - lo)))."""

    lo: float = eqx.field(static=True)
    hi: float = eqx.field(static=True)

    def _c(self, theta0):
        u = (theta0 - self.lo) / (self.hi - self.lo)
        return jnp.log(u / (1 - u))

    def forward(self, z, theta0):
        return self.lo + (self.hi - self.lo) * jax.nn.sigmoid(z + self._c(theta0))

    def inverse(self, theta, theta0):
        u = (theta - self.lo) / (self.hi - self.lo)
        return jnp.log(u / (1 - u)) - self._c(theta0)


class Affine(eqx.Module):
    """theta = theta0 + scale z (signed parameters such as B12 or k3); scale defaults to |theta0|
    (or 1 if theta0 = 0)."""

    scale: float | None = eqx.field(static=True, default=None)

    def _s(self, theta0):
        if self.scale is not None:
            return self.scale
        return jnp.where(theta0 == 0, 1.0, jnp.abs(theta0))

    def forward(self, z, theta0):
        return theta0 + self._s(theta0) * z

    def inverse(self, theta, theta0):
        return (theta - theta0) / self._s(theta0)


DEFAULT_TRANSFORMS: Mapping[str, Any] = MappingProxyType({
    "m_Ts": Bounded(0.0, 2.0),
    "m_Ms": Bounded(0.0, 2.0),
    "b": Bounded(0.0, 1.0),
    "B12": Affine(),
    "B13": Affine(),
    "B23": Affine(),
    "k1": Affine(),
    "k2": Affine(),
    "k3": Affine(),
})
"""Transform per parameter name; any other free parameter is `Positive`. The generalised Pade
exponents live in (0, 2] (0 < m <= 2), b in (0, 1]. Read-only."""


def transform_of(name: str, transforms: dict[str, Any] | None = None) -> Any:
    """The transform of parameter ``name``: from ``transforms``, else `DEFAULT_TRANSFORMS`, else `Positive`."""
    return (transforms or {}).get(name, DEFAULT_TRANSFORMS.get(name, Positive()))
