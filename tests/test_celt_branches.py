"""The wobblestone's period-1 branch through the 15.6 rad/s orbit (slow: minutes of Newton solves).

* `continue_orbit` over omega_pi in (14.6, 18.2) finds one fold and one Neimark-Sacker point.
  Checked without the continuation's own test functions: just above the fold periodic_orbit
  converges from both sheets to two different orbits, one stable and one with a real multiplier
  above 1 (a saddle-node pair); just below it Newton from the fold state finds nothing. Past the
  NS point a perturbation of the orbit along the direction of its complex pair grows in a plain
  `simulate` (no Newton, no variational equations); before it, it decays. The windows on the
  growth/decay ratio are loose (|mu|^n with |mu| within 1e-2 of 1 over n = 200 periods: factors
  between 0.2 and 5), since only the sign of log|mu| is asserted.
* d(omega_fold)/d(mu) by the implicit function theorem (`locate_orbit_bifurcation`, jax.grad) vs
  central differences of the located fold (h = 1e-4: truncation ~h^2 f''' ~1e-8, Newton noise
  1e-10/h ~1e-6): relative 1e-4.
"""

import importlib.util
import json
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow


def _orbit():
    d = json.loads((ROOT / "docs/orbits/orbit_check.json").read_text())
    p = jc.CeltParams.paper(omega_pi=15.6)
    return p, jc.periodic_orbit(p, np.asarray(d["y"]), t0=d["t0"])


def _pair_growth(om, orb, periods=200, eps=1e-6):
    """Growth of the leading complex pair's amplitude over ``periods``, by plain integration.

    The orbit and the orbit perturbed along Re v (v: eigenvector of the leading multiplier of the
    state-space monodromy) are integrated with `simulate`; the difference is decomposed on
    (Re v, -Im v) (r_C excluded: translations are neutral), giving the complex amplitude c with
    delta = 2 Re(c v). In the linear regime |c_n| / |c_0| = |mu|^n, the other modes having
    decayed (next |mu| <~ 0.75: 0.75^200 ~ 1e-25)."""
    p = jc.CeltParams.paper(omega_pi=om)
    T = 2 * np.pi / om
    w, V = np.linalg.eig(np.asarray(orb.monodromy_full))
    v = V[:, np.argmin(np.abs(w - np.asarray(orb.multipliers[0])))]
    y = np.asarray(orb.y)
    y1 = np.asarray(jc.project_state(jnp.asarray(y + eps * np.real(v) / np.linalg.norm(np.real(v))), p))
    ts = jnp.array([periods * T])
    a, b = (jc.simulate(p, jnp.asarray(s), periods * T, ts=ts, rtol=1e-11, atol=1e-13, exact_ts=True) for s in (y, y1))
    keep = np.r_[0:9, 12]
    A = np.stack([np.real(v), -np.imag(v)], axis=1)[keep]

    def amp(d):
        c = np.linalg.lstsq(A, d[keep], rcond=None)[0]
        return np.hypot(*c)

    return amp(np.asarray(b.ys[-1]) - np.asarray(a.ys[-1])) / amp(y1 - y), float(np.abs(orb.multipliers[0])) ** periods


def test_branch_fold_and_neimark_sacker_checked_by_newton_and_simulation():
    p, orb = _orbit()
    br = jc.continue_orbit(p, orb, "omega_pi", (14.6, 18.2))
    kinds = [b.kind for b in br.bifurcations]
    assert sorted(kinds) == ["Neimark-Sacker", "fold"], kinds
    fold = next(b for b in br.bifurcations if b.kind == "fold")
    ns = next(b for b in br.bifurcations if b.kind == "Neimark-Sacker")
    assert 14.8 < fold.value < 15.0 and 17.5 < ns.value < 18.0

    # saddle-node: two orbits just above the fold (one per sheet: the branch crosses `above` twice,
    # Newton from the nearer point of each crossing), none just below
    above = fold.value + 0.02
    v = br.values
    cross = [i for i in range(len(v) - 1) if (v[i] - above) * (v[i + 1] - above) <= 0]
    assert len(cross) == 2
    sheets = []
    for i in cross:
        j = i if abs(v[i] - above) <= abs(v[i + 1] - above) else i + 1
        o = jc.periodic_orbit(jc.CeltParams.paper(omega_pi=above), br.y[j], t0=0.0, newton_max_steps=10)
        assert int(o.status) == 0
        sheets.append(o)
    assert np.max(np.abs(np.asarray(sheets[0].y) - np.asarray(sheets[1].y))) > 1e-3
    mods = sorted(float(np.abs(s.multipliers[0])) for s in sheets)
    assert mods[0] < 1.0 < mods[1]
    unstable = sheets[int(np.argmax([float(np.abs(s.multipliers[0])) for s in sheets]))]
    assert abs(float(np.imag(unstable.multipliers[0]))) < 1e-8  # a real multiplier > 1 (saddle)
    below = jc.periodic_orbit(jc.CeltParams.paper(omega_pi=fold.value - 0.02), fold.y, t0=0.0, newton_max_steps=10)
    assert int(below.status) != 0

    # Neimark-Sacker: the complex pair's amplitude decays before, grows after (plain simulate),
    # at the rate |mu|^n of the multipliers (1e-2 relative: integration error ~1e-5 of the 1e-6
    # perturbation, nonlinear terms ~1e-6)
    complex_lead = np.abs(np.imag(br.multipliers[:, 0])) > 1e-8
    for om, grows in ((ns.value - 0.25, False), (ns.value + 0.25, True)):
        j = int(np.argmin(np.abs(br.values - om) + 1e3 * ~complex_lead))
        o = jc.periodic_orbit(jc.CeltParams.paper(omega_pi=om), br.y[j], t0=0.0, newton_max_steps=10)
        assert int(o.status) == 0 and bool(o.stable) != grows
        g, expected = _pair_growth(om, o)
        assert (g > 1.0) == grows, (om, g)
        np.testing.assert_allclose(g, expected, rtol=1e-2)


def test_fold_derivative_in_mu_matches_finite_differences():
    spec = importlib.util.spec_from_file_location("celt_fold_grad", ROOT / "scripts" / "celt_fold_grad.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    r = mod.check(1e-4)
    assert r["status"] == 0 and r["fd_status"] == [0, 0]
    assert abs(r["multipliers_abs"][0] - 1.0) < 1e-7
    assert r["relative_difference"] < 1e-4, r
