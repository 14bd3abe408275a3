"""Neimark-Sacker curves (`jaxcelt.continue_bifurcation(..., kind="neimark-sacker")`), on known answers.

* Linear oscillator x'' + 2 zeta x' + w0^2 x = F cos(w t): the monodromy of the 2 pi / w map has the multipliers
  exp((-zeta +- i sqrt(w0^2 - zeta^2)) T), so the Neimark-Sacker curve is exactly zeta = 0 with kappa = cos(w0 T).
  (a) In (zeta, w) at w0 = 1: every point has zeta = 0 to 1e-9 and kappa = cos(2 pi / w) to 1e-8 (the corrector's
  Newton tolerance is 1e-9 on the unknowns, the ODE tolerances 1e-10 / 1e-11; measured: 3e-12 and 9e-12), and the
  1:3 and 1:4 points (kappa = -1/2, 0) are located, converged, at w = 3, 3/2 (w0 T = 2 pi / 3, 4 pi / 3) and 4, 4/3
  (w0 T = pi / 2, 3 pi / 2) to 1e-8. (b) In (zeta, w0^2) at w = 1: the curve passes the 1:1 point at w0^2 = 0 (the
  pair meets at +1 and continues as a neutral saddle, real multipliers e^{+-|w0| T}: kappa = cosh(|w0| T) > 1 for
  w0^2 < 0, checked to 1e-8) and the 1:4, 1:3 points at w0 = 1/4, 1/3 (to 1e-8); the 1:1 point, where this linear
  orbit is not isolated, is interpolated (to 1e-6).
* Forced van der Pol x'' - 0.5 (1 - x^2) x' + x = F cos(w t) (slow: about 35 s on the 2-core CPU): the torus (Neimark-Sacker) curve of the entrained
  period-1 orbit in (w, F) from w ~ 1.27, F = 1. At every fifth curve point with |kappa| < 1 an independent scipy
  integration (`solve_ivp` DOP853, rtol 1e-11, atol 1e-12, of the equation and its variational equations written
  here) from the curve's state returns to it within 1e-7 and has a complex pair of multipliers of modulus 1 to
  1e-6 (measured: 3e-12) whose angle is arccos(kappa) to 1e-6; at the located 1:3, 1:4 and 1:1 points the
  scipy multipliers' angle is 2 pi / k to 1e-5 (the located test function is below 1e-6 of its bracket's).
* Bad input: an unknown kind or detect name raises ValueError naming it.
* The wobblestone (docs/orbits/curves_omega_q.json): every curve started on a branch passes its branch's
  one-parameter point at q_pi = 0.04 (fold 14.8798 rad/s, docs/orbits/celt_fold_grad.json; NS 17.7475 rad/s,
  docs/orbits/branches.json) to 1e-4 in omega_pi, on both mirror branches; NS points have a pair on the unit circle
  to 1e-7, fold points a multiplier at +1 to 1e-7. Slow: the NS start recomputed on the mirror branch.
"""

import json
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaxcelt as jc
from jaxcelt.orbits.ns_system import NS_TESTS, ns_tests
from jaxcelt.physics.model import STATE_NAMES

W0 = 1.0
MU = 0.5


def oscillator(t, y, a):
    zeta, w0sq, w = a
    return jnp.stack([y[1], -2.0 * zeta * y[1] - w0sq * y[0] + 0.3 * jnp.cos(w * t)])


def period(a):
    return 2.0 * jnp.pi / a[2]


def vdp(t, y, a):
    w, F = a
    return jnp.stack([y[1], MU * (1.0 - y[0] ** 2) * y[1] - y[0] + F * jnp.cos(w * t)])


def test_ns_test_functions():
    # pair e^{+-i pi/3} (kappa 1/2) and a third multiplier 0.5: fold-NS (0.5 - 1), flip-NS (0.5 + 1)
    mu = np.array([np.exp(1j * np.pi / 3), np.exp(-1j * np.pi / 3), 0.5])
    t = ns_tests(mu, 0.5)
    assert set(t) == set(NS_TESTS) == set(jc.orbits.CODIM2_TESTS["neimark-sacker"])
    assert t["1:1 resonance"] == -0.5 and t["1:2 resonance"] == 1.5 and t["1:3 resonance"] == 1.0
    assert t["1:4 resonance"] == 0.5 and t["fold-NS"] == pytest.approx(-0.5) and t["flip-NS"] == pytest.approx(1.5)


