"""Regime labels on synthetic stroboscopic sequences whose answer is known by construction."""

import numpy as np
import pytest

from jaxcelt.sweeps.regimes import classify, detect_period, regime_names


def _samples(x):
    s = np.zeros((len(x), 13))
    s[:, 3:6] = x[:, None] * np.array([1.0, 0.5, -0.2])
    s[:, 8] = 1.0
    return s


def test_detect_period_known_sequences():
    k = np.arange(60)
    assert detect_period(np.cos(np.pi * k)[:, None]) == 2  # period-2 by construction
    assert detect_period(np.cos(2 * np.pi * k / 3)[:, None]) == 3
    assert detect_period(np.ones((20, 2))) == 1
    # irrational rotation: never repeats to 1e-4 within 16 samples
    assert detect_period(np.cos(2 * np.pi * k * (np.sqrt(5) - 1) / 2)[:, None]) == 0
    assert detect_period(np.array([[np.nan], [1.0]])) == 0


def test_classify_status_validity_lyapunov_drift():
    k = np.arange(40)
    periodic = _samples(np.cos(np.pi * k))
    irregular = _samples(np.cos(2 * np.pi * k * (np.sqrt(5) - 1) / 2))
    samples = np.stack([periodic, irregular, irregular, periodic, periodic, periodic])
    status = np.array([0, 0, 0, 1, 2, 0])
    valid = np.array([True, True, True, True, False, False])
    r_O = np.zeros((6, 40, 3))
    r_O[1, :, 0] = 0.01 * k  # steady wandering: 0.39 m net, all of it net displacement
    lyap = np.array([np.nan, 0.5, 0.001, np.nan, np.nan, np.nan])
    lab = classify(samples, status, valid, r_O, lyap, chaos_threshold=0.02, drift_threshold=0.05)
    names = list(regime_names(lab["regime"], lab["period"]))
    assert names == ["period-2", "chaotic", "quasi-periodic", "failed", "invalid", "invalid"]
    assert list(lab["global_motion"][:3]) == [0, 1, 0]


def test_classify_exponent_interval():
    # one non-periodic sequence, labelled by (lambda_1, standard error) alone; threshold 0.02 1/s,
    # +-2 standard errors: the expected labels follow from the rule's arithmetic by hand
    k = np.arange(40)
    irregular = _samples(np.cos(2 * np.pi * k * (np.sqrt(5) - 1) / 2))
    lam = np.array([0.5, 0.5, -0.3, -0.3, 0.005, 0.005, 0.05, -0.05, 0.3])
    se = np.array([0.1, 0.3, 0.1, 0.2, 0.005, 0.01, np.nan, np.nan, 0.0])
    n = len(lam)
    samples = np.repeat(irregular[None], n, axis=0)
    args = (samples, np.zeros(n, int), np.ones(n, bool), np.zeros((n, 40, 3)), lam)
    lab = classify(*args, lyapunov_stderr=se, chaos_threshold=0.02)
    names = list(regime_names(lab["regime"], lab["period"]))
    # 0.5-0.2 > 0.02; 0.5-0.6 < 0.02 < 0.5+0.6; -0.3+0.2 < -0.02; -0.3+0.4 > -0.02; 0.005+-0.01 within +-0.02;
    # 0.005+0.02 > 0.02; NaN error counts as 0: 0.05 chaotic, -0.05 converging; 0.3 with 0 error chaotic
    assert names == [
        "chaotic", "uncertain", "converging", "uncertain", "quasi-periodic", "uncertain", "chaotic",
        "converging", "chaotic",
    ]  # fmt: skip
    # without errors the point estimate decides
    lab0 = classify(*args, chaos_threshold=0.02)
    assert list(regime_names(lab0["regime"], lab0["period"])) == [
        "chaotic", "chaotic", "converging", "converging", "quasi-periodic", "quasi-periodic", "chaotic",
        "converging", "chaotic",
    ]  # fmt: skip
    with pytest.raises(ValueError, match="confidence"):
        classify(*args, lyapunov_stderr=se, confidence=-1.0)
    with pytest.raises(ValueError, match="chaos_threshold"):
        classify(*args, chaos_threshold=np.nan)


def test_exponent_stderr_batch_means():
    from jaxcelt.integrate.lyapunov import exponent_stderr

    # 8 segments of length 0.5 in 4 blocks of 2: block exponents 1, 2, 3, 4 (sum of logs / 1.0 s);
    # std(ddof=1) of (1, 2, 3, 4) = sqrt(5/3), over sqrt(4): by hand, not by the code under test
    g = np.array([0.5, 0.5, 1.0, 1.0, 1.5, 1.5, 2.0, 2.0])
    assert float(exponent_stderr(g, 0.5)) == pytest.approx(np.sqrt(5 / 3) / 2, rel=1e-12)
    assert float(exponent_stderr(np.full(10, 0.3), 2.0)) == pytest.approx(0.0, abs=1e-15)  # constant growth
    # 10 segments in blocks of 2, 3, 3, 2 (edges 0, 2.5, 5, 7.5, 10 rounded half to even: 0, 2, 5, 8, 10)
    g = np.arange(10.0)
    blocks = [g[0:2].sum() / 2, g[2:5].sum() / 3, g[5:8].sum() / 3, g[8:10].sum() / 2]
    assert float(exponent_stderr(g, 1.0)) == pytest.approx(np.std(blocks, ddof=1) / 2, rel=1e-12)
    assert np.isnan(float(exponent_stderr(np.ones(3), 1.0)))  # fewer segments than blocks
    batch = exponent_stderr(np.stack([np.full(8, 0.1), g[:8]]), 1.0)  # leading axes
    assert batch.shape == (2,)
    with pytest.raises(ValueError, match="n_blocks"):
        exponent_stderr(g, 1.0, n_blocks=1)
