"""Automatic regime labels of a stroboscopic sweep: period-k, quasi-periodic, chaotic, invalid, failed.

Local motion (attitude and spin) and global motion (path of the geometric centre O on the
base) are labelled separately, as the paper does (Figs. 4-7: "locally periodic with
unbounded global wandering" at omega_pi = 15.6 rad/s).

Local label, from the section samples x_j = (omega, n)(t_j) (state components 3:9, which
with psi determine the dynamics; r_C does not feed back):

* ``failed``   -- the solve did not finish (status 1 or 3, e.g. max_steps);
* ``invalid``  -- the model left its validity (lift-off, n3 <= 0) somewhere in the run, or the
  lane was stopped there (status 2, ``stop_on_invalid``), or, integrated on, it ended lying on its
  side (status 4, `jaxcelt.integrate.solve.HEADING_GAP`);
* ``period-k`` -- smallest k <= ``max_period`` with max_j |x_{j+k} - x_j| <= tol (1 + max|x|)
  over the samples; k = 1 is the forcing period (a period-1 orbit of the stroboscopic map);
* otherwise, from the largest Lyapunov exponent lambda_1 and, where it comes with one, its
  standard error s (`jaxcelt.integrate.lyapunov.exponent_stderr`; s = 0 if not given), with the interval
  [lo, hi] = lambda_1 -+ ``confidence`` s and th = ``chaos_threshold`` [1/s]:

  - ``chaotic``        -- lo > th;
  - ``converging``     -- hi < -th: no period was found in the samples, but every perturbation
    shrinks, so the lane is attracted to a periodic orbit (on the stroboscopic section an
    attractor with a negative largest exponent is a sink) that it has not reached to the
    detector's tolerance yet: a slowly attracting orbit, or a period above ``max_period``;
  - ``quasi-periodic`` -- -th <= lo and hi <= th (an exponent indistinguishable from 0);
  - ``uncertain``      -- the interval reaches across +-th: the window was too short to tell,
    integrate the exponent over more periods;
  - ``aperiodic``      -- no exponent was computed.

Global label: ``unbounded`` when O's net horizontal displacement over the samples exceeds
``drift_threshold`` [m] and is at least half of its maximum excursion (steady wandering
away), else ``bounded``. The thresholds are heuristics; the raw numbers (drift, excursion,
exponent) are kept beside the labels.

Along the swept axis of a one-parameter sweep dataset, `regime_ranges` and `regime_runs` group
consecutive lanes with the same label into ranges (the regime table of ``jaxcelt bifurcation``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["REGIMES", "GLOBAL_MOTION", "detect_period", "classify", "regime_names", "regime_ranges", "regime_runs"]

REGIMES: dict[int, str] = {
    0: "failed",
    1: "invalid",
    2: "periodic",
    3: "quasi-periodic",
    4: "chaotic",
    5: "aperiodic",
    6: "converging",
    7: "uncertain",
}
"""Integer codes of the local regime (periodic carries its period k separately)."""
GLOBAL_MOTION: dict[int, str] = {0: "bounded", 1: "unbounded", -1: "unknown"}


def detect_period(x: np.ndarray, *, max_period: int = 16, tol: float = 1e-4) -> int:
    """Smallest period k (in samples) of a sequence x (S, d), or 0 if none up to max_period.

    Criterion: max over j and components of |x[j+k] - x[j]| <= tol * (1 + max|x|), using all
    S - k pairs (needs S >= 2k so each point is compared at least once). Non-finite -> 0.
    """
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    if not np.all(np.isfinite(x)):
        return 0
    scale = tol * (1.0 + np.max(np.abs(x)))
    S = x.shape[0]
    for k in range(1, max_period + 1):
        if S < 2 * k:
            break
        if np.max(np.abs(x[k:] - x[:-k])) <= scale:
            return k
    return 0


def classify(
    samples: np.ndarray,
    status: np.ndarray,
    valid: np.ndarray,
    r_O: np.ndarray,
    lyapunov: np.ndarray | None = None,
    *,
    lyapunov_stderr: np.ndarray | None = None,
    max_period: int = 16,
    tol: float = 1e-4,
    chaos_threshold: float = 0.02,
    confidence: float = 2.0,
    drift_threshold: float = 0.05,
) -> dict[str, np.ndarray]:
    """Labels for every lane (any leading shape ``...``).

    Args:
        samples: section states (..., S, 13). status, valid: (...). r_O: (..., S, 3) [m].
        lyapunov: (...) [1/s] or None.
        lyapunov_stderr: (...) standard errors of ``lyapunov`` [1/s], or None (no error known:
            the point estimate decides); NaN entries count as 0.
        max_period, tol: see `detect_period`.
        chaos_threshold: [1/s] an exponent above it is chaos, below minus it a sink; the
            finite-time estimate of a quasi-periodic orbit is O(1/t) from 0.
        confidence: half-width of the exponent's interval in standard errors.
        drift_threshold: net displacement of O that counts as unbounded wandering [m].

    Returns:
        dict of arrays (...): ``regime`` (`REGIMES` code), ``period`` (k, 0 if not periodic),
        ``global_motion`` (`GLOBAL_MOTION` code).
    """
    samples = np.asarray(samples)
    lead = samples.shape[:-2]
    flat = samples.reshape(-1, *samples.shape[-2:])
    st = np.asarray(status).reshape(-1)
    va = np.asarray(valid).reshape(-1)
    ro = np.asarray(r_O).reshape(-1, *np.shape(r_O)[-2:])
    ly = None if lyapunov is None else np.asarray(lyapunov, dtype=float).reshape(-1)
    if not (np.isfinite(chaos_threshold) and chaos_threshold >= 0):
        raise ValueError(f"classify: 'chaos_threshold' must be finite and >= 0, got {chaos_threshold!r}")
    if not (np.isfinite(confidence) and confidence >= 0):
        raise ValueError(f"classify: 'confidence' must be finite and >= 0, got {confidence!r}")
    se = np.zeros(flat.shape[0])
    if lyapunov_stderr is not None:
        se = np.asarray(lyapunov_stderr, dtype=float).reshape(-1)
        se = np.where(np.isnan(se), 0.0, se)
    regime = np.zeros(flat.shape[0], dtype=np.int32)
    period = np.zeros(flat.shape[0], dtype=np.int32)
    glob = np.full(flat.shape[0], -1, dtype=np.int32)
    for i in range(flat.shape[0]):
        if st[i] in (2, 4):  # stopped at its first invalid state (stop_on_invalid), or on its side past validity
            regime[i] = 1
            continue
        if st[i] != 0:
            regime[i] = 0
            continue
        k = detect_period(flat[i][:, 3:9], max_period=max_period, tol=tol)
        if not va[i]:
            regime[i] = 1
        elif k > 0:
            regime[i], period[i] = 2, k
        elif ly is not None and np.isfinite(ly[i]):
            lo, hi = ly[i] - confidence * se[i], ly[i] + confidence * se[i]
            if lo > chaos_threshold:
                regime[i] = 4
            elif hi < -chaos_threshold:
                regime[i] = 6
            elif lo >= -chaos_threshold and hi <= chaos_threshold:
                regime[i] = 3
            else:
                regime[i] = 7
        else:
            regime[i] = 5
        d = ro[i][:, :2] - ro[i][0, :2]
        if np.all(np.isfinite(d)):
            net = float(np.linalg.norm(d[-1]))
            exc = float(np.max(np.linalg.norm(d, axis=-1)))
            glob[i] = int(net > drift_threshold and net >= 0.5 * exc)
    return dict(regime=regime.reshape(lead), period=period.reshape(lead), global_motion=glob.reshape(lead))


def regime_names(regime: np.ndarray, period: np.ndarray) -> np.ndarray:
    """Human-readable labels ("period-2", "chaotic", ...) for code arrays."""
    regime = np.asarray(regime)
    period = np.asarray(period)
    out = np.empty(regime.shape, dtype=object)
    for idx in np.ndindex(regime.shape):
        r = int(regime[idx])
        out[idx] = f"period-{int(period[idx])}" if r == 2 else REGIMES[r]
    return out


def _first_start(ds) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Swept values and (regime, period, global motion) of a sweep dataset; a multi-start one by its first start."""
    vals = ds[ds.attrs["swept_parameter"]].values
    reg, per, glob = ds["regime"].values, ds["period"].values, ds["global_motion"].values
    if reg.ndim == 2:
        reg, per, glob = reg[:, 0], per[:, 0], glob[:, 0]
    return vals, reg, per, glob


