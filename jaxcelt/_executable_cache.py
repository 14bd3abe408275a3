"""Compiled programs kept across processes: tracing and XLA compilation both skipped.

JAX's persistent compilation cache (``jax_compilation_cache_dir``) skips XLA's compilation but
not tracing and lowering, which for a program holding a differentiated ODE solve costs seconds
in every new process. `compiled` keeps the loaded executable itself, in memory for the process
and -- when JAX's persistent cache directory is set -- serialised under
``<jax_compilation_cache_dir>/jaxcelt-executables/`` (``jax.experimental.serialize_executable``).

A stored executable is found by a key that covers everything that shapes the program: the
caller's description of the function (its static configuration), the shapes and dtypes of the
arguments, the source of the jaxcelt package, the versions of jax, jaxlib, diffrax, equinox and
optimistix, the backend, the CPU's instruction-set flags, and the environment variables that
change tracing or code generation (``EQX_ON_ERROR``, ``XLA_FLAGS``). Editing an installed
dependency in place without changing its version is not seen: delete the directory then. A file
that cannot be read (truncated, damaged, another format) is reported with a warning and replaced
by a fresh compilation; files are written to a temporary name, flushed and renamed. Loading an
executable runs code from the file: the directory must be the user's own, as JAX's cache is.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import functools
import gc
import hashlib
import os
import pickle
import platform
import tempfile
import threading
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import jax

_MEMORY: dict[str, Any] = {}  # key -> executable, or a Future of one being compiled in the background
_DEFERRED: list[Callable[[], None]] = []  # deferred programs' jobs, not started yet (`start_deferred`)
_DEFERRED_LOCK = threading.Lock()
SUBDIR = "jaxcelt-executables"


@contextlib.contextmanager
def gc_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while the block runs (then back as it was).

    Tracing a program that holds an ODE solve allocates millions of objects that live until the
    trace ends, and every full collection during the trace walks all of them; without collections
    the traces of the sweep's pool, its Lyapunov stage and `jaxcelt.sweeps.dense.dense_trajectory` are faster. The
    block's cycles are collected later, as usual."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


@functools.cache
def _source_hash() -> str:
    h = hashlib.sha256()
    root = Path(__file__).parent
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()


@functools.cache
def _environment() -> str:
    from importlib.metadata import PackageNotFoundError, version

    parts = []
    for pkg in ("jax", "jaxlib", "diffrax", "equinox", "optimistix", "lineax"):
        try:
            parts.append(f"{pkg}={version(pkg)}")
        except PackageNotFoundError:
            parts.append(f"{pkg}=none")
    parts.append(f"backend={jax.default_backend()}")
    parts.append("devices=" + ",".join(sorted({d.device_kind for d in jax.devices()})))
    parts.append(f"machine={platform.machine()}")
    try:  # the instruction-set extensions XLA's CPU backend compiles for
        with open("/proc/cpuinfo") as fh:
            flags = next((ln for ln in fh if ln.startswith(("flags", "Features"))), "")
    except OSError:
        flags = platform.processor()
    parts.append("cpu=" + hashlib.sha256(flags.encode()).hexdigest())
    parts.append(f"x64={jax.config.jax_enable_x64}")
    return ";".join(parts)


def cache_dir() -> Path | None:
    """Directory of the stored executables, or None when JAX's persistent cache is not set."""
    d = jax.config.jax_compilation_cache_dir
    return Path(d) / SUBDIR if d else None


def _key(name: str, description: str, args: tuple, options: dict | None = None) -> str:
    shapes = [(tuple(a.shape), str(a.dtype)) for a in jax.tree.leaves(args)]
    env = [os.environ.get(v, "") for v in ("EQX_ON_ERROR", "XLA_FLAGS")]
    opts = repr(sorted((options or {}).items()))
    text = "\n".join([name, description, repr(jax.tree.structure(args)), repr(shapes), repr(env), opts, _environment()])
    return name + "-" + hashlib.sha256((text + _source_hash()).encode()).hexdigest()[:32]


def compiled(name: str, fn: Callable, args: tuple, description: str, options: dict | None = None) -> Callable:
    """``jax.jit(fn)`` compiled for ``args`` (a tuple of arrays or lists of arrays), from this
    process's memory, from the directory of stored executables, or compiled now (and stored).

    ``description`` must determine ``fn`` completely apart from the arguments (e.g. the repr of the
    static part of the problem it closes over): two functions with equal ``name`` and
    ``description`` are taken to be the same program. If `compile_in_background` has started
    this program, the call waits for it. ``options``: XLA compiler options of this program.
    """
    key = _key(name, description, args, options)
    exe = _MEMORY.get(key)
    if isinstance(exe, concurrent.futures.Future):
        start_deferred()  # a deferred program is needed now
    if exe is None:
        exe = _load(key)
        if exe is None:
            with gc_paused():
                lowered = jax.jit(fn).lower(*args)
            exe = _compile_and_store(key, lowered, options)
        _MEMORY[key] = exe
    if isinstance(exe, concurrent.futures.Future):
        try:
            exe = exe.result()
        except BaseException:
            _MEMORY.pop(key, None)  # a later call compiles again
            raise
        _MEMORY[key] = exe
    return exe


