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

Options (`jaxcelt.ensemble.SweepConfig`): ``field_dtype="float32"`` evaluates the field in float32
while the state, the stage sums and the error control stay float64 (mixed precision);
``stiffness="auto"`` lets each lane switch to a Rodas4P step while its explicit steps are
stability-limited (`jaxcelt.ensemble.stiff`). The step, the controller and the loop do not depend
on the wobblestone: `jaxcelt.ensemble.kernel_ode.solve_lanes` runs them for any per-lane field.

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
from jaxcelt.ensemble.stiff import step_either
from jaxcelt.integrate.solve import HEADING_GAP, MIN_STEP_ULPS
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import field_time, vector_field_and_normal

__all__ = [
    "BLOCK",
    "KERNEL_FIELDS",
    "Segment",
    "flatten_state",
    "kernel_supported",
    "make_segment",
    "run_kernel_lanes",
    "unflatten_state",
]

BLOCK = 32
"""lanes per kernel program: one warp, one lane per thread"""

KERNEL_FIELDS = ("tprev", "tnext", "num_steps", "code", "first_invalid_t", "first_invalid_kind", "min_N", "min_n3",
                 "stiff", "stiff_count", "stiff_steps")  # fmt: skip
"""per-lane scalars of the kernel's state besides y (n) and the FSAL derivative f (n). ``code``:
0 running or done, 2 stopped at an invalid state, 3 step size collapsed, 4 past validity at the heading's
singularity (`jaxcelt.STATUS`);
``stiff``: 1 while the lane takes the stiff step (`jaxcelt.ensemble.stiff`), ``stiff_count`` its
switch's counter, ``stiff_steps`` the stiff steps taken"""
_INT = ("num_steps", "code", "first_invalid_kind", "stiff", "stiff_count", "stiff_steps")


def _pick(i: Array, col: list[float], dtype: Any) -> Array:
    """col[i] for a traced index: a chain of scalar selects (no constant arrays in a kernel)."""
    out = jnp.asarray(col[-1], dtype)
    for r in range(len(col) - 2, -1, -1):
        out = jnp.where(i == r, jnp.asarray(col[r], dtype), out)
    return out


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


