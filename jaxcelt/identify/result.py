"""The outcome of a fit (`FitResult`): fitted values, Gauss-Newton uncertainty, history, timings; and `predict`.

Uncertainty (`FitResult.stderr`, ``ci95``, ``corr``): the Gauss-Newton approximation cov(z) = s^2 (J^T J)^-1 at the
optimum with s^2 = RSS_misfit / (n_data - n_unknowns), marginalised over the window states, mapped to the physical
parameters by the delta method.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import equinox as eqx
import jax
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt.identify.observe import OBSERVABLES, SENSOR_KINDS, observe, rotation_matrix
from jaxcelt.identify.optimisers import Trace
from jaxcelt.identify.options import FitOptions
from jaxcelt.identify.problem import TIME_OFFSET_SCALE, Problem, theta_and_jacobian, to_device
from jaxcelt.physics.params import CeltParams

__all__ = ["FitResult", "make_result", "split_times", "predict"]


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



def split_times(iter_marks: list[float]) -> tuple[float, float]:
    """(compile time, run time) from the iteration end times: the first iteration pays for
    compilation; it is counted as a typical (median) iteration in the run time."""
    iter_times = np.diff(np.asarray(iter_marks))
    typical = float(np.median(iter_times[1:])) if iter_times.size > 1 else 0.0
    compile_time = max(float(iter_times[0]) - typical, 0.0) if iter_times.size else 0.0
    return compile_time, float(iter_marks[-1] - iter_marks[0]) - compile_time


def make_result(
    prob: Problem, trace: Trace, r: np.ndarray, Jflat: np.ndarray, config: FitOptions, t_start: float
) -> FitResult:
    """`FitResult` at the final unknowns ``trace.zf`` with residuals ``r`` and Jacobian ``Jflat`` there; the times
    from ``trace.iter_marks`` (`split_times`) and ``t_start`` (the start of the fit)."""
    zf, loss_hist, par_hist, converged = trace.zf, trace.loss_history, trace.param_history, trace.converged
    compile_time, wall = split_times(trace.iter_marks)
    # on the host or in compiled programs: eager jnp operations would compile one program each
    free, P = prob.free, len(prob.free)
    zf = np.asarray(zf, dtype=float)
    th, dth = (np.asarray(a) for a in theta_and_jacobian(prob, zf))
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
    if config.uncertainty:
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
        params=eqx.tree_at(lambda p: [getattr(p, n) for n in free], prob.params0, [to_device(th[i]) for i in range(P)]),
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
        optimiser=config.optimiser,
        windows=config.windows,
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

