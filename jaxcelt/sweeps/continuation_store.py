"""What a global continuation keeps of one parameter value, and its resumable files.

A continuation runs value after value; the seeds of value i come from the attractors found at value
i - 1, so one value is the unit of work and of writing. `ValueRecord` is everything later values and the
final dataset need from one value: each fresh lane's outcome and final section point, each seed's origin
and outcome, and the table of attractors (global id, kind, period, basin count, representative section
point, section points for matching and seeding, refinement, exponent).

`ContinuationStore` (xarray and the sweep dataset helpers are imported on first use) writes one netCDF file per value in ``out/values/`` with the helpers of the sweep
datasets (`jaxcelt.sweeps.dataset`: temp file, fsync, atomic rename) and a ``manifest.json`` with the
fingerprint of the whole run (model, parameter values, starts, settings): a rerun with another fingerprint
in the same directory is refused. On resume a value file is used only if it opens, carries the run's
fingerprint and its index, was computed from the same seeds (their SHA-256: the seeds are recomputed from
the previous value's record) and has the expected shapes; otherwise it is recomputed with a
`jaxcelt.sweeps.dataset.DamagedChunkWarning`. Values are a deterministic function of their inputs and float64
round-trips netCDF exactly, so a resumed run gives the same dataset as an uninterrupted one.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import warnings
from pathlib import Path

import numpy as np

__all__ = ["ValueRecord", "ContinuationStore", "REFINE_STATUS", "seeds_digest"]

REFINE_STATUS: dict[int, str] = {-1: "not run", 0: "converged", 1: "not converged", 2: "solver failed", 3: "error"}
"""Codes of a periodic attractor's refinement."""

_LANE = ("lane_outcome", "lane_kind", "lane_period", "lane_final")
_SEED = ("seed_origin", "seed_outcome")
_ATT = (
    "att_id", "att_kind", "att_k", "att_count", "att_lanes", "att_state", "att_t", "att_cloud", "att_cloud_n",
    "att_refine", "att_mu_max", "att_stable", "att_lyap", "att_lyap_se", "att_orbit_state", "att_orbit_k",
    "att_orbit_mu",
)  # fmt: skip
_DIMS = {
    "lane_outcome": ("lane",), "lane_kind": ("lane",), "lane_period": ("lane",), "lane_final": ("lane", "dim"),
    "seed_origin": ("seed",), "seed_outcome": ("seed",),
    "att_state": ("att", "dim"), "att_cloud": ("att", "point", "dim"), "att_orbit_state": ("att", "dim"),
}  # fmt: skip


@dataclasses.dataclass
class ValueRecord:
    """One parameter value of a continuation (N fresh lanes, M seeds, A attractors, d state dimensions, P
    points per attractor at most).

    Attributes:
        index, value: position and value of the parameter; seeds_sha: `seeds_digest` of the seeds it ran;
        next_id: the next free global attractor id after this value.
        lane_outcome: (N,) global attractor id of each fresh lane, -1 tipping over, -2 failed;
        lane_kind: (N,) kind code (`jaxcelt.sweeps.continuation_match.KINDS` index; -1, -2 as above);
        lane_period: (N,) k (0 unless periodic); lane_final: (N, d) last section state.
        seed_origin: (M,) global id of the attractor each seed came from; seed_outcome: (M,) where it went.
        att_id: (A,) global ids; att_kind, att_k: kind code and period; att_count: fresh lanes in the basin;
        att_lanes: all lanes (fresh and seeds) on it; att_state: (A, d) representative section state (the
        refined orbit's when Newton converged); att_t: its section time [s]; att_cloud: (A, P, d) section
        points (a periodic attractor's k cycle points, a set's samples), NaN-padded; att_cloud_n: (A,) how
        many; att_refine: `REFINE_STATUS` code; att_mu_max: largest Floquet multiplier modulus (NaN if not
        refined); att_stable: 1 / 0 / -1 unknown; att_lyap, att_lyap_se: median lambda_1 of its lanes and
        the median of their standard errors [1/s] (NaN if not computed).
        att_orbit_state, att_orbit_k, att_orbit_mu: the periodic orbit that goes with the attractor (its own
        refined orbit, or the orbit of its predecessor continued to this value by Newton), its period (0: none)
        and largest multiplier modulus; the next value continues it and seeds from it.
    """

    index: int
    value: float
    seeds_sha: str
    next_id: int
    lane_outcome: np.ndarray
    lane_kind: np.ndarray
    lane_period: np.ndarray
    lane_final: np.ndarray
    seed_origin: np.ndarray
    seed_outcome: np.ndarray
    att_id: np.ndarray
    att_kind: np.ndarray
    att_k: np.ndarray
    att_count: np.ndarray
    att_lanes: np.ndarray
    att_state: np.ndarray
    att_t: np.ndarray
    att_cloud: np.ndarray
    att_cloud_n: np.ndarray
    att_refine: np.ndarray
    att_mu_max: np.ndarray
    att_stable: np.ndarray
    att_lyap: np.ndarray
    att_lyap_se: np.ndarray
    att_orbit_state: np.ndarray
    att_orbit_k: np.ndarray
    att_orbit_mu: np.ndarray

    def cloud(self, a: int) -> np.ndarray:
        """Section points (n, d) of the a-th attractor of this value."""
        return self.att_cloud[a, : int(self.att_cloud_n[a])]


