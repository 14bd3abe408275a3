"""Self-describing sweep datasets (xarray, netCDF via h5netcdf), written chunk by chunk, resumable.

Layout of an output directory ``out/``::

    out/manifest.json          what is being computed (fingerprint of params, values, y0,
                               solver settings, chunking) -- a resume must match it
    out/chunks/chunk_00000.nc  one netCDF file per finished chunk (atomic: temp file, fsync,
                               rename, fsync of the directory)
    out/sweep.nc               the merged dataset, written when every chunk is done

An interrupted sweep (killed process, power cut) is resumed by calling the same
`jaxcelt.sweeps.api.sweep`/`bifurcation` with the same ``out``: finished chunks are read back, the
missing ones computed. A chunk file is used only if it opens, belongs to this sweep (its
fingerprint), holds this chunk's lanes (their indices) and every expected variable with the
expected shape; a damaged one (torn write, bad copy, a file of another sweep or version) is
recomputed with a `warnings.warn` (`DamagedChunkWarning`) instead of failing the resume. Every chunk is a deterministic function of its lanes, and float64
round-trips netCDF exactly, so the final dataset is identical to an uninterrupted run's.

The merged dataset has dimensions ``(<param>, [start,] sample, state)`` and variables
``section`` (states at the stroboscopic times), ``t_section``, ``status``, ``valid``,
``first_invalid_t``, ``first_invalid_kind``, ``min_N``, ``max_tilt``, ``drift``,
``max_excursion``, ``num_steps``, ``lyapunov``, ``r_O``, ``y_final`` and the regime labels
(`jaxcelt.sweeps.regimes`). Its attributes hold the parameters, the reading switches, the solver,
its tolerances, the sweep settings and the package/JAX versions (as JSON strings where
nested). Load it with `open_sweep` (or plain ``xarray.open_dataset``).
"""

from __future__ import annotations

import hashlib
import json
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from jaxcelt.physics.model import STATE_NAMES
from jaxcelt.physics.params import CeltParams
from jaxcelt.sweeps.regimes import GLOBAL_MOTION, REGIMES, classify
from jaxcelt.sweeps.result import LANE_DIMS, LANE_FIELDS

__all__ = ["SweepWriter", "to_dataset", "to_map_dataset", "open_sweep", "SWEEP_FILE", "DamagedChunkWarning"]

SWEEP_FILE = "sweep.nc"
_ENGINE = "h5netcdf"


class DamagedChunkWarning(RuntimeWarning):
    """A chunk file of an interrupted sweep could not be used on resume; the chunk is recomputed."""


def read_manifest(path: Path) -> dict | None:
    """A resumable run's manifest (JSON), None if there is none; a damaged one is reported with a
    `DamagedChunkWarning` and treated as absent (the caller rewrites it)."""
    if not path.exists():
        return None
    try:
        return json.loads(path.read_text())
    except (ValueError, OSError) as e:
        warnings.warn(f"{path} is damaged ({e}); rewriting it", DamagedChunkWarning, stacklevel=4)
        return None


_RENAME = {"samples": "section", "t_samples": "t_section"}
_DOCS = {
    "section": ("state at the stroboscopic times t0 + (transient + k) 2 pi/omega_pi", "SI (see state)"),
    "t_section": ("stroboscopic sample times", "s"),
    "status": ("solver status: 0 success, 1 max_steps, 2 stopped invalid, 3 solver failure (e.g. a collapsed step size), 4 on its side past validity (the heading's singularity)", ""),
    "valid": ("model stayed valid (N > 0, n3 > 0) on all accepted steps", ""),
    "first_invalid_t": ("time where validity was first lost (inf if never)", "s"),
    "first_invalid_kind": ("0 valid, 1 lift-off, 2 n3 <= 0, 3 constraint denominator <= 0", ""),
    "min_N": ("minimum normal force over accepted steps", "N"),
    "max_tilt": ("maximum tilt arccos(n3) over accepted steps", "rad"),
    "drift": ("horizontal displacement of O from first to last sample", "m"),
    "max_excursion": ("max horizontal distance of O from its first-sample position", "m"),
    "num_steps": ("solver steps of the main solve", ""),
    "lyapunov": ("largest Lyapunov exponent (NaN: not computed or failed)", "1/s"),
    "lyapunov_stderr": ("batch-means standard error of lyapunov over 4 sub-windows of its window", "1/s"),
    "r_O": ("global position of the geometric centre O at the samples", "m"),
    "y_final": ("last section state (continuation start)", "SI"),
    "regime": ("local regime code, see attrs['regime_codes']", ""),
    "period": ("period k of a periodic lane in forcing periods (0: not periodic)", ""),
    "global_motion": ("0 bounded, 1 unbounded wandering of O, -1 unknown", ""),
}


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return x


