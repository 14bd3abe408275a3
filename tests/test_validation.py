"""Bad inputs raise ValueError naming the culprit; good inputs never give NaN (must-show 7).

Hypothesis draws bad parameter values, corrupted initial states and bad solver arguments.
All checks happen before compilation, so these tests are cheap.
"""

import re

import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import jaxcelt as jc

P = jc.CeltParams.paper()
Y0 = np.asarray(jc.initial_state(P))
SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

NONFINITE = st.sampled_from([np.nan, np.inf, -np.inf])
POSITIVE = ("a1", "a2", "a3", "m", "g", "a_hat", "eps", "eps_R", "b_r", "b_Ts", "b_Ms", "m_Ts", "m_Ms", "S0")
NONNEGATIVE = ("mu", "k_r", "q_pi", "omega_pi", "kappa", "S2", "S3")


def _raises_naming(fn, *names):
    with pytest.raises(ValueError) as info:
        fn()
    msg = str(info.value)
    assert any(re.search(rf"\b{re.escape(n)}\b", msg) for n in names), (names, msg)


@SETTINGS
@given(name=st.sampled_from(POSITIVE), value=st.floats(max_value=0.0, allow_nan=False, allow_infinity=True))
def test_nonpositive_parameter(name, value):
    _raises_naming(lambda: jc.CeltParams.paper(**{name: value}), name)
    _raises_naming(lambda: P.replace(**{name: value}), name)


@SETTINGS
@given(name=st.sampled_from(NONNEGATIVE), value=st.floats(max_value=-1e-300, allow_nan=False, allow_infinity=True))
def test_negative_parameter(name, value):
    _raises_naming(lambda: jc.CeltParams.paper(**{name: value}), name)


@SETTINGS
@given(name=st.sampled_from(jc.PARAM_NAMES), value=NONFINITE)
def test_nonfinite_parameter(name, value):
    _raises_naming(lambda: jc.CeltParams.paper(**{name: value}), name)


@SETTINGS
@given(b=st.one_of(st.floats(max_value=0.0, allow_nan=False), st.floats(min_value=1.0 + 1e-12, allow_nan=False)))
def test_axis_ratio_outside_unit_interval(b):
    _raises_naming(lambda: jc.CeltParams.paper(b=b), "b")


@SETTINGS
@given(
    which=st.sampled_from(["B12", "B13", "B23"]),
    factor=st.floats(min_value=1.0, max_value=1e3),
    sign=st.sampled_from([-1.0, 1.0]),
)
def test_inertia_not_positive_definite(which, factor, sign):
    # |B_ij| >= sqrt(B_ii B_jj) makes a 2x2 principal minor non-positive
    i, j = {"B12": (1, 2), "B13": (1, 3), "B23": (2, 3)}[which]
    bound = np.sqrt(float(getattr(P, f"B{i}")) * float(getattr(P, f"B{j}")))
    _raises_naming(lambda: jc.CeltParams.paper(**{which: sign * factor * bound}), "B")


@SETTINGS
@given(B1=st.floats(min_value=-1e-2, max_value=0.0))
def test_inertia_nonpositive_moment(B1):
    _raises_naming(lambda: jc.CeltParams.paper(B1=B1), "B")


def test_inertia_triangle_inequality():
    # positive definite but no real body has it: B3 > B1 + B2
    _raises_naming(lambda: jc.CeltParams.paper(B3=2e-3, B12=0.0, B2=1e-3, B1=2.463e-4), "B")


@pytest.mark.parametrize(
    "name,value", [("v_pi_sign", 0.5), ("v_pi_sign", 0.0), ("derivative_exact", 0.5), ("m_Ts", 2.5), ("k3", -0.03)]
)
def test_other_bad_parameters(name, value):
    _raises_naming(lambda: jc.CeltParams.paper(**{name: value}), name, "k")


def test_unknown_parameter_name():
    _raises_naming(lambda: jc.CeltParams.paper(mass=1.0), "mass")
    _raises_naming(lambda: P.replace(mass=1.0), "mass")


# ---- initial states ---------------------------------------------------------------------------


def _state(omega, tilt, azimuth, psi, vA):
    n = np.array([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)])
    vA = np.asarray(vA) - (np.asarray(vA) @ n) * n
    return np.asarray(jc.initial_state(P, omega=omega, n=n, psi=psi, v_A=vA))


VEC = st.lists(st.floats(-5, 5), min_size=3, max_size=3)
STATES = st.builds(
    _state,
    omega=VEC,
    tilt=st.floats(0.0, 1.2),
    azimuth=st.floats(-3.1, 3.1),
    psi=st.floats(-3.1, 3.1),
    vA=st.lists(st.floats(-0.1, 0.1), min_size=3, max_size=3),
)


def _bad_y0(y0, kind, mag, idx):
    y = y0.copy()
    if kind == "norm":  # |n| != 1
        y[6:9] *= 1 + mag
    elif kind == "normal_velocity":  # v_A . n != 0
        y[0:3] += mag * y[6:9]
    elif kind == "height":  # r_C3 != height of C over the contact
        y[11] += mag
    elif kind == "nonfinite":
        y[idx] = [np.nan, np.inf, -np.inf][idx % 3]
    return y


@SETTINGS
@given(
    y0=STATES,
    kind=st.sampled_from(["norm", "normal_velocity", "height", "nonfinite"]),
    mag=st.one_of(st.floats(1e-5, 0.5), st.floats(-0.5, -1e-5)),
    idx=st.integers(0, 12),
)
def test_simulate_rejects_off_manifold_y0(y0, kind, mag, idx):
    """Deviations >= 1e-5 (10x the documented MANIFOLD_TOL = 1e-6) must be caught."""
    jc.check_state(y0, P)  # the unmodified state is fine
    bad = _bad_y0(y0, kind, mag, idx)
    _raises_naming(lambda: jc.simulate(P, bad, 0.1), "y0")


