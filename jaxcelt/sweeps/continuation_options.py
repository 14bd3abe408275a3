"""`ContinuationOptions`: the one options object of a global continuation of attractors.

`jaxcelt.sweeps.continuation.continue_attractors` (the wobblestone) and
`jaxcelt.sweeps.continuation_core.continue_section_attractors` (any forced ODE) take the same settings,
documented here once: how long each lane runs and is sampled on the stroboscopic section, how lanes are
told apart (period detection, cycle and set tolerances), how attractors are matched from one parameter
value to the next, how many seeds each attractor hands on, whether periodic attractors are refined by
Newton and exponents computed, and where the resumable files go. Each function accepts the fields as
keywords or ``options=ContinuationOptions(...)`` (keywords given beside it replace its fields).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from typing import Any

from jaxcelt._options import with_keywords

__all__ = ["ContinuationOptions", "resolve_continuation_options"]

_INTS = {"transient_periods": 0, "sample_periods": 2, "lyapunov_periods": 0, "seeds_per_attractor": 0}
_POSITIVE = ("period_tol", "group_tol", "set_factor", "match_tol")
_NONNEGATIVE = ("chaos_threshold", "confidence", "tie_rtol")


@dataclasses.dataclass(frozen=True, kw_only=True)
class ContinuationOptions:
    """Settings of a global continuation of attractors (frozen; keyword-only; checked when made).

    Lanes (at every parameter value, from the fresh starts and the seeds):

    Attributes:
        transient_periods: forcing periods discarded before sampling.
        sample_periods: stroboscopic samples kept per lane (periods up to ``sample_periods // 2`` are
            detected; the samples of a non-periodic lane are the point set it is identified by).
        lyapunov_periods: > 0: each lane also computes its largest Lyapunov exponent lambda_1 and its
            standard error over that many periods after the transient (where the lane runner supports it;
            the wobblestone's does), and non-periodic attractors are labelled chaotic / quasi-periodic /
            converging / uncertain by it (`jaxcelt.sweeps.regimes.classify`'s rule); 0 (default): off, such
            attractors are ``aperiodic``.

    Identification at one value:

    Attributes:
        period_tol: period detection tolerance (`jaxcelt.sweeps.regimes.detect_period`, relative to
            1 + max|x| in section coordinates).
        group_tol: two periodic lanes of the same period k are one attractor when their last k section
            points coincide up to a cyclic shift within ``group_tol`` (1 + max|x|).
        set_factor: two non-periodic lanes are one attractor when the distance between their section
            point sets (the larger of the two mean nearest-neighbour distances, A to B and B to A) is at most
            ``group_tol`` (1 + max|x|) + ``set_factor`` x the larger of the sets' own mean spacings (the
            mean distance from a point to the nearest other point of its set): samples of one attractor
            interleave, samples of two do not.
        chaos_threshold, confidence: the exponent rule of `jaxcelt.sweeps.regimes.classify` [1/s].

    Matching across values and seeding:

    Attributes:
        match_tol: an attractor at a value continues an attractor of the previous value when their
            distance (periodic, same k: the cycle distance; else the set distance) is at most
            ``match_tol`` (1 + max|x|); ``math.inf`` matches whenever there is a partner (Attractors.jl's
            default). Pairs are matched greedily by increasing distance, one to one.
        tie_rtol: distances within this relative band count as tied; among tied pairs the one where more
            of the previous attractor's seeds landed in the new attractor wins (the periodic orbit's own
            continuation by its seeds breaks the tie).
        seeds_per_attractor: section points of each attractor of the previous value started as extra
            lanes (seeds) at the next value: a periodic attractor's refined point and cycle points, a set's
            points spread over its samples. Seeds find attractors whose basins the fresh starts miss; they
            never count in basin fractions. 0: no seeding (every value independent).
        refine: refine each periodic attractor by Newton on the stroboscopic map (the lane runner's
            refiner, `jaxcelt.periodic_orbit` for the wobblestone) for its Floquet multipliers and stability.
        shooting: options of the refinement (`jaxcelt.ShootingOptions`; None: the refiner's defaults).
        sweep: the wobblestone's lane settings (`jaxcelt.SweepOptions`: solver, tolerances, engine,
            chunking; None: its defaults but ``stop_on_invalid=True``: a lane that tips over ends there, its
            outcome known, instead of integrating the model on past its validity). Its ``transient_periods``, ``sample_periods``,
            ``lyapunov_periods``, ``out``, ``progress`` and ``on_chunk`` are replaced by this object's.

    Execution:

    Attributes:
        out: directory of the resumable files (`jaxcelt.sweeps.continuation_store`): one file per value,
            written when the value is done; a rerun with the same settings reads the finished values back
            and computes the rest (a damaged file is recomputed with a `DamagedChunkWarning`). None: in memory.
        progress: tqdm bar over the parameter values.
    """

    transient_periods: int = 200
    sample_periods: int = 16
    lyapunov_periods: int = 0
    period_tol: float = 1e-4
    group_tol: float = 1e-3
    set_factor: float = 3.0
    chaos_threshold: float = 0.02
    confidence: float = 2.0
    match_tol: float = 0.25
    tie_rtol: float = 0.1
    seeds_per_attractor: int = 4
    refine: bool = True
    shooting: Any = None
    sweep: Any = None
    out: str | None = None
    progress: bool = False

    def __post_init__(self):
        for name, lo in _INTS.items():
            x = getattr(self, name)
            if isinstance(x, bool) or not isinstance(x, numbers.Integral) or x < lo:
                raise ValueError(f"{name!r} must be an int >= {lo}, got {x!r}")
        for name in _POSITIVE:
            x = getattr(self, name)
            ok = isinstance(x, numbers.Real) and not isinstance(x, bool) and x > 0 and not math.isnan(x)
            if not ok or (name != "match_tol" and not math.isfinite(x)):
                raise ValueError(f"{name!r} must be a positive number, got {x!r}")
        for name in _NONNEGATIVE:
            x = getattr(self, name)
            if isinstance(x, bool) or not isinstance(x, numbers.Real) or not (math.isfinite(x) and x >= 0):
                raise ValueError(f"{name!r} must be a finite number >= 0, got {x!r}")
        for name in ("refine", "progress"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name!r} must be a bool, got {getattr(self, name)!r}")
        if self.out is not None and not isinstance(self.out, str | bytes) and not hasattr(self.out, "__fspath__"):
            raise ValueError(f"'out' must be a directory path or None, got {self.out!r}")

    def replace(self, **changes: Any) -> ContinuationOptions:
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)

    def fingerprint(self) -> dict[str, Any]:
        """The settings that change what is computed (for the resume check): all but ``out`` and ``progress``;
        the nested options by their ``repr``."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name not in ("out", "progress")}
        for name in ("shooting", "sweep"):
            d[name] = None if d[name] is None else _settings_repr(d[name])
        d["match_tol"] = repr(float(self.match_tol))
        return d


def _settings_repr(options: Any) -> str:
    """A stable text of a nested options object (execution-only fields of `SweepOptions` left out)."""
    if dataclasses.is_dataclass(options):
        skip = {"out", "progress", "on_chunk", "devices", "width", "chunk_size", "sort_by_cost", "engine"}
        return repr({f.name: repr(getattr(options, f.name)) for f in dataclasses.fields(options) if f.name not in skip})
    return repr(options)


def resolve_continuation_options(
    options: ContinuationOptions | None, keywords: Mapping[str, Any], *, caller: str
) -> ContinuationOptions:
    """``options`` (default `ContinuationOptions()`) with ``keywords`` replacing its fields (TypeError for a
    keyword that is no field, naming ``caller``)."""
    return with_keywords(ContinuationOptions, options, ContinuationOptions(), keywords, caller=caller)
