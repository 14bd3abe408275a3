"""Numerical configuration shared by every entry point.

jaxcelt works in float64 by default: the contact law is stiff while the stone sticks
(relaxation rate ~ 355/sqrt(eps) s^-1, MODEL.md section 10) and the bifurcation study
needs stroboscopic samples to 1e-10. Importing jaxcelt therefore turns on
``jax_enable_x64``. float32 stays available per call (``simulate(..., dtype=jnp.float32)``)
and is measured, not assumed, in the speed-vs-accuracy study.
"""

import jax

jax.config.update("jax_enable_x64", True)
