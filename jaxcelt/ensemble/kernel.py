"""The lane kernel: stroboscopic lanes stepped inside one GPU kernel, one thread per lane.

On a GPU the lane pool (`jaxcelt.ensemble.pool`) pays for every step of every slot with a
sequence of XLA kernels, each reading and writing its slots' state from memory, and with a
device-to-host round trip for the while loop's predicate: ≈ 0.3 ms per pool iteration whatever
the width, so a lane that sticks to the base (10⁵–10⁶ stability-limited steps) takes minutes.
Here every lane keeps its state in registers while a Pallas kernel (Triton backend) steps it:

* the right-hand side is `jaxcelt.physics.model.vector_field_and_normal` re-expressed on blocks of lanes
  (`jaxcelt.ensemble.soa.blockwise`), with what the varying parameters do not touch folded at
  trace time;
* one step is `FusedERKStepper`'s algorithm (an explicit FSAL tableau, diffrax's PID controller
  with I-control, the step clipped onto the next section time, diffeqsolve's end-of-interval
  rounding, the validity monitor from the FSAL evaluation and the stop-on-invalid event); the
  stages run in a loop over the tableau's rows, so the kernel holds one copy of the field;
* one kernel call advances every lane of a block of `BLOCK` lanes to its next section time (a
  block steps until all its lanes are there), so a sweep of S samples is S + 1 calls.

Step for step this is the pool's algorithm with its arithmetic in another order (sums of the
field written out, the tableau's zero coefficients multiplied rather than skipped) and with one
simplification: a step "too small to take" is measured against ``|t| 2⁻⁵²`` instead of the
exact spacing of floats at t (within a factor of 2 of it). Lanes therefore agree with the pool's
to the integration tolerance, not bitwise, and may differ by a few steps
(``tests/test_kernel.py``). Only explicit FSAL tableaux with an error estimate (Tsit5, the
default; Dopri5; Dopri8) run here, and no Lyapunov stage (that stays a diffrax solve).

Off a GPU the same kernel runs in Pallas' interpreter (``interpret=True``): slow, for tests.
"""

from __future__ import annotations

import functools
from typing import Any

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt._types import Array
from jaxcelt.ensemble.soa import blockwise
from jaxcelt.ensemble.stepper import erk_tableau
from jaxcelt.integrate.solve import MIN_STEP_ULPS
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import field_time, vector_field_and_normal

__all__ = ["BLOCK", "kernel_supported", "make_segment", "run_kernel_lanes", "KERNEL_FIELDS"]

BLOCK = 32
"""lanes per kernel program: one warp, one lane per thread"""

KERNEL_FIELDS = ("tprev", "tnext", "num_steps", "code", "first_invalid_t", "first_invalid_kind", "min_N", "min_n3")
"""per-lane scalars of the kernel's state besides y (13) and the FSAL derivative f (13). ``code``:
0 running or done, 2 stopped at an invalid state, 3 step size collapsed (`jaxcelt.STATUS`)"""
_INT = ("num_steps", "code", "first_invalid_kind")


def kernel_supported(solver: Any) -> bool:
    """Whether ``solver`` runs in the lane kernel (an explicit FSAL tableau with an error estimate)."""
    return erk_tableau(solver) is not None


def _pallas():
    from jax.experimental import pallas as pl

    return pl


def _triton_params() -> Any:
    """One warp per program (`BLOCK` = 32 lanes, one per thread); no software pipelining (no loads in the loop)."""
    from jax.experimental.pallas import triton as plt

    return plt.CompilerParams(num_warps=1, num_stages=1)