@functools.cache
def _compiler() -> concurrent.futures.ThreadPoolExecutor:
    return concurrent.futures.ThreadPoolExecutor(max_workers=2, thread_name_prefix="jaxcelt-compile")


def compile_later(compile_fn: Callable[[], Any]) -> concurrent.futures.Future:
    """Run ``compile_fn`` (e.g. a lowered program's ``compile``) on one of jaxcelt's compile
    threads: XLA's compilation releases the GIL, so the caller can trace other programs, and two
    compilations can run at once."""
    return _compiler().submit(compile_fn)


def compile_in_background(
    name: str, fn: Callable, args: tuple, description: str, options: dict | None = None, *, defer: bool = False
) -> None:
    """Start making the program `compiled` would return: traced and lowered now (in the calling
    thread: tracing is Python), compiled by XLA on a worker thread, so that the caller can trace and
    compile its other programs meanwhile (XLA's compilation releases the GIL). A program already in
    memory or on disk is loaded now instead.

    ``defer=True``: trace and compile it later, both on a worker thread, once `start_deferred` is
    called -- by work about to wait on a computation that leaves CPU cores idle (the sweep's
    Lyapunov stage), by `compiled` or by a later call without ``defer`` for this program."""
    key = _key(name, description, args, options)
    if key in _MEMORY:
        if not defer:
            start_deferred()
        return
    exe = _load(key)
    if exe is not None:
        _MEMORY[key] = exe
        return
    if defer:
        future: concurrent.futures.Future = concurrent.futures.Future()

        def job() -> None:
            if not future.set_running_or_notify_cancel():
                return
            try:
                with gc_paused():
                    lowered = jax.jit(fn).lower(*args)
                future.set_result(_compile_and_store(key, lowered, options))
            except BaseException as e:  # reported where the program is used (`compiled`)
                future.set_exception(e)

        with _DEFERRED_LOCK:
            _DEFERRED.append(job)
        _MEMORY[key] = future
        return
    with gc_paused():
        lowered = jax.jit(fn).lower(*args)
    _MEMORY[key] = compile_later(functools.partial(_compile_and_store, key, lowered, options))


def start_deferred() -> None:
    """Start tracing and compiling the deferred programs (`compile_in_background` with
    ``defer=True``) on a worker thread, one after another; returns at once."""
    with _DEFERRED_LOCK:
        jobs = list(_DEFERRED)
        _DEFERRED.clear()
    if jobs:
        _compiler().submit(lambda: [job() for job in jobs])


def _compile_and_store(key: str, lowered: Any, options: dict | None) -> Any:
    """XLA-compile ``lowered`` with ``options`` and store the executable under ``key`` (if a directory is set)."""
    exe = lowered.compile(options)
    _store_for(key, exe)
    return exe


def _load(key: str) -> Any:
    """The stored executable of ``key``, or None (none stored, no directory, or unreadable)."""
    d = cache_dir()
    path = d / f"{key}.bin" if d is not None else None
    if path is None or not path.exists():
        return None
    from jax.experimental import serialize_executable

    try:
        payload, in_tree, out_tree = pickle.loads(path.read_bytes())
        return serialize_executable.deserialize_and_load(payload, in_tree, out_tree)
    except Exception as e:  # truncated, damaged or foreign file: compile again and replace it
        warnings.warn(
            f"jaxcelt: stored executable {path} could not be loaded ({type(e).__name__}: {e}); recompiling",
            RuntimeWarning,
            stacklevel=3,
        )
        return None


def _store_for(key: str, exe: Any) -> None:
    d = cache_dir()
    if d is not None:
        _store(d / f"{key}.bin", exe)


def _store(path: Path, exe: Any) -> None:
    from jax.experimental import serialize_executable

    try:
        blob = pickle.dumps(serialize_executable.serialize(exe))
    except Exception:  # noqa: BLE001
        # A program with a host callback (a progress bar, an error check) cannot be serialised: it is simply not
        # stored, and a later process compiles it as it would without this cache. Nothing for the user to act on.
        return
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            fh.write(blob)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        tmp = None
    except OSError as e:  # an unwritable or full directory: worth saying, the cache does not work
        warnings.warn(f"jaxcelt: could not store executable {path.name} ({type(e).__name__}: {e})", stacklevel=3)
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.remove(tmp)
