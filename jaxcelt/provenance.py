"""Where a result came from: the one helper every result file is written through.

``provenance()`` records the jaxcelt commit (and whether the working tree had uncommitted changes), the machine
(CPU model, cores the process may use, GPU model when JAX runs on one), the versions of the numerical stack, the
load average when the result was written, the UTC time and the command line. ``write_result(path, data)`` writes
a JSON result file with that record under the key ``"provenance"``; the CLI, the benchmarks and the study scripts
all write their result files through it, so a number quoted in the docs can be traced to a commit and a machine.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

from .versions import versions

_SOURCE = Path(__file__).resolve().parent


def _git(*args: str) -> str | None:
    try:
        out = subprocess.run(
            ["git", *args], cwd=_SOURCE, capture_output=True, text=True, timeout=10, check=True
        ).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    return out.strip()


def source_commit() -> dict[str, Any]:
    """The jaxcelt commit this process imports, and whether its tree differs from that commit.

    ``{"commit": None, "dirty": None}`` when jaxcelt is not imported from a git checkout (an installed wheel):
    the package version in ``versions()`` is then what identifies the code.
    """
    commit = _git("rev-parse", "HEAD")
    if not commit:
        return {"commit": None, "dirty": None}
    status = _git("status", "--porcelain", "--untracked-files=no")
    return {"commit": commit, "dirty": bool(status)}


def cpu_model() -> str:
    """The CPU's model name (from /proc/cpuinfo on Linux, sysctl on macOS), else ``platform.processor()``."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith(("model name", "hardware")):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    if sys.platform == "darwin":
        try:
            return subprocess.run(
                ["sysctl", "-n", "machdep.cpu.brand_string"], capture_output=True, text=True, timeout=5
            ).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            pass
    return platform.processor() or platform.machine()


def machine() -> dict[str, Any]:
    """CPU model, logical cores (all, and those this process may run on), accelerator model, host OS."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        usable = os.cpu_count()
    out: dict[str, Any] = {
        "cpu": cpu_model(),
        "cpu_cores": os.cpu_count(),
        "cpu_cores_usable": usable,
        "platform": platform.platform(),
    }
    import jax

    devs = jax.devices()
    if devs and devs[0].platform != "cpu":
        out["accelerator"] = devs[0].device_kind
        out["accelerator_count"] = len(devs)
    return out


def load_average() -> list[float] | None:
    """The 1, 5 and 15 minute load averages (None where the OS has none)."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def provenance(*, load_at_start: list[float] | None = None) -> dict[str, Any]:
    """The provenance record stored in every result file (see the module docstring).

    Args:
        load_at_start: the load average taken when the measurement began (``load_average()``), stored next to
            the load when the file is written; pass it from timing scripts so a busy machine shows.
    """
    rec: dict[str, Any] = {
        **source_commit(),
        "written_utc": _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
        "command": shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]]) if sys.argv and sys.argv[0] else None,
        "machine": machine(),
        "versions": versions(),
        "load_average": load_average(),
    }
    if load_at_start is not None:
        rec["load_average_at_start"] = [round(float(x), 2) for x in load_at_start]
    return rec


def write_result(
    path: str | os.PathLike,
    data: dict[str, Any],
    *,
    load_at_start: list[float] | None = None,
    indent: int | None = 1,
    default=None,
) -> Path:
    """Write ``data`` as a JSON result file at ``path`` with ``data["provenance"] = provenance()``.

    The file is written to a temporary name and renamed, so an interrupted write never leaves a damaged result.
    Returns the path written.

    Args:
        path: the JSON file to write (its folder is created).
        data: the result, a dict; a ``"provenance"`` key in it is replaced.
        load_at_start: see ``provenance``.
        indent: JSON indentation (``None``: one line).
        default: how to write objects JSON does not know (as ``json.dumps``); numpy and JAX scalars and arrays
            and paths are written as numbers, lists and strings without it.
    """
    if not isinstance(data, dict):
        raise ValueError(f"data: a result must be a dict (a JSON object), got {type(data).__name__}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    out = {**data, "provenance": provenance(load_at_start=load_at_start)}
    tmp = path.with_name(path.name + ".tmp")
    def fallback(x):
        try:
            return _default(x)
        except TypeError:
            if default is None:
                raise
            return default(x)

    tmp.write_text(json.dumps(out, indent=indent, default=fallback) + "\n", encoding="utf-8")
    os.replace(tmp, path)
    return path


def append_run(
    path: str | os.PathLike,
    run: dict[str, Any],
    *,
    load_at_start: list[float] | None = None,
) -> Path:
    """Append ``run`` to the list ``"runs"`` of the result file at ``path`` (written through ``write_result``).

    For benchmarks whose file gathers runs of several processes or machines: each run keeps its own
    ``"provenance"``, and the file's top-level provenance is that of the last write. A file that holds a bare
    list (an older layout) is read as that list of runs. Returns the path written.

    Raises:
        ValueError: ``path`` exists but is not a result file of runs (it is left as it is).
    """
    if not isinstance(run, dict):
        raise ValueError(f"run: a run must be a dict (a JSON object), got {type(run).__name__}")
    path = Path(path)
    runs: list = []
    if path.exists():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as e:
            raise ValueError(f"path: {path} is not valid JSON ({e}); move it aside to start a new file") from None
        runs = old if isinstance(old, list) else old.get("runs") if isinstance(old, dict) else None
        if not isinstance(runs, list):
            raise ValueError(f"path: {path} holds no list of runs; move it aside to start a new file")
    runs = [*runs, {**run, "provenance": provenance(load_at_start=load_at_start)}]
    return write_result(path, {"runs": runs}, load_at_start=load_at_start)


def _default(x):
    """numpy and JAX scalars and arrays in result dicts."""
    if hasattr(x, "tolist"):
        return x.tolist()
    if hasattr(x, "item"):
        return x.item()
    if isinstance(x, Path):
        return str(x)
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")
