"""Global continuation of attractors over one parameter, for any periodically forced ODE (seed, continue, match).

In the spirit of Attractors.jl's ``AttractorSeedContinueMatch``: at every parameter value p_i

1. **lanes** run from the *fresh starts* (the same N states at every value) and from the *seeds* (section
   points of the attractors found at p_{i-1}, `ContinuationOptions.seeds_per_attractor` each), through a
   transient and then sampled on the stroboscopic section (`SectionModel.run`);
2. **attractors** are identified from the section samples (`jaxcelt.sweeps.continuation_match`): periodic
   lanes by their cycle (and refined by Newton with their Floquet multipliers, `SectionModel.refine`),
   quasi-periodic / chaotic / aperiodic lanes by the distance between their sets of section points, with
   the largest Lyapunov exponent when the lanes computed it; a set whose lanes close in on a stable orbit
   continued from p_{i-1} (`jaxcelt.sweeps.continuation_match.contraction_onto`) is that orbit's attractor,
   not reached yet: ``converging`` (near a Neimark-Sacker point, |mu| -> 1, lanes settle too slowly to be
   periodic within the transient); lanes that left the model's validity
   ("tipping over") or failed are outcomes of their own;
3. **basin fractions** count the fresh lanes only (seeds are excluded: they are not a sample of the
   starts), with the binomial standard error sqrt(f (1 - f) / N);
4. **matching**: each attractor at p_i takes the global id of the nearest attractor at p_{i-1} (distance in
   section coordinates, greedy, one to one, under ``match_tol``; ties broken by where the previous
   attractor's seeds went); unmatched ones get new ids. An id absent at a value has vanished there.

The model enters only through a `SectionModel`: a lane runner, section coordinates, an optional refiner.
`jaxcelt.sweeps.continuation_ode.forced_ode_model` builds one for any ``f(t, y, args)``;
`jaxcelt.sweeps.continuation.continue_attractors` is the wobblestone's. The result is an `xarray.Dataset`
(`continuation_dataset` documents its variables); with ``out`` one file per value is written as it finishes
and a rerun resumes (`jaxcelt.sweeps.continuation_store`).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from typing import Any

import numpy as np

from jaxcelt.sweeps.continuation_match import (
    KINDS,
    OUTCOMES,
    _same_set,
    attractor_distance,
    contraction_onto,
    group_lanes,
    lane_kinds,
    match_attractors,
)
from jaxcelt.sweeps.continuation_options import ContinuationOptions, resolve_continuation_options
from jaxcelt.sweeps.continuation_store import REFINE_STATUS, ContinuationStore, ValueRecord, seeds_digest

__all__ = ["LaneBatch", "Refined", "SectionModel", "continue_section_attractors", "continuation_summary"]


@dataclasses.dataclass(frozen=True)
class LaneBatch:
    """What a lane runner returns for L lanes at one parameter value (S samples, d state dimensions).

    Attributes:
        samples: (L, S, d) states on the stroboscopic section; t_samples: (L, S) their times [s].
        outcome: (L,) 0 ran, 1 left the model's validity (tipping over), 2 the solve failed.
        lyapunov, lyapunov_stderr: (L,) largest exponent and its standard error [1/s], or None.
    """

    samples: np.ndarray
    t_samples: np.ndarray
    outcome: np.ndarray
    lyapunov: np.ndarray | None = None
    lyapunov_stderr: np.ndarray | None = None


@dataclasses.dataclass(frozen=True)
class Refined:
    """A periodic attractor refined by Newton: ``status`` (`REFINE_STATUS` name, or ``"error: ..."``), the
    refined section ``state`` (d,) and the Floquet multipliers' moduli (decreasing), None where not available."""

    status: str
    state: np.ndarray | None = None
    multipliers: np.ndarray | None = None


def _identity(y: np.ndarray) -> np.ndarray:
    return np.asarray(y, dtype=float)


