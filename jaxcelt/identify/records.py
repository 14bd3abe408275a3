"""Measured trajectories for identification: the records (`Trajectory`, `MeasuredData`), a synthetic-data
generator and a documented, pickle-free file format (``.npz`` / netCDF, and CSV for one record).

The observation kinds a record may hold are those of `jaxcelt.identify.observe` (`OBSERVABLES`).

File format (``.npz``, written by `save_data`, read by `load_data` with ``allow_pickle=False``).
All arrays are float64 unless stated; ``i`` is the trajectory index 0..n-1:

==========================  =====================================================================
``format``                  str, ``"jaxcelt-measured-data"``
``version``                 int, 1
``n_trajectories``          int
``meta_json``               str, JSON object (generator settings, true parameters if synthetic...)
``traj{i}_ts``              (T,) sample times [s]
``traj{i}_omega_pi``        () base angular frequency of this record [rad/s]
``traj{i}_q_pi``            () base amplitude of this record [m]
``traj{i}_y0``              (13,) state at ts[0] if known (the release condition), else all NaN
``traj{i}_kinds``           str, comma-separated observation kinds present
``traj{i}_obs_{kind}``      (T, k) observed values
``traj{i}_sigma_{kind}``    (k,) standard deviation used to weight each channel (same units)
==========================  =====================================================================

The same content can be written as netCDF (``.nc``, via xarray/h5netcdf): one group-free file with
variables named exactly as above and dimensions ``traj{i}_time``, ``{kind}_channel``.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt import _config  # noqa: F401
from jaxcelt._types import Array, ArrayLike
from jaxcelt.identify.observe import OBSERVABLES, SENSOR_KINDS, observe, rotation_matrix
from jaxcelt.physics.params import CeltParams

__all__ = [
    "Trajectory",
    "MeasuredData",
    "generate_data",
    "save_data",
    "load_data",
    "from_arrays",
    "save_csv",
    "load_csv",
    "CSV_COLUMNS",
]

FORMAT = "jaxcelt-measured-data"
FORMAT_VERSION = 1


@dataclasses.dataclass(frozen=True)
class Trajectory:
    """One measured record. Arrays are numpy float64.

    ts: (T,) sample times [s]; obs: kind -> (T, k); sigma: kind -> (k,) per-channel standard
    deviations (weights are 1/sigma); omega_pi [rad/s], q_pi [m]: base forcing of this record;
    y0: (13,) state at ts[0] if known, else None.
    """

    ts: np.ndarray
    obs: dict[str, np.ndarray]
    sigma: dict[str, np.ndarray]
    omega_pi: float
    q_pi: float
    y0: np.ndarray | None = None

    def __post_init__(self):
        ts = np.asarray(self.ts, float)
        if ts.ndim != 1 or ts.size < 2 or np.any(np.diff(ts) <= 0):
            raise ValueError(f"Trajectory: 'ts' must be an increasing 1-D array of >= 2 times, got shape {ts.shape}")
        if not self.obs:
            raise ValueError("Trajectory: no observations")
        for kind, x in self.obs.items():
            if kind not in OBSERVABLES:
                raise ValueError(f"Trajectory: unknown observation kind {kind!r}; known: {sorted(OBSERVABLES)}")
            k = OBSERVABLES[kind]
            if np.shape(x) != (ts.size, k):
                raise ValueError(f"Trajectory: obs[{kind!r}] must have shape {(ts.size, k)}, got {np.shape(x)}")
            s = np.asarray(self.sigma.get(kind, np.full(k, np.nan)), float)
            if s.shape != (k,) or not np.all(np.isfinite(s) & (s > 0)):
                raise ValueError(f"Trajectory: sigma[{kind!r}] must be {k} positive finite numbers, got {s}")
        if self.y0 is not None and np.shape(self.y0) != (13,):
            raise ValueError(f"Trajectory: 'y0' must have shape (13,), got {np.shape(self.y0)}")

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(self.obs)

    def subset(self, kinds: Sequence[str]) -> Trajectory:
        """The same record with only the observation kinds ``kinds`` (partial observation)."""
        missing = set(kinds) - set(self.obs)
        if missing:
            raise ValueError(f"Trajectory.subset: kinds {sorted(missing)} not in the record ({self.kinds})")
        return dataclasses.replace(self, obs={k: self.obs[k] for k in kinds}, sigma={k: self.sigma[k] for k in kinds})


@dataclasses.dataclass(frozen=True)
class MeasuredData:
    """Several trajectories (possibly with different base forcing) and free-form metadata."""

    trajectories: tuple[Trajectory, ...]
    meta: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        if len(self.trajectories) == 0:
            raise ValueError("MeasuredData: no trajectories")

    def subset(self, kinds: Sequence[str]) -> MeasuredData:
        """Keep only the observation kinds ``kinds`` in every trajectory."""
        return MeasuredData(tuple(t.subset(kinds) for t in self.trajectories), dict(self.meta))


def generate_data(
    params: CeltParams,
    y0s: Sequence[Array] | Array,
    t1: float | Sequence[float],
    *,
    rate: float = 100.0,
    kinds: Sequence[str] = ("state", "omega", "orientation", "centre"),
    noise: float = 0.0,
    seed: int = 0,
    omega_pis: Sequence[float] | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    sensor_rotation: ArrayLike | None = None,
    time_offset: float | Sequence[float] = 0.0,
) -> MeasuredData:
    """Synthetic "measured" records: simulate at ``params`` and sample, with Gaussian noise.

    Args:
        params: the true parameters.
        y0s: one initial state (13,) or a sequence (one per trajectory), on the contact manifold.
        t1: record length [s] (one, or one per trajectory); samples at ``0, 1/rate, ...``.
        rate: sampling rate [Hz].
        kinds: observation kinds to record (partial observation: e.g. ``("omega",)``).
        noise: relative noise level: channel c gets N(0, sigma_c^2) with
            sigma_c = noise * RMS_c (RMS over the record of the noise-free channel, floored at
            1e-6 of the largest channel RMS of that kind). ``noise=0``: exact samples, and
            sigma_c is the nominal 1% of RMS_c (used as weights).
        seed: numpy random seed (reproducible).
        omega_pis: base frequency per trajectory [rad/s]; default ``params.omega_pi`` for all.
        rtol, atol: integration tolerances (tighter than a fit uses, so data are "exact").
        sensor_rotation: rotation vector (3,) [rad] from body to sensor axes: ``"omega"`` and
            ``"accel"`` are recorded in sensor axes, R h (`rotation_matrix`); default none.
        time_offset: model time minus record time [s] (one, or one per trajectory): the record
            starts (t = 0, state y0) at model time ``time_offset``, i.e. at that phase of the base's motion.

    Returns:
        `MeasuredData`; ``meta`` records the true parameters and the settings; each trajectory
        stores its true ``y0`` (the release condition known to the experimenter).
    """
    from jaxcelt.integrate.solve import simulate

    y0s = np.atleast_2d(np.asarray(y0s, float))
    nt = len(y0s)
    t1s = np.broadcast_to(np.asarray(t1, float), (nt,))
    omega_pis = np.broadcast_to(np.asarray(params.omega_pi if omega_pis is None else omega_pis, float), (nt,))
    for k in kinds:
        if k not in OBSERVABLES:
            raise ValueError(f"generate_data: unknown observation kind {k!r}; known: {sorted(OBSERVABLES)}")
    if not (rate > 0 and noise >= 0):
        raise ValueError(f"generate_data: need rate > 0 and noise >= 0, got rate={rate}, noise={noise}")
    offsets = np.broadcast_to(np.asarray(time_offset, float), (nt,))
    Rs = np.asarray(rotation_matrix(np.zeros(3) if sensor_rotation is None else sensor_rotation))
    rng = np.random.default_rng(seed)
    trajs = []
    for i in range(nt):
        p = params.replace(omega_pi=float(omega_pis[i]))
        ts = np.arange(0.0, t1s[i] + 0.5 / rate, 1.0 / rate)
        ts = ts[ts <= t1s[i] + 1e-12]
        tm = ts + offsets[i]  # model time
        sol = simulate(
            p, jnp.asarray(y0s[i]), float(tm[-1]), t0=float(tm[0]), ts=jnp.asarray(tm), rtol=rtol, atol=atol
        )
        if not bool(sol.success) or not bool(sol.valid):
            raise ValueError(f"generate_data: trajectory {i} failed or left the model's validity: {sol.summary()}")
        obs, sig = {}, {}
        for k in kinds:
            clean = np.asarray(jax.vmap(lambda y, t, k=k, p=p: observe(y, p, k, t))(sol.ys, sol.ts))
            if k in SENSOR_KINDS:
                clean = clean @ Rs.T
            rms = np.sqrt(np.mean(clean**2, axis=0))
            rms = np.maximum(rms, 1e-6 * rms.max())
            sigma = (noise if noise > 0 else 0.01) * rms
            obs[k] = clean + (noise > 0) * rng.standard_normal(clean.shape) * sigma
            sig[k] = sigma
        trajs.append(
            Trajectory(ts=ts, obs=obs, sigma=sig, omega_pi=float(omega_pis[i]), q_pi=float(p.q_pi), y0=y0s[i].copy())
        )
    from jaxcelt.physics.params import PARAM_NAMES

    meta = dict(
        generator="jaxcelt.generate_data",
        true_params={n: float(getattr(params, n)) for n in PARAM_NAMES},
        noise=float(noise),
        rate=float(rate),
        seed=int(seed),
        kinds=list(kinds),
        sensor_rotation=[0.0, 0.0, 0.0] if sensor_rotation is None else np.asarray(sensor_rotation, float).tolist(),
        time_offset=offsets.tolist(),
    )
    return MeasuredData(tuple(trajs), meta)


def _to_arrays(data: MeasuredData) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {
        "format": np.array(FORMAT),
        "version": np.array(FORMAT_VERSION),
        "n_trajectories": np.array(len(data.trajectories)),
        "meta_json": np.array(json.dumps(data.meta)),
    }
    for i, tr in enumerate(data.trajectories):
        out[f"traj{i}_ts"] = np.asarray(tr.ts, float)
        out[f"traj{i}_omega_pi"] = np.array(float(tr.omega_pi))
        out[f"traj{i}_q_pi"] = np.array(float(tr.q_pi))
        out[f"traj{i}_y0"] = np.full(13, np.nan) if tr.y0 is None else np.asarray(tr.y0, float)
        out[f"traj{i}_kinds"] = np.array(",".join(tr.kinds))
        for k in tr.kinds:
            out[f"traj{i}_obs_{k}"] = np.asarray(tr.obs[k], float)
            out[f"traj{i}_sigma_{k}"] = np.asarray(tr.sigma[k], float)
    return out


def _from_arrays(get) -> MeasuredData:
    fmt = str(get("format"))
    if fmt != FORMAT:
        raise ValueError(f"not a jaxcelt data file (format {fmt!r})")
    if int(get("version")) > FORMAT_VERSION:
        raise ValueError(f"data file version {int(get('version'))} is newer than this jaxcelt ({FORMAT_VERSION})")
    trajs = []
    for i in range(int(get("n_trajectories"))):
        kinds = [k for k in str(get(f"traj{i}_kinds")).split(",") if k]
        y0 = np.asarray(get(f"traj{i}_y0"), float)
        trajs.append(
            Trajectory(
                ts=np.asarray(get(f"traj{i}_ts"), float),
                obs={k: np.asarray(get(f"traj{i}_obs_{k}"), float) for k in kinds},
                sigma={k: np.asarray(get(f"traj{i}_sigma_{k}"), float) for k in kinds},
                omega_pi=float(get(f"traj{i}_omega_pi")),
                q_pi=float(get(f"traj{i}_q_pi")),
                y0=None if np.all(np.isnan(y0)) else y0,
            )
        )
    return MeasuredData(tuple(trajs), json.loads(str(get("meta_json"))))


def save_data(data: MeasuredData, path: str | Path) -> Path:
    """Write ``data`` to ``path`` (``.npz``, or ``.nc`` for netCDF); see the module docstring."""
    path = Path(path)
    arrays = _to_arrays(data)
    if path.suffix == ".nc":
        import xarray as xr

        dvars = {}
        for name, a in arrays.items():
            if a.dtype.kind == "U":
                dvars[name] = ((), str(a))
            elif a.ndim == 0:
                dvars[name] = ((), a)
            elif name.endswith("_ts"):
                dvars[name] = ((f"{name[:-3]}_time",), a)
            elif name.endswith("_y0"):
                dvars[name] = (("state_channel",), a)
            else:
                i, kind = name.split("_", 1)[0], name.split("_", 2)[2]
                dims = (f"{i}_time", f"{kind}_channel") if a.ndim == 2 else (f"{kind}_channel",)
                dvars[name] = (dims, a)
        xr.Dataset(dvars).to_netcdf(path, engine="h5netcdf")
    elif path.suffix == ".npz":
        np.savez(path, **arrays)
    else:
        raise ValueError(f"save_data: use a .npz or .nc path, got {path}")
    return path


def load_data(path: str | Path) -> MeasuredData:
    """Read a file written by `save_data` (``.npz`` or ``.nc``); never unpickles."""
    path = Path(path)
    if path.suffix == ".nc":
        import xarray as xr

        with xr.open_dataset(path, engine="h5netcdf") as ds:
            ds = ds.load()
        return _from_arrays(lambda k: ds[k].values)
    with np.load(path, allow_pickle=False) as f:
        return _from_arrays(lambda k: f[k])


# ----------------------------------------------------------------------------- arrays and CSV
CSV_COLUMNS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "omega": ("omega1", "omega2", "omega3"),
    "orientation": ("n1", "n2", "n3", "psi"),
    "centre": ("x_O", "y_O", "z_O"),
    "accel": ("f1", "f2", "f3"),
    "state": tuple(f"y{i}" for i in range(13)),
})
"""CSV column names per observation kind (units: omega [rad/s] in body axes, n [-], psi [rad],
centre [m], accel [m/s^2] in body axes, state as MODEL.md section 8)."""


def from_arrays(
    t,
    *,
    omega_pi: float,
    q_pi: float,
    sigma: dict[str, Sequence[float] | float] | None = None,
    y0=None,
    **obs,
) -> Trajectory:
    """One record from plain arrays, as measured data arrive.

    Args:
        t: (T,) sample times [s], increasing.
        omega_pi: base angular frequency [rad/s]; q_pi: base amplitude [m] of this record.
        sigma: per kind, the standard deviation of each channel (a scalar applies to all channels);
            default 1 % of the channel's RMS (a weight only: with real noise, s^2 rescales it).
        y0: (13,) release state if known, else None (then fit with ``fit_y0=True`` and a guess).
        **obs: observations by kind, e.g. ``omega=(T, 3)`` array [rad/s, body axes],
            ``orientation=(T, 4)``, ``centre=(T, 3)``, ``state=(T, 13)``.
    """
    if not obs:
        raise ValueError(f"from_arrays: pass at least one observation ({', '.join(OBSERVABLES)})")
    sigma = dict(sigma or {})
    o, sg = {}, {}
    for kind, x in obs.items():
        if kind not in OBSERVABLES:
            raise ValueError(f"from_arrays: unknown observation kind {kind!r}; known: {sorted(OBSERVABLES)}")
        x = np.asarray(x, float)
        if not np.all(np.isfinite(x)):
            raise ValueError(f"from_arrays: {kind!r} contains non-finite values")
        o[kind] = x
        if kind in sigma:
            sg[kind] = np.broadcast_to(np.asarray(sigma[kind], float), (OBSERVABLES[kind],)).copy()
        else:
            rms = np.sqrt(np.mean(x**2, axis=0)) if x.ndim == 2 else np.ones(OBSERVABLES[kind])
            sg[kind] = 0.01 * np.maximum(rms, 1e-6 * max(float(np.max(rms)), 1e-300))
    return Trajectory(
        ts=np.asarray(t, float),
        obs=o,
        sigma=sg,
        omega_pi=float(omega_pi),
        q_pi=float(q_pi),
        y0=None if y0 is None else np.asarray(y0, float),
    )


def save_csv(tr: Trajectory, path: str | Path) -> Path:
    """Write one record as CSV (format: `load_csv`)."""
    path = Path(path)
    head = [f"# omega_pi = {tr.omega_pi!r}", f"# q_pi = {tr.q_pi!r}"]
    if tr.y0 is not None:
        head.append("# y0 = " + ",".join(repr(float(v)) for v in tr.y0))
    for k in tr.kinds:
        head.append(f"# sigma_{k} = " + ",".join(repr(float(v)) for v in tr.sigma[k]))
    cols = ["t"] + [c for k in tr.kinds for c in CSV_COLUMNS[k]]
    table = np.column_stack([tr.ts] + [tr.obs[k] for k in tr.kinds])
    with open(path, "w") as f:
        f.write("\n".join(head) + "\n" + ",".join(cols) + "\n")
        np.savetxt(f, table, delimiter=",", fmt="%.17g")
    return path


def load_csv(path: str | Path, *, omega_pi: float | None = None, q_pi: float | None = None) -> Trajectory:
    """Read one record from a CSV file.

    Format: optional comment lines ``# name = value`` (``omega_pi`` [rad/s], ``q_pi`` [m],
    ``y0`` = 13 comma-separated numbers, ``sigma_<kind>`` = one number per channel), then a header
    row with ``t`` [s] and the columns of any kinds of `CSV_COLUMNS` (all columns of a kind), then
    one row per sample. ``omega_pi``/``q_pi`` arguments override the file's values; one of the
    two is required.
    """
    path = Path(path)
    meta, header = {}, None
    with open(path) as f:
        for n_skip, line in enumerate(f):  # noqa: B007
            s = line.strip()
            if s.startswith("#"):
                if "=" in s:
                    k, v = s[1:].split("=", 1)
                    meta[k.strip()] = v.strip()
                continue
            header = [c.strip() for c in s.split(",")]
            break
    if header is None or "t" not in header:
        raise ValueError(f"load_csv: {path}: no header row with a 't' column")
    table = np.loadtxt(path, delimiter=",", comments="#", skiprows=n_skip + 1, ndmin=2)
    if table.shape[1] != len(header):
        raise ValueError(f"load_csv: {path}: {table.shape[1]} values per row but {len(header)} columns in the header")
    col = {c: table[:, i] for i, c in enumerate(header)}
    obs = {}
    for kind, names in CSV_COLUMNS.items():
        present = [c in col for c in names]
        if any(present) and not all(present):
            raise ValueError(f"load_csv: {path}: kind {kind!r} needs all of the columns {names}")
        if all(present):
            obs[kind] = np.column_stack([col[c] for c in names])
    unknown = set(header) - {"t"} - {c for names in CSV_COLUMNS.values() for c in names}
    if unknown:
        raise ValueError(f"load_csv: {path}: unknown columns {sorted(unknown)}; known: t and {CSV_COLUMNS}")

    def num(name, given):
        if given is not None:
            return float(given)
        if name not in meta:
            raise ValueError(f"load_csv: {path}: {name!r} not in the file; pass {name}=...")
        return float(meta[name])

    sigma = {k: [float(v) for v in meta[f"sigma_{k}"].split(",")] for k in obs if f"sigma_{k}" in meta}
    y0 = [float(v) for v in meta["y0"].split(",")] if "y0" in meta else None
    return from_arrays(col["t"], omega_pi=num("omega_pi", omega_pi), q_pi=num("q_pi", q_pi), sigma=sigma, y0=y0, **obs)