def _attrs(params: CeltParams, name: str, config: Any, n_starts: int) -> dict[str, Any]:
    from jaxcelt.provenance import machine, source_commit
    from jaxcelt.versions import versions

    pd = params.as_dict()
    cfg = config.attrs()
    return {
        "title": f"jaxcelt stroboscopic sweep over {name}",
        "swept_parameter": name,
        "n_starts": int(n_starts),
        "params_json": json.dumps(_jsonable(pd), sort_keys=True),
        "switch_v_pi_sign": float(pd["v_pi_sign"]),
        "switch_derivative_exact": float(pd["derivative_exact"]),
        "solver": cfg["solver"],
        "rtol": cfg["rtol"],
        "atol": cfg["atol"],
        "max_steps": cfg["max_steps"],
        "transient_periods": cfg["transient_periods"],
        "sample_periods": cfg["sample_periods"],
        "lyapunov_periods": cfg["lyapunov_periods"],
        "config_json": json.dumps(cfg, sort_keys=True),
        "versions_json": json.dumps(versions(), sort_keys=True),
        # the code and machine (not the time or load: a resumed sweep equals an uninterrupted one)
        "provenance_json": json.dumps({**source_commit(), "machine": machine()}, sort_keys=True),
        "regime_codes": json.dumps(REGIMES),
        "global_motion_codes": json.dumps(GLOBAL_MOTION),
        "state_names": ",".join(STATE_NAMES),
        "model": "Awrejcewicz & Kudra (2014), DNC 3(2) 123-132; equations in MODEL.md",
    }


def _lane_variables(fields: dict[str, Any], lead: tuple[str, ...], **classify_kwargs) -> dict[str, xr.Variable]:
    """Dataset variables (and regime labels) from lane arrays with leading dims ``lead``."""
    data = {}
    for key in LANE_FIELDS:
        arr = np.asarray(fields[key])
        if arr.dtype == bool:
            arr = arr.astype(np.int8)
        out = _RENAME.get(key, key)
        desc, units = _DOCS[out]
        data[out] = xr.Variable(lead + LANE_DIMS.get(key, ()), arr, attrs={"long_name": desc, "units": units})
    f = fields
    labels = classify(
        f["samples"], f["status"], f["valid"], f["r_O"], f["lyapunov"], lyapunov_stderr=f["lyapunov_stderr"],
        **classify_kwargs,
    )  # fmt: skip
    for key, arr in labels.items():
        desc, units = _DOCS[key]
        data[key] = xr.Variable(lead, arr, attrs={"long_name": desc, "units": units})
    return data


def _base_coords(n_samples: int) -> dict[str, Any]:
    return {"state": list(STATE_NAMES), "xyz": ["X1", "X2", "X3"], "sample": np.arange(n_samples)}


