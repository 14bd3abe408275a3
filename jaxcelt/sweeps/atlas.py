"""The atlas of the forced wobblestone over the forcing frequency: one object for the reader of the paper's Fig. 3.

`atlas` puts together, over one window of omega_pi, what the other tools compute separately:

1. the **brute-force diagram**: section points of one lane per value from rest (`jaxcelt.bifurcation`, the
   paper's Fig. 3 itself);
2. the **attractors** and their **basin fractions**, tipping over included (`jaxcelt.continue_attractors`: fresh
   starts at every value plus seeds, matched from value to value; resumable through ``out``);
3. the **periodic branches** through the continuation's period-1 / period-2 orbits (`jaxcelt.continue_orbit`, both
   ways to the window's ends, through folds; stability along them; fold / period-doubling / Neimark-Sacker points).
   Each orbit of the continuation that does not lie on a branch already found starts a new one; the half-turn image
   of a branch (`half_turn`: the mirror pair, psi differing by 180 deg) is its second branch, checked by one Newton
   solve and not continued again;
4. the **Lyapunov exponents** of every attractor at every value: lambda_1 (and its standard error) from the
   continuation's lanes (``lyapunov_periods > 0``) and, with ``spectrum_periods > 0``, lambda_1 and lambda_2 from
   `jaxcelt.lyapunov_spectrum` started at the attractor's representative section point (one vmapped batch), and
   from them a label per attractor and value (`AtlasResult.kind_spectrum`, `jaxcelt.sweeps.regimes.spectrum_regime`
   with the continuation's thresholds): lambda_1 ~ 0 with lambda_2 clearly negative is a 2-torus
   (quasi-periodic), lambda_1 ~ lambda_2 ~ 0 uncertain (a focus near a Neimark-Sacker point, or a 3-torus).

The result is an `AtlasResult` (plain arrays, the continuation's `xarray.Dataset`, the branches); `AtlasResult.summary`
is its JSON-ready form. Drawing it is `jaxcelt.plotting.atlas.plot_atlas`; the command line is ``jaxcelt atlas``.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from jaxcelt.physics.params import CeltParams

__all__ = ["AtlasOptions", "AtlasResult", "atlas", "spectrum_kinds"]


@dataclasses.dataclass(frozen=True, kw_only=True)
class AtlasOptions:
    """Settings of `atlas` (one keyword-only object; every field has a default sized for a 2-core CPU).

    Attributes:
        starts: (n_psi0, n_tilt) fresh starts at rest of the continuation (`jaxcelt.attractor_starts`: headings
            over a full turn x tilts in +-``tilt``).
        tilt: largest initial tilt [rad] of the fresh starts.
        transient_periods, sample_periods, lyapunov_periods, seeds_per_attractor: the continuation's lanes
            (`jaxcelt.ContinuationOptions`); ``lyapunov_periods`` 0 leaves lambda_1 out (non-periodic attractors
            are then labelled aperiodic).
        brute_values: number of omega_pi values of the brute-force diagram over the window (0: none).
        brute_transient, brute_sample: its transient and sampled periods.
        brute_psi0: its start's heading [rad] (at rest; default 157.5 deg, the paper's start).
        branches: continue the periodic orbits of the continuation into branches.
        branch_max_points: points of a branch at most (`jaxcelt.continue_orbit`'s ``max_points``).
        max_branches: branches at most.
        spectrum_periods: periods of `jaxcelt.lyapunov_spectrum` per attractor and value (0: off).
        spectrum_transient: its transient periods (the tangent frame aligns).
        spectrum_rtol: its relative tolerance (atol = rtol / 100); the finite-time error of the exponents
            (about 1 / (spectrum_periods T)) dominates the solver's at 1e-8.
        out: directory of the continuation's resumable files (None: nothing written).
        progress: progress bars.
    """

    starts: tuple[int, int] = (8, 3)
    tilt: float = 0.1
    transient_periods: int = 100
    sample_periods: int = 16
    lyapunov_periods: int = 40
    seeds_per_attractor: int = 4
    brute_values: int = 51
    brute_transient: int = 100
    brute_sample: int = 24
    brute_psi0: float = float(np.radians(157.5))
    branches: bool = True
    branch_max_points: int = 120
    max_branches: int = 4
    spectrum_periods: int = 0
    spectrum_transient: int = 10
    spectrum_rtol: float = 1e-8
    out: str | None = None
    progress: bool = False

    def __post_init__(self):
        s = tuple(self.starts)
        if len(s) != 2 or not all(isinstance(n, int | np.integer) and n > 0 for n in s):
            raise ValueError(f"AtlasOptions: 'starts' must be two positive integers, got {self.starts!r}")
        if not (np.isfinite(self.tilt) and self.tilt >= 0):
            raise ValueError(f"AtlasOptions: 'tilt' must be finite and >= 0, got {self.tilt!r}")
        for f in ("transient_periods", "lyapunov_periods", "seeds_per_attractor", "brute_values", "brute_transient",
                  "spectrum_periods", "spectrum_transient"):  # fmt: skip
            v = getattr(self, f)
            if not isinstance(v, int | np.integer) or v < 0:
                raise ValueError(f"AtlasOptions: '{f}' must be an integer >= 0, got {v!r}")
        for f in ("sample_periods", "brute_sample", "branch_max_points", "max_branches"):
            v = getattr(self, f)
            if not isinstance(v, int | np.integer) or v < 1:
                raise ValueError(f"AtlasOptions: '{f}' must be a positive integer, got {v!r}")
        if self.sample_periods < 2:
            raise ValueError(f"AtlasOptions: 'sample_periods' must be >= 2, got {self.sample_periods!r}")
        if not (np.isfinite(self.spectrum_rtol) and 0 < self.spectrum_rtol < 1):
            raise ValueError(f"AtlasOptions: 'spectrum_rtol' must be in (0, 1), got {self.spectrum_rtol!r}")
        if not np.isfinite(self.brute_psi0):
            raise ValueError(f"AtlasOptions: 'brute_psi0' must be finite, got {self.brute_psi0!r}")
        object.__setattr__(self, "starts", (int(s[0]), int(s[1])))


@dataclasses.dataclass(frozen=True)
class AtlasResult:
    """What `atlas` returns.

    Attributes:
        params: the stone (its omega_pi is replaced by each value).
        values: the continuation's omega_pi values [rad/s] (V,).
        brute: `jaxcelt.SweepResult` of the brute-force diagram (None if ``brute_values`` is 0).
        continuation: the `jaxcelt.continue_attractors` dataset (attractor x value).
        branches: list of (label, `jaxcelt.orbits.branch.ArclengthBranch`), each with ``stable`` along it and its
            ``bifurcations`` (kind, value, y).
        branch_attractors: per branch, the id of the continuation's attractor whose orbit lies on it (-1: none).
        lambda1, lambda1_stderr, lambda2, lambda2_stderr: (attractor, value) exponents [1/s] from
            `jaxcelt.lyapunov_spectrum` at the representative section point (NaN where absent or not computed).
        seconds: wall time of each part [s] (first calls include compilation).
        options: the `AtlasOptions` used.
        kind_spectrum: (attractor, value) label from lambda_1 and lambda_2 (`spectrum_kinds`): ``"chaotic"``,
            ``"converging"`` (a sink: a periodic orbit, reached or not), ``"quasi-periodic"`` (a 2-torus) or
            ``"uncertain"``; ``""`` where there is no spectrum. None at construction: computed from the exponents
            with the continuation's ``chaos_threshold`` and ``confidence``.
    """

    params: CeltParams
    values: np.ndarray
    brute: Any
    continuation: Any
    branches: list
    branch_attractors: list
    lambda1: np.ndarray
    lambda1_stderr: np.ndarray
    lambda2: np.ndarray
    lambda2_stderr: np.ndarray
    seconds: dict
    options: AtlasOptions
    kind_spectrum: np.ndarray | None = None

    def __post_init__(self):
        if self.kind_spectrum is None:
            rule = _rule(self.continuation)
            kinds = spectrum_kinds(self.lambda1, self.lambda1_stderr, self.lambda2, self.lambda2_stderr, **rule)
            object.__setattr__(self, "kind_spectrum", kinds)

    def summary(self) -> dict[str, Any]:
        """JSON-ready: the continuation summary, the branches with their bifurcation points, the exponents."""
        from jaxcelt.orbits.branch import branch_to_dict
        from jaxcelt.physics.model import STATE_NAMES
        from jaxcelt.sweeps.continuation_core import continuation_summary

        cont = continuation_summary(self.continuation)
        for j, row in enumerate(cont["values"]):
            for a in row["attractors"]:
                i = a["id"]
                a["spectrum"] = [_num(self.lambda1[i, j]), _num(self.lambda2[i, j])]
                a["spectrum_stderr"] = [_num(self.lambda1_stderr[i, j]), _num(self.lambda2_stderr[i, j])]
                a["kind_spectrum"] = str(self.kind_spectrum[i, j]) or None
        branches = []
        for (label, br), a in zip(self.branches, self.branch_attractors, strict=True):
            d = branch_to_dict(br, STATE_NAMES)
            branches.append(dict(label=label, attractor=a, n_points=len(br.values), stopped=br.stopped,
                                 bifurcations=[dict(kind=b.kind, value=float(b.value)) for b in br.bifurcations],
                                 branch=d))  # fmt: skip
        brute = None
        if self.brute is not None:
            brute = dict(n_values=int(len(self.brute.values)), invalid=int(np.sum(~np.asarray(self.brute.valid))))
        return dict(options=dataclasses.asdict(self.options), params={k: float(v) for k, v in
                    dataclasses.asdict(self.params).items() if np.ndim(v) == 0}, continuation=cont,
                    branches=branches, brute_force=brute, seconds=self.seconds)  # fmt: skip


def spectrum_kinds(
    lambda1, lambda1_stderr, lambda2, lambda2_stderr, *, chaos_threshold: float = 0.02, confidence: float = 2.0
) -> np.ndarray:
    """Labels (object array of str, the inputs' shape) from lambda_1, lambda_2 and their standard errors [1/s]:
    the `REGIMES` names of `jaxcelt.sweeps.regimes.spectrum_regime`, ``""`` where lambda_1 is missing (NaN)."""
    from jaxcelt.sweeps.regimes import REGIMES, spectrum_regime

    code = spectrum_regime(lambda1, lambda1_stderr, lambda2, lambda2_stderr, chaos_threshold=chaos_threshold,
                           confidence=confidence)  # fmt: skip
    out = np.empty(code.shape, dtype=object)
    for idx in np.ndindex(code.shape):
        out[idx] = "" if code[idx] == 5 else REGIMES[int(code[idx])]
    return out


def _rule(ds) -> dict[str, float]:
    """The continuation's exponent thresholds (``chaos_threshold``, ``confidence``; the defaults if not recorded)."""
    import json

    from jaxcelt.sweeps.continuation_options import ContinuationOptions

    d = ContinuationOptions()
    rec = json.loads(getattr(ds, "attrs", {}).get("options_json", "{}"))
    return dict(chaos_threshold=float(rec.get("chaos_threshold", d.chaos_threshold)),
                confidence=float(rec.get("confidence", d.confidence)))  # fmt: skip


def _num(x) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


def atlas(params: CeltParams, values: Any, *, options: AtlasOptions | None = None) -> AtlasResult:
    """The atlas of the wobblestone over ``values`` of omega_pi (see the module's docstring).

    Args:
        params: the stone and the base (q_pi etc.); omega_pi is replaced by each value.
        values: increasing omega_pi values [rad/s] of the continuation (at least 2); the brute-force diagram and the
            branches cover [min, max].
        options: `AtlasOptions`.

    Returns:
        `AtlasResult`.

    Raises:
        ValueError: bad input, naming the parameter.
    """
    o = AtlasOptions() if options is None else options
    if not isinstance(o, AtlasOptions):
        raise ValueError(f"atlas: 'options' must be an AtlasOptions, got {type(o).__name__}")
    if not isinstance(params, CeltParams) or np.ndim(params.omega_pi) != 0:
        raise ValueError("atlas: 'params' must be a single CeltParams")
    try:
        vals = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"atlas: 'values' must be numbers, got {values!r}") from None
    if vals.ndim != 1 or vals.size < 2 or not np.all(np.isfinite(vals)) or not np.all(vals > 0):
        raise ValueError(f"atlas: 'values' must be at least 2 finite omega_pi values > 0, got {values!r}")
    if not np.all(np.diff(vals) > 0):
        raise ValueError("atlas: 'values' must be increasing")
    import jaxcelt as jc

    seconds: dict[str, float] = {}
    window = (float(vals[0]), float(vals[-1]))

    t = time.perf_counter()
    starts = jc.attractor_starts(params, psi0=(0.0, 2 * np.pi), tilt=(-o.tilt, o.tilt), n=o.starts)
    ds = jc.continue_attractors(
        params, "omega_pi", vals, starts=starts, transient_periods=o.transient_periods,
        sample_periods=o.sample_periods, lyapunov_periods=o.lyapunov_periods,
        seeds_per_attractor=o.seeds_per_attractor, refine=True, out=o.out, progress=o.progress,
    )  # fmt: skip
    seconds["continuation"] = round(time.perf_counter() - t, 2)

    brute = None
    if o.brute_values > 0:
        t = time.perf_counter()
        y0 = jc.initial_state(params, psi=o.brute_psi0)
        brute = jc.bifurcation(params, np.linspace(*window, o.brute_values), y0=y0,
                               transient_periods=o.brute_transient, sample_periods=o.brute_sample,
                               stop_on_invalid=True, progress=o.progress)  # fmt: skip
        seconds["brute_force"] = round(time.perf_counter() - t, 2)

    branches: list = []
    owners: list = []
    if o.branches:
        t = time.perf_counter()
        branches = _branches(params, ds, window, o)
        seeds = orbit_seeds(ds)
        for _, br in branches:
            on = [a for a, j, _ in seeds if _on_branch(br, float(vals[j]), ds["orbit_point"].values[a, j])]
            owners.append(on[0] if on else -1)
        seconds["branches"] = round(time.perf_counter() - t, 2)

    shape = (ds.sizes["attractor"], vals.size)
    lam = [np.full(shape, np.nan) for _ in range(4)]
    if o.spectrum_periods > 0:
        t = time.perf_counter()
        lam = _spectra(params, ds, o)
        seconds["spectrum"] = round(time.perf_counter() - t, 2)
    return AtlasResult(params, vals, brute, ds, branches, owners, *lam, seconds, o)


def orbit_seeds(ds) -> list[tuple[int, int, int]]:
    """(attractor, value index, k) of the continuation's orbits to start branches from: per attractor id, its
    refined period-1 or period-2 orbit (own or continued by Newton) with the smallest largest multiplier."""
    out = []
    per = ds["orbit_period"].values
    mu = ds["orbit_multiplier_max"].values
    pt = ds["orbit_point"].values
    for a in range(ds.sizes["attractor"]):
        ok = np.isin(per[a], (1, 2)) & np.isfinite(mu[a]) & np.all(np.isfinite(pt[a]), axis=-1)
        if ok.any():
            j = int(np.flatnonzero(ok)[np.argmin(mu[a][ok])])
            out.append((a, j, int(per[a, j])))
    return sorted(out, key=lambda s: mu[s[0], s[1]])


def _on_branch(br, value: float, y: np.ndarray, tol: float = 1e-3) -> bool:
    """Whether the orbit (value, y) lies on ``br``: within ``tol`` (1 + |y|) of the branch between two points."""
    from jaxcelt.sweeps.continuation import celt_section_coords

    lam, ys = np.asarray(br.values), celt_section_coords(np.asarray(br.y))
    c = celt_section_coords(np.asarray(y)[None])[0]
    scale = 1.0 + np.max(np.abs(c))
    for i in range(len(lam) - 1):
        lo, hi = sorted((lam[i], lam[i + 1]))
        if lo - 1e-9 <= value <= hi + 1e-9:
            s = 0.0 if hi == lo else (value - lam[i]) / (lam[i + 1] - lam[i])
            if np.max(np.abs(ys[i] + s * (ys[i + 1] - ys[i]) - c)) < max(tol, 0.05) * scale:
                return True
    return False


def _branches(params: CeltParams, ds, window: tuple[float, float], o: AtlasOptions) -> list:
    """Continue the continuation's period-1/2 orbits into branches (one per orbit not on a branch found before)."""
    import jaxcelt as jc

    vals = ds["omega_pi"].values
    out: list = []
    seeds = orbit_seeds(ds)
    bar = None
    if o.progress and seeds:
        from tqdm.auto import tqdm

        bar = tqdm(unit="branch", desc="periodic branches (continued)")
    for a, j, k in seeds:
        if len(out) >= o.max_branches:
            break
        w, y = float(vals[j]), np.asarray(ds["orbit_point"].values[a, j])
        if any(_on_branch(br, w, y) for _, br in out):
            continue
        p = params.replace(omega_pi=w)
        orb = jc.periodic_orbit(p, y, k=k)
        if int(orb.status) != 0:
            continue
        lo, hi = window
        if not lo < w < hi:  # continue_orbit wants the start inside the window
            span = hi - lo
            lo, hi = min(lo, w - 1e-3 * span), max(hi, w + 1e-3 * span)
        br = jc.continue_orbit(p, orb, "omega_pi", (lo, hi), max_points=o.branch_max_points)
        psi = float(np.degrees(np.asarray(orb.y)[12]) % 360)
        out.append((f"period-{k} through #{a} at {w:g} rad/s (ψ {psi:.0f}°)", br))
        if bar is not None:
            bar.update(1)
        mirror = _mirror_branch(p, br, k) if len(out) < o.max_branches else None
        if mirror is not None:  # the half-turn image is an orbit too: its branch without a second continuation
            out.append((f"period-{k}, its half-turn image (ψ {(psi + 180) % 360:.0f}°)", mirror))
    if bar is not None:
        bar.close()
    return out


HALF_TURN = np.array([-1.0, -1.0, 1.0, -1.0, -1.0, 1.0, -1.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0])
"""signs of the state's components under the half turn about the body's x3 axis (with psi -> psi + pi): the same
stone described in axes turned by pi (MODEL.md section 10; tests/test_symmetry.py). For a stone symmetric under it
(the paper's: B12, the shape and the centre of mass are) it maps every orbit to an orbit, the mirror pair's two
members onto each other."""


def half_turn(y: np.ndarray) -> np.ndarray:
    """The half-turn image of states ``y`` (..., 13): body components of v, omega, n times (-1, -1, 1), psi + pi."""
    y = np.asarray(y, dtype=np.float64) * HALF_TURN
    y[..., 12] = np.mod(y[..., 12] + np.pi, 2 * np.pi)
    return y


def _mirror_branch(params: CeltParams, br, k: int):
    """The half-turn image of ``br`` if it is a different orbit of this stone (checked by one Newton solve at the
    image of the branch's start: it must converge onto the image within 1e-7); else None."""
    import jaxcelt as jc

    i = int(br.start)
    y, yi = np.asarray(br.y[i]), half_turn(br.y[i])
    d = np.abs(yi - y)
    d[12] = abs(np.mod(yi[12] - y[12] + np.pi, 2 * np.pi) - np.pi)
    if d.max() < 1e-6:  # symmetric orbit: its own image
        return None
    orb = jc.periodic_orbit(params.replace(omega_pi=float(br.values[i])), yi, k=k)
    e = np.abs(np.asarray(orb.y) - yi)
    e[12] = abs(np.mod(float(orb.y[12]) - yi[12] + np.pi, 2 * np.pi) - np.pi)
    if int(orb.status) != 0 or e.max() > 1e-7:
        return None
    bifs = [b._replace(y=half_turn(b.y)) for b in br.bifurcations]
    return br._replace(y=half_turn(br.y), bifurcations=bifs)


def _spectra(params: CeltParams, ds, o: AtlasOptions) -> list[np.ndarray]:
    """lambda_1, lambda_2 and their errors per (attractor, value) from the representative section points."""
    import jax
    import jax.numpy as jnp

    from jaxcelt.integrate.spectrum import celt_lyapunov_spectrum

    vals = ds["omega_pi"].values
    pts = ds["section_point"].values
    ok = ds["exists"].values & np.all(np.isfinite(pts), axis=-1)
    idx = np.argwhere(ok)
    out = [np.full(ok.shape, np.nan) for _ in range(4)]
    if len(idx) == 0:
        return out

    import equinox as eqx

    def one(w, y):
        p = eqx.tree_at(lambda q: q.omega_pi, params, w)  # a traced value: no validation (values checked above)
        return celt_lyapunov_spectrum(p, y, periods=o.spectrum_periods, transient_periods=o.spectrum_transient,
                                      rtol=o.spectrum_rtol, atol=o.spectrum_rtol / 100)  # fmt: skip

    r = jax.vmap(one)(jnp.asarray(vals[idx[:, 1]]), jnp.asarray(pts[idx[:, 0], idx[:, 1]]))
    good = np.asarray(r.status) == 0
    ex, se = np.asarray(r.exponents), np.asarray(r.stderr)
    for arr, src, col in ((0, ex, 0), (1, se, 0), (2, ex, 1), (3, se, 1)):
        out[arr][idx[:, 0], idx[:, 1]] = np.where(good, src[:, col], np.nan)
    return out
