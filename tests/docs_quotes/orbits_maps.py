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
    (MAP, lambda: f"lie up to {_wc_bias()[0]:.1f} s⁻¹ from their 160-period values"),
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


# ---- docs/orbits/README.md, whole rows and sentences (scripts/periodic_known_answers.py, orbit_check.py,
# attractor_census.py, duffing_cascade.py, bifurcation_grad.py, orbit_branches.py, celt_fold_grad.py)


def _e(x: float, digits: int = 1) -> str:
    """An error as the orbits page prints it: 1.4e-13, 5.2e-9 (no leading zero in the exponent)."""
    return format(x, f".{digits}e").replace("e-0", "e-").replace("e+0", "e+")


def _ka() -> dict:
    return _orb("known_answers")


def _oc() -> dict:
    return _orb("orbit_check")


def _pairs(mu: list[float]) -> str:
    """|μ| in decreasing order, equal neighbours (a complex pair) written once with '(pair)'."""
    out, i = [], 0
    while i < len(mu):
        if i + 1 < len(mu) and abs(mu[i] - mu[i + 1]) < 1e-12:
            out.append(f"{mu[i]:.4f} (pair)")
            i += 2
        else:
            out.append(f"{mu[i]:.4f}")
            i += 1
    return ", ".join(out)


def _census_row(w: str) -> str:
    """A row of the census table, as scripts/attractor_census.py --table prints it."""
    import math

    r = _orb("census")["results"][w]
    per = [
        f"period-{a['k']}, {math.degrees(a['state'][12]) % 360:.1f}°, {a['fraction']:.3f}, {a['multipliers'][0]:.4f}"
        for a in r["attractors"] if a["kind"] == "periodic"
    ]
    frac = {a["kind"]: a["fraction"] for a in r["attractors"] if a["kind"] != "periodic"}
    return (f"| {w} | {r['n_lanes']} | {'; '.join(per) or 'none'} | {frac.get('aperiodic', 0.0):.3f} "
            f"| {frac.get('invalid', 0.0):.3f} | {r['wall_s']:.0f} |")


def _pd(i: int) -> dict:
    return _orb("duffing_cascade")["period_doublings"][i]


def _pd_periods(i: int) -> str:
    (below,), (above,) = {*_pd(i)["brute_force_periods_below"]}, {*_pd(i)["brute_force_periods_above"]}
    return f"{below} / {above}"


def _bg() -> dict:
    return _orb("bifurcation_grad")


def _bifs() -> dict:
    return {b["kind"]: b for b in next(iter(_orb("branches")["branches"].values()))["branch"]["bifurcations"]}


def _paper_freq(w: str) -> list[float]:
    """Largest |μ| of the family's orbits at a paper frequency: (stable, saddle)."""
    orbits = _orb("branches")["paper_frequencies"][w]
    stable = [o for o in orbits if o["multipliers_abs"][0] < 1.5]
    saddle = [o for o in orbits if o["multipliers_abs"][0] >= 1.5]
    return [stable[0]["multipliers_abs"][0], saddle[0]["multipliers_abs"][0]]


def _ns_multiplier() -> complex:
    re, im = max(_bifs()["Neimark-Sacker"]["multipliers"], key=lambda m: m[1])
    return complex(re, im)


def _cf() -> dict:
    return _orb("celt_fold_grad")


