"""Period doubling on a pseudo-arclength branch and switching onto the period-2 branch.

Double-well Duffing x'' + 0.3 x' - x + x^3 = F cos(1.2 t), right-well period-1 orbit continued
in F from 0.24 (start: scipy DOP853 after 100 periods). Literature value of the first doubling:
F ~ 0.26558. Independent checks (scipy DOP853, no Newton, no JAX):
* the located F_pd is bracketed by brute force: at 0.995 F_pd the attractor reached from the
  branch's first point is period-1, at 1.005 F_pd (with 1500 periods, the period-2 neighbour
  attracts slowly near the doubling) it is period-2 (points alternate by > 1e-3);
* the period-2 orbit found by branch switching at F_pd + 0.002 is the brute-force attractor
  there (section point within 1e-6 of one of the two alternating points, after 1000 periods);
* Liouville: the product of the multipliers is exp(-0.3 kT) (k = 1 on the branch, 2 for the
  switched orbit), to 1e-7 (variational solve at rtol 1e-10);
* the PD multiplier is -1 to 1e-6 (30 bisections of a bracket of width ~0.015).
"""

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from jaxcelt.orbits.branch import continue_arclength
from jaxcelt.orbits.switching import switch_at_period_doubling

W, D = 1.2, 0.3
T = 2 * np.pi / W


def duffing(t, y, p):
    d, f = p
    x, v = y
    return jnp.stack([v, -d * v + x - x**3 + f * jnp.cos(W * t)])


def sections(F, y0, periods, last=4):
    rhs = lambda t, y: [y[1], -D * y[1] + y[0] - y[0] ** 3 + F * np.cos(W * t)]  # noqa: E731
    ts = T * np.arange(periods - last, periods + 1)
    s = solve_ivp(rhs, (0, periods * T), y0, method="DOP853", rtol=1e-11, atol=1e-12, t_eval=ts)
    return s.y.T


@pytest.mark.slow  # ~140 s on 2 loaded cores (3500 brute-force periods + bisection)
def test_period_doubling_located_and_switched_matches_brute_force():
    args_of = lambda F: jnp.stack([D, F])  # noqa: E731
    period_of = lambda a: 2 * jnp.pi / W  # noqa: E731
    y0 = sections(0.24, [1.0, 0.0], 100, last=0)[-1]
    br = continue_arclength(duffing, y0, args_of, period_of, 0.24, 0.30, ds=0.01, ds_max=0.05)
    assert br.stopped == "end value reached"
    pd = [b for b in br.bifurcations if b.kind == "period-doubling"]
    assert len(pd) == 1 and not [b for b in br.bifurcations if b.kind == "fold"]
    F_pd = pd[0].value
    assert abs(F_pd - 0.26558) < 1e-4
    assert np.min(np.abs(pd[0].multipliers + 1)) < 1e-6
    np.testing.assert_allclose(np.prod(br.multipliers, axis=1).real, np.exp(-D * T), atol=1e-7)

    below = sections(0.995 * F_pd, br.y[0], 800)
    assert np.max(np.abs(np.diff(below, axis=0))) < 1e-6
    above = sections(1.005 * F_pd, br.y[0], 1500)
    assert np.min(np.abs(above[1:] - above[:-1]).max(axis=1)) > 1e-3

    F2 = F_pd + 0.002
    orb = switch_at_period_doubling(duffing, pd[0], args_of, period_of, lam=F2, eps=0.05)
    assert int(orb.status) == 0 and bool(orb.stable)
    brute = sections(F2, np.asarray(pd[0].y), 1000)
    assert np.max(np.abs(brute[2:] - brute[:-2])) < 1e-6
    assert min(np.abs(brute[-1] - orb.y).max(), np.abs(brute[-2] - orb.y).max()) < 1e-6
    assert abs(np.prod(orb.multipliers).real - np.exp(-D * 2 * T)) < 1e-7


@pytest.mark.slow  # ~90 s: three branches and a 383-value scipy orbit diagram
def test_duffing_cascade_by_continuation_matches_brute_force_orbit_diagram():
    # scripts/duffing_cascade.py: period 1 -> 2 -> 4 -> 8 by continuation and branch switching. The
    # scipy orbit diagram (no JAX, no Newton) has period k just below each located doubling and 2k
    # just above; where the period-2k window is wide enough, the brute-force onset of the splitting
    # (|x_{n+k} - x_n|^2 linear in F, extrapolated) agrees with the located doubling within one
    # grid step (1e-4); the PD multipliers are -1 to 1e-8 (bisection in F to ~1e-10).
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / "duffing_cascade.py"
    spec = importlib.util.spec_from_file_location("duffing_cascade", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    pds, _ = mod.cascade()
    assert [r["k"] for r in pds] == [1, 2, 4]
    assert all(r["multiplier_nearest_minus_one"] < 1e-8 for r in pds)
    Fs = np.linspace(0.255, 0.2932, 383)
    h = Fs[1] - Fs[0]
    periods, points = mod.brute_force(Fs, [1.0, 0.0])
    prev = None
    for r in pds:
        k, F = r["k"], r["F_pd"]
        d = (max(2, min(10, int((F - prev) / 4.669 / 3 / h))) if prev else 10) * h
        assert np.all(periods[Fs < F - d][-3:] == k) and np.all(periods[Fs > F + d][:3] == 2 * k), (k, F)
        prev = F
    onset, _ = mod.split_onset(
        Fs, points, 1, pds[0]["F_pd"] + 10 * h, pds[0]["F_pd"] + (pds[1]["F_pd"] - pds[0]["F_pd"]) / 3
    )
    assert abs(onset - pds[0]["F_pd"]) < h
