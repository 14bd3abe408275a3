"""The 0–1 test for chaos (Gottwald & Melbourne): a second opinion on a regime label from a long record.

A lane's label (`jaxcelt.sweeps.regimes`) comes from its stroboscopic samples (a period) and from its largest
Lyapunov exponent with a standard error. The 0–1 test needs neither the equations nor a tangent: from one
observable φ(j) of a long record (for example a component of the section samples) it builds the
translation variables

    p_c(n) = Σ_{j<n} φ(j) cos(j c),    q_c(n) = Σ_{j<n} φ(j) sin(j c),

whose mean square displacement M_c(n) stays bounded for regular dynamics (periodic or quasi-periodic) and
grows linearly with n for chaotic dynamics. K_c is the correlation of n with the modified displacement
D_c(n) = M_c(n) − (E φ)² (1 − cos n c)/(1 − cos c) over n ≤ N/10, and K is the median of K_c over random
c in (π/5, 4π/5): **K ≈ 0 regular, K ≈ 1 chaotic** (G. A. Gottwald and I. Melbourne, "On the implementation
of the 0–1 test for chaos", SIAM J. Appl. Dyn. Syst. 8 (2009) 129–145, the correlation method of §3.2).

It is a statistical test: a few thousand samples are needed for a clear answer, and K drifts from 0 or 1 for
short records or where the sampling is close to a resonance (the median over c guards against single
resonant c). Use it where a long record exists; the sweeps' default 100 samples are too few.
"""

from __future__ import annotations

import numpy as np

__all__ = ["zero_one_test"]


def zero_one_test(phi, *, n_c: int = 100, seed: int = 0) -> float:
    """K of the 0–1 test (module docstring) of the record ``phi`` (N,), N >= 100: ≈ 0 regular, ≈ 1 chaotic.

    ``n_c`` random frequencies c in (π/5, 4π/5), drawn from ``seed`` (the same K for the same record)."""
    phi = np.asarray(phi, dtype=float)
    if phi.ndim != 1:
        raise ValueError(f"phi must be a 1-D record, got shape {phi.shape}")
    N = phi.shape[0]
    if N < 100:
        raise ValueError(f"phi: the 0-1 test needs at least 100 samples, got {N}")
    if not np.all(np.isfinite(phi)):
        raise ValueError("phi must be finite (a failed or stopped lane's samples are inf)")
    if isinstance(n_c, bool) or not isinstance(n_c, int | np.integer) or n_c < 1:
        raise ValueError(f"n_c must be a positive int, got {n_c!r}")
    ncut = N // 10
    j = np.arange(N)
    n = np.arange(1, ncut + 1)
    mean2 = phi.mean() ** 2
    cs = np.random.default_rng(seed).uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    ks = []
    for c in cs:
        p = np.concatenate([[0.0], np.cumsum(phi * np.cos(j * c))])
        q = np.concatenate([[0.0], np.cumsum(phi * np.sin(j * c))])
        # mean square displacement M_c(n) = mean over j < N - n of |(p, q)(j + n) - (p, q)(j)|^2
        M = np.array([np.mean((p[k : N] - p[: N - k]) ** 2 + (q[k : N] - q[: N - k]) ** 2) for k in n])
        D = M - mean2 * (1 - np.cos(n * c)) / (1 - np.cos(c))
        if np.std(D) == 0:
            ks.append(0.0)
            continue
        ks.append(float(np.corrcoef(n, D)[0, 1]))
    return float(np.median(ks))
