"""Quoted texts of the map, periodic-orbit and paper-reproduction pages (and the regime-label how-to, the model
page and the notebooks' text), each computed from the result file it comes from.

Each entry is (document, function returning the quoted text); ``SETTINGS`` lists (document, phrase) for numbers
that are inputs, not results.
"""

from __future__ import annotations

from .files import _json

MAP = "docs/map/README.md"
ORBITS = "docs/orbits/README.md"
PAPER = "docs/paper-reproduction.md"
LABELS = "docs/how-to/regime-labels.md"


def _m(x: float, fmt: str) -> str:
    """A number as the docs print it: a unicode minus."""
    return format(x, fmt).replace("-", "−")


# ---- docs/map/README.md: the 100 x 60 map (scripts/map_study.py) and its window check (scripts/map_lyapunov_check.py)


def _map() -> dict:
    return _json("docs/map/map_omega_q_100x60.json")


def _wc() -> dict:
    return _json("docs/map/lyapunov_window_check.json")


def _wc_lanes(group: str) -> list[int]:
    return [i for i, lane in enumerate(_wc()["lanes"]) if lane["group"] == group]


def _wc_periodic() -> list[int]:
    """Lanes of the lower left that are period-1 after the long transient."""
    lt = _wc()["runs"]["long_transient"]["label"]
    return [i for i in _wc_lanes("low") if lt[i].startswith("period")]


def _wc_values(run: str, idx: list[int], key: str = "lyapunov_per_s") -> list[float]:
    v = _wc()["runs"][run][key]
    return [v[i] for i in idx if v[i] is not None]


def _wc_range(run: str, idx: list[int]) -> str:
    v = _wc_values(run, idx)
    return f"{_m(min(v), '.2f')} to {_m(max(v), '.2f')}"


def _wc_bias() -> tuple[float, int, int]:
    """Largest |lambda_1 over 10 - lambda_1 over 160| over the checked lanes, how many lie above, how many lanes."""
    r = _wc()["runs"]
    d = [a - b for a, b in zip(r["map"]["lyapunov_per_s"], r["long_lyapunov"]["lyapunov_per_s"])]
    return max(abs(x) for x in d), sum(x > 0 for x in d), len(d)


def _gpu_map_f64() -> dict:
    return next(r for r in _json("docs/performance/gpu_map_kernel.json")["machine_2"] if r.get("dtype") == "float64")