def seeds_digest(seeds: np.ndarray) -> str:
    """SHA-256 of the seed states (float64 bytes, shape included)."""
    s = np.ascontiguousarray(seeds, dtype=np.float64)
    return hashlib.sha256(repr(s.shape).encode() + s.tobytes()).hexdigest()


class ContinuationStore:
    """One file per parameter value under ``out/values/`` and the run's manifest (see the module docstring)."""

    def __init__(self, out, fingerprint: dict) -> None:
        from jaxcelt.sweeps.dataset import _atomic_write_text, read_manifest

        self.dir = Path(out)
        text = json.dumps(fingerprint, sort_keys=True, default=repr)
        self.fingerprint = hashlib.sha256(text.encode()).hexdigest()
        (self.dir / "values").mkdir(parents=True, exist_ok=True)
        mpath = self.dir / "manifest.json"
        old = read_manifest(mpath)
        if old is not None and old.get("fingerprint") != self.fingerprint:
            raise ValueError(
                f"out: {self.dir} holds a different continuation (manifest fingerprint differs); "
                "use a new directory or delete it"
            )
        if old is None:
            _atomic_write_text(mpath, json.dumps({"fingerprint": self.fingerprint, "run": json.loads(text)}, indent=1))

    def path(self, index: int) -> Path:
        return self.dir / "values" / f"value_{index:05d}.nc"

    def write(self, rec: ValueRecord) -> None:
        import xarray as xr

        from jaxcelt.sweeps.dataset import _atomic_write_dataset

        data = {}
        for key in _LANE + _SEED + _ATT:
            arr = np.asarray(getattr(rec, key))
            dims = _DIMS.get(key, ("att",) if key.startswith("att") else (key.split("_")[0],))
            data[key] = xr.Variable(dims, arr)
        attrs = dict(fingerprint=self.fingerprint, index=rec.index, value=rec.value, seeds_sha=rec.seeds_sha,
                     next_id=rec.next_id)  # fmt: skip
        _atomic_write_dataset(xr.Dataset(data, attrs=attrs), self.path(rec.index))

    def load(self, index: int, seeds_sha: str, *, n_lanes: int, dim: int) -> ValueRecord | None:
        """The record of value ``index`` if its file is usable, else None (a damaged or stale file warns)."""
        from jaxcelt.sweeps.dataset import DamagedChunkWarning

        path = self.path(index)
        if not path.exists():
            return None
        try:
            return self._read(path, index, seeds_sha, n_lanes, dim)
        except ValueError as e:
            warnings.warn(f"value file {path} cannot be used, recomputing it: {e}", DamagedChunkWarning, stacklevel=3)
            return None

    def _read(self, path: Path, index: int, seeds_sha: str, n_lanes: int, dim: int) -> ValueRecord:
        import xarray as xr

        from jaxcelt.sweeps.dataset import _ENGINE

        try:
            with xr.open_dataset(path, engine=_ENGINE) as ds:
                attrs = dict(ds.attrs)
                arrs = {k: ds[k].values for k in ds.data_vars}
        except Exception as e:  # h5py/h5netcdf raise OSError, KeyError, ValueError... on damaged files
            raise ValueError(f"unreadable ({type(e).__name__}: {str(e)[:120]})") from None
        if attrs.get("fingerprint") != self.fingerprint:
            raise ValueError("written by another continuation (fingerprint differs)")
        if int(attrs.get("index", -1)) != index:
            raise ValueError(f"holds value {attrs.get('index')!r}, not {index}")
        if attrs.get("seeds_sha") != seeds_sha:
            raise ValueError("computed from other seeds (the previous value changed)")
        missing = [k for k in _LANE + _SEED + _ATT if k not in arrs]
        if missing:
            raise ValueError(f"variables {missing} missing")
        A = arrs["att_id"].shape[0]
        want = {"lane_outcome": (n_lanes,), "lane_final": (n_lanes, dim), "att_state": (A, dim)}
        for key, shape in want.items():
            if arrs[key].shape != shape:
                raise ValueError(f"variable {key!r} has shape {arrs[key].shape}, expected {shape}")
        if arrs["att_cloud"].ndim != 3 or arrs["att_cloud"].shape[::2] != (A, dim):
            raise ValueError(f"variable 'att_cloud' has shape {arrs['att_cloud'].shape}")
        return ValueRecord(index=index, value=float(attrs["value"]), seeds_sha=seeds_sha,
                           next_id=int(attrs["next_id"]), **arrs)  # fmt: skip
