"""Compiled programs stored across processes (`jaxcelt._executable_cache`): a stored executable is
loaded instead of traced, gives the same result as a fresh compilation, is keyed by what shapes the
program, and a damaged file is recompiled with a warning instead of crashing."""

import subprocess
import sys
import textwrap
import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxcelt import _executable_cache as ec


@pytest.fixture
def cache(tmp_path, monkeypatch):
    old = jax.config.jax_compilation_cache_dir
    jax.config.update("jax_compilation_cache_dir", str(tmp_path))
    monkeypatch.setattr(ec, "_MEMORY", {})
    yield tmp_path / ec.SUBDIR
    jax.config.update("jax_compilation_cache_dir", old)


def _f(leaves, x):
    return jnp.sin(x) * leaves[0] + leaves[1]


def _args():
    return ([jnp.asarray(2.0), jnp.arange(3.0)], jnp.linspace(0.0, 1.0, 3))


def _traced(monkeypatch) -> list:
    """Counts the programs lowered by `compiled` (a loaded executable is not lowered)."""
    calls = []
    real = jax.jit

    def counting(fn, *a, **k):
        calls.append(fn)
        return real(fn, *a, **k)

    monkeypatch.setattr(ec.jax, "jit", counting)
    return calls


def test_stored_executable_is_loaded_not_traced(cache, monkeypatch):
    traced = _traced(monkeypatch)
    args = _args()
    want = np.sin(np.linspace(0.0, 1.0, 3)) * 2.0 + np.arange(3.0)
    out1 = ec.compiled("t", _f, args, "sin")(*args)
    assert len(traced) == 1 and len(list(cache.glob("*.bin"))) == 1
    ec._MEMORY.clear()  # as in a new process
    out2 = ec.compiled("t", _f, args, "sin")(*args)
    assert len(traced) == 1  # loaded from the file
    # the same executable run twice: identical; against numpy's sin to 1e-15 (a few ulp)
    np.testing.assert_array_equal(np.asarray(out1), np.asarray(out2))
    np.testing.assert_allclose(np.asarray(out2), want, rtol=0, atol=1e-15)


def test_key_covers_description_and_shapes(cache, monkeypatch):
    traced = _traced(monkeypatch)
    args = _args()
    ec.compiled("t", _f, args, "sin")
    ec.compiled("t", _f, args, "sin, other settings")  # another description: another program
    longer = ([jnp.asarray(2.0), jnp.arange(4.0)], jnp.linspace(0.0, 1.0, 4))
    ec.compiled("t", _f, longer, "sin")  # other shapes: another program
    assert len(traced) == 3 and len(list(cache.glob("*.bin"))) == 3


