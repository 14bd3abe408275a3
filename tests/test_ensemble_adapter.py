"""The diffrax/equinox internals behind `jaxcelt._diffrax_adapter`: the installed versions are the
pinned ones, the names still exist, and the adapted loop takes diffeqsolve's steps.

If a diffrax or equinox release breaks one of these, the lane pool (`jaxcelt.ensemble`) would no
longer take `jaxcelt.simulate`'s steps: these tests name the cause before the sweep tests fail."""

import functools
import importlib.metadata
import tomllib
from pathlib import Path

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from packaging.requirements import Requirement

from jaxcelt import _diffrax_adapter as ad


def _pinned() -> dict[str, Requirement]:
    deps = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())["project"]["dependencies"]
    return {r.name: r for r in map(Requirement, deps)}


@pytest.mark.parametrize("package", ["diffrax", "equinox"])
def test_installed_versions_are_the_pinned_ones(package):
    req = _pinned()[package]
    # an upper bound is what makes the pin a pin: without one a new release is accepted unchecked
    assert any(s.operator == "<" for s in req.specifier), f"{package}: no upper bound in pyproject.toml ({req})"
    installed = importlib.metadata.version(package)
    assert req.specifier.contains(installed, prereleases=True), f"{package} {installed} is outside {req.specifier}"


def test_adapted_names_exist():
    from diffrax._root_finder import use_stepsize_tol
    from diffrax._term import WrapTerm

    assert ad.use_stepsize_tol is use_stepsize_tol
    assert isinstance(ad.wrap_term(diffrax.ODETerm(lambda t, y, a: -y)), WrapTerm)


def test_clip_helpers_match_diffrax():
    # t1_clip_floor: 100 ULP below t1, counted independently with numpy's nextafter
    for t1 in (1.0, 3.7, 1234.5):
        want = t1
        for _ in range(100):
            want = np.nextafter(want, -np.inf)
        assert float(ad.t1_clip_floor(jnp.asarray(t1))) == want
    # clip_to_end against diffrax's own (private) function, on both sides of the floor
    from diffrax._integrate import _clip_to_end

    t1 = jnp.asarray(2.0)
    floor = ad.t1_clip_floor(t1)
    for tprev, tnext in ((1.0, 1.5), (1.0, float(floor) + 1e-15), (1.9, 2.5)):
        for keep in (True, False):
            args = (jnp.asarray(tprev), jnp.asarray(tnext))
            _, got = ad.clip_to_end(*args, t1, floor, jnp.asarray(keep))
            want = _clip_to_end(jnp.minimum(args[0], t1), args[1], t1, floor, jnp.asarray(keep))
            assert float(got) == float(want), (tprev, tnext, keep)


def _nextafter_count(jaxpr) -> int:
    """How many nextafter operations a jaxpr holds, sub-jaxprs (loops, custom derivatives, calls) included."""
    count = 0
    for eqn in jaxpr.eqns:
        count += eqn.primitive.name == "nextafter"
        for value in eqn.params.values():
            for sub in value if isinstance(value, (tuple, list)) else (value,):
                sub = getattr(sub, "jaxpr", sub)  # a ClosedJaxpr's jaxpr
                if hasattr(sub, "eqns"):
                    count += _nextafter_count(sub)
    return count


def test_compact_end_rounding_same_threshold_fewer_operations():
    import diffrax._integrate as integrate

    with ad.compact_end_rounding():
        # inside the block, the 100 chained calls of diffeqsolve's loop give t1 - 100 ULP, counted with numpy.
        # Exact equality: a step to the neighbouring float is bit arithmetic, the same on every CPU and program
        for t1 in (1.0, 3.7, 1234.5, -2.5):
            x = jnp.asarray(t1)
            for _ in range(100):
                x = integrate.eqxi.prevbefore(x)
            want = np.float64(t1)
            for _ in range(100):
                want = np.nextafter(want, -np.inf)
            assert float(x) == want, t1
    # outside it, one call is one step (equinox's own prevbefore)
    assert float(integrate.eqxi.prevbefore(jnp.asarray(1.0))) == np.nextafter(1.0, -np.inf)

    def solve(field, t1, y0):
        # each program its own vector field (both kept alive): diffeqsolve's trace is not reused between them
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(field),
            diffrax.Tsit5(), 0.0, t1, None, y0, jnp.asarray(4.0),
            saveat=diffrax.SaveAt(ts=jnp.linspace(0.0, 5.0, 6)),
            stepsize_controller=diffrax.PIDController(rtol=1e-8, atol=1e-10),
        )  # fmt: skip
        return sol.ys

    args = (jnp.asarray(5.0), jnp.array([1.0, 0.0]))  # t1 traced: the threshold is computed in the program
    field_plain, field_compact = (lambda t, y, a: _forced_oscillator(t, y, a)), (lambda t, y, a: _forced_oscillator(t, y, a))
    plain = jax.make_jaxpr(functools.partial(solve, field_plain))(*args)
    with ad.compact_end_rounding():
        compact = jax.make_jaxpr(functools.partial(solve, field_compact))(*args)
    assert _nextafter_count(plain.jaxpr) >= 100  # diffrax's unrolled chain
    assert _nextafter_count(compact.jaxpr) <= 2
    # the same solve: two compiled programs, so to rounding (1e-13 of states of order 1), though the threshold,
    # and so every step, is the same
    ys_plain = jax.core.eval_jaxpr(plain.jaxpr, plain.consts, *args)[0]
    ys_compact = jax.core.eval_jaxpr(compact.jaxpr, compact.consts, *args)[0]
    np.testing.assert_allclose(np.asarray(ys_compact), np.asarray(ys_plain), rtol=0, atol=1e-13)


