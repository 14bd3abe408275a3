"""The result of a global continuation of attractors: one `xarray.Dataset` (attractor id x parameter value).

`continuation_dataset` assembles it from the per-value records (`jaxcelt.sweeps.continuation_store.ValueRecord`).
Dimensions: ``attractor`` (global ids 0..A-1, in order of discovery), the continued parameter (its values),
``lane`` (the N fresh starts), ``state`` (the state components).

Per attractor and value (an attractor absent at a value has ``exists`` 0, ``fraction`` 0, ``kind`` "" and
NaN / -1 elsewhere):

* ``exists``; ``fraction`` (fresh lanes in its basin / N; seeds excluded) and ``fraction_stderr``
  (binomial, sqrt(f (1 - f) / N)); ``count`` (fresh lanes) and ``n_lanes`` (fresh and seed lanes on it);
* ``kind`` (`jaxcelt.sweeps.continuation_match.KINDS`), ``period`` (k; 0 unless periodic);
* ``refine_status``, ``multiplier_max`` (largest |Floquet multiplier| of the refined orbit), ``stable``
  (1, 0, -1 unknown); ``lyapunov``, ``lyapunov_stderr`` [1/s] (median over its lanes, NaN if not computed);
* ``orbit_period``, ``orbit_multiplier_max``, ``orbit_point``: the periodic orbit that goes with the attractor -- its own
  refined orbit, or, for an attractor that is not periodic here, the orbit of its predecessor continued to
  this value by Newton (from one value to the next, as long as Newton converges). A stable orbit there
  (``orbit_multiplier_max`` < 1) on a non-periodic attractor says its lanes are still converging to it (weak
  attraction, |mu| near 1); an unstable one says the attractor has left the orbit (after a torus or
  period-doubling bifurcation);
* ``section_point`` (representative section state: the refined orbit's when Newton converged), ``t_section`` [s];
  ``section_points`` (dim ``point``: a periodic attractor's k cycle points, a set's samples; NaN-padded).

Per value: ``tipping_fraction`` and its ``tipping_fraction_stderr`` (fresh lanes that left the model's
validity: the wobblestone tipped over or lifted off), ``failed_fraction``, ``n_seeds``, ``n_attractors``.
Per value and lane: ``outcome`` (attractor id, -1 tipping over, -2 failed), ``lane_kind``, ``lane_period``,
``lane_final`` (the lane's last section state). Per lane: ``starts``.
Attributes: ``continued_parameter``, ``options_json``, ``fingerprint_json``, ``kind_codes``,
``outcome_codes`` and the model's own (for the wobblestone its parameters, versions and provenance).
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from jaxcelt.sweeps.continuation_match import KINDS, OUTCOMES
from jaxcelt.sweeps.continuation_store import REFINE_STATUS

__all__ = ["continuation_dataset"]


def _kind_name(code: int) -> str:
    return OUTCOMES[code] if code < 0 else KINDS[code]


def continuation_dataset(records, *, name: str, starts: np.ndarray, model, options, fingerprint: dict) -> xr.Dataset:
    """The dataset of a continuation (see the module docstring) from its per-value records, in value order."""
    V, (N, d) = len(records), starts.shape
    A = max((r.next_id for r in records), default=0)
    f = np.zeros((A, V))
    fe = np.zeros((A, V))
    cnt = np.zeros((A, V), np.int64)
    nl = np.zeros((A, V), np.int64)
    ex = np.zeros((A, V), np.int8)
    kind = np.full((A, V), "", dtype=object)
    per = np.zeros((A, V), np.int64)
    rst = np.full((A, V), "", dtype=object)
    mu = np.full((A, V), np.nan)
    stab = np.full((A, V), -1, np.int8)
    ly = np.full((A, V), np.nan)
    lse = np.full((A, V), np.nan)
    st = np.full((A, V, d), np.nan)
    ts = np.full((A, V), np.nan)
    ok = np.zeros((A, V), np.int64)
    omu = np.full((A, V), np.nan)
    opt = np.full((A, V, d), np.nan)
    P = max((r.att_cloud.shape[1] for r in records), default=1)
    pts = np.full((A, V, P, d), np.nan)
    for j, r in enumerate(records):
        for a, gid in enumerate(r.att_id):
            c = int(r.att_count[a])
            f[gid, j] = c / N
            fe[gid, j] = np.sqrt(f[gid, j] * (1 - f[gid, j]) / N)
            cnt[gid, j], nl[gid, j], ex[gid, j] = c, int(r.att_lanes[a]), 1
            kind[gid, j], per[gid, j] = KINDS[int(r.att_kind[a])], int(r.att_k[a])
            rst[gid, j] = REFINE_STATUS[int(r.att_refine[a])] if int(r.att_kind[a]) == 0 else ""
            mu[gid, j], stab[gid, j] = r.att_mu_max[a], r.att_stable[a]
            ly[gid, j], lse[gid, j] = r.att_lyap[a], r.att_lyap_se[a]
            st[gid, j], ts[gid, j] = r.att_state[a], r.att_t[a]
            pts[gid, j, : r.att_cloud.shape[1]] = r.att_cloud[a]
            ok[gid, j], omu[gid, j], opt[gid, j] = r.att_orbit_k[a], r.att_orbit_mu[a], r.att_orbit_state[a]
    tip = np.array([np.mean(r.lane_outcome == -1) for r in records])
    fail = np.array([np.mean(r.lane_outcome == -2) for r in records])
    vals = np.array([r.value for r in records])
    AV, VL = ("attractor", name), (name, "lane")

    def var(dims, x, long_name, units=""):
        return xr.Variable(dims, x, attrs={"long_name": long_name, "units": units})

    data = {
        "exists": var(AV, ex, "attractor present at this value (1) or not (0)"),
        "fraction": var(AV, f, "basin fraction: fresh starts that reach it / all fresh starts (seeds excluded)"),
        "fraction_stderr": var(AV, fe, "binomial standard error of fraction, sqrt(f (1 - f) / N)"),
        "count": var(AV, cnt, "fresh starts that reach it"),
        "n_lanes": var(AV, nl, "lanes that reach it, fresh starts and seeds"),
        "kind": var(AV, kind.astype(str), "periodic, quasi-periodic, chaotic, converging, uncertain, aperiodic"),
        "period": var(AV, per, "period k in forcing periods (0 unless periodic)"),
        "refine_status": var(AV, rst.astype(str), "Newton refinement of a periodic attractor"),
        "multiplier_max": var(AV, mu, "largest Floquet multiplier modulus of the refined orbit"),
        "stable": var(AV, stab, "1 all |mu| < 1, 0 not, -1 unknown"),
        "lyapunov": var(AV, ly, "median largest Lyapunov exponent of its lanes", "1/s"),
        "lyapunov_stderr": var(AV, lse, "median standard error of the lanes' exponents", "1/s"),
        "section_point": var((*AV, "state"), st, "representative section state (refined when Newton converged)", "SI"),
        "section_points": var((*AV, "point", "state"), pts, "its section points: a periodic attractor's k cycle "
                              "points, a set's samples (NaN-padded)", "SI"),
        "orbit_period": var(AV, ok, "period k of the orbit that goes with it: its own refined orbit, or its "
                            "predecessor's continued here by Newton (0: none)"),
        "orbit_multiplier_max": var(AV, omu, "largest Floquet multiplier modulus of that orbit"),
        "orbit_point": var((*AV, "state"), opt, "that orbit's section state", "SI"),
        "t_section": var(AV, ts, "time of the representative section state", "s"),
        "tipping_fraction": var((name,), tip, "fresh starts that left the model's validity (tipping over)"),
        "tipping_fraction_stderr": var((name,), np.sqrt(tip * (1 - tip) / N), "binomial standard error"),
        "failed_fraction": var((name,), fail, "fresh starts whose solve failed"),
        "n_seeds": var((name,), np.array([len(r.seed_origin) for r in records], np.int64), "seed lanes"),
        "n_attractors": var((name,), np.array([len(r.att_id) for r in records], np.int64), "attractors found"),
        "outcome": var(VL, np.stack([r.lane_outcome for r in records]), "attractor id, -1 tipping over, -2 failed"),
        "lane_kind": var(VL, np.array([[_kind_name(int(c)) for c in r.lane_kind] for r in records], dtype=str),
                         "the lane's own label"),
        "lane_period": var(VL, np.stack([r.lane_period for r in records]), "the lane's period k"),
        "lane_final": var((*VL, "state"), np.stack([r.lane_final for r in records]), "last section state", "SI"),
        "starts": var(("lane", "state"), starts, "fresh start states (the same at every value)", "SI"),
    }  # fmt: skip
    names = list(model.state_names) if model.state_names is not None else [f"y{i}" for i in range(d)]
    coords = {"attractor": np.arange(A), name: vals, "lane": np.arange(N), "state": names, "point": np.arange(P)}
    attrs: dict[str, Any] = {
        "title": f"global continuation of attractors over {name}",
        "continued_parameter": name,
        "options_json": json.dumps(options.fingerprint(), sort_keys=True, default=repr),
        "fingerprint_json": json.dumps(fingerprint, sort_keys=True, default=repr),
        "kind_codes": json.dumps(list(KINDS)),
        "outcome_codes": json.dumps({str(k): v for k, v in OUTCOMES.items()}),
        **model.attrs,
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)
