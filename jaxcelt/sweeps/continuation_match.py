"""Section geometry of a global continuation: lanes labelled, grouped into attractors, matched across values.

Everything here works on *section coordinates*: points of the stroboscopic section mapped into a
Euclidean space where distances mean something (for the wobblestone (v, omega, n, cos psi, sin psi), the
cyclic position r_C left out; for a plain ODE the state itself). No model, no integration: numpy only.

* `lane_kinds`: per lane, periodic with period k (`jaxcelt.sweeps.regimes.detect_period`), else a
  non-periodic kind from the largest Lyapunov exponent when there is one (and from lambda_2 too when given:
  `jaxcelt.sweeps.regimes.spectrum_regime`, the rule of `jaxcelt.sweeps.regimes.classify`), else
  ``aperiodic``; lanes that left the model's validity or whose solve failed are outcomes, not attractors.
* `cycle_distance`, `set_distance`, `spacing`: how far two periodic cycles (up to a cyclic shift) or two
  point sets are apart.
* `group_lanes`: the distinct attractors among the lanes at one value: periodic lanes of one period whose
  cycles coincide, non-periodic lanes whose point sets interleave (connected components).
* `match_attractors`: which attractor at this value continues which at the previous one: greedy by
  increasing distance under a threshold, one to one, ties broken by where the seeds went.
"""

from __future__ import annotations

import math

import numpy as np

from jaxcelt.sweeps.regimes import REGIMES, detect_period, spectrum_regime

__all__ = [
    "KINDS",
    "OUTCOMES",
    "lane_kinds",
    "cycle_distance",
    "set_distance",
    "spacing",
    "group_lanes",
    "attractor_distance",
    "match_attractors",
]

KINDS: tuple[str, ...] = ("periodic", "quasi-periodic", "chaotic", "converging", "uncertain", "aperiodic")
"""Kinds of attractor (`jaxcelt.sweeps.regimes.REGIMES` names); codes are indices into this tuple."""
OUTCOMES: dict[int, str] = {-1: "tipping over", -2: "failed"}
"""Lane outcomes that are no attractor: -1 left the model's validity (the wobblestone tips over / lifts off,
a plain ODE leaves its ``valid`` region), -2 the solve did not finish."""
TIPPING, FAILED = -1, -2


