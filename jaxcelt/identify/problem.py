"""The least-squares problem of a fit: the records stacked for one program, the unknowns, and the residuals.

The unknowns are the free parameters, mapped to an unconstrained vector z by per-parameter transforms
(`jaxcelt.identify.transforms`), the sensor rotation and per-record time offsets when fitted, and -- with multiple
shooting -- the initial states of the windows.

Residuals r(z) (all dimensionless, stacked into one vector):

* misfit: (h(y(t_j)) - d_j) / sigma for every sample j, observation kind and channel, times
  sqrt(weight[kind]); h is the observation model (`jaxcelt.identify.observe.observe`);
* continuity (multiple shooting): (y_k(end of window k) - s_{k+1}) / state_scale times
  sqrt(continuity_weight), where s_{k+1} is the next window's (projected) initial state;
* gauge (optimised window states): (s - P(s)) / state_scale times sqrt(continuity_weight), P the
  projection onto the contact manifold (`jaxcelt.physics.state.project_state`), which pins the three directions of
  the 13-vector that the projection removes.

loss = 1/2 |r|^2. Multiple shooting splits each record into ``windows`` windows of equal sample count; each is
integrated from its own initial state, so the sensitivity of the loss to the unknowns grows like
e^{lambda T_window} instead of e^{lambda T_record} (lambda: largest Lyapunov exponent) -- the remedy for long and
chaotic records (`jaxcelt.identify.chaos`).

`Problem` is an equinox Module: a pytree whose arrays are the data and whose static fields are the shape of the
problem, so that one compiled program serves every fit of the same shape. `build_problem` makes it from measured
records, starting parameters and a `jaxcelt.identify.options.FitOptions`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array
from jaxcelt.identify.observe import OBSERVABLES, SENSOR_KINDS, observe, rotation_matrix
from jaxcelt.identify.options import FitOptions
from jaxcelt.identify.records import MeasuredData
from jaxcelt.identify.transforms import transform_of
from jaxcelt.integrate.solve import simulate
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import project_state

__all__ = [
    "Problem",
    "Records",
    "build_problem",
    "to_device",
    "theta_and_jacobian",
    "thetas",
    "residuals",
    "value_and_jacobian",
    "STATE_SCALE",
    "TIME_OFFSET_SCALE",
]

TIME_OFFSET_SCALE = 0.01
"""Scale [s] of the optimised time offsets (z = offset / TIME_OFFSET_SCALE)."""

STATE_SCALE = np.array([0.1, 0.1, 0.1, 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.01, 0.01, 0.01, 0.1])
"""Typical size of a change of each state component (v [m/s], omega [rad/s], n [-], r_C [m],
psi [rad]); scales the optimised window states and the continuity/gauge residuals. Read-only."""
STATE_SCALE.flags.writeable = False



class Records(eqx.Module):
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


class Problem(eqx.Module):
    """Residual function of a fit; a pytree so that jit caches across fits of the same shape."""

    params0: CeltParams
    theta0: Array  # (P,)
    rec: Records
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
                monitor=False,  # the residuals never read validity: a smaller program to trace and compile
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


def to_device(x) -> Array:
    """A float64 host value on the default device, without compiling anything (``jnp.asarray``
    of a host array compiles a copy program per shape: tens of ms each, eagerly)."""
    return jax.device_put(np.asarray(x, dtype=float))


def build_problem(
    data: MeasuredData, params0: CeltParams, config: FitOptions, *, mode: str = "fwd"
) -> tuple[Problem, dict]:
    """The problem of fitting ``params0``'s free parameters (``config.free``) to ``data``, and its starting
    unknowns z (a dict: "params", "rotation", "offsets", "states"; all zero but the window states).

    ``mode``: how the solves are differentiated, ``"fwd"`` (forward mode, the fits' Jacobians) or ``"rev"``.
    Raises ValueError where the data cannot serve the configuration (windows, window states, y0, sensors)."""
    c = config
    free, windows, window_states, fit_y0 = c.free, c.windows, c.window_states, c.fit_y0
    rtol, atol = c.sim_rtol, c.sim_atol
    max_steps = c.steps_per_solve([float(tr.ts[-1] - tr.ts[0]) for tr in data.trajectories])
    sensor_rotation, time_offset = c.sensor_rotation, c.time_offset
    fit_rotation, fit_time_offset = c.fit_rotation, c.fit_time_offset
    trs = [transform_of(n, c.transforms) for n in free]
    theta0 = to_device([float(getattr(params0, n)) for n in free])
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
    rec = Records(
        ts=to_device(ts),
        obs={k: to_device(v) for k, v in obs.items()},
        mask={k: to_device(v) for k, v in mask.items()},
        inv_sigma={k: to_device(v) for k, v in inv_sigma.items()},
        fixed_states=to_device(fixed),
        omega_pi=to_device([float(tr.omega_pi) for tr, _, _ in per]),
        q_pi=to_device([float(tr.q_pi) for tr, _, _ in per]),
        rotation0=to_device(rv0),
        offset0=to_device(off0),
        free_windows=tuple(free_w),
    )
    z_states = to_device(fixed[:, free_w] / STATE_SCALE if free_w else np.zeros((R, 0, 13)))
    w = {k: to_device(float((c.weights or {}).get(k, 1.0))) for k in kinds}
    prob = Problem(
        params0=params0,
        theta0=theta0,
        rec=rec,
        weights=w,
        continuity_weight=to_device(float(c.continuity_weight)),
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
def theta_and_jacobian(prob: Problem, zf: Array) -> tuple[Array, Array]:
    """Physical values of the free parameters and d theta / d z at the flat unknowns zf, in one
    small compiled program (eager, the transforms' operations and their derivatives and the slice
    would cost a compilation each)."""
    zp = zf[: len(prob.free)]
    return prob.theta(zp), jax.jacfwd(prob.theta)(zp)


@eqx.filter_jit
def thetas(prob: Problem, zfs: Array) -> Array:
    """Physical values of the free parameters of a batch of starts (S, n)."""
    return jax.vmap(prob.theta)(zfs[:, : len(prob.free)])


@eqx.filter_jit
def residuals(prob: Problem, z):
    """``prob.residuals(z)``, compiled (for tests and diagnostics; the fits use `jaxcelt.identify.program`)."""
    return prob.residuals(z)


@eqx.filter_jit
def value_and_jacobian(prob: Problem, zf):
    """``prob.value_and_jacobian(zf)`` in forward mode, compiled (see `residuals`)."""
    return dataclasses.replace(prob, mode="fwd").value_and_jacobian(zf)