def _runs(vals: np.ndarray, labels: list[str]) -> list[tuple[float, float, int, str]]:
    out, start = [], 0
    for i in range(1, len(vals) + 1):
        if i == len(vals) or labels[i] != labels[start]:
            out.append((float(vals[start]), float(vals[i - 1]), i - start, labels[start]))
            start = i
    return out


def regime_ranges(ds) -> list[tuple[float, float, int, str]]:
    """Contiguous runs of lanes with the same label along the swept axis: ``(from, to, lanes, label)``.

    ``ds``: a one-parameter sweep dataset (`jaxcelt.sweeps.dataset`). The label is the local regime
    with the global motion of O (``"period-1, bounded"``), or ``"invalid"``/``"failed"`` alone for a
    lane whose global motion is unknown. A multi-start dataset is labelled by its first start."""
    vals, reg, per, glob = _first_start(ds)
    labels = [
        n if g == -1 and n in ("invalid", "failed") else f"{n}, {GLOBAL_MOTION[int(g)]}"
        for n, g in zip(regime_names(reg, per), glob)
    ]
    return _runs(vals, labels)


def regime_runs(ds) -> list[dict]:
    """The regime table as JSON records (``summary.json``'s ``"regimes"`` of ``jaxcelt bifurcation``).

    Contiguous runs of equal (local regime, global motion) along the swept axis, every lane labelled
    ``"<regime>, <global motion>"`` (``"invalid, unknown"`` too): ``{"from", "to", "n", "label"}`` each;
    then, if any lane has a Lyapunov exponent, ``{"lyapunov_range_per_s": [min, max]}``. A multi-start
    dataset is labelled by its first start."""
    vals, reg, per, glob = _first_start(ds)
    labels = [f"{n}, {GLOBAL_MOTION[int(g)]}" for n, g in zip(regime_names(reg, per), glob)]
    out: list[dict] = [{"from": a, "to": b, "n": k, "label": label} for a, b, k, label in _runs(vals, labels)]
    lam = ds["lyapunov"].values
    if np.isfinite(lam).any():
        out.append({"lyapunov_range_per_s": [float(np.nanmin(lam)), float(np.nanmax(lam))]})
    return out