QUOTES += [
    (ORBITS, lambda: "| analytic steady state / exp((−δ/2 ± iω_d)T) | {} / {} |".format(
        _e(_ka()["linear"]["orbit_max_error"]), _e(_ka()["linear"]["multiplier_max_error"]))),
    (ORBITS, lambda: "| Ince–Strutt series to q⁵ | b1: {} (first omitted term 49q⁶/589824: {}) |".format(
        ", ".join(_e(x) for x in _ka()["mathieu"]["b1_minus_series"]),
        ", ".join(_e(x) for x in _ka()["mathieu"]["first_omitted_term_49q6_over_589824"]))),
    (ORBITS, lambda: "| scipy DOP853 after 80 periods / det M = exp(−δT) | {} / {} |".format(
        _e(_ka()["duffing"]["orbit_max_error_vs_scipy"]), _e(_ka()["duffing"]["det_minus_exp_dT"]))),
    (ORBITS, lambda: "give the Newton guess ({} from the orbit; one Newton step)".format(_e(_oc()["guess_distance"]))
        if _oc()["newton_steps"] == 1 else "?"),
    (ORBITS, lambda: f"| periodicity residual (chart coordinates) | {_e(_oc()['residual'])} |"),
    (ORBITS, lambda: "| physical multipliers \\|μ\\| | {} |".format(_pairs(_oc()["multipliers_abs"]))),
    (ORBITS, lambda: "| trivial multipliers | {} |".format(", ".join(
        "1" if x == 1.0 else f"1 − {_e(1 - x, 0)}" for x in _oc()["trivial_multipliers_abs"]))),
    (ORBITS, lambda: "| drift of C per period | {} m (bounded period-1) |".format(
        _e(max(abs(d) for d in _oc()["drift_m"]), 0)) if _oc()["psi_turns"] == 0 else "?"),
    (ORBITS, lambda: "(central differences, DOP853 rtol 1e-12) | {} |".format(_e(_oc()["multiplier_max_abs_diff_vs_scipy_fd"]))),
    (ORBITS, lambda: "| defect of the orbit in the reference model | {} |".format(_e(_oc()["reference_fd_defect"]))),
    *[(ORBITS, (lambda w=w: _census_row(w))) for w in ("14", "15.6", "17", "19")],
    (ORBITS, lambda: "| 1 → 2 | {:.7f} | {} | {:.7f} ({} from F_PD; grid step 1e-4) |".format(
        _pd(0)["F_pd"], _pd_periods(0), _pd(0)["brute_force_onset"], _e(_pd(0)["onset_difference"]))),
    (ORBITS, lambda: "| 2 → 4 | {:.7f} | {} | {} from F_PD |".format(
        _pd(1)["F_pd"], _pd_periods(1), _e(_pd(1)["onset_difference"]))),
    (ORBITS, lambda: "| 4 → 8 | {:.7f} | {} | (window too narrow for the fit) |".format(
        _pd(2)["F_pd"], _pd_periods(2)) if "brute_force_onset" not in _pd(2) else "?"),
    (ORBITS, lambda: "F_PD = {:.7f} ({} Newton steps, residual {}, multipliers {} and {}), and dF_PD/dδ = {:.10f} by".format(
        _bg()["F_pd"], _bg()["newton_steps"], _e(_bg()["residual"]),
        _m(_bg()["multipliers"][0][0], ".11f"), _m(_bg()["multipliers"][1][0], ".4f"), _bg()["dF_pd_ddelta_grad"])),
    (ORBITS, lambda: "{:.10f} by central differences of the located point (step 1e-4): relative difference {}.".format(
        _bg()["dF_pd_ddelta_fd"], _e(_bg()["relative_difference"]))),
    (ORBITS, lambda: "the family does not extend below its fold near {:.2f} rad/s.".format(_bifs()["fold"]["value"])),
    (ORBITS, lambda: "interpolated between points {:.3f} apart | a real multiplier through +1 (the other sheet: a real "
        "multiplier {:.4f} at 15.6 rad/s) |".format(
            _bifs()["fold"]["bracket"][1] - _bifs()["fold"]["bracket"][0], _paper_freq("15.6")[1])),
    (ORBITS, lambda: "| \\|μ\\| = 1 − {}, μ = {:.4f} ± {:.4f}i (rotation {:.3f} rad per period) |".format(
        _e(1 - abs(_ns_multiplier()), 0), _ns_multiplier().real, _ns_multiplier().imag,
        __import__("cmath").phase(_ns_multiplier()))),
    (ORBITS, lambda: "saddle all the way to 20 rad/s, and past {:.4f} rad/s the orbit itself is unstable".format(
        _bifs()["Neimark-Sacker"]["value"])),
    (ORBITS, lambda: "The two branches of the mirror pair have the same bifurcations to {} in ω_π".format(
        _e(_orb("branches")["mirror_check"]["max_bifurcation_value_difference"])) if _orb("branches")["mirror_check"]["same_kinds"] else "?"),
    (ORBITS, lambda: "| 15.6 | stable; saddle | {:.4f}; {:.4f} |".format(*_paper_freq("15.6"))),
    (ORBITS, lambda: "| 19 | unstable (past the Neimark–Sacker point); saddle | {:.4f}; {:.4f} |".format(*_paper_freq("19.0"))),
    (ORBITS, lambda: "a disturbance shrinks by {:.4f} per period, by a factor e only after about {:.0f} periods".format(
        _paper_freq("17.0")[0], round(-1 / __import__("math").log(_paper_freq("17.0")[0]), -1))),
    (ORBITS, lambda: "the fold the continuation interpolated ({:.6f} rad/s): ω_fold = {:.6f} rad/s after {} Newton steps "
        "(residual {}, largest multiplier 1 − {}, the next {:.4f}).".format(
            _cf()["omega_fold_continuation"], _cf()["omega_fold"], _cf()["newton_steps"], _e(_cf()["residual"]),
            _e(1 - _cf()["multipliers_abs"][0]), _cf()["multipliers_abs"][1])),
    (ORBITS, lambda: "dω_fold/dμ = {} rad/s, against central differences of the located fold (step 1e-4): {}, relative "
        "difference {}.".format(_m(_cf()["domega_fold_dmu_grad"], ".7f"), _m(_cf()["domega_fold_dmu_fd"], ".7f"),
                                _e(_cf()["relative_difference"]))),
]

