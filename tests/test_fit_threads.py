"""Fits keep no state between calls: two fits of different data run at the same time in two threads give what
they give one after the other.

Written with top-level names only. Each data set: two 1 s gyro records (50 Hz, 1 % noise) of a stone with its own
parameters; each fit: 8 Levenberg-Marquardt iterations from the paper's values (not to convergence: the test is
about equality, not accuracy). Tolerance: rtol 1e-6 on the fitted values and losses -- the concurrent fits run
the same compiled programs on the same data from the same start, only the scheduling of the threads differs, so
any difference is round-off of the thread pool's order (none expected); a fit that evaluated the other fit's data
is off by percents.
"""

import threading

import numpy as np
import pytest

import jaxcelt as jc

FREE = ("mu", "k_r", "b_Ts", "m_Ts")
PAPER = jc.CeltParams.paper()
JOIN_TIMEOUT = 300  # [s]; the two fits take ~20 s one after the other on 2 loaded cores


def _data(scale: float, seed: int) -> jc.MeasuredData:
    true = PAPER.replace(mu=0.2241 * scale, k_r=0.4345 / scale, b_Ts=0.5305 * scale, m_Ts=0.8161)
    n = (np.sin(np.radians(10)), 0.0, np.cos(np.radians(10)))
    y0s = [
        jc.initial_state(true, omega=(0.0, 0.0, 5.0), n=n),
        jc.initial_state(true, omega=(0.0, 0.0, -3.0), n=(0.1, 0.0, np.sqrt(0.99))),
    ]
    return jc.generate_data(true, y0s, 1.0, rate=50, kinds=("omega",), noise=0.01, seed=seed)


def _fit(data):
    return jc.fit(data, PAPER, free=FREE, optimiser="lm", max_iter=8, uncertainty=False)


def test_concurrent_fits_equal_sequential_fits():
    datasets = [_data(1.3, 1), _data(0.8, 2)]
    sequential = [_fit(d) for d in datasets]
    concurrent: list = [None, None]
    errors: list = []

    def work(i):
        try:
            concurrent[i] = _fit(datasets[i])
        except Exception as e:  # noqa: BLE001  (re-raised in the main thread)
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,), daemon=True) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=JOIN_TIMEOUT)
    assert not any(t.is_alive() for t in threads), f"concurrent fits still running after {JOIN_TIMEOUT} s (deadlock)"
    assert not errors, errors
    for s, c in zip(sequential, concurrent, strict=True):
        for name in FREE:
            assert c.values[name] == pytest.approx(s.values[name], rel=1e-6), (name, s.values, c.values)
        assert c.loss == pytest.approx(s.loss, rel=1e-6)
    # the two data sets have different optima: a fit that evaluated the other's data would not match
    assert abs(sequential[0].values["mu"] - sequential[1].values["mu"]) > 0.05 * sequential[1].values["mu"]