class Segment:
    """The kernel of one call: every lane of a block to its target time (module docstring).

    ``field``: a per-lane function ``(t, y, pv) -> (dy/dt, (N, den))`` of the state's dtype, with
    the normal force N and the denominator ``den`` of the heading rate that the validity monitor
    reads, or None for the wobblestone's (`jaxcelt.physics.model.vector_field_and_normal`);
    ``n``: the state's size; ``omega_of``: the forcing frequency of a lane's parameter values
    (for `field_time`; None: times pass unchanged); ``n3_index``: the state component read as n3
    by the monitor (None: none)."""

    def __init__(self, cfg: Any, params_of: Any, nvary: int, dtype: Any, *, field: Any = None, n: int = 13,
                 omega_of: Any = None, n3_index: int | None = 8):  # fmt: skip
        tab = erk_tableau(cfg.solver)
        if tab is None:
            raise ValueError(
                f"the lane kernel needs an explicit FSAL Runge-Kutta solver, got {type(cfg.solver).__name__}"
            )
        if field is None:
            law = get_contact_law(cfg.contact_law)
            field = lambda t, y, pv: vector_field_and_normal(t, y, params_of(pv), law)  # noqa: E731
            omega_of = lambda pv: params_of(pv).omega_pi  # noqa: E731
        self.n = int(n)
        self.n3_index = n3_index
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
        # the stiffness switch (`jaxcelt.ensemble.stiff`): on where asked and the tableau's last two
        # stages share their time (the explicit step's stiffness estimate needs it)
        self.stiff = getattr(cfg, "stiffness", "off") == "auto" and ns >= 2 and self.c[-1] == self.c[-2]
        self.nvary = nvary
        # mixed precision: the field in float32, the state, its sums and the error control in float64
        self.fdtype = np.dtype(getattr(cfg, "field_dtype", None) or dtype)
        one = np.zeros((), self.fdtype)
        ex_pv = tuple(one for _ in range(nvary))
        ex_y = np.zeros(self.n, self.fdtype)
        self.rhs = blockwise(field, one, ex_y, ex_pv)
        if self.stiff:

            def tangent(t, y, pv, tt, ty):
                return jax.jvp(lambda t_, y_: field(t_, y_, pv)[0], (t, y), (tt, ty))

            self.rhs_jvp = blockwise(tangent, one, ex_y, ex_pv, one, ex_y)
        self.omega_of = omega_of

    def field_time(self, t: Array, pv: tuple[Array, ...]) -> Array:
        """The time the field is evaluated at, in the field's dtype (`jaxcelt.physics.model.field_time`): the
        kernel's times are float64; a float32 field gets the forcing phase from one period."""
        pv = tuple(x.astype(self.fdtype) for x in pv)
        if self.omega_of is None:
            return t.astype(self.fdtype)
        return field_time(t, self.omega_of(pv), self.fdtype)

    def _full(self, e: Any, shape: tuple[int, ...]) -> Array:
        """A field output as a block in the state's dtype."""
        return e.astype(self.dtype) if np.ndim(e) == 1 else jnp.full(shape, np.asarray(e), self.dtype)

    def _obj(self, y: list[Array]) -> np.ndarray:
        yo = np.empty(self.n, dtype=object)
        for m, e in enumerate(y):
            yo[m] = e.astype(self.fdtype)
        return yo

    def field(self, t: Array, y: list[Array], pv: tuple[Array, ...]) -> tuple[list[Array], Array, Array]:
        t = self.field_time(t, pv)
        f, (N, den) = self.rhs(t, self._obj(y), tuple(x.astype(self.fdtype) for x in pv))
        return [self._full(e, t.shape) for e in f], self._full(N[()], t.shape), self._full(den[()], t.shape)

    def field_tangent(self, t: Array, y: list[Array], pv: tuple[Array, ...], tt: Array,
                      ty: list[Array]) -> tuple[list[Array], list[Array]]:  # fmt: skip
        """The field and its derivative along (tt, ty) in (t, y)."""
        t = self.field_time(t, pv)
        f, df = self.rhs_jvp(t, self._obj(y), tuple(x.astype(self.fdtype) for x in pv), tt.astype(self.fdtype),
                             self._obj(ty))  # fmt: skip
        return [self._full(e, t.shape) for e in f], [self._full(e, t.shape) for e in df]

    def validity(self, y1: list[Array], N: Array, den: Array) -> Array:
        """0 valid, else the first failed condition: 3 heading singular, 2 n3 <= 0, 1 N <= 0."""
        n3 = y1[self.n3_index] if self.n3_index is not None else jnp.ones_like(N)
        return jnp.where(den <= 0, 3, jnp.where(n3 <= 0, 2, jnp.where(N <= 0, 1, 0))).astype(jnp.int32)

    def control(self, s: dict, y0: list[Array], y1: list[Array], err: list[Array], dt: Array, q: float,
                target: Array, t1: Array, floor: Array) -> dict:  # fmt: skip
        """diffrax's PID controller (I-control) with exponent 1/q on the scaled RMS error, the step
        clipped onto the section time, diffeqsolve's end-of-interval rounding."""
        dt_ = self.dtype
        t0 = s["tprev"]
        err = [jnp.where(jnp.isnan(x), jnp.inf, x) for x in err]
        y1_nan = functools.reduce(jnp.logical_or, [jnp.isnan(x) for x in y1])
        y1s = [jnp.where(y1_nan, a, b) for a, b in zip(y0, y1)]
        r = [x / (self.atol + jnp.maximum(jnp.abs(a), jnp.abs(b)) * self.rtol) for x, a, b in zip(err, y0, y1s)]
        scaled = jnp.sqrt(sum(x * x for x in r)) / np.sqrt(float(self.n)).astype(dt_)
        keep = scaled < 1
        factor = jnp.clip(
            self.safety * (1 / scaled) ** (1.0 / q),
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
        return dict(keep=keep, tprev=tprev, tnext=tnext, small=small)

    def explicit(
        self, s: dict, pv: tuple[Array, ...]
    ) -> tuple[list[Array], list[Array], list[Array], Array, Array, Array]:
        """One explicit step from every lane's state: (y1, its derivative, the error, N, den, h rho)
        with rho the stiffness estimate |f(y7) - f(y6)| / |y7 - y6| of the last two stages (0
        where the switch is off)."""
        dt_ = self.dtype
        n = self.n
        y0, f0, t0 = s["y"], s["f"], s["tprev"]
        dt = s["tnext"] - t0  # times in float64 (`field_time`)
        dts = dt.astype(dt_)
        ns = len(self.c)
        zero = jnp.zeros(t0.shape, dt_)
        ks = [[f * dts for f in f0]] + [[zero] * n for _ in range(ns)]

        def stage(i, carry):
            ks, yi, fi, _, _, yp, fp = carry
            coef = [_pick(i, [float(x) for x in self.a[:, j]], dt_) for j in range(ns)]
            yn = [y0[m] + sum(coef[j] * ks[j][m] for j in range(ns) if self.a[:, j].any()) for m in range(n)]
            fn, N, den = self.field(t0 + _pick(i, self.c, jnp.float64) * dt, yn, pv)
            new = [f * dts for f in fn]
            ks = [ks[0]] + [[jnp.where(i + 1 == j, new[m], ks[j][m]) for m in range(n)] for j in range(1, ns + 1)]
            return ks, yn, fn, N, den, yi, fi

        ks, yi, fi, N, den, yp, fp = jax.lax.fori_loop(0, ns, stage, (ks, y0, f0, zero, zero, y0, f0))
        if self.fsal_is_y1:
            y1 = yi
        else:
            y1 = [y0[m] + sum(float(self.b[j]) * ks[j][m] for j in range(ns + 1) if self.b[j] != 0) for m in range(n)]
        err = [sum(float(self.e[j]) * ks[j][m] for j in range(ns + 1) if self.e[j] != 0) for m in range(n)]
        if self.stiff:
            num = sum((a - b) * (a - b) for a, b in zip(fi, fp))
            den2 = sum((a - b) * (a - b) for a, b in zip(yi, yp))
            hrho = jnp.abs(dts) * jnp.sqrt(num / jnp.where(den2 > 0, den2, jnp.inf))
        else:
            hrho = zero
        return y1, fi, err, N, den, hrho

    def step(self, s: dict, target: Array, t1: Array, floor: Array, pv: tuple[Array, ...]) -> tuple[dict, Array]:
        """One step of every lane of the block that is still short of ``target``: (the new state, which lanes stepped)."""
        y0, f0, t0 = s["y"], s["f"], s["tprev"]
        act = (s["code"] == 0) & (s["num_steps"] < self.max_steps) & (t0 < target)
        dt = s["tnext"] - t0
        if self.stiff:
            y1, f1, err, N, den, q, mode, count = step_either(self, s, pv, act)
        else:
            y1, f1, err, N, den, _ = self.explicit(s, pv)
            q = self.q
        ctl = self.control(s, y0, y1, err, dt, q, target, t1, floor)
        keep = ctl["keep"]
        kind = self.validity(y1, N, den)
        new_invalid = keep & (kind > 0) & (s["first_invalid_kind"] == 0)
        code = jnp.where(ctl["small"] & (s["code"] == 0), 3, s["code"])
        if self.stop_on_invalid:
            code = jnp.where(new_invalid & (code == 0), 2, code)
        if self.n3_index is not None:  # past validity on its side: the heading's singularity (`HEADING_GAP`)
            past = (s["first_invalid_kind"] > 0) | (kind > 0)
            code = jnp.where(keep & past & (1 - y1[7] * y1[7] < HEADING_GAP) & (code == 0), 4, code)
        n3 = y1[self.n3_index] if self.n3_index is not None else s["min_n3"]
        new = dict(
            y=[jnp.where(keep, a, b) for a, b in zip(y1, y0)],
            f=[jnp.where(keep, a, b) for a, b in zip(f1, f0)],
            tprev=ctl["tprev"],
            tnext=ctl["tnext"],
            num_steps=s["num_steps"] + 1,
            code=code.astype(jnp.int32),
            first_invalid_t=jnp.where(new_invalid, ctl["tprev"], s["first_invalid_t"]),
            first_invalid_kind=jnp.where(new_invalid, kind, s["first_invalid_kind"]),
            min_N=jnp.where(keep, jnp.minimum(s["min_N"], N), s["min_N"]),
            min_n3=jnp.where(keep, jnp.minimum(s["min_n3"], n3), s["min_n3"]),
            stiff=s["stiff"],
            stiff_count=s["stiff_count"],
            stiff_steps=s["stiff_steps"],
        )
        if self.stiff:
            new["stiff_steps"] = s["stiff_steps"] + (s["stiff"] > 0).astype(jnp.int32)
            new["stiff"], new["stiff_count"] = mode, count
        return jax.tree_util.tree_map(lambda a, b: jnp.where(act, a, b), new, s), act

    def kernel(self, *refs):
        nst = 2 * self.n + len(KERNEL_FIELDS)
        ins = refs[: nst + 3 + self.nvary]
        outs = refs[nst + 3 + self.nvary :]
        vals = [r[...] for r in ins]
        s = unflatten_state(vals[:nst], self.n)
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
        for r, v in zip(outs, flatten_state(s) + [jnp.full(target.shape, it, jnp.int32)]):
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


def make_segment(cfg: Any, params_of: Any, nvary: int) -> Segment:
    """The kernel for a sweep's settings ``cfg`` (`jaxcelt.ensemble.SweepConfig`); ``params_of``
    rebuilds a lane's parameters from its ``nvary`` varying values (the others plain numbers)."""
    return Segment(cfg, params_of, nvary, cfg.dtype)


def flatten_state(s: dict) -> list[Array]:
    """The kernel's per-lane state as the list of (L,) arrays its call takes: y, f, then `KERNEL_FIELDS`."""
    return list(s["y"]) + list(s["f"]) + [s[k] for k in KERNEL_FIELDS]


def unflatten_state(v: list[Array], n: int) -> dict:
    """The inverse of `flatten_state` for a state of size ``n``."""
    s = dict(y=list(v[:n]), f=list(v[n : 2 * n]))
    s.update(zip(KERNEL_FIELDS, v[2 * n :]))
    return s


def run_kernel_lanes(
    seg: Segment,
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
        stiff=jnp.zeros(L, jnp.int32),
        stiff_count=jnp.zeros(L, jnp.int32),
        stiff_steps=jnp.zeros(L, jnp.int32),
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

    flat = flatten_state(s)
    (flat, iters), samples = jax.lax.scan(section, (flat, jnp.zeros((L,), jnp.int32)), ts_all.T)
    s = unflatten_state(flat, 13)
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
        stiff_steps=s["stiff_steps"],
    )
    return out, samples, iters