def lane_kinds(
    coords: np.ndarray,
    outcome: np.ndarray,
    lyapunov: np.ndarray | None,
    lyapunov_stderr: np.ndarray | None,
    *,
    period_tol: float,
    chaos_threshold: float,
    confidence: float,
    lyapunov_2: np.ndarray | None = None,
    lyapunov_2_stderr: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Kind code (index into `KINDS`; -1 tipping over, -2 failed) and period k (0 unless periodic) per lane.

    Args:
        coords: (L, S, m) section coordinates of the samples; outcome: (L,) 0 ran, 1 left validity, 2 failed;
        lyapunov, lyapunov_stderr: (L,) [1/s] or None (not computed; NaN entries count as not computed).
        lyapunov_2, lyapunov_2_stderr: (L,) the second exponent [1/s] and its error, or None (not computed): with
            it a lambda_1 near 0 is quasi-periodic only if lambda_2 is clearly negative (`spectrum_regime`).
        chaos_threshold, confidence: the exponent rule (`jaxcelt.sweeps.regimes.spectrum_regime`).
    """
    L, S = coords.shape[:2]
    kind = np.zeros(L, np.int64)
    period = np.zeros(L, np.int64)
    nan = np.full(L, np.nan)
    se = None if lyapunov_stderr is None else np.asarray(lyapunov_stderr, dtype=float)
    code = spectrum_regime(
        nan if lyapunov is None else lyapunov, None if se is None else np.where(np.isfinite(se), se, 0.0),
        lyapunov_2, lyapunov_2_stderr, chaos_threshold=chaos_threshold, confidence=confidence,
    )  # fmt: skip
    for i in range(L):
        if outcome[i] == 1:
            kind[i] = TIPPING
            continue
        if outcome[i] != 0 or not np.all(np.isfinite(coords[i])):
            kind[i] = FAILED
            continue
        k = detect_period(coords[i], max_period=S // 2, tol=period_tol)
        if k > 0:
            kind[i], period[i] = 0, k
        else:
            kind[i] = KINDS.index(REGIMES[int(code[i])])
    return kind, period


def _scale(a: np.ndarray, b: np.ndarray) -> float:
    return 1.0 + max(float(np.max(np.abs(a))), float(np.max(np.abs(b))))


def cycle_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Distance of two cycles a, b (k, m): min over cyclic shifts of max |a - b|, relative to 1 + max|x|
    (inf if the periods differ)."""
    if a.shape != b.shape:
        return math.inf
    return min(float(np.max(np.abs(a - np.roll(b, s, axis=0)))) for s in range(a.shape[0])) / _scale(a, b)


def _nn(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from each point of a (n, m) to the nearest point of b (p, m)."""
    return np.sqrt(np.min(np.sum((a[:, None, :] - b[None, :, :]) ** 2, axis=-1), axis=1))


def set_distance(a: np.ndarray, b: np.ndarray, *, relative: bool = True) -> float:
    """Distance of two point sets a (n, m), b (p, m): max(mean nearest-neighbour distance a -> b, b -> a)
    (a mean Hausdorff distance, robust to single stray points), relative to 1 + max|x| when ``relative``."""
    d = max(float(np.mean(_nn(a, b))), float(np.mean(_nn(b, a))))
    return d / _scale(a, b) if relative else d


def spacing(a: np.ndarray) -> float:
    """Mean distance from a point of a (n, m) to the nearest other point of a (0 for one point or a fixed point)."""
    if a.shape[0] < 2:
        return 0.0
    d = np.sqrt(np.sum((a[:, None, :] - a[None, :, :]) ** 2, axis=-1))
    np.fill_diagonal(d, np.inf)
    return float(np.mean(np.min(d, axis=1)))


def _same_set(a: np.ndarray, b: np.ndarray, group_tol: float, set_factor: float) -> bool:
    d = set_distance(a, b, relative=False)
    return d <= group_tol * _scale(a, b) + set_factor * max(spacing(a), spacing(b))


def group_lanes(
    kind: np.ndarray, period: np.ndarray, coords: np.ndarray, *, group_tol: float, set_factor: float
) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """The distinct attractors among the lanes at one value.

    Args:
        kind, period: (L,) from `lane_kinds`; coords: (L, S, m) section coordinates of the samples.

    Returns:
        (group (L,) index of the lane's attractor, -1 / -2 for tipping over / failed lanes;
        groups [(kind code, k, representative lane)]), periodic groups first, in order of first lane.
        Periodic lanes: greedily against each group's first lane (`cycle_distance` of their last k points
        <= ``group_tol``). A non-periodic lane whose last half of samples lies within ``group_tol`` (relative
        `set_distance`) of a periodic group's cycle is still converging onto it and joins it. Other
        non-periodic lanes of any kind: connected components of "point sets
        interleave" (see `ContinuationOptions.set_factor`); the group's kind is its most common lane kind.
    """
    label = np.where(kind < 0, kind, -3).astype(np.int64)
    groups: list[tuple[int, int, int]] = []
    for i in np.flatnonzero(kind == 0):
        k = int(period[i])
        for g, (_, kg, rep) in enumerate(groups):
            if kg == k and cycle_distance(coords[rep, -k:], coords[i, -k:]) <= group_tol:
                label[i] = g
                break
        else:
            label[i] = len(groups)
            groups.append((0, k, int(i)))
    rest: list[int] = []
    for i in np.flatnonzero(kind > 0):  # a lane still converging onto a periodic attractor joins it
        tail = coords[i, -max(coords.shape[1] // 2, 1) :]
        near = [g for g, (_, k, rep) in enumerate(groups) if set_distance(tail, coords[rep, -k:]) <= group_tol]
        if near:
            label[i] = near[0]
        else:
            rest.append(int(i))
    parent = {i: i for i in rest}

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a_i, i in enumerate(rest):
        for j in rest[a_i + 1 :]:
            if root(i) != root(j) and _same_set(coords[i], coords[j], group_tol, set_factor):
                parent[root(j)] = root(i)
    comps: dict[int, list[int]] = {}
    for i in rest:
        comps.setdefault(root(i), []).append(i)
    for members in sorted(comps.values(), key=lambda m: m[0]):
        kinds = [int(kind[i]) for i in members]
        common = max(set(kinds), key=lambda c: (kinds.count(c), -c))
        label[members] = len(groups)
        groups.append((common, 0, members[0]))
    return label, groups


def attractor_distance(kind_a: int, k_a: int, pts_a: np.ndarray, kind_b: int, k_b: int, pts_b: np.ndarray) -> float:
    """Distance between two attractors given by their section points (coordinates): `cycle_distance` for two
    periodic ones of the same period, else `set_distance` (relative)."""
    if kind_a == 0 and kind_b == 0 and k_a == k_b:
        return cycle_distance(pts_a, pts_b)
    return set_distance(pts_a, pts_b)


def match_attractors(distance: np.ndarray, seed_share: np.ndarray, *, match_tol: float, tie_rtol: float) -> np.ndarray:
    """One-to-one matching of the attractors at a value (rows) to those at the previous value (columns).

    Args:
        distance: (A, B) `attractor_distance` of every pair; seed_share: (A, B) fraction of previous
            attractor b's seeds that landed in attractor a.
        match_tol: pairs farther apart are never matched; tie_rtol: relative band of tied distances.

    Returns:
        (A,) the matched previous attractor per row, -1 for a new one. Greedy, one to one: of the pairs
        left, those within (1 + ``tie_rtol``) of the smallest distance are tied; the tied pair with the
        largest seed share (then the smallest distance) is matched, its row and column removed.
    """
    A, B = distance.shape
    out = np.full(A, -1, dtype=np.int64)
    pairs = [(float(distance[a, b]), a, b) for a in range(A) for b in range(B)
             if np.isfinite(distance[a, b]) and distance[a, b] <= match_tol]  # fmt: skip
    while pairs:
        d_min = min(p[0] for p in pairs)
        tied = [p for p in pairs if p[0] <= (1.0 + tie_rtol) * d_min]
        _, a, b = max(tied, key=lambda p: (float(seed_share[p[1], p[2]]), -p[0]))
        out[a] = b
        pairs = [p for p in pairs if p[1] != a and p[2] != b]
    return out


def contraction_onto(coords: np.ndarray, orbit: np.ndarray, k: int) -> tuple[float, float]:
    """How the lanes of a set approach a periodic orbit: (median over lanes of the ratio of their mean distance
    to the orbit in the last quarter of their samples to that in the first quarter, median relative distance in
    the last quarter).

    Args:
        coords: (n, S, m) section coordinates of the set's lanes; orbit: (m,) one section point of a period-k
            orbit. Every k-th sample of a lane near the orbit comes back near this point: of the k phases, the
            one nearest to it at the end is compared.

    A ratio below 1 says the lanes close in on the orbit (a stable orbit with multipliers near the unit circle
    draws them in by about max|mu| per period, too slowly to settle within a short transient).
    """
    n, S = coords.shape[:2]
    k = max(int(k), 1)
    ratios, last = [], []
    for i in range(n):
        d = np.linalg.norm(coords[i] - orbit, axis=-1)
        best = None
        for r in range(min(k, S)):
            sub = d[r::k]
            if sub.size < 4:
                continue
            q = max(sub.size // 4, 1)
            end, start = float(np.mean(sub[-q:])), float(np.mean(sub[:q]))
            if best is None or end < best[0]:
                best = (end, start)
        if best is None or not np.isfinite(best[0]) or best[1] <= 0:
            continue
        ratios.append(best[0] / best[1])
        last.append(best[0] / _scale(coords[i], orbit[None]))
    if not ratios:
        return math.inf, math.inf
    return float(np.median(ratios)), float(np.median(last))