QUOTES = [
    (MAP, lambda: "{} + {} periods (no λ₁) took {:.1f} s on one H100".format(
        _gpu_map_f64()["transient_periods"], _gpu_map_f64()["sample_periods"], _gpu_map_f64()["run_s"])),
    (MAP, lambda: "lie up to {:.1f} s⁻¹ from their 160-period values".format(_wc_bias()[0])),
    (MAP, lambda: "in the {2} lanes checked they lie up to {0:.1f} s⁻¹ from their 160-period values, above them for {1}".format(
        *_wc_bias())),
    (MAP, lambda: "{} of {} cells leave the model's validity".format(
        f"{_map()['regime_counts']['invalid']:,}".replace(",", " "), f"{_map()['cells']:,}".replace(",", " "))),
    (MAP, lambda: "{} of the {} valid cells are *uncertain*".format(
        f"{_map()['regime_counts']['uncertain']:,}".replace(",", " "), f"{_map()['lyapunov_cells']:,}".replace(",", " "))),
    (MAP, lambda: f"{_map()['regime_counts']['chaotic']} are *chaotic*"),
    (MAP, lambda: "λ₁ ranges from {} to {} s⁻¹ (median {} s⁻¹)".format(
        *(_m(_map()["lyapunov_per_s"][k], ".2f") for k in ("min", "max", "median")))),
    (MAP, lambda: "(up to {:.2f} s⁻¹ over 10 periods, but about {:.2f} s⁻¹ over 160 periods in the checked lanes".format(
        _map()["lyapunov_per_s"]["max"], _wc()["summary"]["chaotic_median_lyapunov_per_s"]["long_lyapunov"])),
    (MAP, lambda: f"{_map()['unbounded_wandering_cells']} cells show unbounded wandering"),
    # the window check (also tests/test_docs_numbers.py::test_map_window_check_from_json)
    (MAP, lambda: "After {} transient periods {} of the {} are period-1 ({} of these were chaotic with the map's windows), "
        "and over {} periods their λ₁ is {} s⁻¹.".format(
            _wc()["runs"]["long_transient"]["transient_periods"], len(_wc_periodic()), len(_wc_lanes("low")),
            sum(_wc()["runs"]["map"]["label_point_estimate"][i] == "chaotic" for i in _wc_periodic()),
            _wc()["runs"]["long_lyapunov"]["lyapunov_periods"], _wc_range("long_lyapunov", _wc_periodic()))),
    (MAP, lambda: "stable orbits with |μ_max| {:.3f}–{:.3f}, i.e. Floquet exponents {} to {} s⁻¹ ({:.1f} s for the {})".format(
        min(o["max_multiplier"] for o in _wc()["floquet"]["orbits"]),
        max(o["max_multiplier"] for o in _wc()["floquet"]["orbits"]),
        _m(min(o["floquet_exponent_per_s"] for o in _wc()["floquet"]["orbits"]), ".3f"),
        _m(max(o["floquet_exponent_per_s"] for o in _wc()["floquet"]["orbits"]), ".3f"),
        _wc()["floquet"]["seconds"], len(_wc()["floquet"]["orbits"]))),
    (MAP, lambda: "λ₁ over 10 periods is {} s⁻¹ ({} of {} above the 0.02 s⁻¹ threshold)".format(
        _wc_range("long_transient", _wc_periodic()),
        sum(x > 0.02 for x in _wc_values("long_transient", _wc_periodic())), len(_wc_periodic()))),
    (MAP, lambda: "(standard errors {:.2f}–{:.2f} s⁻¹)".format(
        min(_wc_values("map", _wc_lanes("low"), "lyapunov_stderr_per_s")),
        max(_wc_values("map", _wc_lanes("low"), "lyapunov_stderr_per_s")))),
    (MAP, lambda: "their median λ₁ falls from {:.2f} s⁻¹ over 10 periods to {:.2f} over 40 and {:.3f} over 160 ({} s⁻¹). "
        "After {} transient periods the 10-period value is again {:.2f} s⁻¹".format(
            *(_wc()["summary"]["chaotic_median_lyapunov_per_s"][k] for k in ("map", "lyapunov_40", "long_lyapunov")),
            _wc_range("long_lyapunov", _wc_lanes("chaotic")), _wc()["runs"]["long_transient"]["transient_periods"],
            _wc()["summary"]["chaotic_median_lyapunov_per_s"]["long_transient"])),
    (MAP, lambda: "(λ₁ {} s⁻¹)".format(" and ".join(
        f"{_wc()['runs']['map']['lyapunov_per_s'][i]:.2f} ± {_wc()['runs']['map']['lyapunov_stderr_per_s'][i]:.2f}"
        for i in _wc_lanes("chaotic") if _wc()["runs"]["map"]["label"][i] == "chaotic"))),
    (MAP, lambda: "the band's still about {:.0f}× its 160-period value".format(
        _wc()["summary"]["chaotic_median_lyapunov_per_s"]["lyapunov_40"]
        / _wc()["summary"]["chaotic_median_lyapunov_per_s"]["long_lyapunov"])),
    (MAP, lambda: "the {} lanes take {:.1f} s with λ₁ over 10 periods and {:.1f} s over 160".format(
        len(_wc()["lanes"]), _wc()["runs"]["map"]["seconds"], _wc()["runs"]["long_lyapunov"]["seconds"])),
]

# ---- docs/orbits/README.md (scripts/orbit_check.py, duffing_cascade.py, bifurcation_grad.py, orbit_branches.py,
# celt_fold_grad.py; the census, branches and fold values are in core.py)


def _orb(name: str) -> dict:
    return _json(f"docs/orbits/{name}.json")


def _branch_seconds(key: str) -> float:
    return next(iter(_orb("branches")["branches"].values()))["seconds"][key]


