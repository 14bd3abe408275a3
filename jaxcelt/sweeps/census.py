"""Attractor census of the forced wobblestone: many starts, one forcing frequency, distinct attractors.

Every start state is one lane of `jaxcelt.sweeps.api.sweep` (same parameters, ``y0`` per lane). After
``transient_periods`` forcing periods each lane is sampled on the stroboscopic section for
``sample_periods`` periods and labelled by `jaxcelt.sweeps.regimes.classify`:

* ``periodic`` with period k (the smallest k with x_{j+k} = x_j on the section, to ``tol``);
* ``chaotic`` / ``quasi-periodic`` / ``converging`` (a negative exponent: attracted to a periodic
  orbit not yet reached) / ``uncertain`` by the largest Lyapunov exponent and its standard error
  when the sweep computed it (``lyapunov_periods > 0``; `jaxcelt.sweeps.regimes.classify`), else
  ``aperiodic`` (not periodic up to ``sample_periods // 2``, not further resolved: possibly
  still in its transient);
* ``invalid`` (the model left its validity: lift-off, n3 <= 0) and ``failed`` (the solve did
  not finish) from the lane's status.

Periodic lanes are grouped into distinct attractors: two lanes are the same attractor when they
have the same k and their last k section points coincide up to a cyclic shift, within
``group_tol`` (1 + max|x|) in (v, omega, n) and ``group_tol`` in psi compared modulo 2 pi;
r_C1, r_C2 are cyclic (the orbit may wander on the base) and ignored. Non-periodic lanes are
grouped by kind only (one row per kind: a chaotic row may hold several chaotic attractors).
Every lane belongs to exactly one row, so the basin fractions sum to 1.

Optionally (``refine=True``) each periodic attractor's representative section state is
refined with `jaxcelt.periodic_orbit` (Newton on the stroboscopic map), adding its Floquet
multipliers and stability; a refinement that raises or does not converge is marked
(``refine_status``), never fatal.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt.physics.params import CeltParams
from jaxcelt.physics.state import initial_state
from jaxcelt.sweeps.api import sweep
from jaxcelt.sweeps.regimes import REGIMES, classify

__all__ = [
    "AttractorStarts",
    "Attractor",
    "AttractorCensus",
    "attractor_starts",
    "attractors",
    "refine_attractor",
    "same_cycle",
]

_PSI = 12
_LOCAL = slice(0, 9)  # v, omega, n (r_C = 9:12 cyclic, psi = 12 compared modulo 2 pi)


@dataclasses.dataclass(frozen=True)
class AttractorStarts:
    """Start states of a census and their coordinates.

    Attributes:
        y0: (N, 13) states on the contact manifold (at rest on the base unless ``spin``).
        psi0: (N,) heading [rad]. tilt: (N,) tilt of the body's vertical n from x3 towards x1 [rad].
        grid_shape: (n_psi0, n_tilt) for a grid (lanes in row-major psi0, tilt order), None if random.
    """

    y0: np.ndarray
    psi0: np.ndarray
    tilt: np.ndarray
    grid_shape: tuple[int, int] | None


def _range(name: str, r: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in r)
    except (TypeError, ValueError):
        raise ValueError(f"attractor_starts: {name!r} must be a (lo, hi) pair of numbers, got {r!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
        raise ValueError(f"attractor_starts: {name!r} must be finite with lo <= hi, got {r!r}")
    return lo, hi


def attractor_starts(
    params: CeltParams,
    *,
    psi0: Any = (0.0, 2 * np.pi),
    tilt: Any = (0.0, 0.0),
    n: int | tuple[int, int] = (8, 1),
    spin: float = 0.0,
    seed: int = 0,
) -> AttractorStarts:
    """Start states over heading psi0 and tilt, on a grid or at random.

    Args:
        params: the stone.
        psi0: (lo, hi) heading range [rad].
        tilt: (lo, hi) range [rad] of the tilt of the body's vertical n from the body x3 axis
            towards x1 (n = (sin tilt, 0, cos tilt)); |tilt| < pi/2.
        n: ``(n_psi0, n_tilt)``: a grid of cell centres (lo + (i + 1/2)(hi - lo)/n_psi0, ...;
            a full turn of psi0 is then sampled without the duplicate end point); an int:
            that many uniform random starts (``seed``).
        spin: initial angular velocity about the vertical [rad/s] (omega = spin n).
        seed: random generator seed (random starts only).
    """
    if not isinstance(params, CeltParams):
        raise ValueError(f"attractor_starts: 'params' must be a CeltParams, got {type(params).__name__}")
    plo, phi = _range("psi0", psi0)
    tlo, thi = _range("tilt", tilt)
    if max(abs(tlo), abs(thi)) >= np.pi / 2:
        raise ValueError(f"attractor_starts: 'tilt' must lie in (-pi/2, pi/2), got {tilt!r}")
    if not np.isfinite(spin):
        raise ValueError(f"attractor_starts: 'spin' must be finite, got {spin!r}")
    if isinstance(n, bool):
        raise ValueError(f"attractor_starts: 'n' must be an int or an (n_psi0, n_tilt) pair, got {n!r}")
    if isinstance(n, int | np.integer):
        if n < 1:
            raise ValueError(f"attractor_starts: 'n' must be >= 1, got {n!r}")
        rng = np.random.default_rng(seed)
        ps = rng.uniform(plo, phi, int(n))
        ts = rng.uniform(tlo, thi, int(n))
        shape = None
    else:
        try:
            a, b = (int(x) for x in n)
        except (TypeError, ValueError):
            raise ValueError(f"attractor_starts: 'n' must be an int or an (n_psi0, n_tilt) pair, got {n!r}") from None
        if a < 1 or b < 1:
            raise ValueError(f"attractor_starts: 'n' must be positive, got {n!r}")
        pc = plo + (np.arange(a) + 0.5) * (phi - plo) / a
        tc = tlo + (np.arange(b) + 0.5) * (thi - tlo) / b
        P, Tt = np.meshgrid(pc, tc, indexing="ij")
        ps, ts, shape = P.ravel(), Tt.ravel(), (a, b)

    def one(psi, t):
        nv = jnp.stack([jnp.sin(t), 0.0 * t, jnp.cos(t)])
        return initial_state(params, omega=spin * nv, n=nv, psi=psi)

    y0 = np.asarray(jax.jit(jax.vmap(one))(jnp.asarray(ps), jnp.asarray(ts)))
    return AttractorStarts(y0=y0, psi0=np.asarray(ps, float), tilt=np.asarray(ts, float), grid_shape=shape)


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def same_cycle(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Whether two section cycles a, b (k, 13) are the same orbit up to a cyclic shift.

    (v, omega, n) within tol (1 + max|x|), psi within tol modulo 2 pi; r_C1, r_C2 ignored.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != b.shape:
        return False
    scale = tol * (1.0 + max(np.max(np.abs(a[:, _LOCAL])), np.max(np.abs(b[:, _LOCAL]))))
    for s in range(a.shape[0]):
        bs = np.roll(b, s, axis=0)
        if (
            np.max(np.abs(a[:, _LOCAL] - bs[:, _LOCAL])) <= scale
            and np.max(np.abs(_wrap(a[:, _PSI] - bs[:, _PSI]))) <= tol
        ):
            return True
    return False


@dataclasses.dataclass
class Attractor:
    """One row of the census table.

    kind: ``periodic``, ``converging``, ``quasi-periodic``, ``chaotic``, ``uncertain``, ``aperiodic``,
    ``invalid`` or ``failed`` (`jaxcelt.sweeps.regimes.REGIMES`);
    k: period (0 unless periodic); state: representative section state (13,) (last sample of
    the representative lane; nan if none finite); t_section: its time [s]; lane: that lane;
    count, fraction: lanes in the row and their share of all lanes; lyapunov: median exponent
    of the row's lanes [1/s] (nan if not computed); refine_status: ``"not run"``,
    ``"converged"``, ``"not converged"``, ``"solver failed"`` or ``"error: ..."``;
    multipliers: |mu| of the refined orbit (decreasing), stable: all |mu| < 1 (None if not refined).
    """

    kind: str
    k: int
    state: np.ndarray
    t_section: float
    lane: int
    count: int
    fraction: float
    lyapunov: float = float("nan")
    refine_status: str = "not run"
    residual: float | None = None
    multipliers: list[float] | None = None
    stable: bool | None = None

    @property
    def name(self) -> str:
        return f"period-{self.k}" if self.kind == "periodic" else self.kind

    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["name"] = self.name
        d["state"] = [None if not np.isfinite(x) else float(x) for x in np.asarray(self.state)]
        d["lyapunov"] = None if not np.isfinite(self.lyapunov) else float(self.lyapunov)
        return d


@dataclasses.dataclass
class AttractorCensus:
    """Result of `attractors`.

    Attributes (N = lanes):
        omega_pi: forcing frequency [rad/s].
        label: (N,) row of `table` each lane belongs to.
        kind: (N,) lane kinds (see `Attractor`); period: (N,) k (0 unless periodic).
        status: (N,) sweep status; lyapunov: (N,) [1/s] (nan if not computed).
        table: the attractors, periodic first (by decreasing count), then the other kinds.
        psi0, tilt, grid_shape: start coordinates when the starts were `AttractorStarts`, else None.
        settings: the census settings (periods, tolerances).
    """

    omega_pi: float
    label: np.ndarray
    kind: np.ndarray
    period: np.ndarray
    status: np.ndarray
    lyapunov: np.ndarray
    table: list[Attractor]
    psi0: np.ndarray | None
    tilt: np.ndarray | None
    grid_shape: tuple[int, int] | None
    settings: dict[str, Any]

    @property
    def fractions(self) -> np.ndarray:
        return np.array([a.fraction for a in self.table])

    def to_dict(self, lanes: bool = True) -> dict[str, Any]:
        """JSON-ready dict (lane arrays as lists when ``lanes``)."""
        d: dict[str, Any] = dict(
            omega_pi=float(self.omega_pi),
            n_lanes=int(self.label.size),
            settings=self.settings,
            attractors=[a.to_dict() for a in self.table],
            grid_shape=None if self.grid_shape is None else list(self.grid_shape),
        )
        if lanes:
            d["lanes"] = dict(
                label=self.label.tolist(),
                kind=[str(x) for x in self.kind],
                period=self.period.tolist(),
                status=self.status.tolist(),
                psi0=None if self.psi0 is None else self.psi0.tolist(),
                tilt=None if self.tilt is None else self.tilt.tolist(),
            )
        return d


def group(
    kinds: np.ndarray, periods: np.ndarray, cycles: list[np.ndarray | None], tol: float
) -> tuple[np.ndarray, list[tuple[str, int, int]]]:
    """Group lanes: periodic ones by `same_cycle` (greedy, against each group's first lane), others by kind.

    Args:
        kinds: (N,) kind strings; periods: (N,) k; cycles: per lane its last k section points
            (k, 13) (None for non-periodic lanes); tol: `same_cycle` tolerance.

    Returns:
        (label (N,), rows [(kind, k, representative lane)]) with periodic rows first.
    """
    n = len(kinds)
    label = np.full(n, -1, dtype=np.int64)
    rows: list[tuple[str, int, int]] = []
    for i in range(n):
        if kinds[i] != "periodic":
            continue
        for g, (_, k, rep) in enumerate(rows):
            if k == periods[i] and same_cycle(cycles[rep], cycles[i], tol):
                label[i] = g
                break
        else:
            label[i] = len(rows)
            rows.append(("periodic", int(periods[i]), i))
    for kind in ("converging", "quasi-periodic", "chaotic", "uncertain", "aperiodic", "invalid", "failed"):
        idx = np.flatnonzero(np.asarray(kinds) == kind)
        if idx.size:
            label[idx] = len(rows)
            rows.append((kind, 0, int(idx[0])))
    return label, rows


def attractors(
    params: CeltParams,
    starts: AttractorStarts | Any,
    *,
    transient_periods: int = 100,
    sample_periods: int = 16,
    tol: float = 1e-4,
    group_tol: float = 1e-3,
    chaos_threshold: float = 0.02,
    refine: bool = False,
    refine_options: dict[str, Any] | None = None,
    **sweep_options: Any,
) -> AttractorCensus:
    """Census of the attractors reached from ``starts`` at ``params`` (one `jaxcelt.sweeps.api.sweep`).

    Args:
        params: the stone and the base (a single parameter set).
        starts: `AttractorStarts` or states (N, 13).
        transient_periods, sample_periods: forcing periods discarded, then sampled on the section
            (periods up to sample_periods // 2 are detected).
        tol: period detection tolerance (`jaxcelt.sweeps.regimes.detect_period`).
        group_tol: tolerance of `same_cycle` for grouping periodic lanes (looser than ``tol``:
            lanes approach the orbit at different rates).
        chaos_threshold: [1/s] exponent separating chaotic from quasi-periodic lanes.
        refine: refine each periodic attractor with `jaxcelt.periodic_orbit` (multipliers).
        refine_options: keyword arguments of `periodic_orbit`.
        sweep_options: further `jaxcelt.sweeps.options.SweepOptions` fields (``lyapunov_periods``, ``rtol``,
            ``width``, ``chunk_size``, ``out``, ...), or ``options=SweepOptions(...)``.
    """
    if not isinstance(params, CeltParams):
        raise ValueError(f"attractors: 'params' must be a CeltParams, got {type(params).__name__}")
    if np.ndim(params.omega_pi) != 0:
        raise ValueError("attractors: 'params' must be a single parameter set (scalar omega_pi)")
    for name, v, lo in (("transient_periods", transient_periods, 0), ("sample_periods", sample_periods, 2)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < lo:
            raise ValueError(f"attractors: {name!r} must be an int >= {lo}, got {v!r}")
    for name, v in (("tol", tol), ("group_tol", group_tol)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"attractors: {name!r} must be a positive finite number, got {v!r}")
    if "y0" in sweep_options:
        raise ValueError("attractors: pass start states as 'starts', not 'y0'")
    if isinstance(starts, AttractorStarts):
        y0, psi0, tilt, shape = starts.y0, starts.psi0, starts.tilt, starts.grid_shape
    else:
        y0, psi0, tilt, shape = starts, None, None, None
    y0 = np.asarray(y0, dtype=float)
    if y0.ndim != 2 or y0.shape[1] != 13 or y0.shape[0] == 0:
        raise ValueError(f"attractors: 'starts' must be states of shape (N, 13), got {y0.shape}")
    if not np.all(np.isfinite(y0)):
        raise ValueError("attractors: 'starts' must be finite")
    omega = float(params.omega_pi)
    r = sweep(
        params,
        "omega_pi",
        [omega],
        transient_periods=int(transient_periods),
        sample_periods=int(sample_periods),
        y0=y0,
        **sweep_options,
    )
    samples = np.asarray(r.samples)[0]  # (N, S, 13)
    lyap = np.asarray(r.lyapunov, dtype=float)[0]
    have_lyap = int(sweep_options.get("lyapunov_periods", 0)) > 0
    lab = classify(
        samples,
        np.asarray(r.status)[0],
        np.asarray(r.valid)[0],
        np.asarray(r.r_O)[0],
        lyap if have_lyap else None,
        lyapunov_stderr=np.asarray(r.lyapunov_stderr, dtype=float)[0] if have_lyap else None,
        max_period=int(sample_periods) // 2,
        tol=tol,
        chaos_threshold=chaos_threshold,
    )
    kinds = np.array([REGIMES[int(c)] for c in lab["regime"]], dtype=object)
    periods = np.asarray(lab["period"], dtype=np.int64)
    cycles = [samples[i, -periods[i] :] if kinds[i] == "periodic" else None for i in range(len(kinds))]
    label, rows = group(kinds, periods, cycles, group_tol)
    N = len(kinds)
    t_samples = np.asarray(r.t_samples)[0]
    table = []
    for g, (kind, k, rep) in enumerate(rows):
        members = label == g
        ly = lyap[members]
        ly = ly[np.isfinite(ly)]
        table.append(
            Attractor(
                kind=kind,
                k=k,
                state=np.asarray(samples[rep, -1], float),
                t_section=float(t_samples[rep, -1]),
                lane=int(rep),
                count=int(members.sum()),
                fraction=float(members.sum()) / N,
                lyapunov=float(np.median(ly)) if ly.size else float("nan"),
            )
        )
    # periodic rows by decreasing count (labels renumbered), the other kinds after them
    order = sorted(range(len(table)), key=lambda g: (table[g].kind != "periodic", -table[g].count, g))
    new = np.empty(len(order), dtype=np.int64)
    new[order] = np.arange(len(order))
    table = [table[g] for g in order]
    label = new[label]
    if refine:
        for a in table:
            if a.kind == "periodic":
                refine_attractor(params, a, **(refine_options or {}))
    settings = dict(
        transient_periods=int(transient_periods),
        sample_periods=int(sample_periods),
        tol=float(tol),
        group_tol=float(group_tol),
        chaos_threshold=float(chaos_threshold),
        lyapunov_periods=int(sweep_options.get("lyapunov_periods", 0)),
        rtol=float(sweep_options.get("rtol", 1e-8)),
        atol=float(sweep_options.get("atol", 1e-10)),
        refine=bool(refine),
    )
    return AttractorCensus(
        omega_pi=omega,
        label=label,
        kind=kinds,
        period=periods,
        status=np.asarray(r.status)[0],
        lyapunov=lyap,
        table=table,
        psi0=psi0,
        tilt=tilt,
        grid_shape=shape,
        settings=settings,
    )


def refine_attractor(params: CeltParams, a: Attractor, **options: Any) -> Attractor:
    """Refine a periodic row with `jaxcelt.periodic_orbit` from its section state (in place).

    Sets ``refine_status``, ``residual`` and, when Newton converged, ``multipliers`` (|mu|,
    decreasing) and ``stable``; an exception is caught and reported in ``refine_status``.
    ``options``: keyword arguments of `periodic_orbit`. Returns ``a``.
    """
    from jaxcelt.orbits.celt import periodic_orbit

    if a.kind != "periodic":
        raise ValueError(f"refine_attractor: 'a' must be a periodic attractor, got kind {a.kind!r}")

    try:
        orb = periodic_orbit(params, a.state, k=a.k, t0=a.t_section, **options)
        st = int(orb.status)
        a.refine_status = {0: "converged", 1: "not converged", 2: "solver failed"}.get(st, f"status {st}")
        a.residual = float(orb.residual)
        if st == 0:
            mu = np.abs(np.asarray(orb.multipliers))
            a.multipliers = [float(x) for x in mu]
            a.stable = bool(np.all(mu < 1.0))
    except Exception as e:  # noqa: BLE001  (a failed refinement is reported, never fatal)
        a.refine_status = f"error: {type(e).__name__}: {e}"[:200]
    return a