def _forced_oscillator(t, y, args):
    return jnp.stack([y[1], -args * y[0] - 0.3 * y[1] + jnp.sin(2.0 * t)])


@pytest.mark.parametrize("solver", [diffrax.Tsit5(), diffrax.Dopri8(), diffrax.Heun()], ids=lambda s: type(s).__name__)
@pytest.mark.parametrize("step_ts", [False, True], ids=["pid", "pid+step_ts"])
def test_adapted_loop_takes_diffeqsolve_steps(solver, step_ts):
    # loop_init + loop_step repeated until t1 against diffeqsolve(SaveAt(steps=True)): the same
    # number of attempted and accepted steps, and the same accepted step times and states.
    # Tolerance 1e-13: the same operations in the same order, but compiled inside another program
    # (XLA may fuse and reassociate differently), so rounding, not bitwise, is what is promised.
    t0, t1, y0, k = 0.0, 6.0, jnp.array([1.0, 0.0]), jnp.asarray(4.0)
    term = diffrax.ODETerm(_forced_oscillator)
    ts = jnp.linspace(0.5, t1, 12)
    tol = 1e-3 if isinstance(solver, diffrax.Heun) else 1e-7  # Heun: 2nd order, 1st-order error estimate
    pid = diffrax.PIDController(rtol=tol, atol=tol / 100)
    ctrl = diffrax.ClipStepSizeController(pid, step_ts=ts) if step_ts else pid
    max_steps = 1000
    sol = diffrax.diffeqsolve(
        term, solver, t0, t1, None, y0, args=k, stepsize_controller=ctrl,
        saveat=diffrax.SaveAt(steps=True), max_steps=max_steps,
    )  # fmt: skip
    n_acc = int(sol.stats["num_accepted_steps"])
    assert sol.result == diffrax.RESULTS.successful and n_acc > 10  # several steps, rejections likely

    @jax.jit
    def adapted():
        wterm = ad.wrap_term(term)
        t0_, t1_ = jnp.asarray(t0), jnp.asarray(t1)
        tnext, cstate, sstate = ad.loop_init(solver, wterm, ctrl, t0_, t1_, y0, k)
        floor = ad.t1_clip_floor(t1_)
        out_t = jnp.full(max_steps, jnp.inf)
        out_y = jnp.full((max_steps, 2), jnp.inf)

        def body(c):
            tprev, tnext, y, sstate, cstate, n, n_acc, out_t, out_y = c
            keep, y1, tprev, tnext, sstate1, cstate, _, _ = ad.loop_step(
                solver, wterm, ctrl, t1_, floor, tprev, tnext, y, k, sstate, cstate
            )
            y = jnp.where(keep, y1, y)
            sstate = jax.tree_util.tree_map(lambda a, b: jnp.where(keep, a, b), sstate1, sstate)
            out_t = jnp.where(keep, out_t.at[n_acc].set(tprev), out_t)
            out_y = jnp.where(keep, out_y.at[n_acc].set(y), out_y)
            return tprev, tnext, y, sstate, cstate, n + 1, n_acc + keep.astype(int), out_t, out_y

        c = (t0_, tnext, y0, sstate, cstate, 0, 0, out_t, out_y)
        c = jax.lax.while_loop(lambda c: (c[0] < t1_) & (c[5] < max_steps), body, c)
        return c[5], c[6], c[7], c[8]

    n, n_acc_ad, got_t, got_y = adapted()
    assert int(n) == int(sol.stats["num_steps"]) and int(n_acc_ad) == n_acc
    np.testing.assert_allclose(np.asarray(got_t[:n_acc]), np.asarray(sol.ts[:n_acc]), rtol=1e-13, atol=0)
    np.testing.assert_allclose(np.asarray(got_y[:n_acc]), np.asarray(sol.ys[:n_acc]), rtol=0, atol=1e-13)
    assert float(got_t[n_acc - 1]) == t1  # the last accepted step ends on t1 exactly (clip_to_end)