@dataclasses.dataclass(frozen=True)
class SectionModel:
    """A forced ODE as a global continuation sees it.

    Attributes:
        run: ``run(value, y0 (L, d), options) -> LaneBatch``: lanes from y0 at t0 (a section time) with the
            parameter at ``value``, ``options.transient_periods`` discarded, ``options.sample_periods``
            sampled (and exponents when ``options.lyapunov_periods > 0``, if supported).
        coords: section coordinates ``coords(y (..., d)) -> (..., m)`` in which distances are measured
            (cyclic components mapped or dropped). Default: the state.
        refine: ``refine(value, state (d,), t_section, k, options) -> Refined`` or None (no refinement).
        key: text identifying the model (its parameters) in the resume fingerprint.
        state_names: names of the d state components (the dataset's ``state`` coordinate).
        attrs: extra dataset attributes (strings or numbers).
    """

    run: Callable[[float, np.ndarray, ContinuationOptions], LaneBatch]
    coords: Callable[[np.ndarray], np.ndarray] = _identity
    refine: Callable[[float, np.ndarray, float, int, ContinuationOptions], Refined] | None = None
    key: str = ""
    state_names: tuple[str, ...] | None = None
    attrs: dict[str, Any] = dataclasses.field(default_factory=dict)


def _seeds(prev: ValueRecord | None, per: int, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Seed states (M, d) from the previous value's attractors and the id each came from."""
    if prev is None or per == 0:
        return np.zeros((0, dim)), np.zeros(0, np.int64)
    seeds, origin = [], []
    for a in range(len(prev.att_id)):
        pts = prev.cloud(a)
        if prev.att_kind[a] == 0:
            extra = pts[: min(int(prev.att_k[a]), per - 1)] if int(prev.att_k[a]) > 1 else pts[:0]
        else:
            extra = (
                pts[np.unique(np.linspace(0, len(pts) - 1, max(per - 1, 0)).round().astype(int))]
                if per > 1
                else pts[:0]
            )
        chosen = np.concatenate([prev.att_state[a][None], extra])[:per]
        orbit = prev.att_orbit_state[a]
        if np.all(np.isfinite(orbit)) and not np.allclose(orbit, prev.att_state[a]):
            chosen = np.concatenate([orbit[None], chosen])[:per]  # the orbit continued to this attractor
        chosen = chosen[np.all(np.isfinite(chosen), axis=1)]
        seeds.append(chosen)
        origin += [int(prev.att_id[a])] * len(chosen)
    return np.concatenate(seeds) if seeds else np.zeros((0, dim)), np.asarray(origin, np.int64)


def _refine(model: SectionModel, value: float, state: np.ndarray, t: float, k: int, o: ContinuationOptions):
    try:
        r = model.refine(value, state, t, k, o)
    except Exception:  # noqa: BLE001  (a failed refinement is reported, never fatal)
        return 3, None, np.nan, -1
    code = {v: c for c, v in REFINE_STATUS.items()}.get(r.status.split(":")[0], 3)
    mu = None if r.multipliers is None else np.abs(np.asarray(r.multipliers, float))
    if code != 0 or mu is None or mu.size == 0:
        return code, None, np.nan, -1
    st = None if r.state is None or not np.all(np.isfinite(r.state)) else np.asarray(r.state, float)
    return code, st, float(np.max(mu)), int(np.all(mu < 1.0))


def _one_value(model, o, index, value, starts, seeds, origin, prev, next_id) -> ValueRecord:
    N, d = starts.shape
    batch = model.run(float(value), np.concatenate([starts, seeds]), o)
    samples = np.asarray(batch.samples, float)
    if samples.shape[:1] != (N + len(seeds),) or samples.shape[2] != d:
        raise ValueError(
            f"SectionModel.run returned samples of shape {samples.shape}, expected ({N + len(seeds)}, S, {d})"
        )
    C = np.asarray(model.coords(samples), float)
    ly = None if batch.lyapunov is None else np.asarray(batch.lyapunov, float)
    lse = None if batch.lyapunov_stderr is None else np.asarray(batch.lyapunov_stderr, float)
    kind, period = lane_kinds(C, np.asarray(batch.outcome), ly, lse, period_tol=o.period_tol,
                              chaos_threshold=o.chaos_threshold, confidence=o.confidence)  # fmt: skip
    label, groups = group_lanes(kind, period, C, group_tol=o.group_tol, set_factor=o.set_factor)
    A, S = len(groups), samples.shape[1]
    rows: dict[str, list] = {k: [] for k in ("kind", "k", "count", "lanes", "state", "t", "cloud", "n", "refine",
                                             "mu", "stable", "lyap", "lse", "ostate")}  # fmt: skip
    for g, (kc, k, rep) in enumerate(groups):
        members = np.flatnonzero(label == g)
        fresh = members[members < N]
        rep = int(fresh[0]) if fresh.size else int(members[0])
        cloud = samples[rep, -k:] if kc == 0 else samples[rep]
        state, t = samples[rep, -1], float(np.asarray(batch.t_samples)[rep, -1])
        ref = (-1, None, np.nan, -1)
        if kc == 0 and o.refine and model.refine is not None:
            ref = _refine(model, float(value), state, t, k, o)
        if ref[1] is not None:
            state = ref[1]
        lv = ly[members] if ly is not None else np.zeros(0)
        sv = lse[members] if lse is not None else np.zeros(0)
        lv, sv = lv[np.isfinite(lv)], sv[np.isfinite(sv)]
        ostate = state if ref[0] == 0 and ref[1] is not None else np.full(d, np.nan)
        for key, v in zip(rows, (kc, k, fresh.size, members.size, state, t, np.pad(cloud, ((0, S - len(cloud)), (0, 0)),
                               constant_values=np.nan), len(cloud), ref[0], ref[2], ref[3],
                               np.median(lv) if lv.size else np.nan, np.median(sv) if sv.size else np.nan,
                               (ostate, k if ref[0] == 0 else 0, ref[2]))):  # fmt: skip
            rows[key].append(v)
    # the previous value's periodic orbits continued to this value by Newton (a tie-breaker of the matching)
    cont: dict[int, tuple] = {}
    if prev is not None and o.refine and model.refine is not None:
        t_new = float(np.asarray(batch.t_samples)[0, -1])  # a section time at this value
        for b in range(len(prev.att_id)):
            if int(prev.att_orbit_k[b]) > 0 and np.all(np.isfinite(prev.att_orbit_state[b])):
                code, y, mu, _ = _refine(
                    model, float(value), prev.att_orbit_state[b], t_new, int(prev.att_orbit_k[b]), o
                )
                if code == 0 and y is not None:
                    cont[b] = (y, int(prev.att_orbit_k[b]), mu)
    # A set that is not periodic here but whose lanes close in on a stable orbit continued from the previous
    # value belongs to that orbit, not reached yet (multipliers near the unit circle draw lanes in slowly):
    # "converging", with the orbit beside it. Chaotic sets (lambda_1 clearly > 0) are left as they are.
    for a in range(A):
        if rows["kind"][a] in (0, KINDS.index("chaotic")):
            continue
        members = np.flatnonzero(label == a)
        for b, (y, kb, mub) in cont.items():
            if not mub < 1.0:
                continue
            ratio, dist = contraction_onto(C[members], np.asarray(model.coords(y[None]), float)[0], kb)
            if ratio < 1.0 and dist <= o.match_tol:
                rows["kind"][a], rows["ostate"][a] = KINDS.index("converging"), cont[b]
                break
    match = np.full(A, -1, np.int64)
    if prev is not None and len(prev.att_id) and A:
        B = len(prev.att_id)
        dist = np.full((A, B), np.inf)
        evidence = np.zeros((A, B))
        for a in range(A):
            ca = np.asarray(model.coords(rows["cloud"][a][: rows["n"][a]]), float)
            for b in range(B):
                cb = np.asarray(model.coords(prev.cloud(b)), float)
                dist[a, b] = attractor_distance(
                    rows["kind"][a], rows["k"][a], ca, int(prev.att_kind[b]), int(prev.att_k[b]), cb
                )
                from_b = origin == prev.att_id[b]
                if from_b.any():  # share of b's seeds that landed on a
                    evidence[a, b] = float(np.mean(label[N:][from_b] == a))
                if b in cont:  # b's orbit, continued to this value, lies on a
                    y = np.asarray(model.coords(cont[b][0][None]), float)
                    evidence[a, b] += float(_same_set(y, ca, o.group_tol, o.set_factor))
        match = match_attractors(dist, evidence, match_tol=o.match_tol, tie_rtol=o.tie_rtol)
    ids = np.empty(A, np.int64)
    for a in range(A):
        if match[a] >= 0:
            ids[a] = int(prev.att_id[match[a]])
            if rows["ostate"][a][1] == 0 and int(match[a]) in cont:  # not periodic here: keep the continued orbit
                rows["ostate"][a] = cont[int(match[a])]
        else:
            ids[a], next_id = next_id, next_id + 1
    glob = np.where(label >= 0, ids[np.maximum(label, 0)] if A else -3, label)
    empty = np.zeros((0, S, d))
    return ValueRecord(
        index=index, value=float(value), seeds_sha=seeds_digest(seeds), next_id=int(next_id),
        lane_outcome=glob[:N], lane_kind=kind[:N], lane_period=period[:N], lane_final=samples[:N, -1],
        seed_origin=origin, seed_outcome=glob[N:], att_id=ids,
        att_kind=np.asarray(rows["kind"], np.int64), att_k=np.asarray(rows["k"], np.int64),
        att_count=np.asarray(rows["count"], np.int64), att_lanes=np.asarray(rows["lanes"], np.int64),
        att_state=np.asarray(rows["state"], float).reshape(A, d), att_t=np.asarray(rows["t"], float),
        att_cloud=np.asarray(rows["cloud"], float) if A else empty, att_cloud_n=np.asarray(rows["n"], np.int64),
        att_refine=np.asarray(rows["refine"], np.int64), att_mu_max=np.asarray(rows["mu"], float),
        att_stable=np.asarray(rows["stable"], np.int64), att_lyap=np.asarray(rows["lyap"], float),
        att_lyap_se=np.asarray(rows["lse"], float),
        att_orbit_state=np.asarray([x[0] for x in rows["ostate"]], float).reshape(A, d),
        att_orbit_k=np.asarray([x[1] for x in rows["ostate"]], np.int64),
        att_orbit_mu=np.asarray([x[2] for x in rows["ostate"]], float),
    )  # fmt: skip


def continue_section_attractors(
    model: SectionModel,
    name: str,
    values: Any,
    starts: Any,
    *,
    lane_coords: dict[str, Any] | None = None,
    options: ContinuationOptions | None = None,
    **keywords: Any,
):
    """Global continuation of the attractors of ``model`` over ``values`` of the parameter ``name``.

    Args:
        model: the forced ODE (`SectionModel`).
        name: the parameter's name (the dataset's coordinate).
        values: 1-D finite values, in the order of continuation.
        starts: (N, d) fresh start states, the same at every value.
        lane_coords: extra coordinates along ``lane`` (e.g. the starts' heading and tilt), {name: (N,)}.
        options: `ContinuationOptions`, or its fields as keywords (which replace those of ``options``).

    Returns:
        the `continuation_dataset` (`xarray.Dataset`).
    """
    o = resolve_continuation_options(options, keywords, caller="continue_section_attractors")
    if not isinstance(model, SectionModel):
        raise ValueError(f"'model' must be a SectionModel, got {type(model).__name__}")
    if not isinstance(name, str) or not name:
        raise ValueError(f"'name' must be a non-empty string, got {name!r}")
    try:
        vals = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"'values' must be numbers, got {values!r}") from None
    if vals.ndim != 1 or vals.size == 0 or not np.all(np.isfinite(vals)):
        raise ValueError(f"'values' must be a non-empty 1-D array of finite numbers, got shape {vals.shape}")
    try:
        y0 = np.asarray(starts, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("'starts' must be an (N, d) array of states") from None
    if y0.ndim != 2 or y0.shape[0] == 0 or not np.all(np.isfinite(y0)):
        raise ValueError(f"'starts' must be a finite (N, d) array with N >= 1, got shape {y0.shape}")
    N, d = y0.shape
    fp = dict(model=model.key, name=name, values=vals.tolist(), starts=seeds_digest(y0), options=o.fingerprint())
    store = None if o.out is None else ContinuationStore(o.out, fp)
    bar = None
    if o.progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(vals), unit="value", desc=f"attractors over {name}")
    records: list[ValueRecord] = []
    next_id = 0
    for i, v in enumerate(vals):
        prev = records[-1] if records else None
        seeds, origin = _seeds(prev, o.seeds_per_attractor, d)
        rec = None if store is None else store.load(i, seeds_digest(seeds), n_lanes=N, dim=d)
        if rec is None:
            rec = _one_value(model, o, i, v, y0, seeds, origin, prev, next_id)
            if store is not None:
                store.write(rec)
        next_id = rec.next_id
        records.append(rec)
        if bar is not None:
            bar.set_postfix_str(f"{name}={v:g}: {len(rec.att_id)} attractors")
            bar.update(1)
    if bar is not None:
        bar.close()
    from jaxcelt.sweeps.continuation_result import continuation_dataset

    ds = continuation_dataset(records, name=name, starts=y0, model=model, options=o, fingerprint=fp)
    if lane_coords:
        ds = ds.assign_coords({k: ("lane", np.asarray(v)) for k, v in lane_coords.items()})
    if store is not None:
        from jaxcelt.sweeps.dataset import _atomic_write_dataset

        _atomic_write_dataset(ds, store.dir / "continuation.nc")
    return ds


