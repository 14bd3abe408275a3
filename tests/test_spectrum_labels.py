"""Regime labels from the Lyapunov spectrum (lambda_1, lambda_2): `jaxcelt.sweeps.regimes.spectrum_regime`.

The rule is checked on constructed numbers for every branch (the expected label follows from the rule's arithmetic
by hand), ``classify`` and ``lane_kinds`` without lambda_2 against the lambda_1-only rule they had before, the atlas's
labels and figure on a constructed result, and the physics on a system we did not write: the forced van der Pol
oscillator x'' - m (1 - x^2) x' + x = F cos(w t), whose exponents come from a plain scipy Benettin QR in this file
(DOP853 on the state and the tangent, re-orthonormalised every forcing period). Weakly forced at a frequency far
from its own (golden ratio) it runs on a 2-torus (lambda_1 = 0, lambda_2 < 0); forced at its own frequency it
locks onto a periodic orbit (both < 0).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jaxcelt.sweeps.continuation_match import KINDS, lane_kinds
from jaxcelt.sweeps.regimes import REGIMES, classify, regime_names, spectrum_regime

CODE = {v: k for k, v in REGIMES.items()}
TH, CONF = 0.02, 2.0


def test_rule_every_branch():
    # (lambda_1, s.e._1, lambda_2, s.e._2) -> label; threshold 0.02 1/s, +-2 s.e.; each interval end is at least
    # 0.005 1/s from the threshold it is compared with, so float rounding cannot flip a label
    cases = [
        ((0.10, 0.01, -0.30, 0.01), "chaotic"),  # lo_1 = 0.08 > 0.02
        ((0.10, 0.01, 0.05, 0.01), "chaotic"),  # hyperchaos: still chaotic
        ((-0.10, 0.01, -0.30, 0.01), "converging"),  # hi_1 = -0.08 < -0.02
        ((-0.10, 0.01, np.nan, np.nan), "converging"),  # lambda_2 missing: lambda_1's rule
        ((0.001, 0.002, -0.20, 0.01), "quasi-periodic"),  # [-0.003, 0.005] inside, hi_2 = -0.18: 2-torus
        ((0.001, 0.002, -0.005, 0.002), "uncertain"),  # lambda_2 ~ 0 too: near-NS focus or 3-torus
        ((0.001, 0.002, -0.03, 0.01), "uncertain"),  # hi_2 = -0.01: lambda_2 not clearly negative
        ((0.001, 0.002, np.nan, 0.01), "quasi-periodic"),  # lambda_2 missing: lambda_1's rule
        ((0.001, 0.02, -0.30, 0.01), "uncertain"),  # [-0.039, 0.041] reaches across both thresholds
        ((0.03, 0.01, -0.30, 0.01), "uncertain"),  # [0.01, 0.05] reaches across +0.02
        ((np.nan, 0.01, -0.30, 0.01), "aperiodic"),  # no exponent
        ((0.001, np.nan, -0.30, np.nan), "quasi-periodic"),  # no errors known: the point estimates decide
    ]
    l1, s1, l2, s2 = (np.array(c) for c in zip(*[c for c, _ in cases], strict=True))
    got = spectrum_regime(l1, s1, l2, s2, chaos_threshold=TH, confidence=CONF)
    assert got.dtype == np.int32 and got.shape == (len(cases),)
    assert [REGIMES[int(c)] for c in got] == [name for _, name in cases]
    # vectorised over any shape, scalars too
    assert spectrum_regime(l1.reshape(3, 4), s1.reshape(3, 4), l2.reshape(3, 4), s2.reshape(3, 4)).shape == (3, 4)
    assert int(spectrum_regime(0.001, 0.002, -0.2, 0.01)) == CODE["quasi-periodic"]
    assert int(spectrum_regime(0.001, None, None, None)) == CODE["quasi-periodic"]


@pytest.mark.parametrize("kw, name", [(dict(chaos_threshold=-1.0), "chaos_threshold"),
                                      (dict(confidence=np.nan), "confidence")])  # fmt: skip
def test_rule_bad_input_names_the_parameter(kw, name):
    with pytest.raises(ValueError, match=name):
        spectrum_regime([0.0], **kw)


def _old_lambda1_rule(ly, se):
    """The lambda_1-only rule as it was written before lambda_2 (copied here to pin the old labels)."""
    if not np.isfinite(ly):
        return "aperiodic"
    se = 0.0 if np.isnan(se) else se
    lo, hi = ly - CONF * se, ly + CONF * se
    if lo > TH:
        return "chaotic"
    if hi < -TH:
        return "converging"
    if lo >= -TH and hi <= TH:
        return "quasi-periodic"
    return "uncertain"


def _irregular(n):
    k = np.arange(40)
    s = np.zeros((40, 13))
    s[:, 3:6] = np.cos(2 * np.pi * k * (np.sqrt(5) - 1) / 2)[:, None] * np.array([1.0, 0.5, -0.2])
    s[:, 8] = 1.0
    return np.repeat(s[None], n, axis=0)


LAM = np.array([0.5, 0.5, -0.3, -0.3, 0.005, 0.005, 0.05, -0.05, 0.3, np.nan, 0.019, -0.019])
SE = np.array([0.1, 0.3, 0.1, 0.2, 0.005, 0.01, np.nan, np.nan, 0.0, 0.1, 0.0, np.nan])


def test_classify_without_lambda2_keeps_the_old_labels():
    n = len(LAM)
    args = (_irregular(n), np.zeros(n, int), np.ones(n, bool), np.zeros((n, 40, 3)), LAM)
    lab = classify(*args, lyapunov_stderr=SE, chaos_threshold=TH, confidence=CONF)
    old = [_old_lambda1_rule(a, b) for a, b in zip(LAM, SE, strict=True)]
    assert list(regime_names(lab["regime"], lab["period"])) == old
    # all-NaN lambda_2 is "not computed": the same labels
    nan = np.full(n, np.nan)
    lab2 = classify(*args, lyapunov_stderr=SE, lyapunov_2=nan, lyapunov_2_stderr=nan)
    np.testing.assert_array_equal(lab2["regime"], lab["regime"])
    # with lambda_2 ~ 0 the quasi-periodic lanes (4, 5, 10, 11) become uncertain, the others keep their label
    lab3 = classify(*args, lyapunov_stderr=SE, lyapunov_2=np.full(n, -0.001), lyapunov_2_stderr=np.full(n, 0.001))
    names3 = list(regime_names(lab3["regime"], lab3["period"]))
    assert names3 == ["uncertain" if o == "quasi-periodic" else o for o in old]
    # and with lambda_2 clearly negative they stay quasi-periodic (a 2-torus)
    lab4 = classify(*args, lyapunov_stderr=SE, lyapunov_2=np.full(n, -0.2), lyapunov_2_stderr=np.full(n, 0.01))
    np.testing.assert_array_equal(lab4["regime"], lab["regime"])


def test_lane_kinds_uses_the_same_rule():
    n = len(LAM)
    coords = _irregular(n)[:, :, 3:9]
    kw = dict(period_tol=1e-4, chaos_threshold=TH, confidence=CONF)
    kind, period = lane_kinds(coords, np.zeros(n, int), LAM, SE, **kw)
    assert [KINDS[k] for k in kind] == [_old_lambda1_rule(a, b) for a, b in zip(LAM, SE, strict=True)]
    assert not period.any()
    kind2, _ = lane_kinds(coords, np.zeros(n, int), LAM, SE, lyapunov_2=np.full(n, -0.001),
                          lyapunov_2_stderr=np.full(n, 0.001), **kw)  # fmt: skip
    assert [KINDS[k] for k in kind2] == ["uncertain" if KINDS[k] == "quasi-periodic" else KINDS[k] for k in kind]
    # no exponents at all: aperiodic, as before
    kind3, _ = lane_kinds(coords, np.zeros(n, int), None, None, **kw)
    assert {KINDS[k] for k in kind3} == {"aperiodic"}


def test_atlas_kind_spectrum_summary_and_figure(tmp_path, monkeypatch):
    # a constructed AtlasResult (no integration): 2 attractors x 3 values, the labels, the JSON, the figure
    import matplotlib
    import xarray as xr

    matplotlib.use("Agg")
    import jaxcelt as jc
    from jaxcelt.plotting.atlas import plot_atlas
    from jaxcelt.sweeps.atlas import AtlasOptions, AtlasResult, spectrum_kinds

    w = np.array([15.0, 15.5, 16.0])
    l1 = np.array([[0.001, -0.1, np.nan], [0.2, 0.001, 0.002]])
    s1 = np.full((2, 3), 0.002)
    l2 = np.array([[-0.2, -0.3, np.nan], [-0.1, -0.004, -0.2]])
    s2 = np.full((2, 3), 0.002)
    expect = [["quasi-periodic", "converging", ""], ["chaotic", "uncertain", "quasi-periodic"]]
    assert spectrum_kinds(l1, s1, l2, s2).tolist() == expect
    ds = xr.Dataset(
        dict(exists=(("attractor", "omega_pi"), np.array([[True, True, False], [True, True, True]])),
             fraction=(("attractor", "omega_pi"), np.array([[0.5, 0.5, np.nan], [0.5, 0.5, 1.0]])),
             kind=(("attractor", "omega_pi"), np.array([["uncertain"] * 3, ["chaotic"] * 3])),
             period=(("attractor", "omega_pi"), np.zeros((2, 3), int)),
             tipping_fraction=("omega_pi", np.zeros(3)), failed_fraction=("omega_pi", np.zeros(3))),
        coords=dict(attractor=[0, 1], omega_pi=w, lane=[0, 1]),
        attrs=dict(options_json=json.dumps(dict(chaos_threshold=0.02, confidence=2.0))),
    )  # fmt: skip
    res = AtlasResult(jc.CeltParams.paper(), w, None, ds, [], [], l1, s1, l2, s2, {},
                      AtlasOptions(spectrum_periods=100))  # fmt: skip
    assert res.kind_spectrum.tolist() == expect
    # a wider band relabels: the continuation's recorded thresholds are the ones used
    ds2 = ds.assign_attrs(options_json=json.dumps(dict(chaos_threshold=0.25, confidence=2.0)))
    res2 = AtlasResult(jc.CeltParams.paper(), w, None, ds2, [], [], l1, s1, l2, s2, {}, AtlasOptions())
    # th = 0.25: lambda_1 = 0.2 and -0.1 fall inside the band; only lambda_2 = -0.3 is still clearly below -0.25
    assert res2.kind_spectrum.tolist() == [["uncertain", "quasi-periodic", ""], ["uncertain"] * 3]
    # the summary JSON carries the label beside "spectrum" (the continuation's own summary stubbed: no real run)
    import jaxcelt.sweeps.continuation_core as core

    stub = dict(values=[dict(value=float(v), attractors=[dict(id=a) for a in range(2) if ds.exists.values[a, j]])
                        for j, v in enumerate(w)])  # fmt: skip
    monkeypatch.setattr(core, "continuation_summary", lambda _: stub)
    rows = json.loads(json.dumps(res.summary()))["continuation"]["values"]
    got = {(a["id"], j): (a["kind_spectrum"], a["spectrum"]) for j, r in enumerate(rows) for a in r["attractors"]}
    assert got[(0, 0)] == ("quasi-periodic", [0.001, -0.2]) and got[(1, 1)] == ("uncertain", [0.001, -0.004])
    assert len(got) == 5
    path = plot_atlas(res, tmp_path / "atlas.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# --- physics: the forced van der Pol oscillator, exponents by a plain Benettin QR ------------------------------


def _vdp(t, z, m, F, w):
    x, y = z[0], z[1]
    J = np.array([[0.0, 1.0], [-2.0 * m * x * y - 1.0, m * (1.0 - x * x)]])
    return np.concatenate([[y, m * (1.0 - x * x) * y - x + F * np.cos(w * t)], (J @ z[2:].reshape(2, 2)).ravel()])


def _benettin(m, F, w, *, transient=60, periods=240, batches=8):
    """lambda_1, lambda_2 [1/time] over ``periods`` forcing periods after ``transient``, their batch-means
    standard errors, and the last state (x, x') at a forcing phase of 0."""
    T = 2 * np.pi / w
    kw = dict(method="DOP853", rtol=1e-9, atol=1e-11, args=(m, F, w))
    z = solve_ivp(_vdp, (0.0, transient * T), np.r_[2.0, 0.0, np.eye(2).ravel()], **kw).y[:2, -1]
    Q, logs = np.eye(2), np.zeros((periods, 2))
    for k in range(periods):
        t0 = (transient + k) * T
        sol = solve_ivp(_vdp, (t0, t0 + T), np.r_[z, Q.ravel()], **kw).y[:, -1]
        z = sol[:2]
        Q, R = np.linalg.qr(sol[2:].reshape(2, 2))
        Q = Q * np.sign(np.diag(R))
        logs[k] = np.log(np.abs(np.diag(R)))
    means = logs.reshape(batches, -1, 2).mean(axis=1) / T
    return logs.mean(axis=0) / T, means.std(axis=0, ddof=1) / np.sqrt(batches), z


def test_forced_van_der_pol_torus_is_quasi_periodic():
    # m = 0.2, F = 0.1, w = golden ratio: far from every low-order locking tongue at this weak forcing, a 2-torus.
    # Averaging (amplitude equation da/dt = (m/2) a (1 - a^2/4 - rho^2/2), rho = F / (1 - w^2) the forced
    # amplitude) gives lambda_2 = -m (1 - rho^2/2) + O(m^2) = -0.1996 + O(0.04): 15 % tolerance.
    m, F, w = 0.2, 0.1, (1 + np.sqrt(5)) / 2
    lam, se, _ = _benettin(m, F, w)
    rho = F / (1 - w**2)
    assert abs(lam[0]) < 0.005  # the torus's neutral direction: finite-time error O(1/t), t ~ 930
    np.testing.assert_allclose(lam[1], -m * (1 - rho**2 / 2), rtol=0.15)
    assert REGIMES[int(spectrum_regime(lam[0], se[0], lam[1], se[1], chaos_threshold=TH, confidence=CONF))] == (
        "quasi-periodic"
    )


def test_forced_van_der_pol_locked_is_converging():
    # m = 0.2, F = 0.3, w = 1: inside the 1:1 tongue, a stable period-1 orbit. The exponents must be the Floquet
    # exponents log|mu| / T of its monodromy matrix (one period of the variational equations from the locked
    # state, the eigenvalues by numpy): 1e-3 absolute, far below the 0.06 1/s gap to the threshold.
    m, F, w = 0.2, 0.3, 1.0
    lam, se, z = _benettin(m, F, w)
    T = 2 * np.pi / w
    M = solve_ivp(_vdp, (0.0, T), np.r_[z, np.eye(2).ravel()], method="DOP853", rtol=1e-11, atol=1e-13,
                  args=(m, F, w)).y[2:, -1].reshape(2, 2)  # fmt: skip
    floquet = np.sort(np.log(np.abs(np.linalg.eigvals(M))) / T)[::-1]
    np.testing.assert_allclose(lam, floquet, atol=1e-3)
    assert lam[0] < -2 * TH
    assert REGIMES[int(spectrum_regime(lam[0], se[0], lam[1], se[1], chaos_threshold=TH, confidence=CONF))] == (
        "converging"
    )