# the test problems' equations and the brute-force diagram's range are inputs; so is Feigenbaum's constant, which
# scripts/duffing_cascade.py uses to size the window of the next doubling
SETTINGS += [
    (ORBITS, "linear oscillator x'' + 0.3x' + 2.25x = 0.7 cos 2.1t"),
    (ORBITS, "Mathieu tongue edges b1(q), a1(q), q = 0.1, 0.2, 0.4"),
    (ORBITS, "Duffing x'' + 0.25x' + x + 0.5x³ = 0.3 cos 1.3t"),
    (ORBITS, "x'' + 0.3x' − x + x³ = F cos 1.2t is continued in F from 0.24"),
    (ORBITS, "383 values of F in [0.255, 0.2932]"),
    (ORBITS, "(Feigenbaum's limit 4.669)"),
    (ORBITS, "x'' + δx' − x + x³ = F cos 1.2t, δ = 0.3"),
    (ORBITS, "arclength steps 0.05–0.3"),
    (ORBITS, "ψ0 = 157.5°"),
]


# ---- docs/paper-reproduction.md, whole rows and sentences (scripts/paper_study.py; the branch values from
# scripts/orbit_branches.py)


def _hd(ic: str) -> float:
    """The start heading in degrees from a study row's initial condition ('rest psi0=22.5deg')."""
    return float(ic.removeprefix("rest psi0=").removesuffix("deg"))


def _deg(x: float) -> str:
    return f"{x:g}°"


def _tab(tag: str) -> list[dict]:
    return _study(tag)["table"]


def _cell(label: str, lam: bool = False) -> str:
    """A table cell from the study's label 'chaotic, bounded, λ=0.284': with its λ₁ in brackets when asked."""
    text, _, value = label.rpartition(", λ=")
    return f"{text} (λ₁ {value})" if lam else text


_W = ("14.0", "15.6", "17.0", "19.0")


def _heading_row(t: dict) -> str:
    return "| {} | {} | {} / {} |".format(
        _deg(_hd(t["ic"])), " | ".join(_cell(t["labels"][w]) for w in _W), t["score_strict"], t["score_allowed"])


def _heading_table_row(deg: float) -> str:
    return _heading_row(next(t for t in _tab("headings_eps1e-4") if _hd(t["ic"]) == deg))


def _eps_row(tag: str, eps: float, deg: float) -> str:
    t = next(t for t in _tab(tag) if t["eps"] == eps and _hd(t["ic"]) == deg)
    lam = deg == 157.5
    return "| {:g} | {} | {} | {} / {} |".format(
        eps, _deg(deg), " | ".join(_cell(t["labels"][w], lam) for w in _W), t["score_strict"], t["score_allowed"])


def _b_set(omega: float, pred) -> set[float]:
    """Headings of study B whose lane at omega satisfies pred(row)."""
    return {_hd(r["ic"]) for r in _study("headings_eps1e-4")["rows"] if r["omega_pi"] == omega and pred(r)}


def _and_mirror(lo: float, hi: float) -> set[float]:
    """Headings lo..hi of the 22.5° grid and their images under +180°."""
    grid = [22.5 * i for i in range(16)]
    return {h for h in grid if lo <= h <= hi} | {h + 180 for h in grid if lo <= h <= hi}


def _check(found: set[float], expected: set[float], text: str) -> str:
    if found != expected:
        raise AssertionError(f"study B gives {sorted(found)}, the text says {sorted(expected)}")
    return text


