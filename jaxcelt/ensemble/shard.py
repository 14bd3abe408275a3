"""Lanes over devices: a 1-D device mesh, padding, and `jax.shard_map` over the lane axis.

Each device runs its own pool over its slice of the lanes (no cross-device synchronisation
inside the time loop). On CPU one XLA computation uses about one core, so split the CPU into K
devices before the first JAX operation (``jax.config.update("jax_num_cpu_devices", K)``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import jax
import numpy as np

__all__ = ["device_mesh", "shard_lanes", "pad_lanes", "dealt_positions", "LANE_AXIS"]

LANE_AXIS = "lanes"


def device_mesh(devices: Sequence[Any] | None) -> Any:
    """``Mesh(devices, ("lanes",))`` (default all local devices), or None for a single device."""
    devs = list(devices) if devices is not None else jax.local_devices()
    if len(devs) <= 1:
        return None
    return jax.sharding.Mesh(np.array(devs), (LANE_AXIS,))


def shard_lanes(run: Callable, mesh: Any, n_in: int) -> Callable:
    """``run`` over the lane axis of its ``n_in`` inputs and of its outputs, split over ``mesh``
    (``run`` itself if None). Every input and output leaf has the lane axis first."""
    if mesh is None:
        return run
    spec = jax.sharding.PartitionSpec(LANE_AXIS)
    return jax.shard_map(run, mesh=mesh, in_specs=(spec,) * n_in, out_specs=spec, check_vma=False)


def pad_lanes(x: np.ndarray, n: int) -> np.ndarray:
    """``x`` padded to ``n`` rows with copies of its last row."""
    if len(x) == n:
        return x
    return np.concatenate([x, np.repeat(x[-1:], n - len(x), axis=0)])


def dealt_positions(n: int, n_devices: int) -> np.ndarray:
    """Lanes 0 .. n - 1 (``n`` a multiple of ``n_devices``) dealt round-robin over the devices of a sharded lane axis:
    position i holds lane ``dealt_positions(n, n_devices)[i]``. Device d holds the contiguous block of positions
    d n / n_devices ... (d + 1) n / n_devices - 1, so it gets lanes d, d + n_devices, d + 2 n_devices, ..."""
    return np.arange(n).reshape(-1, n_devices).T.reshape(-1)
