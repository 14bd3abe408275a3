"""The 0–1 test for chaos (`jaxcelt.zero_one_test`) on the published known answers.

Gottwald & Melbourne (SIAM J. Appl. Dyn. Syst. 8, 2009) show the logistic map x -> r x (1 - x) with K ≈ 0 in
periodic windows (r = 3.55: period 8; r = 3.83: period 3) and K ≈ 1 in chaos (r = 3.97, r = 4); a
quasi-periodic record gives K ≈ 0. Tolerance 0.1 on 2000 samples (measured: |K| <= 0.01 regular,
K >= 0.99 chaotic): the test is statistical and converges like N^(-1/2).
"""

from __future__ import annotations

import numpy as np
import pytest

import jaxcelt as jc


def _logistic(r: float, n: int = 2000, x: float = 0.4, burn: int = 1000) -> np.ndarray:
    out = np.empty(n)
    for i in range(burn + n):
        x = r * x * (1 - x)
        if i >= burn:
            out[i - burn] = x
    return out


@pytest.mark.parametrize("r, chaotic", [(3.55, False), (3.83, False), (3.97, True), (4.0, True)])
def test_logistic_map(r, chaotic):
    K = jc.zero_one_test(_logistic(r))
    assert (K > 0.9) if chaotic else (abs(K) < 0.1), K


def test_quasi_periodic_record_is_regular():
    j = np.arange(2000)
    phi = np.cos(2 * np.pi * 0.2287 * j) + np.cos(2 * np.pi * np.sqrt(2) * 0.21 * j)
    assert abs(jc.zero_one_test(phi)) < 0.1


def test_same_record_same_k_and_bad_input():
    x = _logistic(3.97, 500)
    assert jc.zero_one_test(x, seed=3) == jc.zero_one_test(x, seed=3)
    with pytest.raises(ValueError, match="phi"):
        jc.zero_one_test(np.zeros((10, 10)))
    with pytest.raises(ValueError, match="phi"):
        jc.zero_one_test(np.ones(50))
    with pytest.raises(ValueError, match="phi"):
        jc.zero_one_test(np.r_[np.ones(200), np.inf])
    with pytest.raises(ValueError, match="n_c"):
        jc.zero_one_test(x, n_c=0)