class _Segment:
    """The kernel of one call: every lane of a block to its target time (module docstring)."""

    def __init__(self, cfg: Any, params_of: Any, nvary: int, dtype: Any):
        law = get_contact_law(cfg.contact_law)
        tab = erk_tableau(cfg.solver)
        if tab is None:
            raise ValueError(f"the lane kernel needs an explicit FSAL Runge-Kutta solver, got {type(cfg.solver).__name__}")
        self.dtype = np.dtype(dtype)
        self.c = [float(x) for x in np.asarray(tab.c, dtype=float)]
        ns = len(self.c)  # stages after the first (FSAL) one
        a = np.zeros((ns, ns + 1))
        for i, row in enumerate(tab.a_lower):
            a[i, : len(row)] = np.asarray(row, dtype=float)
        self.a = a
        self.b = np.asarray(tab.b_sol, dtype=float)
        self.e = np.asarray(tab.b_error, dtype=float)
        self.fsal_is_y1 = self.b[-1] == 0.0 and np.array_equal(a[-1, :-1], self.b[:-1])
        pid = diffrax.PIDController(rtol=cfg.rtol, atol=cfg.atol)
        self.safety, self.fmin, self.fmax = float(pid.safety), float(pid.factormin), float(pid.factormax)
        self.rtol, self.atol = float(cfg.rtol), float(cfg.atol)
        self.q = float(cfg.solver.error_order(diffrax.ODETerm(lambda t, y, a: y)))
        self.max_steps = int(cfg.max_steps)
        self.stop_on_invalid = bool(cfg.stop_on_invalid)
        self.nvary = nvary
        one = np.zeros((), self.dtype)
        ex_pv = tuple(one for _ in range(nvary))
        self.rhs = blockwise(lambda t, y, pv: vector_field_and_normal(t, y, params_of(pv), law), one,
                             np.zeros(13, self.dtype), ex_pv)  # fmt: skip
        self.omega_of = lambda pv: params_of(pv).omega_pi

    def field_time(self, t: Array, pv: tuple[Array, ...]) -> Array:
        """The time the field is evaluated at, in the state's dtype (`jaxcelt.physics.model.field_time`): the
        kernel's times are float64; a float32 field gets the forcing phase from one period."""
        return field_time(t, self.omega_of(pv), self.dtype)

    def field(self, t: Array, y: list[Array], pv: tuple[Array, ...]) -> tuple[list[Array], Array, Array]:
        t = self.field_time(t, pv)
        yo = np.empty(13, dtype=object)
        for m, e in enumerate(y):
            yo[m] = e
        f, (N, den) = self.rhs(t, yo, pv)
        full = lambda e: e if np.ndim(e) == 1 else jnp.full(t.shape, np.asarray(e), self.dtype)  # noqa: E731
        return [full(e) for e in f], full(N[()]), full(den[()])

    def step(self, s: dict, target: Array, t1: Array, floor: Array, pv: tuple[Array, ...]) -> tuple[dict, Array]:
        """One step of every lane of the block that is still short of ``target``: (the new state, which lanes stepped)."""
        dt_ = self.dtype
        y0, f0, t0 = s["y"], s["f"], s["tprev"]
        act = (s["code"] == 0) & (s["num_steps"] < self.max_steps) & (t0 < target)
        dt = s["tnext"] - t0  # times in float64 (`field_time`)
        dts = dt.astype(dt_)
        ns = len(self.c)
        zero = jnp.zeros(t0.shape, dt_)
        ks = [[f * dts for f in f0]] + [[zero] * 13 for _ in range(ns)]

        def pick(i, col, dtype=dt_):  # col[i] for a traced stage index: a chain of scalar selects (no constant arrays in a kernel)
            out = jnp.asarray(col[-1], dtype)
            for r in range(len(col) - 2, -1, -1):
                out = jnp.where(i == r, jnp.asarray(col[r], dtype), out)
            return out

        def stage(i, carry):
            ks, _, _, _, _ = carry
            coef = [pick(i, [float(x) for x in self.a[:, j]]) for j in range(ns)]
            yi = [y0[m] + sum(coef[j] * ks[j][m] for j in range(ns) if self.a[:, j].any()) for m in range(13)]
            fi, N, den = self.field(t0 + pick(i, self.c, jnp.float64) * dt, yi, pv)
            new = [f * dts for f in fi]
            ks = [ks[0]] + [[jnp.where(i + 1 == j, new[m], ks[j][m]) for m in range(13)] for j in range(1, ns + 1)]
            return ks, yi, fi, N, den

        ks, yi, fi, N, den = jax.lax.fori_loop(0, ns, stage, (ks, y0, f0, zero, zero))
        if self.fsal_is_y1:
            y1 = yi
        else:
            y1 = [y0[m] + sum(float(self.b[j]) * ks[j][m] for j in range(ns + 1) if self.b[j] != 0) for m in range(13)]
        err = [sum(float(self.e[j]) * ks[j][m] for j in range(ns + 1) if self.e[j] != 0) for m in range(13)]
        err = [jnp.where(jnp.isnan(x), jnp.inf, x) for x in err]
        y1_nan = functools.reduce(jnp.logical_or, [jnp.isnan(x) for x in y1])
        y1s = [jnp.where(y1_nan, a, b) for a, b in zip(y0, y1)]
        r = [x / (self.atol + jnp.maximum(jnp.abs(a), jnp.abs(b)) * self.rtol) for x, a, b in zip(err, y0, y1s)]
        scaled = jnp.sqrt(sum(x * x for x in r)) / np.sqrt(13.0).astype(dt_)
        keep = scaled < 1
        factor = jnp.clip(
            self.safety * (1 / scaled) ** (1.0 / self.q),
            jnp.where(keep, 1.0, self.fmin).astype(dt_),
            jnp.where(keep, self.fmax, self.safety).astype(dt_),
        )
        tprev = jnp.where(keep, s["tnext"], t0)
        tnext = tprev + dt * factor.astype(jnp.float64)
        tnext = jnp.where(tprev >= target, tnext, jnp.minimum(tnext, target))  # onto the section time
        span = tnext - tprev
        small = ~keep & ~((span >= MIN_STEP_ULPS * jnp.abs(tprev) * np.finfo(np.float64).eps) & (span > 0))
        tprev = jnp.minimum(tprev, t1)  # diffeqsolve's end-of-interval rounding
        tnext = jnp.where(tnext > floor, jnp.where(keep, t1, tprev + 0.5 * (t1 - tprev)), tnext)
        kind = jnp.where(den <= 0, 3, jnp.where(y1[8] <= 0, 2, jnp.where(N <= 0, 1, 0))).astype(jnp.int32)
        new_invalid = keep & (kind > 0) & (s["first_invalid_kind"] == 0)
        code = jnp.where(small & (s["code"] == 0), 3, s["code"])
        if self.stop_on_invalid:
            code = jnp.where(new_invalid & (code == 0), 2, code)
        new = dict(
            y=[jnp.where(keep, a, b) for a, b in zip(y1, y0)],
            f=[jnp.where(keep, a, b) for a, b in zip(fi, f0)],
            tprev=tprev,
            tnext=tnext,
            num_steps=s["num_steps"] + 1,
            code=code.astype(jnp.int32),
            first_invalid_t=jnp.where(new_invalid, tprev, s["first_invalid_t"]),
            first_invalid_kind=jnp.where(new_invalid, kind, s["first_invalid_kind"]),
            min_N=jnp.where(keep, jnp.minimum(s["min_N"], N), s["min_N"]),
            min_n3=jnp.where(keep, jnp.minimum(s["min_n3"], y1[8]), s["min_n3"]),
        )
        return jax.tree_util.tree_map(lambda a, b: jnp.where(act, a, b), new, s), act

    def kernel(self, *refs):
        nst = 26 + len(KERNEL_FIELDS)
        ins = refs[: nst + 3 + self.nvary]
        outs = refs[nst + 3 + self.nvary :]
        vals = [r[...] for r in ins]
        s = _unflatten(vals[:nst])
        target, t1, floor = vals[nst : nst + 3]
        pv = tuple(vals[nst + 3 :])
        s["tnext"] = jnp.where(s["tprev"] < target, jnp.minimum(s["tnext"], target), s["tnext"])

        def cond(c):
            s, _, more = c
            return more

        def body(c):
            s, it, _ = c
            s, act = self.step(s, target, t1, floor, pv)
            return s, it + 1, jnp.max(act.astype(jnp.int32)) > 0

        s, it, _ = jax.lax.while_loop(cond, body, (s, jnp.zeros((), jnp.int32), jnp.asarray(True)))
        for r, v in zip(outs, _flatten(s) + [jnp.full(target.shape, it, jnp.int32)]):
            r[...] = v

    def __call__(self, flat: list[Array], target: Array, t1: Array, floor: Array, pv: tuple[Array, ...],
                 interpret: bool) -> tuple[list[Array], Array]:  # fmt: skip
        pl = _pallas()
        L = target.shape[0]
        spec = pl.BlockSpec((BLOCK,), lambda i: (i,))
        args = list(flat) + [target, t1, floor] + list(pv)
        out_shape = [jax.ShapeDtypeStruct((L,), x.dtype) for x in flat] + [jax.ShapeDtypeStruct((L,), jnp.int32)]
        kw = {} if interpret else {"compiler_params": _triton_params()}
        out = pl.pallas_call(
            self.kernel, out_shape=out_shape, grid=(L // BLOCK,), in_specs=[spec] * len(args),
            out_specs=[spec] * len(out_shape), interpret=interpret, name="jaxcelt_lanes", **kw,
        )(*args)  # fmt: skip
        return list(out[:-1]), out[-1]


def make_segment(cfg: Any, params_of: Any, nvary: int) -> _Segment:
    """The kernel for a sweep's settings ``cfg`` (`jaxcelt.ensemble.SweepConfig`); ``params_of``
    rebuilds a lane's parameters from its ``nvary`` varying values (the others plain numbers)."""
    return _Segment(cfg, params_of, nvary, cfg.dtype)


def _flatten(s: dict) -> list[Array]:
    return list(s["y"]) + list(s["f"]) + [s[k] for k in KERNEL_FIELDS]


def _unflatten(v: list[Array]) -> dict:
    s = dict(y=list(v[:13]), f=list(v[13:26]))
    s.update(zip(KERNEL_FIELDS, v[26:]))
    return s


def run_kernel_lanes(
    seg: _Segment,
    lanes0: Any,
    pv: tuple[Array, ...],
    ts_all: Array,
    interpret: bool,
) -> tuple[dict[str, Array], Array, Array]:
    """Every lane from its start (`jaxcelt.ensemble.start_lanes`' lane states, their times made float64
    by `jaxcelt.ensemble.float64_times`) to its last section time: (outputs as
    `jaxcelt.ensemble.lane_outputs` gives them, the samples (L, S, 13), the kernel's loop iterations
    per lane summed over the calls). ``ts_all``: (L, S) float64 section times."""
    dt_ = seg.dtype
    L, S = ts_all.shape
    st = lanes0.step_state
    code = jnp.where(lanes0.done & (st.first_invalid_kind > 0) & seg.stop_on_invalid, 2, 0).astype(jnp.int32)
    s = dict(
        y=[lanes0.y[:, m] for m in range(13)],
        f=[st.f[:, m] for m in range(13)],
        tprev=lanes0.tprev,
        tnext=lanes0.tnext,
        num_steps=lanes0.num_steps.astype(jnp.int32),
        code=code,
        first_invalid_t=st.first_invalid_t,
        first_invalid_kind=st.first_invalid_kind.astype(jnp.int32),
        min_N=st.min_N,
        min_n3=st.min_n3,
    )
    # padding lanes (done at the start without a reason) are parked: a step budget of zero
    parked = lanes0.done & (code == 0)
    s["num_steps"] = jnp.where(parked, seg.max_steps, s["num_steps"])
    t1, floor = lanes0.t1, lanes0.floor

    def call(flat, target):
        return seg(flat, target, t1, floor, pv, interpret)

    def section(carry, target):
        flat, iters = carry
        flat, it = call(flat, target)
        y = jnp.stack(flat[:13], axis=-1)
        sample = jnp.where((flat[26] >= target)[:, None], y, jnp.inf)
        return (flat, iters + it), sample

    flat = _flatten(s)
    (flat, iters), samples = jax.lax.scan(section, (flat, jnp.zeros((L,), jnp.int32)), ts_all.T)
    s = _unflatten(flat)
    samples = jnp.swapaxes(samples, 0, 1).astype(dt_)
    ok = s["code"] == 0
    num_steps = jnp.where(parked, lanes0.num_steps, s["num_steps"])
    status = jnp.where(ok, jnp.where(s["tprev"] >= t1, 0, 1), s["code"]).astype(jnp.int32)
    out = dict(
        y_final=jnp.stack(s["y"], axis=-1),
        status=jnp.where(parked, 0, status),
        num_steps=num_steps,
        first_invalid_t=s["first_invalid_t"],
        first_invalid_kind=s["first_invalid_kind"],
        min_N=s["min_N"],
        max_tilt=jnp.arccos(jnp.clip(s["min_n3"], -1, 1)),
    )
    return out, samples, iters
