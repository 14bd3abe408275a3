"""Gradient-based identification of model parameters from measured trajectories.

The unknowns are the free parameters, mapped to an unconstrained vector z by per-parameter
transforms (`Positive`: theta = theta0 exp(z); `Bounded(lo, hi)`: a scaled logistic; `Affine`:
theta = theta0 + scale z), and -- with multiple shooting -- the initial states of the windows.

Residuals r(z) (all dimensionless, stacked into one vector):

* misfit: (h(y(t_j)) - d_j) / sigma for every sample j, observation kind and channel, times
  sqrt(weight[kind]); h is the observation model (`jaxcelt.identify.records.observe`);
* continuity (multiple shooting): (y_k(end of window k) - s_{k+1}) / state_scale times
  sqrt(continuity_weight), where s_{k+1} is the next window's (projected) initial state;
* gauge (optimised window states): (s - P(s)) / state_scale times sqrt(continuity_weight), P the
  projection onto the contact manifold (`project_state`), which pins the three directions of the
  13-vector that the projection removes.

loss = 1/2 |r|^2. Optimisers: ``"lm"`` (optimistix Levenberg-Marquardt, forward-mode Jacobians via
``diffrax.ForwardMode``), ``"gn"`` (optimistix Gauss-Newton), ``"gn-damped"`` (Gauss-Newton with a
backtracking Armijo line search), ``"adam"`` and ``"lbfgs"`` (optax; gradient J^T r from the same
forward-mode Jacobian). One program per problem shape holds the ODE solves (records padded to a
common length; on a multi-core CPU the one-record program runs every record in its own thread,
elsewhere one program runs them in a `jax.lax.map`); the optimisers call it through
`jax.pure_callback`. With JAX's persistent cache directory set, that program is stored compiled and
later processes load it (`jaxcelt._executable_cache`). Uncertainty (`FitResult.stderr`, ``ci95``, ``corr``): the Gauss-Newton
approximation cov(z) = s^2 (J^T J)^-1 at the optimum with s^2 = RSS_misfit / (n_data - n_unknowns),
marginalised over the window states, mapped to the physical parameters by the delta method.

Multiple shooting splits each record into ``windows`` windows of equal sample count; each is
integrated from its own initial state, so the sensitivity of the loss to the unknowns grows like
e^{lambda T_window} instead of e^{lambda T_record} (lambda: largest Lyapunov exponent) -- the
remedy for long and chaotic records (see `gradient_norm_vs_window`, `finite_time_lyapunov`).
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import os
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
import optimistix as optx

from jaxcelt import _config  # noqa: F401
from jaxcelt._compile_options import compiler_options
from jaxcelt._diffrax_adapter import runtime_checks_as_nan
from jaxcelt._executable_cache import compile_in_background, compiled
from jaxcelt._types import Array, State
from jaxcelt.identify.records import OBSERVABLES, SENSOR_KINDS, MeasuredData, observe, rotation_matrix
from jaxcelt.integrate.solve import simulate
from jaxcelt.physics.model import contact_geometry
from jaxcelt.physics.params import PARAM_NAMES, CeltParams

__all__ = [
    "fit",
    "FitResult",
    "Positive",
    "Bounded",
    "Affine",
    "DEFAULT_TRANSFORMS",
    "STATE_SCALE",
    "OPTIMISERS",
    "DampedGaussNewton",
    "project_state",
    "predict",
    "finite_time_lyapunov",
    "gradient_norm_vs_window",
    "multistart",
    "random_guesses",
    "profile_likelihood",
    "fit_staged",
]

OPTIMISERS = ("lm", "gn", "gn-damped", "adam", "lbfgs")
LSQ_OPTIMISERS = ("lm", "gn", "gn-damped")  # optimistix least squares: `multistart` runs them vmapped

STEPS_PER_SECOND = 2000
"""Default step budget of a fit's solves per second of window (rounded up to whole seconds): a
record of the stone's normal motion needs a few hundred steps per second at rtol 1e-8; the cap
makes a trial point in a stiff parameter region fail fast (``benchmarks/bench_fit.py``)."""

TIME_OFFSET_SCALE = 0.01
"""Scale [s] of the optimised time offsets (z = offset / TIME_OFFSET_SCALE)."""

STATE_SCALE = np.array([0.1, 0.1, 0.1, 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.01, 0.01, 0.01, 0.1])
"""Typical size of a change of each state component (v [m/s], omega [rad/s], n [-], r_C [m],
psi [rad]); scales the optimised window states and the continuity/gauge residuals."""


# ----------------------------------------------------------------------------- transforms
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


DEFAULT_TRANSFORMS: dict[str, Any] = {
    "m_Ts": Bounded(0.0, 2.0),
    "m_Ms": Bounded(0.0, 2.0),
    "b": Bounded(0.0, 1.0),
    "B12": Affine(),
    "B13": Affine(),
    "B23": Affine(),
    "k1": Affine(),
    "k2": Affine(),
    "k3": Affine(),
}
"""Transform per parameter name; any other free parameter is `Positive`. The generalised Pade
exponents live in (0, 2] (the brief's 0 < m <= 2), b in (0, 1]."""

_NOT_FREE = ("v_pi_sign", "derivative_exact", "omega_pi", "q_pi")


# ----------------------------------------------------------------------------- state helpers
def project_state(y: State, params: CeltParams) -> State:
    """Project a 13-vector onto the contact manifold (MODEL.md section 8).

    Normalises n, removes the normal component of the contact-point velocity v_A = v + omega x rho
    (eq. 2) and sets r_C3 to the height of C above the contact (-rho . n). Differentiable.
    """
    v, w, n, r_C, psi = y[0:3], y[3:6], y[6:9], y[9:12], y[12:13]
    n = n / jnp.linalg.norm(n)
    rho = contact_geometry(n, w, params).rho
    v_A = v + jnp.cross(w, rho)
    v_A = v_A - jnp.dot(v_A, n) * n
    v = v_A - jnp.cross(w, rho)
    r_C = r_C.at[2].set(-jnp.dot(rho, n))
    return jnp.concatenate([v, w, n, r_C, psi])


# ----------------------------------------------------------------------------- the problem
class _Record(eqx.Module):
    """All R trajectories, each cut into K windows of n+1 samples (shared boundary samples), stacked
    on a leading record axis and padded to a common n (padded samples have mask 0 and repeat the
    window's last time), so that one vmapped program serves every record."""

    ts: Array  # (R, K, n+1)
    obs: dict  # kind -> (R, K, n+1, k)
    mask: dict  # kind -> (R, K, n+1): 1 for a measured sample, 0 for padding or a missing kind
    inv_sigma: dict  # kind -> (R, k)
    fixed_states: Array  # (R, K, 13) states of windows that are not optimised
    omega_pi: Array  # (R,)
    q_pi: Array  # (R,)
    rotation0: Array  # (3,) given sensor rotation vector (body -> sensor axes) [rad]
    offset0: Array  # (R,) given time offsets: model time = record time + offset [s]
    free_windows: tuple[int, ...] = eqx.field(static=True)


def _map1(mapper: Callable, fn: Callable, xs: Any) -> Any:
    """``mapper(fn)(xs)`` over the leading axis (``jax.vmap`` or ``jax.lax.map``); with a single
    element, ``fn`` is called on it directly: a loop or batch of one adds a layer that every
    transformation (the Jacobian's JVP and its vmap over the unknowns) re-traces, which costs
    seconds of tracing for a program holding an ODE solve."""
    if jax.tree.leaves(xs)[0].shape[0] == 1:
        return jax.tree.map(lambda a: a[None], fn(jax.tree.map(lambda a: a[0], xs)))
    return jax.vmap(fn)(xs) if mapper is jax.vmap else mapper(fn, xs)


class _Problem(eqx.Module):
    """Residual function of a fit; a pytree so that jit caches across fits of the same shape."""

    params0: CeltParams
    theta0: Array  # (P,)
    rec: _Record
    weights: dict  # kind -> scalar
    continuity_weight: Array
    free: tuple[str, ...] = eqx.field(static=True)
    transforms: tuple[Any, ...] = eqx.field(static=True)
    kinds: tuple[str, ...] = eqx.field(static=True)
    mode: str = eqx.field(static=True)  # "fwd" | "rev"
    rtol: float = eqx.field(static=True)
    atol: float = eqx.field(static=True)
    max_steps: int = eqx.field(static=True)
    fit_rotation: bool = eqx.field(static=True, default=False)
    fit_time_offset: bool = eqx.field(static=True, default=False)

    @property
    def n_records(self) -> int:
        return int(self.rec.ts.shape[0])

    def theta(self, zp: Array) -> Array:
        return jnp.stack([tr.forward(zp[i], self.theta0[i]) for i, tr in enumerate(self.transforms)])

    def params(self, zp: Array) -> CeltParams:
        th = self.theta(zp)
        names = self.free
        return eqx.tree_at(lambda p: [getattr(p, n) for n in names], self.params0, [th[i] for i in range(len(names))])

    def _record_params(self, p: CeltParams, omega_pi, q_pi) -> CeltParams:
        return eqx.tree_at(lambda q: (q.omega_pi, q.q_pi), p, (omega_pi, q_pi))

    def _window_states(self, zs: Array, fixed: Array) -> Array:
        """Window initial states (K, 13) of one record from its optimised states zs (k, 13)."""
        if self.rec.free_windows:
            return fixed.at[jnp.array(self.rec.free_windows)].set(zs * STATE_SCALE[None, :])
        return fixed

    def sensor(self, z, xp=jnp) -> tuple[Array, Array]:
        """(rotation vector (3,) of the sensor axes [rad], time offsets (R,) [s]): given + fitted
        (``xp=np``: on the host, for concrete ``z``)."""
        rv = xp.asarray(self.rec.rotation0) + (z["rotation"] if self.fit_rotation else 0.0)
        off = xp.asarray(self.rec.offset0) + (z["offsets"] * TIME_OFFSET_SCALE if self.fit_time_offset else 0.0)
        return rv, off

    def _simulate_record(self, p, zs, fixed, ts) -> tuple[Array, Array]:
        s = jax.vmap(lambda y: project_state(y, p))(self._window_states(zs, fixed))
        adjoint = diffrax.ForwardMode() if self.mode == "fwd" else diffrax.RecursiveCheckpointAdjoint()

        def one(y0, t):
            sol = simulate(
                p,
                y0,
                t[-1],
                t0=t[0],
                ts=t,
                rtol=self.rtol,
                atol=self.atol,
                max_steps=self.max_steps,
                adjoint=adjoint,
            )
            return sol.ys, sol.status

        return _map1(jax.vmap, lambda a: one(*a), (s, ts))

    def simulate_windows(self, z) -> tuple[Array, Array]:
        """States (R, K, n+1, 13) in every window of every record, and the solver status (R, K)."""
        p = self.params(z["params"])
        rec = self.rec
        _, off = self.sensor(z)
        return _map1(
            jax.lax.map,
            lambda a: self._simulate_record(self._record_params(p, a[3], a[4]), a[0], a[1], a[2] + a[5]),
            (z["states"], rec.fixed_states, rec.ts, rec.omega_pi, rec.q_pi, off),
        )

    def residuals(self, z, args=None) -> tuple[Array, dict]:
        """(r (M,), aux) with aux = {"misfit": data-part RSS, "continuity": penalty RSS}. The first
        `n_misfit` entries are the data residuals (padding included, as zeros), the rest penalties."""
        p = self.params(z["params"])
        rec = self.rec
        kinds = self.kinds
        wts = {k: jnp.sqrt(self.weights[k]) for k in kinds}
        cw = jnp.sqrt(self.continuity_weight)
        rv, off = self.sensor(z)
        Rs = rotation_matrix(rv)

        def one(zs, fixed, ts, om, q, obs, mask, inv_sigma, dt):
            pr = self._record_params(p, om, q)
            ts = ts + dt  # model time of the record's samples
            ys, _ = self._simulate_record(pr, zs, fixed, ts)
            mis, pen = [], []
            for kind in kinds:
                h = jax.vmap(jax.vmap(lambda y, t, kind=kind: observe(y, pr, kind, t)))(ys, ts)
                if kind in SENSOR_KINDS:
                    h = h @ Rs.T  # body -> sensor axes
                r = (h - obs[kind]) * inv_sigma[kind][None, None, :] * wts[kind] * mask[kind][..., None]
                # window k>0 starts at the previous window's last sample: count it once
                mis.append(jnp.concatenate([r[0].reshape(-1), r[1:, 1:].reshape(-1)]))
            if ys.shape[0] > 1:
                starts = jax.vmap(lambda y: project_state(y, pr))(self._window_states(zs, fixed))
                c = (ys[:-1, -1] - starts[1:]) / STATE_SCALE[None, :]
                pen.append(c.reshape(-1) * cw)
            if rec.free_windows:
                raw = zs * STATE_SCALE[None, :]
                g = (raw - jax.vmap(lambda y: project_state(y, pr))(raw)) / STATE_SCALE[None, :]
                pen.append(g.reshape(-1) * cw)
            return jnp.concatenate(mis), (jnp.concatenate(pen) if pen else jnp.zeros(0))

        # records one after another in one traced body (lax.map): on CPU a vmapped adaptive solve
        # steps every lane until the slowest is done, at several times the cost of a sequence
        rm, rp = _map1(
            jax.lax.map,
            lambda a: one(*a),
            (z["states"], rec.fixed_states, rec.ts, rec.omega_pi, rec.q_pi, rec.obs, rec.mask, rec.inv_sigma, off),
        )
        rm, rp = rm.reshape(-1), rp.reshape(-1)
        # a failed or diverging solve gives inf/NaN samples: a large finite residual lets the
        # optimiser reject the step instead of poisoning its state
        rm = jnp.where(jnp.isfinite(rm), rm, 1e6)
        rp = jnp.where(jnp.isfinite(rp), rp, 1e6)
        return jnp.concatenate([rm, rp]), {"misfit": jnp.sum(rm**2), "continuity": jnp.sum(rp**2)}

    @property
    def n_misfit(self) -> int:
        """Length of the data part of the residual vector (padding included)."""
        R, K, n1 = self.rec.ts.shape
        return R * (n1 + (K - 1) * (n1 - 1)) * sum(self.rec.obs[k].shape[-1] for k in self.kinds)

    @property
    def n_residuals(self) -> int:
        """Length M of the residual vector: data part, then continuity and gauge penalties."""
        R, K, _ = self.rec.ts.shape
        return self.n_misfit + R * 13 * ((K - 1 if K > 1 else 0) + len(self.rec.free_windows))

    def loss(self, z) -> Array:
        return 0.5 * jnp.sum(self.residuals(z)[0] ** 2)

    # -- flat interface for the optimisers ---------------------------------------------------
    @property
    def n_nuisance(self) -> int:
        """Unknowns after the parameters and before the window states: rotation (3), offsets (R)."""
        return 3 * self.fit_rotation + self.n_records * self.fit_time_offset

    def unflatten(self, zf: Array) -> dict:
        P = len(self.free)
        R = self.n_records
        k = len(self.rec.free_windows)
        nr, no = 3 * self.fit_rotation, R * self.fit_time_offset
        return {
            "params": zf[:P],
            "rotation": zf[P : P + nr],
            "offsets": zf[P + nr : P + nr + no],
            "states": zf[P + nr + no :].reshape(R, k, 13),
        }

    def flatten(self, z: dict) -> np.ndarray:
        """The flat vector of host values ``z`` (the inverse of `unflatten`), on the host."""
        return np.concatenate(
            [np.asarray(z[k], float).reshape(-1) for k in ("params", "rotation", "offsets", "states")]
        )

    def value_and_jacobian(self, zf: Array) -> tuple[Array, Array]:
        """r (M,) and the forward-mode Jacobian dr/dz (M, len(zf)) in one batched JVP pass."""

        def f(x):
            r = self.residuals(self.unflatten(x))[0]
            return r, r

        J, r = jax.jacfwd(f, has_aux=True)(zf)
        return r, J


# ----------------------------------------------------------------------------- result
@dataclasses.dataclass
class FitResult:
    """Outcome of `fit`. Physical values are floats; arrays are numpy.

    values/params: fitted free parameters (name -> value) / full `CeltParams`; stderr, ci95
    (name -> (lo, hi)): Gauss-Newton standard errors and 95% intervals (theta +- 1.96 se);
    corr (P, P): correlation matrix of the free parameters; s2: residual variance factor;
    loss_history, param_history (iteration -> loss, dict of values); wall_time [s] of the
    optimisation after compilation, compile_time [s] of the first iteration, total_time [s];
    n_iter; converged: the optimiser's own criterion (LM/GN) or the gradient-norm test (optax, ``gtol``).
    z: final unknowns; problem: the residual function (for `predict`, plotting).
    """

    free: tuple[str, ...]
    values: dict[str, float]
    params: CeltParams
    stderr: dict[str, float]
    ci95: dict[str, tuple[float, float]]
    corr: np.ndarray
    cov: np.ndarray
    s2: float
    loss: float
    misfit: float
    continuity: float
    n_data: int
    n_unknowns: int
    loss_history: list[float]
    param_history: list[dict[str, float]]
    n_iter: int
    converged: bool
    optimiser: str
    windows: int
    wall_time: float
    compile_time: float
    total_time: float
    z: Any = None
    problem: Any = None
    nuisance: dict[str, Any] = dataclasses.field(default_factory=dict)
    """sensor rotation vector [rad] and time offsets [s] (given or fitted; ``*_stderr`` when fitted)"""
    stages: list[dict[str, Any]] = dataclasses.field(default_factory=list)
    """`fit_staged`: per stage its span [s], iterations, loss, converged, compile and run time [s]"""

    def relative_error(self, true: dict[str, float] | CeltParams) -> dict[str, float]:
        """|fitted - true| / |true| per free parameter."""
        get = (lambda n: float(getattr(true, n))) if isinstance(true, CeltParams) else (lambda n: float(true[n]))
        return {n: abs(self.values[n] - get(n)) / abs(get(n)) for n in self.free}

    def covers(self, true: dict[str, float] | CeltParams) -> dict[str, bool]:
        """Whether each true value lies in the reported 95% interval."""
        get = (lambda n: float(getattr(true, n))) if isinstance(true, CeltParams) else (lambda n: float(true[n]))
        return {n: self.ci95[n][0] <= get(n) <= self.ci95[n][1] for n in self.free}

    def summary(self) -> str:
        lines = [
            f"optimiser {self.optimiser}, windows {self.windows}: {self.n_iter} iterations, converged={self.converged}, "
            f"loss {self.loss:.6g} (misfit RSS {self.misfit:.6g}, continuity {self.continuity:.3g}), s^2 = {self.s2:.4g}",
            f"time: compile {self.compile_time:.2f} s, run {self.wall_time:.2f} s",
        ]
        for n in self.free:
            lo, hi = self.ci95[n]
            lines.append(f"  {n:>8s} = {self.values[n]:.6g} +- {self.stderr[n]:.3g}  (95%: [{lo:.6g}, {hi:.6g}])")
        nu = self.nuisance
        if "rotation_vector_stderr" in nu:
            rv, se = nu["rotation_vector"], nu["rotation_vector_stderr"]
            lines.append("  sensor rotation vector [rad] = " + ", ".join(f"{a:.4g} +- {b:.2g}" for a, b in zip(rv, se)))
        if "time_offset_stderr" in nu:
            to, se = nu["time_offset"], nu["time_offset_stderr"]
            lines.append("  time offsets [s] = " + ", ".join(f"{a:.5g} +- {b:.2g}" for a, b in zip(to, se)))
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-serialisable summary (no arrays of the problem)."""
        return dict(
            free=list(self.free),
            values=self.values,
            stderr=self.stderr,
            ci95={k: list(v) for k, v in self.ci95.items()},
            corr=np.asarray(self.corr).tolist(),
            s2=self.s2,
            loss=self.loss,
            misfit=self.misfit,
            continuity=self.continuity,
            n_data=self.n_data,
            n_unknowns=self.n_unknowns,
            loss_history=list(map(float, self.loss_history)),
            param_history=self.param_history,
            n_iter=self.n_iter,
            converged=self.converged,
            optimiser=self.optimiser,
            windows=self.windows,
            wall_time=self.wall_time,
            compile_time=self.compile_time,
            total_time=self.total_time,
            nuisance=self.nuisance,
            stages=self.stages,
        )


# ----------------------------------------------------------------------------- building
def _dev(x) -> Array:
    """A float64 host value on the default device, without compiling anything (``jnp.asarray``
    of a host array compiles a copy program per shape: tens of ms each, eagerly)."""
    return jax.device_put(np.asarray(x, dtype=float))


def _build(
    data: MeasuredData,
    params0: CeltParams,
    free: tuple[str, ...],
    transforms: dict,
    weights: dict,
    windows: int,
    window_states: str,
    fit_y0: bool,
    continuity_weight: float,
    mode: str,
    rtol: float,
    atol: float,
    max_steps: int,
    sensor_rotation: Any = None,
    time_offset: Any = 0.0,
    fit_rotation: bool = False,
    fit_time_offset: bool = False,
) -> tuple[_Problem, dict]:
    trs = []
    for n in free:
        if n not in PARAM_NAMES:
            raise ValueError(f"fit: unknown parameter {n!r}; known: {PARAM_NAMES}")
        if n in _NOT_FREE:
            raise ValueError(f"fit: {n!r} is a reading switch or a per-record forcing value and cannot be fitted")
        trs.append(transforms.get(n, DEFAULT_TRANSFORMS.get(n, Positive())))
    if len(set(free)) != len(free) or not free:
        raise ValueError(f"fit: 'free' must be a non-empty tuple of distinct names, got {free}")
    if windows < 1:
        raise ValueError(f"fit: windows must be >= 1, got {windows}")
    if window_states not in ("data", "optimise"):
        raise ValueError(f"fit: window_states must be 'data' or 'optimise', got {window_states!r}")
    theta0 = _dev([float(getattr(params0, n)) for n in free])
    kinds_all: set[str] = set()
    per = []
    for it, tr in enumerate(data.trajectories):
        T = tr.ts.size
        n = (T - 1) // windows
        if n < 1:
            raise ValueError(f"fit: trajectory {it} has {T} samples, too few for {windows} windows")
        idx = np.arange(windows)[:, None] * n + np.arange(n + 1)[None, :]  # (K, n+1); tail samples dropped
        p_tr = params0.replace(omega_pi=tr.omega_pi, q_pi=tr.q_pi)
        state_obs = tr.obs.get("state")
        # window initial states: from the data (projected), a known y0, or a simulation at params0
        starts = np.full((windows, 13), np.nan)
        if tr.y0 is not None:
            starts[0] = tr.y0
        elif state_obs is not None:
            starts[0] = np.asarray(project_state(jnp.asarray(state_obs[0]), p_tr))
        elif not fit_y0:
            raise ValueError(
                f"fit: trajectory {it} has no known y0 and no state observations; pass fit_y0=True with a y0 guess"
            )
        if windows > 1:
            if state_obs is not None:
                for k in range(1, windows):
                    starts[k] = np.asarray(project_state(jnp.asarray(state_obs[idx[k, 0]]), p_tr))
            elif window_states == "data":
                raise ValueError("fit: window_states='data' needs full-state observations")
            else:
                if np.isnan(starts[0]).any():
                    raise ValueError(f"fit: trajectory {it}: need y0 to initialise the window states")
                sol = simulate(
                    p_tr,
                    jnp.asarray(starts[0]),
                    float(tr.ts[idx[-1, 0]]),
                    ts=jnp.asarray(tr.ts[idx[:, 0]]),
                    rtol=rtol,
                    atol=atol,
                )
                starts[1:] = np.asarray(sol.ys)[1:]
        fixed = np.where(np.isnan(starts), 0.0, starts)
        per.append((tr, idx, fixed))
        kinds_all |= set(tr.kinds)
    free_w = []
    if fit_y0:
        free_w.append(0)
    if windows > 1 and window_states == "optimise":
        free_w += list(range(1, windows))
    kinds = tuple(sorted(kinds_all))
    # stack the records, padded to the longest window (n1 samples per window)
    R, n1 = len(per), max(idx.shape[1] for _, idx, _ in per)
    ts = np.zeros((R, windows, n1))
    obs = {k: np.zeros((R, windows, n1, OBSERVABLES[k])) for k in kinds}
    mask = {k: np.zeros((R, windows, n1)) for k in kinds}
    inv_sigma = {k: np.ones((R, OBSERVABLES[k])) for k in kinds}
    for r, (tr, idx, _) in enumerate(per):
        m = idx.shape[1]
        ts[r, :, :m] = tr.ts[idx]
        ts[r, :, m:] = tr.ts[idx[:, -1:]]  # padding repeats the window's last time
        for k in tr.kinds:
            obs[k][r, :, :m] = tr.obs[k][idx]
            mask[k][r, :, :m] = 1.0
            inv_sigma[k][r] = 1.0 / tr.sigma[k]
        if m < n1 and windows > 1:
            raise ValueError("fit: multiple shooting needs records of equal length (pad or cut them)")
    fixed = np.stack([f for _, _, f in per])
    rv0 = np.zeros(3) if sensor_rotation is None else np.asarray(sensor_rotation, float)
    if rv0.shape != (3,) or not np.all(np.isfinite(rv0)):
        raise ValueError(f"fit: sensor_rotation must be a finite rotation vector (3,) [rad], got {sensor_rotation!r}")
    off0 = np.broadcast_to(np.asarray(time_offset, float), (R,)) if np.ndim(time_offset) < 2 else None
    if off0 is None or not np.all(np.isfinite(off0)):
        raise ValueError(f"fit: time_offset must be a finite scalar or one per record, got {time_offset!r}")
    if (fit_rotation or fit_time_offset) and not (set(kinds) & set(SENSOR_KINDS)):
        raise ValueError(f"fit: fit_rotation/fit_time_offset need sensor observations {SENSOR_KINDS}, have {kinds}")
    rec = _Record(
        ts=_dev(ts),
        obs={k: _dev(v) for k, v in obs.items()},
        mask={k: _dev(v) for k, v in mask.items()},
        inv_sigma={k: _dev(v) for k, v in inv_sigma.items()},
        fixed_states=_dev(fixed),
        omega_pi=_dev([float(tr.omega_pi) for tr, _, _ in per]),
        q_pi=_dev([float(tr.q_pi) for tr, _, _ in per]),
        rotation0=_dev(rv0),
        offset0=_dev(off0),
        free_windows=tuple(free_w),
    )
    z_states = _dev(fixed[:, free_w] / STATE_SCALE if free_w else np.zeros((R, 0, 13)))
    w = {k: _dev(float(weights.get(k, 1.0))) for k in kinds}
    prob = _Problem(
        params0=params0,
        theta0=theta0,
        rec=rec,
        weights=w,
        continuity_weight=_dev(float(continuity_weight)),
        free=tuple(free),
        transforms=tuple(trs),
        kinds=kinds,
        mode=mode,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
        fit_rotation=bool(fit_rotation),
        fit_time_offset=bool(fit_time_offset),
    )
    z0 = {
        "params": np.zeros(len(free)),
        "rotation": np.zeros(3 if fit_rotation else 0),
        "offsets": np.zeros(R if fit_time_offset else 0),
        "states": z_states,
    }
    return prob, z0


@eqx.filter_jit
def _theta_and_jacobian(prob: _Problem, zf: Array) -> tuple[Array, Array]:
    """Physical values of the free parameters and d theta / d z at the flat unknowns zf, in one
    small compiled program (eager, the transforms' operations and their derivatives and the slice
    would cost a compilation each)."""
    zp = zf[: len(prob.free)]
    return prob.theta(zp), jax.jacfwd(prob.theta)(zp)


@eqx.filter_jit
def _thetas(prob: _Problem, zfs: Array) -> Array:
    """Physical values of the free parameters of a batch of starts (S, n)."""
    return jax.vmap(prob.theta)(zfs[:, : len(prob.free)])


# ----------------------------------------------------------------------------- optimisers (jitted once per shape)
@eqx.filter_jit
def _residuals(prob: _Problem, z):
    return prob.residuals(z)


@eqx.filter_jit
def _value_and_jacobian(prob: _Problem, zf):
    return dataclasses.replace(prob, mode="fwd").value_and_jacobian(zf)


# The only program that contains the ODE solver is the evaluation program (residuals and their
# forward-mode Jacobian, all records): compiled once per problem shape and shared by every
# optimiser, the uncertainty, multi-start and profile likelihood. The optimisers' own (small)
# programs reach it through `jax.pure_callback`, so they never contain the solver and are compiled
# in about a second, once per (residual length, unknowns, optimiser) for the whole process.
_ACTIVE: list = [None]  # the problem the callbacks evaluate (set by `fit`; not thread-safe)
_COMPILE_LOCK = threading.Lock()
_SPLIT: list = [None, None]  # the last problem `_evaluate` split into records, and its parts


def _cpu_workers() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@functools.cache
def _record_pool(workers: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=workers, thread_name_prefix="jaxcelt-fit")


def _one_record(prob: _Problem, i: int) -> tuple[_Problem, np.ndarray, np.ndarray]:
    """Record ``i`` as a problem of its own, the columns of its unknowns in the flat vector and the
    rows of its residuals (misfit block, then penalty block) in the whole problem's residuals."""
    rec, R = prob.rec, prob.n_records
    cut = lambda a: _dev(np.asarray(a)[i : i + 1])  # noqa: E731  (host slicing: no eager program)
    sub_rec = dataclasses.replace(
        rec,
        ts=cut(rec.ts),
        obs=jax.tree.map(cut, rec.obs),
        mask=jax.tree.map(cut, rec.mask),
        inv_sigma=jax.tree.map(cut, rec.inv_sigma),
        fixed_states=cut(rec.fixed_states),
        omega_pi=cut(rec.omega_pi),
        q_pi=cut(rec.q_pi),
        offset0=cut(rec.offset0),
    )
    sub = dataclasses.replace(prob, rec=sub_rec)
    P, nr, k13 = len(prob.free), 3 * prob.fit_rotation, 13 * len(rec.free_windows)
    no = R * prob.fit_time_offset
    cols = np.concatenate(
        [np.arange(P + nr), [P + nr + i] if prob.fit_time_offset else [], P + nr + no + i * k13 + np.arange(k13)]
    ).astype(int)
    lm, lp = sub.n_misfit, sub.n_residuals - sub.n_misfit
    rows = np.concatenate([i * lm + np.arange(lm), R * lm + i * lp + np.arange(lp)]).astype(int)
    return sub, cols, rows


def _parts(prob: _Problem) -> list[tuple[_Problem, np.ndarray, np.ndarray]] | None:
    """How `_evaluate` splits ``prob``: on a CPU with several cores, one part per record (see
    `_one_record`), evaluated in parallel threads by the one-record program (the records share
    its shapes); None: all records by one program (`jax.lax.map`)."""
    R, workers = prob.n_records, min(prob.n_records, _cpu_workers())
    if R == 1 or workers == 1 or jax.default_backend() != "cpu":
        return None
    if _SPLIT[0] is not prob:  # the split is per problem (one fit evaluates it many times)
        _SPLIT[:] = [prob, [_one_record(prob, i) for i in range(R)]]
    return _SPLIT[1]


def _prefetch(prob: _Problem, zf: np.ndarray) -> None:
    """Start compiling the evaluation program `_evaluate` will run at unknowns shaped like ``zf``
    in the background (traced now), so that the optimiser's own programs are traced and compiled
    meanwhile."""
    parts = _parts(prob)
    if parts is None:
        _evaluate_program(prob, zf, background=True)
    else:  # the records share one program
        _evaluate_program(parts[0][0], zf[..., parts[0][1]], background=True)


def _evaluate(prob: _Problem, zf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(r, J) at zf (n,) or at a batch of unknowns (..., n), split as `_parts` says."""
    parts = _parts(prob)
    if parts is None:
        return _evaluate_program(prob, zf)
    workers = min(prob.n_records, _cpu_workers())
    outs = list(_record_pool(workers).map(lambda part: _evaluate_program(part[0], zf[..., part[1]]), parts))
    r = np.empty((*zf.shape[:-1], prob.n_residuals))
    J = np.zeros((*zf.shape[:-1], prob.n_residuals, zf.shape[-1]))
    for (_, cols, rows), (ri, Ji) in zip(parts, outs, strict=True):
        r[..., rows] = ri
        J[..., rows[:, None], cols[None, :]] = Ji
    return r, J


def _evaluate_program(prob: _Problem, zf: np.ndarray, background: bool = False):
    """(r, J) by the compiled evaluation program of ``prob``'s shape (one per batch shape), kept
    in memory and -- with JAX's persistent cache directory set -- on disk across processes
    (`jaxcelt._executable_cache`). Traced without equinox's error callbacks (save times are
    checked by `_build`): a failing solve gives NaN. ``background``: only start compiling it
    (`jaxcelt._executable_cache.compile_in_background`); returns None."""
    prob = dataclasses.replace(prob, mode="fwd")
    dyn, static = eqx.partition(prob, eqx.is_array)
    leaves, treedef = jax.tree.flatten(dyn)
    zf = np.asarray(zf, dtype=float)
    lead, n = zf.shape[:-1], zf.shape[-1]
    x = _dev(zf.reshape(-1, n) if lead else zf)

    def f(leaves, x):
        pr = eqx.combine(jax.tree.unflatten(treedef, leaves), static)
        return jax.vmap(pr.value_and_jacobian)(x) if lead else pr.value_and_jacobian(x)

    description = repr(jax.tree.structure(prob)) + repr(jax.tree.leaves(static))
    with _COMPILE_LOCK, runtime_checks_as_nan():  # one thread traces (the context swaps a global)
        opts = compiler_options(jax.default_backend())
        if background:
            return compile_in_background("fit-residuals-jacobian", f, (leaves, x), description, opts)
        exe = compiled("fit-residuals-jacobian", f, (leaves, x), description, opts)
    r, J = (np.asarray(a) for a in exe(leaves, x))
    return (r.reshape(*lead, -1), J.reshape(*lead, -1, n)) if lead else (r, J)


def _host_vj(zf):
    # under vmap (multi-start) zf has leading batch axes: every start in one vmapped solve
    return _evaluate(_ACTIVE[0], np.asarray(zf, np.float64))


def _vj(zf: Array, m: int) -> tuple[Array, Array]:
    shapes = (jax.ShapeDtypeStruct((m,), zf.dtype), jax.ShapeDtypeStruct((m, zf.shape[-1]), zf.dtype))
    # under vmap the callback receives the whole batch (leading axes) and evaluates it at once
    return jax.pure_callback(_host_vj, shapes, zf, vmap_method="expand_dims")


def _residual_fn(m: int):
    """z -> r(z) with the JVP J dz, both from one callback evaluation."""

    @jax.custom_jvp
    def res(x):
        return _vj(x, m)[0]

    @res.defjvp
    def res_jvp(primals, tangents):
        r, J = _vj(primals[0], m)
        return r, J @ tangents[0]

    return res


def _loss_fn(m: int):
    """z -> 1/2 |r|^2 with the gradient J^T r (forward-mode J; reverse mode differentiates the JVP)."""

    @jax.custom_jvp
    def loss(x):
        r = _vj(x, m)[0]
        return 0.5 * jnp.sum(r**2)

    @loss.defjvp
    def loss_jvp(primals, tangents):
        r, J = _vj(primals[0], m)
        return 0.5 * jnp.sum(r**2), jnp.dot(J.T @ r, tangents[0])

    return loss


class DampedGaussNewton(optx.AbstractGaussNewton):
    """Gauss-Newton with step limiting: the full GN step is shortened by a backtracking Armijo
    line search (halving until the loss decreases sufficiently). Plain `optimistix.GaussNewton`
    accepts every full step; from a start 35-50% off, its first steps land in parameter regions
    where the record's integration is stiff and the loss is far larger (see docs/identification.md)."""

    rtol: float
    atol: float
    norm: Callable = optx.max_norm
    descent: optx.NewtonDescent = optx.NewtonDescent()
    search: optx.BacktrackingArmijo = optx.BacktrackingArmijo(decrease_factor=0.5, slope=0.1, step_init=1.0)
    verbose: Callable = lambda **kw: None


def _lsq_solver(name, rtol, atol):
    if name == "lm":
        return optx.LevenbergMarquardt(rtol=rtol, atol=atol)
    if name == "gn-damped":
        return DampedGaussNewton(rtol=rtol, atol=atol)
    return optx.GaussNewton(rtol=rtol, atol=atol)


def _lsq_fn(m):
    res = _residual_fn(m)
    return lambda zf, args: (res(zf), None)


@eqx.filter_jit
def _lsq_init(z, solver, m):
    fn = _lsq_fn(m)
    f_struct = jax.ShapeDtypeStruct((m,), z.dtype)
    return solver.init(fn, z, None, {}, f_struct, None, frozenset())


@eqx.filter_jit
def _lsq_step(z, state, solver, m):
    fn = _lsq_fn(m)
    z, state, _ = solver.step(fn, z, None, {}, state, frozenset())
    done, result = solver.terminate(fn, z, None, {}, state, frozenset())
    # loss at the last accepted iterate; whether the termination is a success
    return z, state, 0.5 * jnp.sum(state.f_info.residual**2), done, result == optx.RESULTS.successful


@eqx.filter_jit
def _lsq_init_batch(zs, solver, m):
    return eqx.filter_vmap(lambda z: _lsq_init(z, solver, m))(zs)


@eqx.filter_jit
def _lsq_step_batch(zs, states, frozen, solver, m):
    """One step of every start; a start that has terminated (``frozen``) keeps its iterate and state."""

    def one(z, state, stop):
        z2, state2, loss, done, ok = _lsq_step(z, state, solver, m)
        keep = lambda a, b: jnp.where(stop, a, b) if eqx.is_array(a) else b  # noqa: E731
        z2 = jnp.where(stop, z, z2)
        state2 = jax.tree.map(keep, state, state2, is_leaf=lambda x: x is None)
        return z2, state2, loss, done, ok

    return eqx.filter_vmap(one)(zs, states, frozen)


@eqx.filter_jit
def _optax_step(z, opt_state, optimiser, m, linesearch: bool):
    loss_fn = _loss_fn(m)
    if linesearch:  # L-BFGS: value and gradient kept in the state by its line search
        value, grad = optax.value_and_grad_from_state(loss_fn)(z, state=opt_state)
        updates, opt_state = optimiser.update(grad, opt_state, z, value=value, grad=grad, value_fn=loss_fn)
    else:
        value, grad = jax.value_and_grad(loss_fn)(z)
        updates, opt_state = optimiser.update(grad, opt_state, z)
    z_new = optax.apply_updates(z, updates)
    return z_new, opt_state, value, jnp.linalg.norm(grad)


def fit(
    data: MeasuredData,
    params0: CeltParams,
    *,
    free: Sequence[str] = ("mu", "k_r", "b_Ts", "m_Ts"),
    optimiser: str = "lm",
    weights: dict[str, float] | None = None,
    transforms: dict[str, Any] | None = None,
    windows: int = 1,
    window_states: str = "optimise",
    fit_y0: bool = False,
    sensor_rotation: Any = None,
    fit_rotation: bool = False,
    time_offset: Any = 0.0,
    fit_time_offset: bool = False,
    continuity_weight: float = 1e4,
    max_iter: int = 100,
    rtol: float = 1e-8,
    atol: float = 1e-8,
    sim_rtol: float = 1e-8,
    sim_atol: float = 1e-10,
    max_steps: int | None = None,
    learning_rate: float = 0.02,
    gtol: float = 1e-9,
    uncertainty: bool = True,
    max_time: float | None = None,
    callback: Callable[[int, float, dict[str, float]], None] | None = None,
) -> FitResult:
    """Fit the free parameters to measured trajectories.

    Args:
        data: `jaxcelt.identify.records.MeasuredData` (any observation kinds; several records, each with its
            own omega_pi, q_pi).
        params0: starting parameters (also the values of every parameter that is not free).
        free: names of the parameters to fit (any float fields of `CeltParams` except the
            reading switches and the per-record omega_pi, q_pi).
        optimiser: ``"lm"`` (optimistix Levenberg-Marquardt), ``"gn"`` (plain Gauss-Newton, full
            steps), ``"gn-damped"`` (Gauss-Newton with a backtracking line search), all with
            forward-mode Jacobians; ``"adam"`` (cosine-decayed step) or ``"lbfgs"`` (zoom line
            search), optax, with the gradient J^T r from the same forward-mode Jacobian.
        weights: extra weight per observation kind (default 1; residuals are already /sigma).
        transforms: per-parameter transforms overriding `DEFAULT_TRANSFORMS` (else `Positive`).
        windows: number of multiple-shooting windows per record (1 = single shooting).
        window_states: ``"optimise"`` (window initial states are unknowns, initialised from the
            data or from a simulation at params0, tied by the continuity penalty) or ``"data"``
            (fixed to the projected measured states; needs ``"state"`` observations).
        fit_y0: also optimise the first window's initial state (else: the record's known y0, or
            its first projected full-state sample).
        sensor_rotation: rotation vector (3,) [rad] from body to sensor axes of the gyro
            (``"omega"``) and accelerometer (``"accel"``) observations: h_sensor = R h_body
            (`jaxcelt.identify.records.rotation_matrix`); default none. With ``fit_rotation`` it is the
            starting value of a fitted rotation shared by all records.
        time_offset: model time minus record time [s] (scalar or one per record), i.e. the phase
            of the base's motion at the record's t = 0; default 0. With ``fit_time_offset`` the
            starting value of a fitted offset per record.
        continuity_weight: weight of the continuity and gauge residuals (residual scale
            `STATE_SCALE` / sqrt(weight)).
        max_iter: iteration budget. rtol, atol: optimistix termination (relative/absolute change
            of z and of the loss).
        sim_rtol, sim_atol, max_steps: integrator settings. max_steps per solve (default
            `STEPS_PER_SECOND` per second of the longest window, at least that many): a trial
            point of the optimiser in a stiff parameter region fails fast at the cap and is rejected.
        learning_rate: Adam initial step size in z (log-relative units for `Positive`
            parameters), decayed by a cosine schedule to 1e-3 of it over ``max_iter``.
        gtol: optax optimisers stop, converged, when |grad loss| <= gtol |grad loss at start|.
        uncertainty: compute standard errors, intervals and correlations.
        max_time: wall-clock budget [s] for the iterations (checked after each iteration;
            compilation included); the fit stops unconverged when it is spent.
        callback: called as ``callback(iteration, loss, values)`` after each iteration (progress).

    Returns:
        `FitResult`.
    """
    a = dict(locals())  # every argument: shared with `multistart` (`_prepare`, `_result`)
    prob, zf = _prepare(data, params0, a)
    free, P, m = prob.free, len(prob.free), prob.n_residuals
    _ACTIVE[0] = prob
    t_start = time.perf_counter()

    def values_of(zf) -> dict[str, float]:
        th = np.asarray(_theta_and_jacobian(prob, zf)[0])
        return {n: float(th[i]) for i, n in enumerate(free)}

    loss_hist, par_hist = [], []
    converged = False
    iter_marks = [time.perf_counter()]
    if optimiser in LSQ_OPTIMISERS:
        solver = _lsq_solver(optimiser, rtol, atol)
        _prefetch(prob, zf)
        state = _lsq_init(zf, solver, m)
        for it in range(max_iter):
            z_new, state, loss_acc, done, ok = _lsq_step(zf, state, solver, m)
            jax.block_until_ready(z_new)
            iter_marks.append(time.perf_counter())
            zf = z_new
            loss_hist.append(float(loss_acc))
            par_hist.append(values_of(zf))
            if callback is not None:
                callback(it, loss_hist[-1], par_hist[-1])
            if bool(done):
                converged = bool(ok)
                break
            if max_time is not None and iter_marks[-1] - t_start > max_time:
                break
    else:
        if optimiser == "adam":
            # cosine decay to 1e-3 of the initial step over the budget: constant-step Adam hovers
            # around the optimum at a distance ~ learning_rate instead of converging
            opt = optax.adam(optax.cosine_decay_schedule(learning_rate, max_iter, alpha=1e-3))
        else:
            opt = optax.lbfgs()
        _prefetch(prob, zf)
        opt_state = opt.init(zf)
        g0 = None
        for it in range(max_iter):
            z_new, opt_state, value, gnorm = _optax_step(zf, opt_state, opt, m, optimiser == "lbfgs")
            jax.block_until_ready(z_new)
            iter_marks.append(time.perf_counter())
            loss_hist.append(float(value))
            par_hist.append(values_of(zf))
            if callback is not None:
                callback(it, loss_hist[-1], par_hist[-1])
            g = float(gnorm)
            g0 = g if g0 is None else g0
            if not np.isfinite(float(value)):
                break
            # gradient of the loss at zf (before the update) reduced by gtol: zf is the optimum
            if g <= gtol * g0:
                converged = True
                break
            zf = z_new
            if max_time is not None and iter_marks[-1] - t_start > max_time:
                break
    compile_time, wall = _split_times(iter_marks)
    r, J = _evaluate(prob, np.asarray(zf))
    return _result(prob, zf, r, J, a, loss_hist, par_hist, converged, compile_time, wall, t_start)


def _prepare(data: MeasuredData, params0: CeltParams, a: dict) -> tuple[_Problem, Array]:
    """Checks the arguments ``a`` of `fit` and builds the problem; returns it and the flat start z."""
    if a["optimiser"] not in OPTIMISERS:
        raise ValueError(f"fit: optimiser must be one of {OPTIMISERS}, got {a['optimiser']!r}")
    max_iter = a["max_iter"]
    if isinstance(max_iter, bool) or not isinstance(max_iter, int) or max_iter < 1:
        raise ValueError(f"fit: max_iter must be a positive int, got {max_iter!r}")
    windows, max_steps = a["windows"], a["max_steps"]
    if max_steps is None:
        span = max(float(tr.ts[-1] - tr.ts[0]) for tr in data.trajectories) / max(int(windows), 1)
        max_steps = int(STEPS_PER_SECOND * max(1.0, np.ceil(span)))
    prob, z = _build(
        data,
        params0,
        tuple(a["free"]),
        a["transforms"] or {},
        a["weights"] or {},
        windows,
        a["window_states"],
        a["fit_y0"],
        a["continuity_weight"],
        "fwd",
        a["sim_rtol"],
        a["sim_atol"],
        max_steps,
        a["sensor_rotation"],
        a["time_offset"],
        a["fit_rotation"],
        a["fit_time_offset"],
    )
    return prob, prob.flatten(z)


def _split_times(iter_marks: list[float]) -> tuple[float, float]:
    """(compile time, run time) from the iteration end times: the first iteration pays for
    compilation; it is counted as a typical (median) iteration in the run time."""
    iter_times = np.diff(np.asarray(iter_marks))
    typical = float(np.median(iter_times[1:])) if iter_times.size > 1 else 0.0
    compile_time = max(float(iter_times[0]) - typical, 0.0) if iter_times.size else 0.0
    return compile_time, float(iter_marks[-1] - iter_marks[0]) - compile_time


def _result(prob, zf, r, Jflat, a, loss_hist, par_hist, converged, compile_time, wall, t_start) -> FitResult:
    """`FitResult` at the final unknowns ``zf`` with residuals ``r`` and Jacobian ``Jflat`` there."""
    # on the host or in compiled programs: eager jnp operations would compile one program each
    free, P = prob.free, len(prob.free)
    zf = np.asarray(zf, dtype=float)
    th, dth = (np.asarray(a) for a in _theta_and_jacobian(prob, zf))
    values = {n: float(th[i]) for i, n in enumerate(free)}
    z = prob.unflatten(zf)
    mask = {k: np.asarray(prob.rec.mask[k]) for k in prob.kinds}
    n_data = int(sum(float(np.sum(mask[k])) * OBSERVABLES[k] for k in prob.kinds))
    if prob.rec.ts.shape[1] > 1:  # shared window boundary samples are counted once
        n_data -= int(sum(float(np.sum(mask[k][:, 1:, 0])) * OBSERVABLES[k] for k in prob.kinds))
    nm = prob.n_misfit
    misfit, cont = float(np.sum(r[:nm] ** 2)), float(np.sum(r[nm:] ** 2))
    loss_hist = [*loss_hist, 0.5 * (misfit + cont)]
    par_hist = [*par_hist, values]
    n_unk = int(zf.size)
    rv_fit, off_fit = prob.sensor(z, xp=np)
    nuisance: dict[str, Any] = {"rotation_vector": rv_fit.tolist(), "time_offset": off_fit.tolist()}
    stderr = dict.fromkeys(free, np.nan)
    ci = {n: (np.nan, np.nan) for n in free}
    cov = np.full((P, P), np.nan)
    corr = np.full((P, P), np.nan)
    s2 = np.nan
    if a["uncertainty"]:
        n_free_states = prob.n_records * len(prob.rec.free_windows)
        dof = max(n_data - (n_unk - 3 * n_free_states), 1)
        s2 = misfit / dof
        H = Jflat.T @ Jflat
        try:  # a fit that ended in a failing-solve region can leave a non-finite Jacobian
            if not np.all(np.isfinite(H)):
                raise np.linalg.LinAlgError("non-finite Gauss-Newton matrix")
            cov_full = s2 * np.linalg.pinv(H, rcond=1e-13, hermitian=True)
        except np.linalg.LinAlgError:
            cov_full = np.full((n_unk, n_unk), np.nan)
        cov_z = cov_full[:P, :P]
        se_n = np.sqrt(np.maximum(np.diag(cov_full)[P : P + prob.n_nuisance], 0.0))
        nr = 3 * prob.fit_rotation
        if prob.fit_rotation:
            nuisance["rotation_vector_stderr"] = se_n[:nr].tolist()
        if prob.fit_time_offset:
            nuisance["time_offset_stderr"] = (se_n[nr:] * TIME_OFFSET_SCALE).tolist()
        cov = dth @ cov_z @ dth.T
        se = np.sqrt(np.maximum(np.diag(cov), 0.0))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = cov / np.outer(se, se)
        for i, nme in enumerate(free):
            stderr[nme] = float(se[i])
            ci[nme] = (values[nme] - 1.96 * float(se[i]), values[nme] + 1.96 * float(se[i]))
    return FitResult(
        free=free,
        values=values,
        params=eqx.tree_at(lambda p: [getattr(p, n) for n in free], prob.params0, [_dev(th[i]) for i in range(P)]),
        stderr=stderr,
        ci95=ci,
        corr=corr,
        cov=cov,
        s2=float(s2),
        loss=0.5 * (misfit + cont),
        misfit=misfit,
        continuity=cont,
        n_data=n_data,
        n_unknowns=n_unk,
        loss_history=loss_hist,
        param_history=par_hist,
        n_iter=len(loss_hist) - 1,
        converged=bool(converged),
        optimiser=a["optimiser"],
        windows=a["windows"],
        wall_time=wall,
        compile_time=compile_time,
        total_time=time.perf_counter() - t_start,
        z=z,
        problem=prob,
        nuisance=nuisance,
    )


def predict(result: FitResult) -> list[dict[str, Any]]:
    """Fitted trajectories per record: [{"ts": (K, n+1), "ys": (K, n+1, 13), kind: (K, n+1, k)}].

    Windows are simulated from their fitted initial states (one window = single shooting). Records
    shorter than the longest are padded (their last sample repeated; ``"mask"`` marks real samples).
    """
    prob, z = result.problem, result.z
    ys_all, _ = eqx.filter_jit(lambda pr, zz: pr.simulate_windows(zz))(dataclasses.replace(prob, mode="rev"), z)
    rv, off = prob.sensor(z)
    Rs = rotation_matrix(rv)
    out = []
    for i in range(prob.n_records):
        rec = prob.rec
        ys = ys_all[i]
        p = prob.params(z["params"])
        p = eqx.tree_at(lambda q: (q.omega_pi, q.q_pi), p, (rec.omega_pi[i], rec.q_pi[i]))
        d = {"ts": np.asarray(rec.ts[i]), "ys": np.asarray(ys)}
        for kind in OBSERVABLES:
            h = jax.vmap(jax.vmap(lambda y, t, kind=kind, p=p: observe(y, p, kind, t)))(ys, rec.ts[i] + off[i])
            d[kind] = np.asarray(h @ Rs.T if kind in SENSOR_KINDS else h)
        d["data"] = {k: np.asarray(v[i]) for k, v in rec.obs.items()}
        d["mask"] = {k: np.asarray(v[i]) > 0 for k, v in rec.mask.items()}
        out.append(d)
    return out


# ----------------------------------------------------------------------------- growing spans
def _truncate(data: MeasuredData, t_end: float) -> MeasuredData:
    trs = []
    for tr in data.trajectories:
        keep = tr.ts <= tr.ts[0] + t_end + 1e-9
        trs.append(dataclasses.replace(tr, ts=tr.ts[keep], obs={k: v[keep] for k, v in tr.obs.items()}))
    return MeasuredData(tuple(trs), data.meta)


def fit_staged(data: MeasuredData, params0: CeltParams, spans: Sequence[float], **fit_kw) -> FitResult:
    """`fit` on the first ``spans[0]`` seconds of every record, then on longer spans, each fit
    started from the last one's parameters, release states (``fit_y0``), sensor rotation and time
    offsets. Over a short span the loss is nearly quadratic in a roughly known release and in the
    offsets, which over the whole record would trap the fit in a local minimum (measured in
    ``scripts/fit_sensor_study.py``). Returns the last fit (make the last span cover the records),
    with every stage's iterations, loss and times in ``stages``."""
    if not spans or any(not (s > 0) for s in spans):
        raise ValueError(f"fit_staged: spans must be positive durations [s], got {spans!r}")
    kw = dict(fit_kw)
    p, res = params0, None
    y0s = [tr.y0 for tr in data.trajectories]
    stages: list[dict[str, Any]] = []
    for span in spans:
        d = _truncate(data, float(span))
        d = MeasuredData(tuple(dataclasses.replace(tr, y0=y) for tr, y in zip(d.trajectories, y0s)), d.meta)
        res = fit(d, p, **kw)
        stages.append(
            dict(span=float(span), n_iter=res.n_iter, loss=res.loss, converged=res.converged,
                 compile_time=res.compile_time, wall_time=res.wall_time)
        )  # fmt: skip
        p = res.params
        kw["sensor_rotation"] = res.nuisance["rotation_vector"]
        kw["time_offset"] = res.nuisance["time_offset"]
        if kw.get("fit_y0"):
            states = np.asarray(res.z["states"])[:, 0] * STATE_SCALE
            y0s = [np.asarray(project_state(jnp.asarray(s), p)) for s in states]
    res.stages = stages
    return res


# ----------------------------------------------------------------------------- multi-start, profile likelihood
def multistart(
    data: MeasuredData,
    params0: CeltParams,
    guesses: Sequence[dict[str, float]],
    *,
    vmapped: bool | None = None,
    **fit_kw,
) -> tuple[FitResult, dict[str, Any]]:
    """Fits from several initial guesses; returns the best (lowest loss) and a summary.

    With a least-squares optimiser (``"lm"``, ``"gn"``, ``"gn-damped"``) and ``vmapped=True`` every
    start iterates at once: one vmapped optimiser step per iteration, and the ODE solves of all
    starts in one vmapped program per iteration; a start that has terminated keeps its iterate
    while the others go on. ``guesses``: dicts of starting values of free parameters (the others,
    the problem's fixed values and multiple-shooting window states, from ``params0``); the returned
    fits share the batch's timings. Otherwise (``vmapped=False``, optax optimisers) the fits run one
    after another, sharing one compilation; there a guess may also set fixed parameters. Default
    (None): vmapped on an accelerator, one after another on the CPU, where a vmapped adaptive solve
    steps every start until the stiffest is done (measured 2x slower for 8 starts on 2 cores,
    ``benchmarks/bench_multistart.py``). ``fit_kw``: as for `fit` (``callback`` receives the
    lowest loss over the starts).

    Summary: per fit its start, values, loss, converged; per parameter the spread (min, max) over
    the converged fits whose loss is within 1e-6 relative of the best (the fits that found the same
    optimum) and how many did; ``vmapped``, ``compile_time`` and ``wall_time`` [s] of the whole call.
    """
    if not guesses:
        raise ValueError("multistart: 'guesses' is empty")
    t0 = time.perf_counter()
    a = inspect.signature(fit).bind(data, params0, **fit_kw)
    a.apply_defaults()
    a = dict(a.arguments)
    if vmapped is None:
        vmapped = jax.default_backend() != "cpu"
    vmapped = bool(vmapped) and a["optimiser"] in LSQ_OPTIMISERS
    if vmapped:
        results = _fit_batch(data, params0, guesses, a)
        compile_time = results[0].compile_time
    else:
        results = [fit(data, params0.replace(**g), **fit_kw) for g in guesses]
        compile_time = results[0].compile_time
    best = min(results, key=lambda r: r.loss if np.isfinite(r.loss) else np.inf)
    same = [r for r in results if r.converged and abs(r.loss - best.loss) <= 1e-6 * abs(best.loss) + 1e-12]
    summary = dict(
        fits=[
            dict(start=dict(g), values=r.values, loss=r.loss, converged=r.converged, n_iter=r.n_iter)
            for g, r in zip(guesses, results, strict=True)
        ],
        n_at_best=len(same),
        spread={n: (min(r.values[n] for r in same), max(r.values[n] for r in same)) for n in best.free} if same else {},
        vmapped=vmapped,
        compile_time=compile_time,
        wall_time=time.perf_counter() - t0 - compile_time,
    )
    return best, summary


def random_guesses(
    params0: CeltParams,
    n: int,
    *,
    free: Sequence[str] = ("mu", "k_r", "b_Ts", "m_Ts"),
    transforms: dict[str, Any] | None = None,
    spread: float = float(np.log(2.0)),
    seed: int = 0,
) -> list[dict[str, float]]:
    """``n`` starting guesses for `multistart`: the start itself (``{}``) and ``n - 1`` guesses with
    the unknown coordinates z of the free parameters drawn uniformly in [-spread, spread] (seeded),
    i.e. within a factor e^spread (default 2) of ``params0`` for positive parameters, and inside
    the range of a `Bounded` one."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"random_guesses: n must be a positive int, got {n!r}")
    if not (np.isfinite(spread) and spread > 0):
        raise ValueError(f"random_guesses: spread must be positive, got {spread!r}")
    transforms = transforms or {}
    for name in free:
        if name not in PARAM_NAMES or name in _NOT_FREE:
            raise ValueError(f"random_guesses: {name!r} is not a parameter that can be fitted")
    rng = np.random.default_rng(seed)
    out: list[dict[str, float]] = [{}]
    for _ in range(n - 1):
        g = {}
        for name in free:
            tr = transforms.get(name, DEFAULT_TRANSFORMS.get(name, Positive()))
            th0 = jnp.asarray(float(getattr(params0, name)))
            g[name] = float(tr.forward(jnp.asarray(rng.uniform(-spread, spread)), th0))
        out.append(g)
    return out


def _fit_batch(
    data: MeasuredData, params0: CeltParams, guesses: Sequence[dict[str, float]], a: dict
) -> list[FitResult]:
    """Least-squares fits from every guess at once (see `multistart`)."""
    prob, zf0 = _prepare(data, params0, a)
    free, m = prob.free, prob.n_residuals
    starts = np.repeat(np.asarray(zf0)[None], len(guesses), axis=0)
    for i, g in enumerate(guesses):
        for name, v in g.items():
            if name not in free:
                raise ValueError(f"multistart: guess {i} sets {name!r}, which is not a free parameter {free}")
            j = free.index(name)
            zj = float(prob.transforms[j].inverse(jnp.asarray(float(v)), prob.theta0[j]))
            if not np.isfinite(zj):
                raise ValueError(f"multistart: guess {i}: {name} = {v!r} is outside the range of its transform")
            starts[i, j] = zj
    _ACTIVE[0] = prob
    t_start = time.perf_counter()
    S = len(guesses)
    zs = _dev(starts)
    solver = _lsq_solver(a["optimiser"], a["rtol"], a["atol"])
    _prefetch(prob, starts)
    states = _lsq_init_batch(zs, solver, m)
    frozen, converged = np.zeros(S, bool), np.zeros(S, bool)
    loss_hist: list[list[float]] = [[] for _ in range(S)]
    par_hist: list[list[dict]] = [[] for _ in range(S)]
    iter_marks = [time.perf_counter()]
    for it in range(a["max_iter"]):
        zs, states, loss, done, ok = _lsq_step_batch(zs, states, jax.device_put(frozen), solver, m)
        jax.block_until_ready(zs)
        iter_marks.append(time.perf_counter())
        loss, done, ok = np.asarray(loss), np.asarray(done), np.asarray(ok)
        th = np.asarray(_thetas(prob, zs))
        for i in np.flatnonzero(~frozen):
            loss_hist[i].append(float(loss[i]))
            par_hist[i].append({n: float(th[i, j]) for j, n in enumerate(free)})
            if done[i]:
                frozen[i], converged[i] = True, bool(ok[i])
        if a["callback"] is not None:
            last = np.array([h[-1] if h else np.inf for h in loss_hist])
            b = int(np.argmin(np.where(np.isfinite(last), last, np.inf)))
            a["callback"](it, float(last[b]), par_hist[b][-1])
        if frozen.all():
            break
        if a["max_time"] is not None and iter_marks[-1] - t_start > a["max_time"]:
            break
    compile_time, wall = _split_times(iter_marks)
    r, J = _evaluate(prob, np.asarray(zs))
    zs = np.asarray(zs)
    return [
        _result(prob, zs[i], r[i], J[i], a, loss_hist[i], par_hist[i], converged[i], compile_time, wall, t_start)
        for i in range(S)
    ]


def profile_likelihood(
    data: MeasuredData, result: FitResult, name: str, values: Sequence[float], **fit_kw
) -> dict[str, Any]:
    """Profile of the loss over one parameter: for each fixed value, the other free parameters are
    re-fitted (started from ``result``). With Gaussian noise, 2 (loss(v) - loss_min) / s^2 is
    asymptotically chi^2_1; the 95 % profile interval is where it stays below 3.84. Compare it with
    the Gauss-Newton interval ``result.ci95[name]``: agreement means the quadratic (linearised)
    picture holds; a lopsided or wider profile flags weak, nonlinear identification.

    Returns dict(values, loss, delta = 2 (loss - min loss)/s^2, interval (lo, hi) from linear
    interpolation of the 3.84 crossings (NaN where the grid does not cross), ci95_gauss_newton).
    """
    if name not in result.free:
        raise ValueError(f"profile_likelihood: {name!r} is not a free parameter of the fit ({result.free})")
    others = tuple(n for n in result.free if n != name)
    if not others:
        raise ValueError("profile_likelihood: needs at least two free parameters")
    kw = dict(free=others, uncertainty=False) | fit_kw
    losses = []
    for v in values:
        r = fit(data, result.params.replace(**{name: float(v)}), **kw)
        losses.append(r.loss)
    vals, losses = np.asarray(values, float), np.asarray(losses)
    lmin = min(float(losses.min()), result.loss)
    delta = 2 * (losses - lmin) / result.s2
    lo = hi = np.nan
    below = delta <= 3.84
    i_best = int(np.argmin(delta))
    for i in range(i_best, 0, -1):  # left crossing
        if below[i] and not below[i - 1]:
            lo = float(np.interp(3.84, [delta[i], delta[i - 1]], [vals[i], vals[i - 1]]))
            break
    for i in range(i_best, len(vals) - 1):  # right crossing
        if below[i] and not below[i + 1]:
            hi = float(np.interp(3.84, [delta[i], delta[i + 1]], [vals[i], vals[i + 1]]))
            break
    return dict(
        name=name,
        values=vals.tolist(),
        loss=losses.tolist(),
        delta=delta.tolist(),
        interval=(lo, hi),
        ci95_gauss_newton=tuple(result.ci95[name]),
    )


# ----------------------------------------------------------------------------- chaos diagnostics
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
    prob, z = _build(sub, params0, tuple(free), {}, {}, 1, "data", False, 1.0, "fwd", sim_rtol, sim_atol, max_steps)
    zf = z["params"]
    r, J = (np.asarray(a) for a in _value_and_jacobian(prob, zf))
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