def continuation_summary(ds) -> dict[str, Any]:
    """A JSON-ready summary of a continuation dataset: per value, the attractors present (id, kind, period,
    fraction and its error, largest multiplier modulus, stability, exponent, representative state) and the
    tipping-over and failed fractions."""
    name = ds.attrs["continued_parameter"]
    out = []
    for j, v in enumerate(ds[name].values):
        rows = []
        for a in ds["attractor"].values:
            if not bool(ds["exists"].values[a, j]):
                continue
            f = lambda key, a=a, j=j: ds[key].values[a, j]  # noqa: E731
            rows.append(dict(
                id=int(a), kind=str(f("kind")), period=int(f("period")), fraction=float(f("fraction")),
                fraction_stderr=float(f("fraction_stderr")), lanes=int(f("n_lanes")),
                refine_status=str(f("refine_status")), multiplier_max=_num(f("multiplier_max")),
                orbit_period=int(f("orbit_period")), orbit_multiplier_max=_num(f("orbit_multiplier_max")),
                orbit_point=[_num(x) for x in f("orbit_point")],
                stable=None if int(f("stable")) < 0 else bool(f("stable")), lyapunov=_num(f("lyapunov")),
                lyapunov_stderr=_num(f("lyapunov_stderr")), section_point=[_num(x) for x in f("section_point")],
            ))  # fmt: skip
        out.append(dict(value=float(v), attractors=rows,
                        tipping_over=float(ds["tipping_fraction"].values[j]),
                        tipping_over_stderr=float(ds["tipping_fraction_stderr"].values[j]),
                        failed=float(ds["failed_fraction"].values[j]), n_seeds=int(ds["n_seeds"].values[j])))  # fmt: skip
    return dict(parameter=name, n_starts=int(ds.sizes["lane"]), options=json.loads(ds.attrs["options_json"]),
                outcome_codes={str(k): v for k, v in OUTCOMES.items()}, kinds=list(KINDS), values=out)  # fmt: skip


def _num(x) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None