QUOTES += [
    (ORBITS, lambda: "| log\\|μ_max\\|/T | {} s⁻¹ |".format(_m(_orb("orbit_check")["floquet_exponent"], ".5f"))),
    (ORBITS, lambda: "λ₁ on the orbit ({} periods, rtol 1e-10) | {} s⁻¹ ({:.2f} %) |".format(
        _orb("orbit_check")["lyapunov_periods"], _m(_orb("orbit_check")["lyapunov_lambda1"], ".5f"),
        100 * _orb("orbit_check")["lyapunov_rel_diff"])),
    (ORBITS, lambda: "times: the {} branches {:.1f} s with compilation, the scipy diagram {:.1f} s".format(
        {3: "three"}[len(_orb("duffing_cascade")["branches"])], _orb("duffing_cascade")["seconds"]["continuation_incl_compile"],
        _orb("duffing_cascade")["seconds"]["brute_force_scipy"])),
    (ORBITS, lambda: "One located point took {:.1f} s on its first call (compilation included) and {:.1f} s on a repeat call".format(
        _orb("bifurcation_grad")["seconds_locate_first_call"], _orb("bifurcation_grad")["seconds_locate_second_call"])),
    (ORBITS, lambda: "1-minute load average {:.2f}–{:.2f}): one Newton solve with the multipliers {:.2f} s; the first corrector "
        "step {:.1f} s with compilation; then a median {:.2f} s per corrector attempt; the whole branch {:.1f} s".format(
            min(min(b["load_average"]) for b in _orb("branches")["branches"].values()),
            max(max(b["load_average"]) for b in _orb("branches")["branches"].values()),
            _branch_seconds("newton_solve"), _branch_seconds("first_corrector_incl_compile"),
            _branch_seconds("median_corrector_attempt"), _branch_seconds("branch_incl_compile"))),
    (ORBITS, lambda: "(1-minute load average {:.1f} at the start and {:.1f} at the end, recorded in the file), every call "
        "compiling afresh: locate {:.0f} s, gradient {:.0f} s, the two finite-difference locates {:.0f} s.".format(
            _orb("celt_fold_grad")["load_average_start"][0], _orb("celt_fold_grad")["load_average_end"][0],
            *(_orb("celt_fold_grad")["seconds"][k] for k in ("locate_incl_compile", "grad_incl_compile", "two_fd_locates_incl_compile")))),
]

# ---- docs/paper-reproduction.md (scripts/paper_study.py, scripts/paper_figures.py; the starts, the 14 rad/s range over
# all files and the figures' times are in core.py)


def _study(tag: str) -> dict:
    return _json(f"docs/paper-reproduction/study_{tag}.json")


def _row(tag: str, ic: str, omega: float, **match) -> dict:
    return next(r for r in _study(tag)["rows"] if r["ic"] == ic and r["omega_pi"] == omega
                and all(r[k] == v for k, v in match.items()))


def _headings(omega: float, degs=None) -> list[dict]:
    rows = [r for r in _study("headings_eps1e-4")["rows"] if r["omega_pi"] == omega]
    return [r for r in rows if degs is None or float(r["ic"].removeprefix("rest psi0=").removesuffix("deg")) in degs]


def _ceil2(x: float) -> float:
    import math

    return math.ceil(100 * x) / 100


QUOTES += [
    (PAPER, lambda: "the heading study's standard error for the same lane ({:.3f} s⁻¹)".format(
        _row("headings_eps1e-4", "rest psi0=157.5deg", 17.0)["lyapunov_stderr"])),
    (PAPER, lambda: "17 rad/s at ψ0 = 90° has λ₁ = {:.2f} s⁻¹ here and {:.3f} s⁻¹ over {} periods".format(
        _row("stageA", "rest psi0=pi/2", 17.0, v_pi_sign=1.0, derivative_exact=0.0)["lyapunov"],
        _row("headings_eps1e-4", "rest psi0=90deg", 17.0)["lyapunov"], _study("headings_eps1e-4")["config"]["lyapunov"])),
    (PAPER, lambda: "give an exponent within {:.2f} s⁻¹ of zero".format(
        _ceil2(max(abs(r["lyapunov"]) for r in _headings(17.0, {90, 112.5, 135, 157.5, 270, 292.5, 315, 337.5}))))),
    (PAPER, lambda: "0°, 180° and 202.5° are {} with λ₁ of {:.2f}–{:.2f} s⁻¹".format(
        "/".join(sorted({r["allowed"] for r in _headings(17.0, {0, 180, 202.5})})),
        min(r["lyapunov"] for r in _headings(17.0, {0, 180, 202.5})),
        max(r["lyapunov"] for r in _headings(17.0, {0, 180, 202.5})))),
    (PAPER, lambda: "At 14 rad/s every heading is {} (λ₁ = {:.2f}–{:.2f} s⁻¹)".format(
        " or ".join(sorted({r["allowed"] for r in _headings(14.0)})),
        min(r["lyapunov"] for r in _headings(14.0)), max(r["lyapunov"] for r in _headings(14.0)))),
    (PAPER, lambda: "{:.2f}–{:.2f} s⁻¹ in the heading study B".format(
        min(r["lyapunov"] for r in _headings(14.0)), max(r["lyapunov"] for r in _headings(14.0)))),
    (PAPER, lambda: "transient {} periods (≈ {:.0f}–{:.0f} s of motion)".format(
        _study("long2000")["config"]["transient"],
        *(round(_study("long2000")["config"]["transient"] * 2 * 3.141592653589793 / w, -1)
          for w in (max(r["omega_pi"] for r in _study("long2000")["rows"]), min(r["omega_pi"] for r in _study("long2000")["rows"]))))),
    (PAPER, lambda: "The 17 rad/s motion of B (λ₁ ≈ {:.3f} s⁻¹, {})".format(
        _row("headings_eps1e-4", "rest psi0=157.5deg", 17.0)["lyapunov"], _row("headings_eps1e-4", "rest psi0=157.5deg", 17.0)["allowed"])),
    (PAPER, lambda: "| 14 | not periodic ({} in study B, λ₁ ≈ {:.1f} s⁻¹), bounded |".format(
        _row("headings_eps1e-4", "rest psi0=157.5deg", 14.0)["allowed"], _row("headings_eps1e-4", "rest psi0=157.5deg", 14.0)["lyapunov"])),
    (PAPER, lambda: "a threshold of {:.3f} s⁻¹ on the point estimate".format(
        _json("docs/paper-reproduction/figures_psi157.5.json")["chaos_threshold"])),
]

