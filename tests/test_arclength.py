"""Pseudo-arclength continuation passes folds (`jaxcelt.orbits.branch.continue_arclength`).

Hardening Duffing x'' + 0.2 x' + x + x^3 = 0.3 cos(w t), period-1 frequency response continued
in w from 0.8 to 2.5: the resonance curve bends right, so the branch turns back once (upper
fold) and forward again (lower fold), giving a hysteresis window. Natural continuation in w
stops at the first fold; the arclength branch, started at w = 1 inside the window (0.8, 2.5)
and followed both ways, must reach both ends and report exactly two folds. It runs in a
nonlinear chart z = (x - x_ref, v - v_ref - 0.3 (x - x_ref)^2), re-centred on every point, so
the chart handling (tangent carried between charts) is exercised; the branch is a property of
the ODE, not of the chart, and is checked against scipy in state coordinates. Independent check with scipy DOP853 (no Newton, no JAX): inside the window two initial
conditions settle on two different period-1 attractors (section points repeat to 1e-6 after
300 periods; Floquet multipliers there have modulus about exp(-0.1 T) ~ 0.6, so 0.6^300 is far
below that), whose amplitudes match the stable points of the branch interpolated at that w to
1e-3 (linear interpolation between branch points spaced at most ~0.3 in arclength).
"""

import jax.numpy as jnp
import numpy as np
from scipy.integrate import solve_ivp

from jaxcelt.orbits.branch import continue_arclength

C, F = 0.2, 0.3


def duffing(t, y, p):
    c, f, w = p
    x, v = y
    return jnp.stack([v, -c * v - x - x**3 + f * jnp.cos(w * t)])


def attractor(w, y0, periods=300):
    rhs = lambda t, y: [y[1], -C * y[1] - y[0] - y[0] ** 3 + F * np.cos(w * t)]  # noqa: E731
    T = 2 * np.pi / w
    ts = T * np.arange(periods - 3, periods + 1)
    s = solve_ivp(rhs, (0, periods * T), y0, method="DOP853", rtol=1e-10, atol=1e-11, t_eval=ts)
    return s.y.T


def embed(z, ref, a):
    return jnp.stack([ref[0] + z[0], ref[1] + z[1] + 0.3 * z[0] ** 2])


def chart(y, ref, a):
    return jnp.stack([y[0] - ref[0], y[1] - ref[1] - 0.3 * (y[0] - ref[0]) ** 2])


def test_arclength_passes_both_folds_of_hardening_duffing():
    br = continue_arclength(
        duffing,
        jnp.array([0.5, 0.0]),
        lambda w: jnp.stack([C, F, w]),
        lambda a: 2 * jnp.pi / a[2],
        1.0,
        (0.8, 2.5),
        ds=0.05,
        ds_max=0.3,
        rtol=1e-9,
        atol=1e-10,
        embed=embed,
        chart=chart,
    )
    assert br.stopped == "decreasing end: end value reached; increasing end: end value reached", br.stopped
    assert br.values[0] < 0.8 and br.values[-1] > 2.5 and br.values[br.start] == 1.0
    folds = [b.value for b in br.bifurcations if b.kind == "fold"]
    assert len(folds) == 2
    hi, lo = folds  # upper fold met first, then the lower one
    assert 1.0 < lo < hi < 2.0
    # lam turns twice: the lam-component of the tangent changes sign exactly twice
    assert np.count_nonzero(np.diff(np.sign(br.tangents[:, -1]))) == 2
    # middle (between the folds along the branch) is unstable, the rest stable
    i_hi, i_lo = np.flatnonzero(np.diff(np.sign(br.tangents[:, -1])))
    assert not br.stable[i_hi + 1 : i_lo + 1].any()
    assert br.stable[:i_hi].all() and br.stable[i_lo + 2 :].all()

    w = 0.5 * (lo + hi)
    a_small = attractor(w, [0.0, 0.0])
    a_big = attractor(w, list(br.y[i_hi]))
    for a in (a_small, a_big):
        assert np.max(np.abs(np.diff(a, axis=0))) < 1e-6
    assert np.abs(a_big[-1] - a_small[-1]).max() > 0.1
    # the two attractors are on the branch's stable parts: nearest branch state within 1e-3
    # after refining the branch state by the brute-force one (compare with the closest point
    # of the piecewise-linear branch in the stable segments)
    seg = np.linspace(0, 1, 200)[:, None, None]
    pts = (1 - seg) * br.y[:-1] + seg * br.y[1:]
    lam = (1 - seg[..., 0]) * br.values[:-1] + seg[..., 0] * br.values[1:]
    for a in (a_small, a_big):
        near = np.abs(lam - w) < 2e-3
        d = np.linalg.norm(pts[near] - a[-1], axis=-1).min()
        assert d < 2e-2


def _args_of_w(w):
    return jnp.stack([C, F, w])


def _period_of(a):
    return 2 * jnp.pi / a[2]


def test_second_branch_of_a_family_reuses_its_compiled_programs():
    """A second branch of the same family (the same functions and settings) takes the jitted start solve and
    stepper of the first from the cache (no compilation), and, the same programs on the same input, repeats its
    points to rounding (1e-12: identical programs, identical input)."""
    from jaxcelt.orbits.branch import _cached_family_programs

    run = lambda: continue_arclength(duffing, jnp.array([0.5, 0.0]), _args_of_w, _period_of, 1.0, 1.3,  # noqa: E731
                                     ds=0.1, ds_max=0.3, max_points=5, rtol=1e-9, atol=1e-10)  # fmt: skip
    first = run()
    before = _cached_family_programs.cache_info()
    again = run()
    after = _cached_family_programs.cache_info()
    assert after.hits == before.hits + 1 and after.misses == before.misses
    assert len(first.values) == len(again.values) > 1
    assert np.max(np.abs(first.values - again.values)) < 1e-12 and np.max(np.abs(first.y - again.y)) < 1e-12


def test_celt_branches_of_one_stone_share_their_parameter_setter():
    """`continue_orbit` keys the family's programs on ``args_of``: one function object per stone and field,
    whatever the start value of that field, and another one for another stone."""
    import jaxcelt as jc
    from jaxcelt.orbits.celt import _field_setter

    p = jc.CeltParams.paper()
    assert _field_setter(p, "omega_pi") is _field_setter(p.replace(omega_pi=17.0), "omega_pi")
    assert _field_setter(p, "omega_pi") is not _field_setter(p.replace(mu=0.3), "omega_pi")
    assert _field_setter(p, "omega_pi") is not _field_setter(p, "q_pi")
    set_w = _field_setter(p.replace(omega_pi=17.0), "omega_pi")
    assert float(set_w(12.5).omega_pi) == 12.5 and float(set_w(12.5).mu) == float(p.mu)