@SETTINGS
@given(tilt=st.floats(np.pi / 2 + 1e-9, np.pi), azimuth=st.floats(0.0, 3.0))
def test_contact_off_lower_half_surface(tilt, azimuth):
    n = np.array([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth) * 0.9, np.cos(tilt)])
    n /= np.linalg.norm(n)
    _raises_naming(lambda: jc.initial_state(P, n=n), "n")
    # a state assembled by hand with n3 <= 0 is rejected by simulate as well
    y = Y0.copy()
    y[6:9] = n
    _raises_naming(lambda: jc.simulate(P, y, 0.1), "y0")


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(omega=(0.0, np.nan, 0.0)), "omega"),
        (dict(n=(0.0, 0.0, 2.0)), "n"),
        (dict(n=(0.0, np.inf, 1.0)), "n"),
        (dict(v_A=(0.0, 0.0, 0.1)), "v_A"),
        (dict(psi=np.nan), "psi"),
        (dict(position=(np.inf, 0.0)), "position"),
        (dict(omega=(1.0, 2.0)), "omega"),
    ],
)
def test_initial_state_bad_inputs(kwargs, name):
    _raises_naming(lambda: jc.initial_state(P, **kwargs), name)


def test_y0_wrong_shape():
    _raises_naming(lambda: jc.simulate(P, Y0[:12], 0.1), "y0")
    _raises_naming(lambda: jc.simulate(P, np.stack([Y0, Y0]), 0.1), "y0")


# ---- times and tolerances --------------------------------------------------------------------


@SETTINGS
@given(t1=st.one_of(st.floats(max_value=0.0, allow_nan=False), NONFINITE))
def test_bad_t1(t1):
    _raises_naming(lambda: jc.simulate(P, Y0, t1), "t1")


@SETTINGS
@given(
    ts=st.one_of(
        st.lists(st.floats(-1.0, 2.0), min_size=2, max_size=6).filter(
            lambda a: np.any(np.diff(a) < 0) or min(a) < 0.0 or max(a) > 1.0
        ),
        st.lists(NONFINITE, min_size=1, max_size=3),
        st.just([]),
    )
)
def test_bad_ts(ts):
    _raises_naming(lambda: jc.simulate(P, Y0, 1.0, ts=ts), "ts")


@SETTINGS
@given(
    which=st.sampled_from(["rtol", "atol"]),
    value=st.one_of(st.floats(max_value=0.0, allow_nan=False), NONFINITE),
)
def test_bad_tolerances(which, value):
    _raises_naming(lambda: jc.simulate(P, Y0, 0.1, **{which: value}), which)


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(dt0=0.0), "dt0"),
        (dict(dt0=-1e-3), "dt0"),
        (dict(dt0=np.nan), "dt0"),
        (dict(max_steps=0), "max_steps"),
        (dict(max_steps=10.5), "max_steps"),
        (dict(t0=np.nan), "t0"),
        (dict(t0=0.2), "t1"),  # t1 = 0.1 < t0
        (dict(rtol=np.array([1e-8, 1e-8])), "rtol"),
        (dict(dtype="int32"), "dtype"),
        (dict(contact_law="no_such_law"), "law"),
        (dict(monitor=1), "monitor"),
    ],
)
def test_bad_solver_arguments(kwargs, name):
    _raises_naming(lambda: jc.simulate(P, Y0, 0.1, **kwargs), name)


def test_nonscalar_times():
    _raises_naming(lambda: jc.simulate(P, Y0, jnp.array([0.1, 0.2])), "t1")
    _raises_naming(lambda: jc.simulate(P, Y0, 0.1, t0=np.zeros(2)), "t0")


# ---- good inputs give finite output -------------------------------------------------------------


@settings(max_examples=25, deadline=None)
@given(
    y0=STATES,
    mu=st.floats(0.0, 0.6),
    k_r=st.floats(0.0, 0.8),
    b=st.floats(0.05, 1.0),
    eps=st.floats(1e-8, 1e-2),
    m_Ts=st.floats(0.3, 2.0),
    t=st.floats(0.0, 10.0),
)
def test_valid_inputs_give_finite_vector_field(y0, mu, k_r, b, eps, m_Ts, t):
    p = P.replace(mu=mu, k_r=k_r, b=b, eps=eps, eps_R=eps, m_Ts=m_Ts)
    f = np.asarray(jc.vector_field(t, jnp.asarray(y0), p))
    assert np.all(np.isfinite(f))
    d = jc.diagnostics(jnp.asarray(t), jnp.asarray(y0), p)
    assert all(np.all(np.isfinite(np.asarray(x))) for x in d)


@settings(max_examples=8, deadline=None)
@given(y0=STATES, mu=st.floats(0.0, 0.6), omega_pi=st.floats(5.0, 25.0))
def test_valid_inputs_give_finite_trajectories(y0, mu, omega_pi):
    """Short solves from random valid states: the output is finite, or the solution says why not
    (status != 0 or validity lost) -- never a silent NaN."""
    p = P.replace(mu=mu, omega_pi=omega_pi)
    sol = jc.simulate(p, y0, 0.05, ts=jnp.linspace(0.0, 0.05, 3), max_steps=20_000)
    ys = np.asarray(sol.ys)
    if bool(sol.success) and bool(sol.valid):
        assert np.all(np.isfinite(ys))
    else:
        assert int(sol.status) != 0 or not bool(sol.valid)
