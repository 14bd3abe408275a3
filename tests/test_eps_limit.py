"""scripts/eps_limit.py: the fit of the eps -> 0 limit recovers known parameters; one located point reruns against
docs/orbits/eps_limit.json."""

from __future__ import annotations

import importlib.util
import json
import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("eps_limit", ROOT / "scripts/eps_limit.py")
E = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(E)


@pytest.mark.parametrize(("omega_0", "c", "alpha", "noise"), [(17.7, -0.3, 0.5, 1e-6), (14.88, -0.0046, 1.0, 1e-10)])
def test_fit_limit_recovers_a_known_power_law(omega_0, c, alpha, noise):
    # synthetic omega(eps) on the script's grid (1e-8 .. 1e-3) plus Gaussian noise; the fit must recover the
    # parameters within 5 of its own one-sigma errors (a correct covariance makes a 5-sigma miss ~1e-6 likely),
    # and its errors must be honest: alpha to 0.05 absolute with the noise used here
    rng = np.random.default_rng(7)
    eps = np.array([1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8])
    w = E.power_law(eps, omega_0, c, alpha) + noise * rng.standard_normal(eps.size)
    f = E.fit_limit(eps, w, sigma=np.full(eps.size, noise))
    for name, true in (("omega_0", omega_0), ("c", c), ("alpha", alpha)):
        assert abs(f[name] - true) <= 5 * f[f"{name}_err"], (name, f[name], true, f[f"{name}_err"])
    assert abs(f["alpha"] - alpha) < 0.05
    assert f["max_abs_residual"] < 5 * noise


def test_fit_linear_is_exact_on_a_line():
    eps = np.array([1e-3, 1e-4, 1e-5, 1e-6])
    f = E.fit_linear(eps, 14.88 - 0.0046 * eps)
    assert abs(f["omega_0"] - 14.88) < 1e-12 and abs(f["c"] + 0.0046) < 1e-9


def test_fit_limit_rejects_bad_input():
    with pytest.raises(ValueError, match="eps"):
        E.fit_limit([1e-3, 0.0, 1e-5, 1e-6], [1.0, 1.0, 1.0, 1.0])


@pytest.mark.slow
def test_fold_at_1e_3_reruns_from_the_committed_3e_4_point():
    # the ladder's step 3e-4 -> 1e-3 redone: the fold located from the committed 3e-4 point must equal the committed
    # 1e-3 value to 1e-8 rad/s (Newton tolerance 1e-9 in the chart's unknowns; the located values of the two runs
    # agree to round-off when nothing changed, 1e-8 allows a different BLAS/CPU)
    d = json.loads((ROOT / "docs/orbits/eps_limit.json").read_text())
    rows = {float(f"{r['eps']:.3g}"): r for r in d["points"]["fold"] if "omega" in r}  # eps = 10**log10(eps)
    r = E.refine("fold", rows[3e-4]["omega"], np.asarray(rows[3e-4]["y"]), 1e-3)
    assert abs(r["omega"] - rows[1e-3]["omega"]) < 1e-8
    assert r["min_abs_multiplier_minus_1"] < 1e-8
