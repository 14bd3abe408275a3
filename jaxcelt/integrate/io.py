"""Writing and reading single trajectories (npz + JSON metadata; no pickle)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.physics.params import CeltParams
from jaxcelt.versions import versions


def save_trajectory(
    path: str | Path, ts, ys, params: CeltParams, *, extra: dict | None = None, meta: dict | None = None
) -> Path:
    """Save times ``ts`` (n,), states ``ys`` (n, 13) and optional extra arrays to ``path`` (.npz).

    Metadata (parameters, state names, versions, anything in ``meta``) is stored as a JSON
    string under the key ``meta`` so the file loads with ``np.load(path)`` alone.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    info = {"state_names": list(STATE_NAMES), "params": params.as_dict(), "versions": versions(), **(meta or {})}
    arrays = {k: np.asarray(v) for k, v in (extra or {}).items()}
    np.savez(path, ts=np.asarray(ts), ys=np.asarray(ys), meta=np.array(json.dumps(info)), **arrays)
    return path


def load_trajectory(path: str | Path) -> tuple[np.ndarray, np.ndarray, dict, dict]:
    """Inverse of `save_trajectory`: (ts, ys, meta, extra arrays)."""
    with np.load(path, allow_pickle=False) as f:
        meta = json.loads(str(f["meta"]))
        extra = {k: f[k] for k in f.files if k not in ("ts", "ys", "meta")}
        return f["ts"], f["ys"], meta, extra
