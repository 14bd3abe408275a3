"""Lanes over single-device worker processes, one pinned to each CPU core.

In one process, XLA's CPU runtime runs the programs of all local devices on one shared thread
pool (one thread per device), and hands a program's ready kernels to that pool, where the
threads take them from each other's queues. One single-device process per core, pinned to
it, shares no pool. What that buys depends on the program: on this project's 2-core CPU, with
the pool compiled for 256-bit vectors, the 400 x 300 sweep integrating every lane on took about
three quarters of the one-process time in 2 pinned processes, and varied less; with the
512-bit program the library compiles now, it took 19.4 s in the processes against
18.1 s in one process, and stopping lanes at invalid states 3.57 s against 3.69 s
(``benchmarks/bench_processes.py`` -> docs/bifurcation/processes.json).

`HostProcesses` (an `jaxcelt.ensemble.runners.AbstractLaneRunner`) is accepted wherever a sweep takes
``devices`` (`jaxcelt.sweeps.api.sweep`, ``bifurcation``, ``parameter_map``, `jaxcelt.ensemble.run_lanes`):
each chunk's lanes are dealt
round-robin to the workers (lane i to worker i mod n, as lanes are dealt to devices), each
worker runs them through its own lane pool on its one core, and the results are put back in
lane order. The workers are started at the first chunk and kept for the next ones (each
compiles its programs once; with JAX's persistent cache directory set, as the command line sets
it, later processes load them); `close` (or the end of a ``with`` block, or of the interpreter)
stops them. Lanes are independent, so the dataset equals a one-process run's to rounding: a
single-device program is another compiled program than a multi-device one (same steps and
statuses over a few periods; a chaotic lane integrated for hundreds of periods may take its
own path).
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import traceback
import weakref
from multiprocessing.connection import Connection
from typing import Any

import jax
import numpy as np

from jaxcelt.ensemble.pool import PoolStats
from jaxcelt.ensemble.runners import AbstractLaneRunner
from jaxcelt.ensemble.stroboscopic import run_lanes, varying_names

__all__ = ["HostProcesses"]

# the JAX settings a worker copies from the parent before it starts its CPU backend
_SETTINGS = (
    "jax_enable_x64",
    "jax_compilation_cache_dir",
    "jax_persistent_cache_min_compile_time_secs",
    "jax_persistent_cache_min_entry_size_bytes",
)


def _worker_main() -> None:
    """A worker's main loop (started by `HostProcesses`, pinned and configured by its environment):
    (args, kwargs) of `jaxcelt.ensemble.run_lanes` in, results and statistics out."""
    conn = Connection(int(os.environ["JAXCELT_WORKER_FD"]))
    device = jax.local_devices()[:1]
    while True:
        try:
            msg = conn.recv()
        except EOFError:  # the parent went away
            return
        if msg is None:
            return
        args, kwargs = msg
        try:
            out, st = run_lanes(*args, devices=device, stats=True, **kwargs)
            conn.send(("ok", out, (int(st.iterations), int(st.slot_steps), int(st.width))))
        except Exception as e:  # reported to the parent, which raises it there
            conn.send(("error", type(e).__name__, str(e), traceback.format_exc()))


# Run as ``python -c``: pinned to its core before anything imports JAX (whose CPU runtime sizes its
# thread pool to the cores it may use), and without importing the parent's ``__main__`` (which
# multiprocessing's spawn does, and which re-runs a script that has no ``if __name__ == "__main__"``).
_BOOT = (
    "import os\n"
    "c = os.environ.get('JAXCELT_WORKER_CORE')\n"
    "if c: os.sched_setaffinity(0, {int(c)})\n"
    "from jaxcelt.ensemble.processes import _worker_main\n"
    "_worker_main()\n"
)


def _stop(workers: list[tuple[Any, Any]]) -> None:
    for conn, _ in workers:
        try:
            conn.send(None)
        except (BrokenPipeError, OSError):
            pass
    for conn, proc in workers:
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        conn.close()
    workers.clear()


class HostProcesses(AbstractLaneRunner):
    """``n`` single-device worker processes, one pinned to each of ``n`` CPU cores: pass as
    ``devices`` to a sweep (see the module docstring for when this pays).

    ``n``: an int >= 1 or ``"auto"`` (the cores this process may run on). ``cores``: the CPU
    cores to pin the workers to (default the first ``n`` of this process's affinity set; on
    systems without ``os.sched_setaffinity`` the workers are not pinned). Workers start at the
    first chunk; use as a context manager or call `close`.
    """

    def __init__(self, n: int | str = "auto", *, cores: list[int] | None = None):
        if os.name != "posix":
            raise ValueError("HostProcesses needs a POSIX system (it passes sockets to its worker processes)")
        avail = (
            sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else list(range(os.cpu_count() or 1))
        )
        if isinstance(n, str) and n == "auto":
            n = len(avail)
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ValueError(f"n must be an int >= 1 or 'auto', got {n!r}")
        if cores is None:
            cores = [avail[i % len(avail)] for i in range(int(n))]
        elif len(cores) != n or any(c not in avail for c in cores):
            raise ValueError(f"cores must list {n} of the CPU cores this process may use ({avail}), got {cores!r}")
        self.n = int(n)
        self.cores: list[int | None] = list(cores) if hasattr(os, "sched_setaffinity") else [None] * self.n
        self._workers: list[tuple[Any, Any]] = []
        self._finalizer = weakref.finalize(self, _stop, self._workers)  # also runs at interpreter exit

    def __repr__(self) -> str:
        return f"HostProcesses({self.n}, cores={self.cores})"

    def __enter__(self) -> HostProcesses:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        """Stop the workers (a later chunk starts new ones)."""
        _stop(self._workers)

    def _start(self) -> None:
        env = dict(os.environ, JAX_PLATFORMS="cpu", JAX_NUM_CPU_DEVICES="1")
        for k in _SETTINGS:  # JAX reads its settings from upper-case environment variables too
            v = getattr(jax.config, k)
            if v is not None:
                env[k.upper()] = str(v)
        for core in self.cores:
            here, there = socket.socketpair()
            wenv = dict(
                env, JAXCELT_WORKER_FD=str(there.fileno()), JAXCELT_WORKER_CORE="" if core is None else str(core)
            )
            proc = subprocess.Popen([sys.executable, "-c", _BOOT], env=wenv, pass_fds=(there.fileno(),))
            there.close()
            self._workers.append((Connection(here.detach()), proc))

    def run(
        self,
        pb: Any,
        y0b: Any,
        cfg: Any,
        *,
        pad_to: int | None,
        varying: tuple[str, ...],
        engine: str = "auto",
        **kwargs: Any,
    ) -> tuple[dict[str, np.ndarray], PoolStats]:
        """`jaxcelt.ensemble.run_lanes` (``stats=True``) over the workers (lanes dealt round-robin)."""
        if engine == "kernel":
            raise ValueError("engine='kernel' steps lanes on a GPU; HostProcesses are CPU worker processes (use the pool)")
        pb = jax.tree_util.tree_map(np.asarray, pb)
        y0b = np.asarray(y0b, dtype=np.float64)
        L = int(y0b.shape[0])
        # what varies over the whole chunk, so that every worker (and every chunk) compiles one program
        varying = tuple(sorted(set(varying) | varying_names(pb)))
        per = -(-max(L, pad_to or 0) // self.n)  # lanes per worker, padding included
        if not self._workers:
            self._start()
        jobs = []
        for i, (conn, _) in enumerate(self._workers):
            idx = np.arange(i, L, self.n)
            if len(idx) == 0 and not kwargs.get("compile_only"):
                continue
            send = idx if len(idx) else np.arange(min(1, L))  # compile_only: any lane (all count as padding)
            sub = jax.tree_util.tree_map(lambda x, s=send: x[s], pb)
            conn.send(((sub, y0b[send], cfg), dict(kwargs, pad_to=per, varying=varying, engine=engine)))
            jobs.append((idx, conn))
        outs, stats, error = [], [], None
        for idx, conn in jobs:
            try:
                msg = conn.recv()
            except EOFError:
                msg = ("error", "RuntimeError", "a lane worker process ended unexpectedly", "")
            if msg[0] == "ok":
                if len(idx):
                    outs.append((idx, msg[1]))
                stats.append(msg[2])
            elif error is None:
                error = msg
        if error is not None:
            _, name, text, tb = error
            if name in ("ValueError", "TypeError"):  # bad input, named by the check that found it
                raise {"ValueError": ValueError, "TypeError": TypeError}[name](text)
            if name == "RuntimeError" and not tb:
                self.close()
            raise RuntimeError(f"a lane worker failed: {name}: {text}\n{tb}")
        merged = {}
        for k, v in (outs[0][1] if outs else {}).items():
            a = np.empty((L,) + v.shape[1:], dtype=v.dtype)
            for idx, out in outs:
                a[idx] = out[k][: len(idx)]
            merged[k] = a
        st = PoolStats(
            iterations=max((s[0] for s in stats), default=0),
            slot_steps=sum(s[1] for s in stats),
            width=max((s[2] for s in stats), default=0),
        )
        return merged, st