@pytest.mark.parametrize("damage", ["truncate", "garbage", "empty"])
def test_damaged_file_is_recompiled_with_a_warning(cache, monkeypatch, damage):
    args = _args()
    ec.compiled("t", _f, args, "sin")
    (path,) = cache.glob("*.bin")
    blob = path.read_bytes()
    path.write_bytes({"truncate": blob[: len(blob) // 2], "garbage": b"not a pickle" * 10, "empty": b""}[damage])
    ec._MEMORY.clear()
    traced = _traced(monkeypatch)
    with pytest.warns(RuntimeWarning, match="could not be loaded"):
        exe = ec.compiled("t", _f, args, "sin")
    assert len(traced) == 1
    np.testing.assert_allclose(np.asarray(exe(*args)), np.sin(np.linspace(0, 1, 3)) * 2 + np.arange(3.0), atol=1e-15)
    assert path.read_bytes() != b"" and len(path.read_bytes()) > 1000  # replaced by a good file
    ec._MEMORY.clear()
    ec.compiled("t", _f, args, "sin")  # and that file loads
    assert len(traced) == 1


def test_no_directory_no_files(tmp_path, monkeypatch):
    old = jax.config.jax_compilation_cache_dir
    jax.config.update("jax_compilation_cache_dir", None)
    monkeypatch.setattr(ec, "_MEMORY", {})
    try:
        assert ec.cache_dir() is None
        args = _args()
        a = ec.compiled("t", _f, args, "sin")
        assert ec.compiled("t", _f, args, "sin") is a  # kept in memory
    finally:
        jax.config.update("jax_compilation_cache_dir", old)


def test_second_process_loads_the_fit_program(tmp_path):
    """The fit's evaluation program, stored by one process, is loaded by the next: its (r, J) at the
    start equal the first process's to 1e-12 relative (the same executable; the tolerance only
    covers printing) and the second process lowers no evaluation program."""
    script = textwrap.dedent(
        f"""
        import json, sys
        import jax
        jax.config.update("jax_compilation_cache_dir", {str(tmp_path)!r})
        import numpy as np
        import jaxcelt as jc
        from jaxcelt import _executable_cache as ec
        from jaxcelt.identify.options import FitOptions
        from jaxcelt.identify.problem import build_problem
        from jaxcelt.identify.program import evaluate
        from jaxcelt.identify.records import generate_data
        p = jc.CeltParams.paper()
        y0 = jc.initial_state(p, omega=(0.0, 0.0, 5.0), n=(0.17, 0.0, 0.985), normalize=True)
        data = generate_data(p, y0, 0.1, rate=50, kinds=("omega",))
        prob, z = build_problem(data, p, FitOptions(free=("mu", "k_r"), continuity_weight=1.0, max_steps=2000))
        lowered = []
        real = ec.jax.jit
        ec.jax.jit = lambda fn, *a, **k: (lowered.append(1), real(fn, *a, **k))[1]
        r, J = evaluate(prob, np.asarray(prob.flatten(z)) + 0.1)
        print(json.dumps(dict(lowered=len(lowered), r=r.tolist(), J=J.ravel().tolist())))
        """
    )
    import json

    outs = []
    for _ in range(2):
        p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr[-3000:]
        outs.append(json.loads(p.stdout.strip().splitlines()[-1]))
    assert outs[0]["lowered"] == 1 and outs[1]["lowered"] == 0
    for k in ("r", "J"):
        np.testing.assert_allclose(outs[1][k], outs[0][k], rtol=1e-12, atol=1e-300)


def test_background_compilation_is_waited_for_and_stored(cache, monkeypatch):
    """`compile_in_background` lowers once; `compiled` then waits for that program (no second
    lowering), which is stored like a synchronous compilation and gives the same values."""
    traced = _traced(monkeypatch)
    args = _args()
    want = np.sin(np.linspace(0.0, 1.0, 3)) * 2.0 + np.arange(3.0)
    assert ec.compile_in_background("t", _f, args, "sin") is None
    ec.compile_in_background("t", _f, args, "sin")  # already started: nothing new
    exe = ec.compiled("t", _f, args, "sin")
    assert len(traced) == 1
    np.testing.assert_allclose(np.asarray(exe(*args)), want, rtol=0, atol=1e-15)
    assert len(list(cache.glob("*.bin"))) == 1
    ec._MEMORY.clear()  # a new process: loaded from the file, not lowered
    ec.compile_in_background("t", _f, args, "sin")
    assert len(traced) == 1 and not hasattr(ec._MEMORY[next(iter(ec._MEMORY))], "result")


def test_background_compilation_error_reaches_the_caller(cache, monkeypatch):
    """An XLA compilation that fails on the worker thread raises where `compiled` is called, and
    nothing is stored."""

    class Lowered:
        def compile(self, options=None):
            raise RuntimeError("XLA compilation failed")

    class Jitted:
        def lower(self, *args):
            return Lowered()

    monkeypatch.setattr(ec.jax, "jit", lambda fn: Jitted())
    ec.compile_in_background("t", _f, _args(), "sin")
    with pytest.raises(RuntimeError, match="XLA compilation failed"):
        ec.compiled("t", _f, _args(), "sin")
    assert not list(cache.glob("*.bin"))


def test_deferred_compilation_waits_for_start_deferred(cache, monkeypatch):
    """``defer=True`` lowers nothing at the call; `start_deferred` lowers and compiles the program
    on a worker thread, and `compiled` then returns that program (one lowering in all)."""
    traced = _traced(monkeypatch)
    monkeypatch.setattr(ec, "_DEFERRED", [])
    args = _args()
    want = np.sin(np.linspace(0.0, 1.0, 3)) * 2.0 + np.arange(3.0)
    ec.compile_in_background("t", _f, args, "sin", defer=True)
    ec.compile_in_background("t", _f, args, "sin", defer=True)  # already queued: nothing new
    assert len(traced) == 0 and len(ec._DEFERRED) == 1
    ec.start_deferred()
    exe = ec.compiled("t", _f, args, "sin")
    assert len(traced) == 1 and not ec._DEFERRED
    np.testing.assert_allclose(np.asarray(exe(*args)), want, rtol=0, atol=1e-15)
    assert len(list(cache.glob("*.bin"))) == 1


@pytest.mark.parametrize("ask", ["compiled", "compile_in_background"])
def test_deferred_compilation_starts_when_asked_for(cache, monkeypatch, ask):
    """A deferred program nobody started is started by `compiled` (no deadlock waiting for it) or
    by a `compile_in_background` call without ``defer``; an error while it is made reaches the
    caller of `compiled`."""
    traced = _traced(monkeypatch)
    monkeypatch.setattr(ec, "_DEFERRED", [])
    args = _args()
    ec.compile_in_background("t", _f, args, "sin", defer=True)
    if ask == "compile_in_background":
        ec.compile_in_background("t", _f, args, "sin")
        assert not ec._DEFERRED  # started
    exe = ec.compiled("t", _f, args, "sin")
    assert len(traced) == 1
    np.testing.assert_allclose(np.asarray(exe(*args)), np.sin(np.asarray(args[1])) * 2.0 + np.arange(3.0), rtol=0, atol=1e-15)

    def bad(leaves, x):
        raise TypeError("broken program")

    ec.compile_in_background("u", bad, args, "bad", defer=True)
    with pytest.raises(TypeError, match="broken program"):
        ec.compiled("u", bad, args, "bad")
    assert not any(k.startswith("u-") for k in ec._MEMORY)


def test_program_with_a_host_callback_is_not_stored_and_says_nothing(cache):
    # such a program cannot be serialised (its callback is a local Python object): it is compiled and run as usual,
    # nothing is written, and no warning reaches the user (README command 1 used to print one mid progress bar)
    def host(x):
        return np.asarray(x) + 1.0

    def f(leaves, x):
        return jax.pure_callback(host, jax.ShapeDtypeStruct(x.shape, x.dtype), x) * leaves[0]

    args = _args()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = ec.compiled("cb", f, args, "callback")(*args)
    np.testing.assert_allclose(np.asarray(out), (np.linspace(0.0, 1.0, 3) + 1.0) * 2.0, rtol=0, atol=1e-15)
    assert list(cache.glob("*.bin")) == []


def test_unwritable_directory_is_reported(cache, monkeypatch):
    # a directory that cannot be written is worth a warning: the cache does not work there
    def refuse(*a, **k):
        raise PermissionError("read-only file system")

    monkeypatch.setattr(ec.tempfile, "mkstemp", refuse)
    args = _args()
    with pytest.warns(UserWarning, match="could not store executable .*PermissionError"):
        ec.compiled("t", _f, args, "sin-unwritable")(*args)