@pytest.mark.parametrize("solver", [diffrax.Tsit5(), diffrax.Dopri5()], ids=lambda s: type(s).__name__)
def test_solve_to_takes_diffeqsolve_steps(solver):
    # solve_to against diffeqsolve(SaveAt(t1=True)) of the same problem: the same number of
    # steps, the same result code, y(t1) to 1e-13 (the same operations compiled in another program:
    # rounding, not bitwise, is promised); a step budget too small gives max_steps_reached in both
    t0, t1, y0, k = 0.0, 6.0, jnp.array([1.0, 0.0]), jnp.asarray(4.0)
    term = diffrax.ODETerm(_forced_oscillator)
    pid = diffrax.PIDController(rtol=1e-8, atol=1e-10)
    for max_steps in (1000, 20):
        sol = diffrax.diffeqsolve(term, solver, t0, t1, None, y0, args=k, stepsize_controller=pid, max_steps=max_steps, throw=False)
        y, result, n = jax.jit(
            lambda y0, ms=max_steps: ad.solve_to(solver, term, pid, jnp.asarray(t0), jnp.asarray(t1), y0, k, ms)
        )(y0)
        assert int(n) == int(sol.stats["num_steps"]), max_steps
        assert result == sol.result, max_steps
        if max_steps == 1000:
            assert sol.result == diffrax.RESULTS.successful and int(n) > 50
            np.testing.assert_allclose(np.asarray(y), np.asarray(sol.ys[-1]), rtol=0, atol=1e-13)
        else:
            assert sol.result == diffrax.RESULTS.max_steps_reached


def test_forward_only_plain_stage_loop_where_diffrax_chose():
    # solve_to's solvers: a Runge-Kutta solver left at diffrax's default scan_kind (None: checkpointed stages, for
    # reverse mode) gets the plain loop; a scan_kind the caller chose and solvers without stages are kept
    assert ad.forward_only(diffrax.Tsit5()).scan_kind == "lax"
    assert ad.forward_only(diffrax.Kvaerno5()).scan_kind == "lax"
    kept = diffrax.Tsit5(scan_kind="bounded")
    assert ad.forward_only(kept) is kept
    euler = diffrax.Euler()
    assert ad.forward_only(euler) is euler
    assert diffrax.Tsit5().scan_kind is None  # the default this relies on


def test_runtime_checks_as_nan_removes_host_callbacks():
    """Inside `runtime_checks_as_nan` a traced `eqx.error_if` lowers without a host callback and
    returns NaN where it would raise; outside, equinox's default (a callback that raises) holds --
    also after the jitted check was traced in the default mode first (its trace is cached)."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp
    import numpy as np

    from jaxcelt._diffrax_adapter import runtime_checks_as_nan

    def f(x):
        return eqx.error_if(x, x < 0, "x must be >= 0") + 1.0

    plain = jax.jit(f).lower(jnp.asarray(1.0)).as_text()
    with runtime_checks_as_nan():
        low = jax.jit(lambda x: f(x) * 1.0).lower(jnp.asarray(1.0))
    assert "callback" in plain and "callback" not in low.as_text()
    comp = low.compile()
    assert np.isnan(comp(jnp.asarray(-1.0))) and comp(jnp.asarray(2.0)) == 3.0
    with pytest.raises(Exception, match="x must be >= 0"):
        jax.jit(lambda x: f(x) * 2.0)(jnp.asarray(-1.0))


def test_every_diffeqsolve_goes_through_the_adapter():
    # jaxcelt's solves call the adapter's diffeqsolve (t1 - 100 ULP by a loop), never diffrax's directly
    root = Path(ad.__file__).parent
    direct = [
        str(f.relative_to(root))
        for f in root.rglob("*.py")
        if f.name != "_diffrax_adapter.py" and "diffrax.diffeqsolve(" in f.read_text()
    ]
    assert direct == []
