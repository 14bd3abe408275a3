"""Where a chunk of lanes runs when it does not run on this process's JAX devices.

`jaxcelt.ensemble.run_lanes` shards a chunk over local devices (`jaxcelt.ensemble.shard`) by
default. Passed as its ``devices``, an `AbstractLaneRunner` takes the whole chunk instead and
returns the same per-lane arrays: `jaxcelt.ensemble.processes.HostProcesses` runs it in worker
processes, one per CPU core, each calling `run_lanes` on its own device. The interface lives in
this module so that the engine depends on it and not on any particular runner (a runner calls
the engine, the engine only calls the runner).
"""

from __future__ import annotations

import abc
from typing import Any

import numpy as np

from jaxcelt.ensemble.pool import PoolStats

__all__ = ["AbstractLaneRunner"]


class AbstractLaneRunner(abc.ABC):
    """Runs one chunk of stroboscopic lanes somewhere else than on this process's devices."""

    @abc.abstractmethod
    def run(
        self, pb: Any, y0b: Any, cfg: Any, *, pad_to: int | None, varying: tuple[str, ...], engine: str, **kwargs: Any
    ) -> tuple[dict[str, np.ndarray], PoolStats]:
        """`jaxcelt.ensemble.run_lanes` with ``stats=True`` for the chunk (batched ``pb``, ``y0b``, settings
        ``cfg``): per-lane arrays in lane order and the pool's statistics. ``kwargs``: the pool's
        other settings (``width``, ``compile_only``, ``pilot_fraction``, ``drain_factor``,
        ``min_drain_width``, ``drain_min_steps``). ValueError for an ``engine`` the runner cannot use."""
