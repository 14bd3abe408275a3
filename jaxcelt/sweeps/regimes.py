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

  With the second exponent lambda_2 and its standard error (``lyapunov_2``, ``lyapunov_2_stderr``) the
  quasi-periodic label asks more: see `spectrum_regime` (lambda_1 indistinguishable from 0 *and* lambda_2
  clearly negative: a 2-torus; lambda_2 near 0 too: uncertain).

Global label: ``unbounded`` when O's net horizontal displacement over the samples exceeds
``drift_threshold`` [m] and is at least half of its maximum excursion (steady wandering
away), else ``bounded``. The thresholds are heuristics; the raw numbers (drift, excursion,
exponent) are kept beside the labels.

Along the swept axis of a one-parameter sweep dataset, `regime_ranges` and `regime_runs` group
consecutive lanes with the same label into ranges (the regime table of ``jaxcelt bifurcation``).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "REGIMES",
    "GLOBAL_MOTION",
    "detect_period",
    "spectrum_regime",
    "classify",
    "regime_names",
    "regime_ranges",
    "regime_runs",
]

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


def _check_rule(where: str, chaos_threshold: float, confidence: float) -> None:
    if not (np.isfinite(chaos_threshold) and chaos_threshold >= 0):
        raise ValueError(f"{where}: 'chaos_threshold' must be finite and >= 0, got {chaos_threshold!r}")
    if not (np.isfinite(confidence) and confidence >= 0):
        raise ValueError(f"{where}: 'confidence' must be finite and >= 0, got {confidence!r}")


def _floats(x, shape_of=None) -> np.ndarray:
    if x is None:
        return np.full(np.shape(shape_of), np.nan)
    return np.asarray(x, dtype=float)


def spectrum_regime(
    lambda1,
    stderr1=None,
    lambda2=None,
    stderr2=None,
    *,
    chaos_threshold: float = 0.02,
    confidence: float = 2.0,
) -> np.ndarray:
    """`REGIMES` code of a non-periodic motion from its Lyapunov exponents: the one rule of `classify` and
    `jaxcelt.sweeps.continuation_match.lane_kinds` (vectorised, any broadcastable shapes).

    The wobblestone on the vibrating base is a periodically *forced* system: time is no state variable, so the
    spectrum of its stroboscopic section has no zero exponent from the flow direction. Counted that way,

    * a stable periodic orbit has every exponent < 0 (a complex Floquet pair mu gives lambda_1 = lambda_2 =
      log|mu| / T; near a Neimark-Sacker point |mu| -> 1, so both tend to 0: a slowly attracting focus);
    * a 2-torus (quasi-periodic motion, born at a Neimark-Sacker point) has lambda_1 = 0, lambda_2 < 0;
    * a 3-torus has lambda_1 = lambda_2 = 0, lambda_3 < 0;
    * chaos has lambda_1 > 0 (hyperchaos lambda_2 > 0 too).

    With the intervals [lo_i, hi_i] = lambda_i -+ ``confidence`` stderr_i and th = ``chaos_threshold`` [1/s]:

    * ``chaotic`` (4)        -- lo_1 > th;
    * ``converging`` (6)     -- hi_1 < -th: every perturbation shrinks, a sink (a periodic orbit);
    * ``quasi-periodic`` (3) -- lambda_1's interval inside [-th, th] and hi_2 < -th: a 2-torus;
    * ``uncertain`` (7)      -- lambda_1's interval inside [-th, th] but lambda_2 not clearly negative: a focus
      near a Neimark-Sacker point or a 3-torus, which lambda_1 and lambda_2 alone cannot tell apart (lambda_3,
      or the Floquet multipliers of a periodic orbit found by Newton, can); or lambda_1's interval reaches
      across +-th: the window was too short to tell;
    * ``aperiodic`` (5)      -- lambda_1 is missing (NaN): no exponent was computed.

    Where lambda_2 is missing (None or NaN) the rule is lambda_1's alone, as before lambda_2 existed: an
    interval inside [-th, th] is ``quasi-periodic``.

    Args:
        lambda1, lambda2: exponents [1/s] (lambda2 None: not computed).
        stderr1, stderr2: their standard errors [1/s] (None or NaN: no error known, the point estimate decides).
        chaos_threshold: th [1/s]; a finite-time exponent of a torus is O(1/t) from 0, hence a band.
        confidence: half-width of the intervals in standard errors.

    Returns:
        int32 array of `REGIMES` codes (3, 4, 5, 6 or 7), the broadcast shape of the inputs.

    Raises:
        ValueError: ``chaos_threshold`` or ``confidence`` not finite and >= 0.
    """
    _check_rule("spectrum_regime", chaos_threshold, confidence)
    l1 = _floats(lambda1)
    l1, s1, l2, s2 = np.broadcast_arrays(l1, _floats(stderr1, l1), _floats(lambda2, l1), _floats(stderr2, l1))
    s1, s2 = np.where(np.isnan(s1), 0.0, s1), np.where(np.isnan(s2), 0.0, s2)
    th = chaos_threshold
    with np.errstate(invalid="ignore"):
        lo1, hi1 = l1 - confidence * s1, l1 + confidence * s1
        hi2 = l2 + confidence * s2
        inside = (lo1 >= -th) & (hi1 <= th)
        torus = np.where(np.isnan(l2), True, hi2 < -th)  # no lambda_2: lambda_1's rule alone
        out = np.full(l1.shape, 7, dtype=np.int32)
        out[inside & torus] = 3
        out[hi1 < -th] = 6
        out[lo1 > th] = 4
    out[~np.isfinite(l1)] = 5
    return out


def classify(
    samples: np.ndarray,
    status: np.ndarray,
    valid: np.ndarray,
    r_O: np.ndarray,
    lyapunov: np.ndarray | None = None,
    *,
    lyapunov_stderr: np.ndarray | None = None,
    lyapunov_2: np.ndarray | None = None,
    lyapunov_2_stderr: np.ndarray | None = None,
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
        lyapunov_2, lyapunov_2_stderr: (...) the second exponent lambda_2 [1/s] and its standard error, or None
            (not computed; NaN entries count as not computed). Where lambda_2 is given, a lambda_1
            indistinguishable from 0 is ``quasi-periodic`` only if lambda_2 is clearly negative (a 2-torus), else
            ``uncertain`` (`spectrum_regime`); without it the labels are lambda_1's alone.
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
    _check_rule("classify", chaos_threshold, confidence)
    n = flat.shape[0]

    def lane(x):
        return None if x is None else np.asarray(x, dtype=float).reshape(-1)

    exponent_code = spectrum_regime(
        np.full(n, np.nan) if lyapunov is None else lane(lyapunov), lane(lyapunov_stderr), lane(lyapunov_2),
        lane(lyapunov_2_stderr), chaos_threshold=chaos_threshold, confidence=confidence,
    )  # fmt: skip
    regime = np.zeros(n, dtype=np.int32)
    period = np.zeros(n, dtype=np.int32)
    glob = np.full(n, -1, dtype=np.int32)
    for i in range(n):
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
        else:
            regime[i] = exponent_code[i]  # 5 (aperiodic) where no exponent was computed
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
