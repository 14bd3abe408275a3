"""Chaos diagnostics of identification: why long records need multiple shooting.

The sensitivity of a record's loss to the unknowns grows like e^{lambda T} over a record of length T (lambda: the
largest Lyapunov exponent). `finite_time_lyapunov` estimates lambda along a trajectory; `gradient_norm_vs_window`
measures the gradient of a single-shooting loss against the window length, to compare with e^{lambda T}.
"""

from __future__ import annotations

from collections.abc import Sequence

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import State
from jaxcelt.identify.observe import OBSERVABLES
from jaxcelt.identify.options import FitOptions
from jaxcelt.identify.problem import STATE_SCALE, build_problem, value_and_jacobian
from jaxcelt.identify.records import MeasuredData
from jaxcelt.integrate.solve import simulate
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import project_state

__all__ = ["finite_time_lyapunov", "gradient_norm_vs_window"]


def finite_time_lyapunov(
    params: CeltParams, y0: State, t1: float, *, n_samples: int = 50, seed: int = 0
) -> tuple[np.ndarray, np.ndarray, float]:
    """Growth of a random initial perturbation along a trajectory (forward-mode tangent).

    Returns (ts (n,), log|delta y(t)| (n,), lambda [1/s]): lambda is the least-squares slope of
    the log tangent norm over the second half of the record (a finite-time estimate of the
    largest Lyapunov exponent). The perturbation is tangent to the contact manifold.
    """
    ts = jnp.linspace(0.0, t1, n_samples)
    rng = np.random.default_rng(seed)
    d = jnp.asarray(rng.standard_normal(13) * STATE_SCALE)

    def traj(y):
        return simulate(params, project_state(y, params), t1, ts=ts, adjoint=diffrax.ForwardMode()).ys

    _, tang = jax.jvp(traj, (jnp.asarray(y0),), (d,))
    lg = np.log(np.linalg.norm(np.asarray(tang) / STATE_SCALE, axis=1))
    tsn = np.asarray(ts)
    h = n_samples // 2
    lam = float(np.polyfit(tsn[h:], lg[h:], 1)[0])
    return tsn, lg, lam


def gradient_norm_vs_window(
    data: MeasuredData,
    params0: CeltParams,
    lengths: Sequence[int] | None = None,
    *,
    free: Sequence[str] = ("mu", "k_r", "b_Ts", "m_Ts"),
    sim_rtol: float = 1e-8,
    sim_atol: float = 1e-10,
    max_steps: int = 200_000,
) -> tuple[np.ndarray, np.ndarray]:
    """|d loss / d z_params| of a single-shooting fit on the first ``L`` samples of record 0.

    One forward-mode pass over the whole record gives the residuals r_j and their parameter
    sensitivities dr_j/dz; the gradient of the loss on the first L samples is the partial sum
    sum_{j<=L} r_j dr_j/dz, so every window length costs one compilation and one solve.

    Args: data, params0, lengths: window lengths in samples (default: every sample). Returns
    (T [s] (L,), gradient norms (L,)); compare with e^{lambda T} from `finite_time_lyapunov`.
    """
    tr = data.trajectories[0]
    sub = MeasuredData((tr,), getattr(data, "meta", {}))
    config = FitOptions(
        free=tuple(free), windows=1, window_states="data", continuity_weight=1.0,
        sim_rtol=sim_rtol, sim_atol=sim_atol, max_steps=max_steps,
    )  # fmt: skip
    prob, z = build_problem(sub, params0, config)
    zf = z["params"]
    r, J = (np.asarray(a) for a in value_and_jacobian(prob, zf))
    n1 = len(tr.ts)
    per_sample, i = np.zeros((n1, J.shape[1])), 0
    for kind in prob.kinds:  # residual blocks: kind-major, then sample-major
        m = n1 * OBSERVABLES[kind]
        per_sample += (r[i : i + m, None] * J[i : i + m]).reshape(n1, OBSERVABLES[kind], -1).sum(axis=1)
        i += m
    g = np.cumsum(per_sample, axis=0)  # (n1, P): gradient of the loss on samples 0..L
    lengths = np.arange(1, n1) if lengths is None else np.asarray(lengths)
    norms = np.linalg.norm(g[lengths], axis=1)
    return np.asarray(tr.ts[lengths] - tr.ts[0]), norms