def to_dataset(result: Any, params: CeltParams, config: Any, **classify_kwargs) -> xr.Dataset:
    """An xarray Dataset from a `jaxcelt.sweeps.result.SweepResult` (regime labels added)."""
    name = result.name
    vals = np.asarray(result.values)
    multi = vals.ndim == 2
    lead = (name, "start") if multi else (name,)
    coords: dict[str, Any] = {name: vals[:, 0] if multi else vals, **_base_coords(np.shape(result.samples)[-2])}
    if multi:
        coords["start"] = np.arange(vals.shape[1])
    fields = {k: getattr(result, k) for k in LANE_FIELDS}
    data = _lane_variables(fields, lead, **classify_kwargs)
    attrs = _attrs(params, name, config, vals.shape[1] if multi else 1)
    attrs["classify_json"] = json.dumps(classify_kwargs, sort_keys=True)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def to_lanes_dataset(
    lanes: dict[str, np.ndarray],
    *,
    lane_values: dict[str, np.ndarray],
    params: CeltParams,
    config: Any,
    **classify_kwargs,
) -> xr.Dataset:
    """A dataset of an arbitrary batch of lanes (`jaxcelt.sweeps.api.sweep_lanes`): dim ``lane``, each
    varied parameter a coordinate along it."""
    n = len(lanes["status"])
    coords: dict[str, Any] = {"lane": np.arange(n), **_base_coords(lanes["samples"].shape[-2])}
    coords.update({k: ("lane", np.asarray(v)) for k, v in lane_values.items()})
    data = _lane_variables(lanes, ("lane",), **classify_kwargs)
    names = ", ".join(lane_values) or "lanes"
    attrs = _attrs(params, names, config, 1)
    attrs["title"] = f"jaxcelt stroboscopic lanes over {names}"
    attrs["classify_json"] = json.dumps(classify_kwargs, sort_keys=True)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def to_map_dataset(
    lanes: dict[str, np.ndarray],
    *,
    x: tuple[str, np.ndarray],
    y: tuple[str, np.ndarray],
    n_starts: int,
    params: CeltParams,
    config: Any,
    **classify_kwargs,
) -> xr.Dataset:
    """A two-parameter map's Dataset, dims ``(x, y, [start,] ...)``, from lane arrays shaped
    (nx, ny, [K,] ...) (``n_starts`` = K, 0 for a single start without a ``start`` dim)."""
    (xn, xs), (yn, ys) = x, y
    lead = (xn, yn, "start") if n_starts else (xn, yn)
    coords: dict[str, Any] = {xn: np.asarray(xs), yn: np.asarray(ys), **_base_coords(lanes["samples"].shape[-2])}
    if n_starts:
        coords["start"] = np.arange(n_starts)
    data = _lane_variables(lanes, lead, **classify_kwargs)
    attrs = _attrs(params, f"{xn} x {yn}", config, max(n_starts, 1))
    attrs.pop("swept_parameter")
    attrs["title"] = f"jaxcelt two-parameter map over {xn} x {yn}"
    attrs["x_parameter"], attrs["y_parameter"] = xn, yn
    attrs["classify_json"] = json.dumps(classify_kwargs, sort_keys=True)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def open_sweep(path: str | os.PathLike) -> xr.Dataset:
    """Load a sweep dataset (a ``sweep.nc`` file or an output directory) into memory."""
    p = Path(path)
    if p.is_dir():
        p = p / SWEEP_FILE
    with xr.open_dataset(p, engine=_ENGINE) as ds:
        return ds.load()