# inputs, not results: the labelling rule's thresholds and the period detector's tolerance
SETTINGS = [
    (MAP, "λ₁ − 2 s.e. > 0.02 s⁻¹"),
    (LABELS, "λ₁ − 2 s.e. > 0.02 s⁻¹"),
    (LABELS, "λ₁ + 2 s.e. < −0.02 s⁻¹"),
    (LABELS, "the interval λ₁ ± 2 s.e. reaches across +0.02 or −0.02 s⁻¹"),
    (LABELS, "within 1e-4 × (1 + max |x|) of sample"),
    (LABELS, "**0.02 s⁻¹** — the threshold"),
    (PAPER, "from λ₁ ± 2 standard errors against 0.02 s⁻¹"),
]


# ---- docs/map/README.md: the map's load, the window check's lanes, the diagram's band it meets


def _wc_box(group: str) -> str:
    lanes = [_wc()["lanes"][i] for i in _wc_lanes(group)]
    w = [x["omega_pi"] for x in lanes]
    q = [x["q_pi"] for x in lanes]
    return f"ω_π {min(w):g}–{max(w):g} rad/s, q_π {min(q):.3f}–{max(q):.3f} m"


def _diagram_band() -> dict:
    """The 400 x 300 diagram's longest run of valid lanes (summary_400x300.json)."""
    runs = _json("docs/bifurcation/summary_400x300.json")["regimes"]
    return max((r for r in runs if not r["label"].startswith("invalid")), key=lambda r: r["n"])


QUOTES += [
    (MAP, lambda: "(load average {:.2f} at the start, {:.1f} at the end; both in the JSON)".format(
        _map()["load_average_before_after"][0][0], _map()["load_average_before_after"][1][0])),
    (MAP, lambda: "runs {} lanes of the lower left ({}) and {} of the band at {}".format(
        len(_wc_lanes("low")), _wc_box("low"), len(_wc_lanes("chaotic")), _wc_box("chaotic").replace("ω_π ", ""))),
    (MAP, lambda: "at q_π = 0.04 m this is the band the bifurcation diagram shows at {:.1f}–{:.1f} rad/s".format(
        _diagram_band()["from"], _diagram_band()["to"])),
]

# the map's grid (its command line)
SETTINGS += [
    (MAP, "--y q_pi=0.02:0.06:60"),
    (MAP, "60 amplitudes 0.02–0.06 m"),
]


def _stable_omega2(w: str) -> float:
    return next(o for o in _orb("branches")["paper_frequencies"][w] if o["stable"])["omega2"]


def _b_drift() -> str:
    """The period-1 lanes of study B at 15.6 rad/s: net drift of O below the quoted bound."""
    drift = max(r["drift_m"] for r in _headings(15.6) if r["allowed"].startswith("period"))
    if drift >= 1e-4:
        raise AssertionError(f"drift {drift} m is not below 0.1 mm")
    return "|Δr_O| < 0.1 mm over {} periods".format(_study("headings_eps1e-4")["config"]["sample"])


QUOTES += [
    (PAPER, lambda: "(the orbit of `branches.json` has ω₂ = {} rad/s on the section there)".format(
        _m(_stable_omega2("15.6"), ".2f"))),
    (PAPER, _b_drift),
    ("notebooks/06_periodic_orbits.ipynb",
     lambda: "loses stability in a Neimark–Sacker bifurcation near {:.1f} rad/s".format(_bifs()["Neimark-Sacker"]["value"])),
]

SETTINGS += [
    ("notebooks/06_periodic_orbits.ipynb", "ψ0 = 157.5°"),
    ("notebooks/02_bifurcation.ipynb", "from rest at ψ0 = 157.5°"),
]