def _b_period1() -> str:
    p1 = _b_set(15.6, lambda r: r["allowed"].startswith("period"))
    lo, hi = min(p1), max(h for h in p1 if h < 180)
    inv = sorted(h for h in p1 if h < 180 and h in _b_set(15.6, lambda r: r["strict"] == "invalid"))
    return _check(p1, _and_mirror(lo, hi),
                  "Headings ψ0 = {}–{} (and +180°) give a period-1 motion at 15.6 rad/s (at {} after leaving the model's "
                  "validity)".format(_deg(lo), _deg(hi), " and ".join(_deg(h) for h in inv)))


def _b_tip156() -> str:
    tip = _b_set(15.6, lambda r: r["strict"] == "invalid" and not r["allowed"].startswith("period"))
    lo, hi = min(h for h in tip if h % 180), max(h for h in tip if h < 180)
    return _check(tip, {0.0, 180.0} | _and_mirror(lo, hi),
                  f"the headings along the vibration (ψ0 = 0°, 180°) and {_deg(lo)}–{_deg(hi)} (and +180°) tip past 90° at 15.6 rad/s")


def _b_near_zero17() -> str:
    near = {_hd(r["ic"]) for r in _headings(17.0) if abs(r["lyapunov"]) < 0.01 and r["allowed"] == "uncertain"}
    lo, hi = min(near), max(h for h in near if h < 180)
    return _check(near, _and_mirror(lo, hi), "At 17 rad/s the headings {}–{} (and +180°) give an exponent within {:.2f} s⁻¹ "
                  "of zero".format(_deg(lo), _deg(hi), _ceil2(max(abs(r["lyapunov"]) for r in _headings(17.0, near)))))


def _b_valid19() -> str:
    valid = _b_set(19.0, lambda r: r["strict"] != "invalid")
    a = sorted(h for h in valid if h < 180)
    kinds = {r["allowed"] for r in _headings(19.0) if r["strict"] != "invalid"}
    bounded = {r["global_motion"] for r in _headings(19.0) if r["strict"] != "invalid"}
    return _check(valid, _and_mirror(a[0], a[-1]), "except {}–{} and {}–{}, which stay valid with a {}, {} motion".format(
        _deg(a[0]), _deg(a[-1]), _deg(a[0] + 180), _deg(a[-1] + 180), "/".join(sorted(bounded)), "/".join(sorted(kinds))))


def _long_row() -> str:
    t = next(t for t in _tab("long2000") if _hd(t["ic"]) == 157.5)
    c = [_cell(t["labels"][w]) for w in _W]
    lam14 = float(t["labels"]["14.0"].rpartition("λ=")[2])
    first, rest = c[2].split(", ", 1)
    return f"| 157.5° | {c[0]} (λ₁ {lam14:.2f}) | {c[1]} | **{first}**, {rest} | {c[3]} |"


QUOTES += [
    (PAPER, lambda: "is born in a fold at {:.2f} rad/s".format(_bifs()["fold"]["value"])),
    (PAPER, lambda: "stable but weakly so there (largest multiplier {:.4f} per period), which loses stability in a "
        "Neimark–Sacker bifurcation at {:.2f} rad/s".format(_paper_freq("17.0")[0], _bifs()["Neimark-Sacker"]["value"])),
    *[(PAPER, (lambda d=22.5 * i: _heading_table_row(d))) for i in range(16)],
    (PAPER, _b_period1),
    (PAPER, _b_tip156),
    (PAPER, _b_near_zero17),
    (PAPER, _b_valid19),
    (PAPER, _long_row),
    *[(PAPER, (lambda a=a: _eps_row(*a))) for a in (
        ("eps_large", 0.01, 157.5), ("eps_large", 0.01, 0.0), ("eps_large", 0.001, 157.5), ("eps_large", 0.001, 0.0),
        ("headings_eps1e-4", 0.0001, 157.5), ("headings_eps1e-4", 0.0001, 0.0),
        ("eps1e-6", 1e-06, 157.5), ("eps1e-6", 1e-06, 0.0), ("eps1e-8", 1e-08, 157.5), ("eps1e-8", 1e-08, 0.0))],
]

# the start headings and the sets of them each study ran are inputs
SETTINGS += [
    (PAPER, "ψ0 = 157.5°"),
    (PAPER, "its long axis x1 turned 22.5° from the vibration direction"),
    (PAPER, "16 headings ψ0 = 0°, 22.5°, …, 337.5°"),
    (PAPER, "ψ0 ∈ {0°, 90°, 157.5°}"),
    (PAPER, "ψ0 ∈ {0°, 135°, 157.5°}"),
    (PAPER, "ψ0 ∈ {0°, 157.5°}"),
    (PAPER, "each of their 157.5° scores"),
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