def test_linear_oscillator_ns_curve_in_zeta_and_forcing_frequency():
    c = jc.continue_bifurcation(
        oscillator, jnp.zeros(2), lambda z, w: (z, W0**2, w), period, (0.01, 1.3), ((-0.5, 0.5), (1.05, 4.5)),
        kind="neimark-sacker", ds=0.05, ds_max=0.25, max_points=120,
    )  # fmt: skip
    assert c.kind == "neimark-sacker" and c.stopped[1] == "left the bounds"
    assert c.p2.min() < 1.2 and c.p2.max() > 4.4
    np.testing.assert_array_less(np.abs(c.p1), 1e-9)
    np.testing.assert_array_less(np.abs(c.kappa - np.cos(W0 * 2 * np.pi / c.p2)), 1e-8)
    np.testing.assert_array_less(np.abs(np.abs(c.multipliers) - 1.0), 1e-8)
    got = sorted((pt.kind, round(pt.p2, 6)) for pt in c.points)
    assert got == [("1:3 resonance", 1.5), ("1:3 resonance", 3.0), ("1:4 resonance", 1.333333), ("1:4 resonance", 4.0)]
    for pt in c.points:
        k = 3 if pt.kind == "1:3 resonance" else 4
        assert pt.converged
        w_exact = min((W0 * k / m for m in (1, 2, 3)), key=lambda w: abs(w - pt.p2))
        assert abs(pt.p2 - w_exact) < 1e-8 and abs(pt.p1) < 1e-9
        assert abs(pt.kappa - np.cos(2 * np.pi / k)) < 1e-8
    assert np.allclose(c.theta, np.arccos(c.kappa))


def test_linear_oscillator_ns_curve_through_the_1_1_point():
    c = jc.continue_bifurcation(
        oscillator, jnp.zeros(2), lambda z, w0sq: (z, w0sq, 1.0), period, (0.01, 0.04), ((-0.5, 0.5), (-0.05, 0.13)),
        kind="neimark-sacker", ds=0.02, ds_max=0.05, max_points=80,
    )  # fmt: skip
    assert c.stopped == ("left the bounds", "left the bounds")
    np.testing.assert_array_less(np.abs(c.p1), 1e-9)
    w0 = np.sqrt(np.abs(c.p2)) * 2 * np.pi
    exact = np.where(c.p2 >= 0, np.cos(w0), np.cosh(w0))
    np.testing.assert_array_less(np.abs(c.kappa - exact), 1e-8)
    assert np.any(c.kappa > 1.01) and np.all(np.isnan(c.theta[c.kappa > 1]))
    found = {pt.kind: pt for pt in c.points}
    assert sorted(found) == ["1:1 resonance", "1:3 resonance", "1:4 resonance"]
    # at w0^2 = 0, zeta = 0 the orbit is not isolated (x'' = F cos t has the periodic solutions -F cos t + c for every
    # c): the corrector is singular there, so the 1:1 point is interpolated linearly between its bracketing points
    # (kappa - 1 is smooth in the arclength; 1e-6 allows a curvature of 1e-6 / (0.05^2 / 8) ~ 3e-3; measured 6e-8)
    assert found["1:3 resonance"].converged and found["1:4 resonance"].converged
    assert abs(found["1:1 resonance"].p2) < 1e-6
    assert abs(found["1:4 resonance"].p2 - 1 / 16) < 1e-8 and abs(found["1:3 resonance"].p2 - 1 / 9) < 1e-8


def _scipy_monodromy(y0, w, F):
    def rhs(t, s):
        x, v = s[0], s[1]
        J = np.array([[0.0, 1.0], [-2.0 * MU * x * v - 1.0, MU * (1.0 - x**2)]])
        Phi = s[2:].reshape(2, 2)
        return np.concatenate([[v, MU * (1 - x**2) * v - x + F * np.cos(w * t)], (J @ Phi).ravel()])

    T = 2 * np.pi / w
    sol = solve_ivp(rhs, (0.0, T), np.concatenate([y0, np.eye(2).ravel()]), method="DOP853", rtol=1e-11, atol=1e-12)
    return sol.y[:2, -1], sol.y[2:, -1].reshape(2, 2)


@pytest.mark.slow
def test_forced_van_der_pol_torus_curve_against_scipy():
    c = jc.continue_bifurcation(
        vdp, jnp.array([-1.3383, -0.7657]), lambda w, F: (w, F), lambda a: 2 * jnp.pi / a[0], (1.27, 1.0),
        ((0.8, 2.5), (0.4, 2.2)), kind="neimark-sacker", ds=0.05, ds_max=0.2, max_points=60,
    )  # fmt: skip
    assert c.stopped[1] == "left the bounds"
    ns = np.nonzero(np.abs(c.kappa) < 1.0)[0]
    assert ns.size >= 15
    worst = 0.0
    for i in ns[::5]:
        y1, M = _scipy_monodromy(c.y[i], c.p1[i], c.p2[i])
        assert np.max(np.abs(y1 - c.y[i])) < 1e-7
        mu = np.linalg.eigvals(M)
        assert abs(mu[0].imag) > 1e-3  # a complex pair
        worst = max(worst, float(np.max(np.abs(np.abs(mu) - 1.0))))
        assert abs(abs(np.angle(mu[0])) - np.arccos(c.kappa[i])) < 1e-6
    assert worst < 1e-6
    kinds = {pt.kind for pt in c.points if pt.converged}
    assert {"1:1 resonance", "1:3 resonance", "1:4 resonance"} <= kinds
    for pt in c.points:
        if not pt.converged or pt.kind not in ("1:1 resonance", "1:3 resonance", "1:4 resonance"):
            continue
        k = int(pt.kind[2])
        _, M = _scipy_monodromy(pt.y, pt.p1, pt.p2)
        theta = np.max(np.abs(np.angle(np.linalg.eigvals(M))))
        assert abs(theta - (2 * np.pi / k if k > 1 else 0.0)) < 1e-5 * (1 if k > 1 else 1e2), (pt.kind, theta)


