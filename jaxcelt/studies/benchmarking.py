"""Speed-against-accuracy analysis: test scenes, reference solutions, timed solver runs.

The building blocks of ``benchmarks/{reference,work_precision,stability,peers}.py`` and of
``notebooks/05_speed_accuracy.ipynb``. Nothing here is physics: every trajectory comes
from `jaxcelt.simulate` (or from a peer integrator calling the same right-hand side).

* `BenchmarkScene` / `make_scene`: named test problems (from rest at omega_pi = 14, 17, 19; a fixed-table
  spin reversal; a stick-slip scene with small eps) with their stroboscopic sample times.
* `state_error`: the accuracy measure of every chart -- the largest absolute state error (SI
  units) over the sample times and the 13 state components.
* `time_call`: compile time and best-of-n run time of a JAX call, apart (``block_until_ready``).
* `run_diffrax`: one solver at one tolerance (or fixed step) on one scene: time, steps, RHS
  evaluations, status, error.
* solvers are named as in `jaxcelt.integrate.solvers.SOLVERS` (``make_solver``); committed results are read back
  by `jaxcelt.plotting.results`.
* `count_rhs_evals`: number of right-hand-side calls of a solve via a counting contact law. For
  implicit solvers this does *not* include the forward-mode Jacobian's columns (jax.jacfwd
  evaluates them as one batched call, which the host-side counter sees once), so it understates
  their work: compare implicit methods by run time.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from collections.abc import Callable
from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt.integrate.solve import simulate
from jaxcelt.integrate.solvers import SOLVERS, make_solver
from jaxcelt.physics.contact.laws import AbstractContactLaw
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import initial_state

__all__ = [
    "BenchmarkScene",
    "SCENES",
    "make_scene",
    "state_error",
    "time_call",
    "run_diffrax",
    "count_rhs_evals",
    "CountingLaw",
    "device_string",
]


# --------------------------------------------------------------------------------------------
# scenes


@dataclasses.dataclass(frozen=True)
class BenchmarkScene:
    """A test problem: parameters, initial state, horizon and the sample times of the error."""

    name: str
    params: CeltParams
    y0: np.ndarray
    t1: float
    ts: np.ndarray
    description: str

    @property
    def period(self) -> float:
        return float(2 * np.pi / float(self.params.omega_pi))


SCENES = ("rest14", "rest17", "rest19", "spin_reversal", "stick_slip")


def make_scene(name: str, periods: int = 5, **overrides) -> BenchmarkScene:
    """A named test scene.

    * ``rest14|rest17|rest19``: the stone at rest on the base, n = e3, psi = 0, driven at
      omega_pi = 14/17/19 rad/s for ``periods`` base periods; samples at t = k 2 pi/omega_pi
      (the stroboscopic section of the paper's Fig. 3).
    * ``spin_reversal``: fixed table (q_pi = 0), spun the "wrong" way, omega = (0, 2, -10) rad/s;
      the spin reverses near t = 1.6 s. ``periods`` counts 0.25 s intervals (default 5 -> 1.25 s;
      10 reaches past the reversal).
    * ``stick_slip``: omega_pi = 17, q_pi = 0.01 m (peak base acceleration 2.9 m/s^2, just above
      mu g = 2.2 m/s^2: the stone sticks for part of each period) with eps = eps_R = 1e-6 s^-2
      (stiff: relaxation rate ~ 355/sqrt(eps) = 3.6e5 1/s while sticking).
    ``overrides`` replace parameters (e.g. ``eps=1e-8``).
    """
    if name.startswith("rest"):
        w = float(name[4:])
        p = CeltParams.paper(omega_pi=w, **overrides)
        y0 = initial_state(p)
        T = 2 * np.pi / w
        desc = f"from rest, omega_pi = {w:g} rad/s, {periods} periods"
        ts = T * np.arange(periods + 1)
    elif name == "spin_reversal":
        p = CeltParams.paper(q_pi=0.0, **overrides)
        y0 = initial_state(p, omega=(0.0, 2.0, -10.0))
        ts = 0.25 * np.arange(periods + 1)
        desc = f"fixed table, omega0 = (0, 2, -10) rad/s, {ts[-1]:g} s"
    elif name == "stick_slip":
        kw = dict(omega_pi=17.0, q_pi=0.01, eps=1e-6, eps_R=1e-6)
        kw.update(overrides)
        p = CeltParams.paper(**kw)
        y0 = initial_state(p)
        T = 2 * np.pi / float(p.omega_pi)
        ts = T * np.arange(5 * periods + 1) / 5  # 5 samples per period (same shape as 5 periods of rest*)
        desc = f"stick-slip, q_pi = {float(p.q_pi):g} m, eps = {float(p.eps):g}, {periods} period(s), T/5 samples"
    else:
        raise ValueError(f"unknown scene {name!r}; known: {SCENES}")
    return BenchmarkScene(name=name, params=p, y0=np.asarray(y0), t1=float(ts[-1]), ts=ts, description=desc)


def state_error(ys: Any, ys_ref: Any) -> float:
    """max over sample times and components of |y - y_ref| (SI units: m/s, rad/s, 1, m, rad).

    Non-finite entries (a failed or stopped solve) give ``inf``.
    """
    a, b = np.asarray(ys, dtype=np.float64), np.asarray(ys_ref, dtype=np.float64)
    if a.shape != b.shape or not np.all(np.isfinite(a)):
        return float("inf")
    return float(np.max(np.abs(a - b)))


def device_string() -> str:
    d = jax.devices()[0]
    return f"{jax.default_backend()}: {d.device_kind} (x{jax.device_count()})"



# --------------------------------------------------------------------------------------------
# timing


def time_call(fn: Callable[[], Any], repeats: int = 3) -> tuple[Any, float, float]:
    """Run ``fn`` once (compile + run) and ``repeats`` more times; return (out, compile_s, run_s).

    ``run_s`` is the best repeat (least disturbed by other load); ``compile_s`` is the first
    call's time minus ``run_s`` (tracing + XLA compilation). Everything is
    ``block_until_ready``-ed. If the first call hit the compilation cache, compile_s ~ 0.
    """
    t = time.perf_counter()
    out = jax.block_until_ready(fn())
    first = time.perf_counter() - t
    best = np.inf
    for _ in range(max(repeats, 1)):
        t = time.perf_counter()
        out = jax.block_until_ready(fn())
        best = min(best, time.perf_counter() - t)
    return out, max(first - best, 0.0), float(best)


class _Counter:
    """Mutable host-side counter (hashable by identity, so it can be a static field)."""

    def __init__(self):
        self.n = 0


# A cache of one object, kept on purpose: the counter is a static field of `CountingLaw`, so one process-wide counter
# lets the counting solve compile once per solver. `count_rhs_evals` holds the lock while it resets and reads it,
# so counts from two threads never mix.
_COUNTER = _Counter()
_COUNTER_LOCK = threading.Lock()


class CountingLaw(AbstractContactLaw):
    """A contact law that counts its evaluations on the host (for RHS counts only, not timing).

    ``simulate`` evaluates the law once per vector-field call and once per accepted-or-rejected
    step in the validity monitor; `count_rhs_evals` subtracts the latter.
    """

    inner: AbstractContactLaw
    counter: _Counter = eqx.field(static=True)
    rolling_resistance: bool = eqx.field(static=True)

    def friction(self, kin, d_c, d_s, p):
        return self.inner.friction(kin, d_c, d_s, p)

    def rolling_distortion(self, kin, p):
        return self.inner.rolling_distortion(kin, p)

    def loads(self, kin, e_x, e_y, n, p):
        def bump(x):
            self.counter.n += int(np.size(x))

        jax.debug.callback(bump, kin.vsx)
        return self.inner.loads(kin, e_x, e_y, n, p)


def count_rhs_evals(scene: BenchmarkScene, solver, *, rtol=1e-8, atol=1e-10, dt0=None, law=None, dtype=None, max_steps=200_000):
    """Right-hand-side calls of one solve (for implicit solvers: Jacobian columns not included --
    a batched jacfwd call is seen once; see the module docstring).

    Counts contact-law calls and subtracts the validity monitor's one per step (+1 at init).
    """
    inner = get_contact_law(law)
    with _COUNTER_LOCK:
        counter = _COUNTER
        counter.n = 0
        cl = CountingLaw(inner=inner, counter=counter, rolling_resistance=inner.rolling_resistance)
        sol = simulate(
            scene.params, scene.y0, scene.t1, ts=scene.ts, solver=solver, rtol=rtol, atol=atol, dt0=dt0,
            contact_law=cl, exact_ts=dt0 is None, dtype=dtype, max_steps=max_steps,
        )  # fmt: skip
        jax.block_until_ready(sol.ys)
        jax.effects_barrier()
        return int(counter.n - int(sol.num_steps) - 1)


def run_diffrax(
    scene: BenchmarkScene,
    solver_name: str,
    *,
    rtol: float = 1e-8,
    atol: float | None = None,
    dt0: float | None = None,
    law=None,
    dtype=None,
    ys_ref: Any = None,
    repeats: int = 2,
    max_steps: int = 200_000,
    count_evals: bool = False,
) -> dict[str, Any]:
    """Solve ``scene`` with one diffrax solver at one tolerance (or fixed ``dt0``), timed.

    ``atol`` defaults to ``rtol * 1e-2`` (the state has O(0.01-10) components). Samples at
    ``scene.ts`` are exact solver states (``exact_ts=True``) for adaptive methods; fixed-step
    methods interpolate. Returns a JSON-able dict (error vs ``ys_ref`` if given).
    """
    solver = make_solver(solver_name)
    atol = rtol * 1e-2 if atol is None else atol
    fixed = SOLVERS[solver_name][1] == "fixed"

    def fn():
        return simulate(
            scene.params, scene.y0, scene.t1, ts=scene.ts, solver=solver, rtol=rtol, atol=atol,
            dt0=dt0, contact_law=law, exact_ts=not fixed, dtype=dtype, max_steps=max_steps,
        )  # fmt: skip

    sol, compile_s, run_s = time_call(fn, repeats)
    ys = np.asarray(sol.ys, dtype=np.float64)
    out = dict(
        scene=scene.name,
        solver=solver_name,
        kind=SOLVERS[solver_name][1],
        law=type(get_contact_law(law)).__name__,
        dtype=str(jnp.dtype(dtype or jnp.float64)),
        rtol=None if fixed else rtol,
        atol=None if fixed else atol,
        dt0=dt0,
        compile_s=compile_s,
        run_s=run_s,
        status=int(sol.status),
        valid=bool(sol.valid),
        steps=int(sol.num_steps),
        accepted=int(sol.num_accepted_steps),
        rejected=int(sol.num_rejected_steps),
        error=None if ys_ref is None else state_error(ys, ys_ref),
        final_state=ys[-1].tolist(),
    )
    if count_evals:
        out["rhs_evals"] = count_rhs_evals(
            scene, solver, rtol=rtol, atol=atol, dt0=dt0, law=law, dtype=dtype, max_steps=max_steps
        )
    return out
