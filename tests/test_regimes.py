"""Regime labels on synthetic stroboscopic sequences whose answer is known by construction."""

import numpy as np

from jaxcelt.regimes import classify, detect_period, regime_names


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