def test_bad_kind_and_detect_name_it():
    with pytest.raises(ValueError, match="kind"):
        jc.continue_bifurcation(vdp, jnp.zeros(2), lambda w, F: (w, F), period, (1.0, 1.0), ((0, 2), (0, 2)),
                                kind="torus")  # fmt: skip
    with pytest.raises(ValueError, match="cusp"):
        jc.continue_bifurcation(vdp, jnp.zeros(2), lambda w, F: (w, F), period, (1.0, 1.0), ((0, 2), (0, 2)),
                                kind="neimark-sacker", detect=("cusp",))  # fmt: skip


# --- the wobblestone (docs/orbits/curves_omega_q.json from scripts/curves_omega_q.py) -------------------------------

ROOT = Path(__file__).resolve().parents[1]


def _one_parameter_points():
    """The fold and NS values of each period-1 branch (branches.json) and the located fold (celt_fold_grad.json):
    written by other scripts (orbit_branches.py, celt fold gradient), not by the curves script."""
    d = json.loads((ROOT / "docs/orbits/branches.json").read_text())
    fold = float(json.loads((ROOT / "docs/orbits/celt_fold_grad.json").read_text())["omega_fold"])
    out = []
    for b in d["branches"].values():
        bif = {x["kind"]: x for x in b["branch"]["bifurcations"]}
        out.append({"fold": fold, "neimark-sacker": float(bif["Neimark-Sacker"]["value"]), "bif": bif})
    return out


def test_committed_wobblestone_curves_pass_the_one_parameter_points():
    # every curve started on a branch is refined at q_pi = 0.04 (the paper's) with omega_pi free: that point must be
    # the one-parameter fold (14.8798) / NS point (17.7475) of its branch to 1e-4 in omega_pi (both are Newton or
    # bisection solves to 1e-9 or better; 1e-4 is the stated check), on both mirror branches
    res = json.loads((ROOT / "docs/orbits/curves_omega_q.json").read_text())
    ref = _one_parameter_points()
    seen = set()
    for key, c in res["curves"].items():
        if c.get("continues"):
            continue
        ib = int(key.endswith("_b"))
        cd = c["curve"]
        i = cd["start"]
        assert cd["q_pi"][i] == pytest.approx(0.04, abs=1e-12)
        assert abs(cd["omega_pi"][i] - ref[ib][c["kind"]]) < 1e-4, key
        seen.add((c["kind"], ib))
        mu = np.array([[complex(*z) for z in m] for m in cd["multipliers"]])
        if c["kind"] == "neimark-sacker":  # a complex pair on the unit circle at every point
            k = np.asarray(cd["kappa"])
            assert np.all(np.abs(k) < 1.0)
            pair = np.sort(np.abs(np.abs(mu) - 1.0), axis=1)[:, :2]
            assert np.max(pair) < 1e-7
        else:
            assert np.max(np.min(np.abs(mu - 1.0), axis=1)) < 1e-7
    assert seen == {("fold", 0), ("fold", 1), ("neimark-sacker", 0), ("neimark-sacker", 1)}
    # the two mirror branches give the same curves (psi -> psi + pi is not built in: a check)
    a, b = res["curves"]["ns_a"]["curve"], res["curves"]["ns_b"]["curve"]
    assert abs(a["omega_pi"][a["start"]] - b["omega_pi"][b["start"]]) < 1e-6


@pytest.mark.slow
def test_wobblestone_ns_curve_starts_at_the_one_parameter_point_on_the_mirror_branch():
    ref = _one_parameter_points()[1]
    bif = ref["bif"]["Neimark-Sacker"]
    y = np.array([bif["state"][n] for n in STATE_NAMES])
    p = jc.CeltParams.paper(omega_pi=float(bif["value"]))
    c = jc.continue_orbit_bifurcation(
        p, y, ("omega_pi", "q_pi"), ((10.0, 20.0), (0.02, 0.06)), kind="neimark-sacker", scale=(1.0, 0.01),
        max_points=1, max_steps=20_000,
    )  # fmt: skip
    assert len(c.p1) == 1 and c.p2[0] == pytest.approx(0.04, abs=1e-12)
    assert abs(c.p1[0] - ref["neimark-sacker"]) < 1e-4
    assert abs(np.sort(np.abs(np.abs(c.multipliers[0]) - 1.0))[1]) < 1e-7
    assert 0 < c.theta[0] < np.pi