class SweepWriter:
    """Chunk-by-chunk writer with resume (used by `jaxcelt.sweeps.driver` when ``out`` is given)."""

    def __init__(self, out, *, params, name, lane_values, lane_y0, n_starts, config, chunks):
        self.dir = Path(out)
        self.params, self.name, self.config, self.n_starts = params, name, config, n_starts
        self.chunks = chunks
        manifest = {
            "name": name,
            "params": _jsonable(params.as_dict()),
            "lane_values": np.asarray(lane_values).tolist(),
            "lane_y0_sha256": hashlib.sha256(np.ascontiguousarray(lane_y0, dtype=np.float64).tobytes()).hexdigest(),
            "n_starts": int(n_starts),
            "config": config.attrs(),
            "chunks": [np.asarray(c).tolist() for c in chunks],
        }
        self.fingerprint = hashlib.sha256(json.dumps(manifest, sort_keys=True).encode()).hexdigest()
        manifest["fingerprint"] = self.fingerprint
        (self.dir / "chunks").mkdir(parents=True, exist_ok=True)
        mpath = self.dir / "manifest.json"
        old = read_manifest(mpath)  # a torn manifest: the chunk files carry the fingerprint too
        if old is not None:
            if old.get("fingerprint") != self.fingerprint:
                raise ValueError(
                    f"{self.dir} holds a different sweep (manifest fingerprint differs); use a new directory or delete it"
                )
        else:
            _atomic_write_text(mpath, json.dumps(manifest, indent=1, sort_keys=True))

    def _chunk_path(self, ci: int) -> Path:
        return self.dir / "chunks" / f"chunk_{ci:05d}.nc"

    def write_chunk(self, ci: int, res: dict[str, np.ndarray]) -> None:
        data = {"lane_index": xr.Variable(("lane",), np.asarray(self.chunks[ci], dtype=np.int64))}
        for key, arr in res.items():
            arr = np.asarray(arr)
            if arr.dtype == bool:
                arr = arr.astype(np.int8)
            data[key] = xr.Variable(("lane",) + tuple(f"{key}_{i}" for i in range(1, arr.ndim)), arr)
        ds = xr.Dataset(data, attrs={"fingerprint": self.fingerprint, "chunk": ci})
        _atomic_write_dataset(ds, self._chunk_path(ci))

    def _read_chunk(self, ci: int, path: Path) -> dict[str, np.ndarray]:
        """A chunk file's lane arrays; ValueError saying why it cannot be used."""
        try:
            with xr.open_dataset(path, engine=_ENGINE) as ds:
                attrs = dict(ds.attrs)
                res = {k: ds[k].values for k in ds.data_vars}  # reads every byte: a torn file fails here
        except Exception as e:  # h5py/h5netcdf raise OSError, KeyError, ValueError... on damaged files
            raise ValueError(f"unreadable ({type(e).__name__}: {str(e)[:120]})") from None
        if attrs.get("fingerprint") != self.fingerprint:
            raise ValueError("written by another sweep or version (fingerprint differs)")
        if int(attrs.get("chunk", -1)) != ci:
            raise ValueError(f"holds chunk {attrs.get('chunk')!r}, not {ci}")
        lanes = np.asarray(self.chunks[ci])
        if not np.array_equal(res.pop("lane_index", None), lanes):
            raise ValueError("does not hold this chunk's lanes")
        S = int(self.config.sample_periods)
        shapes = {k: (len(lanes),) for k in _CHUNK_SCALARS}
        shapes.update(samples=(len(lanes), S, 13), t_samples=(len(lanes), S), r_O=(len(lanes), S, 3))
        shapes["y_final"] = (len(lanes), 13)
        for key, shape in shapes.items():
            if key not in res:
                raise ValueError(f"variable {key!r} missing")
            if res[key].shape != shape:
                raise ValueError(f"variable {key!r} has shape {res[key].shape}, expected {shape}")
        res["valid"] = res["valid"].astype(bool)
        return res

    def load_done(self) -> dict[int, dict[str, np.ndarray]]:
        """The finished chunks on disk; damaged ones are left out (recomputed) with a warning."""
        done = {}
        for ci in range(len(self.chunks)):
            path = self._chunk_path(ci)
            if not path.exists():
                continue
            try:
                done[ci] = self._read_chunk(ci, path)
            except ValueError as e:
                warnings.warn(f"chunk file {path} is damaged, recomputing it: {e}", DamagedChunkWarning, stacklevel=3)
        return done

    def finalize(self, result: Any) -> xr.Dataset:
        return self.write_dataset(to_dataset(result, self.params, self.config))

    def write_dataset(self, ds: xr.Dataset) -> xr.Dataset:
        """Write the merged dataset (``out/sweep.nc``)."""
        _atomic_write_dataset(ds, self.dir / SWEEP_FILE)
        return ds


_CHUNK_SCALARS = tuple(f for f in LANE_FIELDS if f not in LANE_DIMS)
"""per-lane scalars every chunk file holds (besides samples, t_samples, r_O, y_final)"""


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # platforms without directory handles (Windows)
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _durable_replace(tmp: Path, path: Path) -> None:
    """Flush ``tmp`` to disk, rename it onto ``path`` (atomic), flush the directory entry."""
    with open(tmp, "rb+") as f:
        os.fsync(f.fileno())
    os.replace(tmp, path)
    _fsync_dir(path.parent)


def _atomic_write_dataset(ds: xr.Dataset, path: Path) -> None:
    tmp = path.with_suffix(f"{path.suffix}.tmp{os.getpid()}")  # processes of one sweep may race
    ds.to_netcdf(tmp, engine=_ENGINE)
    _durable_replace(tmp, path)


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_suffix(f"{path.suffix}.tmp{os.getpid()}")
    tmp.write_text(text)
    _durable_replace(tmp, path)
