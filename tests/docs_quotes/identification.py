"""Quoted texts of the identification pages (docs/identification.md, docs/how-to/fit-recording.md, notebook 04),
each computed from the result file under docs/fit/ it comes from.

Writers: benchmarks/bench_fit.py (bench_fit.json), benchmarks/fit_records_parallel.py (records_parallel.json),
benchmarks/fit_compile_parts.py (compile_parts.json), benchmarks/bench_multistart.py (multistart.json),
scripts/fit_sensor_study.py (sensor_study.json), scripts/fit_study.py (recover, coverage, chaos_*, compare).
"""

from __future__ import annotations

import statistics
from decimal import ROUND_HALF_UP, Decimal

from .files import _json

D = "docs/identification.md"
HOW = "docs/how-to/fit-recording.md"
NB = "notebooks/04_identification.ipynb"
NAMES = ("mu", "k_r", "b_Ts", "m_Ts")
GREEK = {"mu": "μ", "k_r": "k_r", "b_Ts": "b_Ts", "m_Ts": "m_Ts"}


def _minus(s: str) -> str:
    return s.replace("-", "−")


def _sp(n: int) -> str:
    return f"{n:,}".replace(",", " ")


def _bf(problem: str, optimiser: str, noise: float = 0.0, cache: str = "off") -> dict:
    """A row of bench_fit.json; cache "off", "cold" (the process that fills it) or "warm" (the 2nd process)."""
    rows = [
        r for r in _json("docs/fit/bench_fit.json")["rows"] if r["problem"] == problem and r["optimiser"] == optimiser
    ]
    rows = [r for r in rows if r["noise"] == noise]
    if cache == "off":
        return next(r for r in rows if not r["persistent_cache"])
    cached = [r for r in rows if r["persistent_cache"]]
    return cached[0] if cache == "cold" else cached[1]


def _offsets() -> dict:
    """The records' true parameters relative to the paper's values (every fit's start), in percent."""
    d = _json("docs/fit/recover.json")
    return {n: 100 * (d["true"][n] / d["start"][n] - 1) for n in NAMES}


def _offset_range() -> str:
    o = [abs(v) for v in _offsets().values()]
    return f"{min(o):.0f}–{max(o):.0f}"


def _signed_offsets() -> str:
    return ", ".join(f"{GREEK[n]} {_minus(f'{v:+.0f}')}%" for n, v in _offsets().items())


def _true_values() -> str:
    d = _json("docs/fit/recover.json")

    def r4(x):
        return str(Decimal(repr(x)).quantize(Decimal("0.0001"), ROUND_HALF_UP))

    return ", ".join(f"{GREEK[n]} = {r4(d['true'][n])} ({_minus(f'{v:+.0f}')}%)" for n, v in _offsets().items())


def _records_parallel() -> str:
    b = _json("docs/fit/records_parallel.json")["best_s"]
    return (
        f"below takes {1000 * b['threads']:.0f} ms, against {1000 * b['one_program_lax_map']:.0f} ms for the all-records "
        f"program and {1000 * b['records_in_turn']:.0f} ms for the records in turn"
    )


def _compile_parts() -> str:
    m = _json("docs/fit/compile_parts.json")["modes"]
    new, old = m["nan-options"]["first_process"], m["nan"]["first_process"]
    return (
        f"the two-record program compiles in {new['compile_s']:.1f} s instead of {old['compile_s']:.1f} s and runs as "
        f"fast (best warm run {1000 * new['run_best_of_10_s']:.0f} ms against {1000 * old['run_best_of_10_s']:.0f} ms); "
        f"tracing and lowering it take {new['trace_lower_s']:.1f} s"
    )


def _lm_4p() -> str:
    r0, r1 = _bf("4p", "lm"), _bf("4p", "lm", 0.01)
    return (
        f"converges in {r0['n_iter']} iterations to {r0['max_rel_err_vs_true']:.2g} (noise-free) and to the least-squares "
        f"optimum with {100 * r1['noise']:g} % noise ({100 * r1['max_rel_err_vs_true']:.2f} % off the truth"
    )


def _lm_cold() -> str:
    r = _bf("4p", "lm", 0.0, "cold")
    return (
        f"**{r['call_total_s']:.1f} s, of which {r['compile_s']:.1f} s compilation and {r['run_s']:.1f} s of iterations"
    )


def _lm_warm() -> str:
    r = _bf("4p", "lm", 0.0, "warm")
    return f"{r['call_total_s']:.1f} s including what is still compiled ({r['compile_s']:.1f} s: the optimiser's own programs)"


def _lbfgs_4p() -> str:
    r, r1, lm = _bf("4p", "lbfgs"), _bf("4p", "lbfgs", 0.01), _bf("4p", "lm")
    same = f"{r1['max_rel_err_vs_true']:.2g}" == f"{_bf('4p', 'lm', 0.01)['max_rel_err_vs_true']:.2g}"
    return (
        f"in {r['n_iter']} iterations to the same values as LM ({r['max_rel_err_vs_true']:.2g}; the same "
        f"{100 * r1['noise']:g} %-noise optimum{'' if same else ' (differs)'}), cold total {r['call_total_s']:.1f} s — "
        f"{r['call_total_s'] / lm['call_total_s']:.1f}× LM's"
    )


def _lbfgs_chaos() -> str:
    r, lm = _bf("chaos", "lbfgs"), _bf("chaos", "lm")
    return f"it reaches LM's values in {r['n_iter']} iterations ({r['call_total_s']:.1f} s against LM's {lm['call_total_s']:.1f} s)"


def _lbfgs_release() -> str:
    r, lm = _bf("release", "lbfgs"), _bf("release", "lm")
    caps = {s["n_iter"] for s in r["stages"]}
    return (
        f"it stops at its {'/'.join(map(str, sorted(caps)))}-iteration cap per stage, {r['max_rel_err_vs_true']:.2g} off, "
        f"in {r['call_total_s']:.0f} s; LM needs {lm['n_iter']} iterations there"
    )


def _adam_4p() -> str:
    r = _bf("4p", "adam")
    return f"with {r['n_iter']} iterations it leaves the worst parameter {100 * r['max_rel_err_vs_true']:.0f} % off"


def _adam_long() -> str:
    r = _bf("adam-long", "adam")
    h = r["max_rel_err_every_100"]
    return (
        f"given {_sp(r['max_iter'])} (`adam-long`) the schedule converges — the gradient test stops it after {r['n_iter']} "
        f"iterations, {r['max_rel_err_vs_true']:.2g} off, in {r['call_total_s']:.0f} s (worst error every 100 iterations "
        f"in the JSON: {h[3]:.1e} after {_sp(300)}, {h[10]:.1e} after {_sp(1000)})"
    )


def _adam_vs_lm() -> str:
    return f"LM's Gauss–Newton steps win by {_bf('adam-long', 'adam')['call_total_s'] / _bf('4p', 'lm')['call_total_s']:.0f}×"


def _chaos_shooting() -> str:
    lm, gn, adam = _bf("chaos", "lm"), _bf("chaos", "gn-damped"), _bf("chaos", "adam")

    def short(r):
        return f"{r['max_rel_err_vs_true']:.2g} ({r['n_iter']} iterations each, {r['call_total_s']:.1f} s each)"

    both = short(lm) if short(lm) == short(gn) else f"{short(gn)} / {short(lm)}"
    return (
        f"damped Gauss–Newton and LM both converge to {both}; Adam is {100 * adam['max_rel_err_vs_true']:.1f} % off "
        f"after {adam['n_iter']} iterations"
    )


def _multistart() -> str:
    ms = {r["mode"]: r for r in _json("docs/fit/multistart.json")["rows"]}
    v, s = ms["vmapped"], ms["sequential"]
    same = v["n_at_best"] == s["n_at_best"]
    spread = max(max(r["spread_rel"].values()) for r in (v, s))
    return (
        f"vmapped: compile {v['compile_s']:.1f} s, run {v['run_s']:.1f} s; sequential: compile {s['compile_s']:.1f} s, "
        f"run {s['run_s']:.1f} s. Both find the same optimum{'' if same else ' (not)'}: {v['n_at_best']} of "
        f"{v['n_starts']} starts reach the best loss (spread of the fitted values over them ≤ {spread:.2g} relative), and "
        f"one stops in a local minimum (loss {max(v['loss']):.0f} against {min(v['loss']):.1f})"
    )


def _sensor_truth() -> str:
    t = _json("docs/fit/sensor_study.json")["truth"]
    rot = ", ".join(_minus(f"{x:g}") for x in t["rotation_vector"])
    off = " and ".join(_minus(f"{1000 * x:.0f}") + " ms" for x in t["time_offset"])
    rel = t["releases"]
    tilts = " and ".join(f"{r['tilt']:.0f}°" for r in rel)
    spins = " and ".join(_minus(f"{r['spin']:+.0f}") for r in rel)
    heads = " and ".join(_minus(f"{r['heading']:g}") for r in rel)
    return (
        f"in sensor axes rotated by ({rot}) rad, time offsets {off}; releases tilted {tilts}, spinning {spins} rad/s, "
        f"headings {heads} rad"
    )


def _sensor_results() -> str:
    d = _json("docs/fit/sensor_study.json")
    s = d["summary"]
    med = ", ".join(f"{n} {100 * s[n]['median_rel_err']:.2f} %" for n in NAMES)
    cov = ", ".join(f"{n} {100 * s[n]['coverage']:.0f} %" for n in NAMES)
    conv = ", ".join(f"{n} {100 * s['coverage_over_converged'][n]:.0f} %" for n in NAMES)
    return (
        f"Over {s['seeds']} noise seeds {s['converged']} fits converge. Median relative errors: {med}; 95 % intervals "
        f"cover the truth in {cov} of the seeds (of the converged fits: {conv}); the rotation vector's components "
        f"{100 * s['rotation']['coverage']:.0f} % and the offsets {100 * s['time_offset']['coverage']:.0f} %."
    )


def _sensor_failed() -> str:
    d = _json("docs/fit/sensor_study.json")
    bad = [r for r in d["rows"] if not r["converged"]]
    r = bad[0]
    worst = max(NAMES, key=lambda n: r["rel_err"][n])
    return (
        f"The fit that does not converge (seed {r['seed']}, the iteration cap of {r['n_iter']}) says so: "
        f"s² = {r['s2']:.0f} instead of ≈ 1, {worst} {100 * r['rel_err'][worst]:.0f} % off"
        + ("" if len(bad) == 1 else " (more than one)")
    )


def _sensor_whole() -> str:
    w = _json("docs/fit/sensor_study.json")["whole_record_fit_seed0"]
    zero = "b_Ts driven to zero" if w["values"]["b_Ts"] < 1e-12 else "b_Ts not at zero"
    return f"(s² = {w['s2']:.0f}; {zero}, m_Ts {100 * w['rel_err']['m_Ts']:.0f} % off)"


def _coverage() -> dict:
    return _json("docs/fit/coverage.json")


def _coverage_runs() -> str:
    rows = _coverage()["rows"]
    run = [r["run_s"] for r in rows]
    return (
        f"median {statistics.median(r['n_iter'] for r in rows):g} iterations and {statistics.median(run):.0f} s of "
        f"iterations per fit on the loaded machine ({min(run):.0f}–{max(run):.0f} s); all "
        f"{sum(r['converged'] for r in rows)} converged; mean s² = {statistics.mean(r['s2'] for r in rows):.2f}"
    )


def _coverage_row(name: str) -> str:
    d = _coverage()
    n = d["seeds"]
    c = d["per_parameter_coverage"][name] if name != "all" else d["joint_all_four_inside"]
    label = "all four at once" if name == "all" else GREEK[name]
    return f"| {label} | {round(c * n)}/{n} = {100 * c:.0f}% |"


def _coverage_span() -> str:
    d = _coverage()
    c = d["per_parameter_coverage"].values()
    lo, hi = 100 * min(c), 100 * max(c)
    return f"so {lo:.0f}–{hi:.0f}% is consistent with nominal coverage — {d['seeds']} seeds cannot tell {lo:.0f}% from {hi:.0f}%"


def _chaos_gnd_single() -> str:
    e = _json("docs/fit/chaos_single_gnd.json")["row"]["rel_err"]
    others = [e[n] for n in NAMES if n != "b_Ts"]
    return (
        f"b_Ts happens to be within {100 * e['b_Ts']:.1f}%, the other three are "
        f"{100 * min(others):.0f}–{100 * max(others):.0f}% off"
    )


def _chaos_multiple_below() -> str:
    d = _json("docs/fit/chaos_multiple_gnd.json")
    truth, hist = d["truth"], d["row"]["param_history"]
    worst = [max(abs(h[n] / truth[n] - 1) for n in NAMES) for h in hist]
    k = next(i for i in range(len(worst)) if all(w < 0.01 for w in worst[i:]))
    return f"converges in {d['row']['n_iter']} iterations; every parameter is below 1% from iteration {k} on"


def _gradnorm_near() -> str:
    """The gradient-norm table's second point, relative to the record's truth (the paper's values)."""
    truth = _json("docs/fit/chaos_single.json")["truth"]
    near = _json("docs/fit/gradnorm.json")["points"]["near"]["params"]
    off = {round(100 * abs(near[n] / truth[n] - 1)) for n in NAMES}
    return f"| {'/'.join(map(str, sorted(off)))}% off the truth |"


def _compare(label: str) -> dict:
    return next(r for r in _json("docs/fit/compare.json")["rows"] if r["label"] == label)


def _compare_lm() -> str:
    r = _compare("lm")
    worst = max(NAMES, key=lambda n: r["rel_err"][n])
    return f"max relative error {100 * r['max_rel_err']:.1f}% = {worst}, inside its 95% interval"


def _compare_se() -> str:
    r = _compare("lm")
    se = {n: 100 * r["stderr"][n] / r["values"][n] for n in NAMES}
    return f"relative standard errors {se['mu']:.2f}% for μ vs {se['b_Ts']:.0f}% for b_Ts"


def _compare_adam() -> str:
    a, lm = _compare("adam"), _compare("lm")
    return (
        f"reaches loss {a['loss']:.0f} (LM's optimum: {lm['loss']:.1f}) in its {a['n_iter']} iterations "
        f"({a['run_s']:.0f} s) and is still creeping (`compare_loss.png`); b_Ts is {100 * a['rel_err']['b_Ts']:.0f}% off"
    )


QUOTES = [
    # what a fit compiles: records in threads (benchmarks/fit_records_parallel.py)
    (D, _records_parallel),
    # bench_fit.json (benchmarks/bench_fit.py)
    (D, lambda: f"can store), {_bf('4p', 'lm', 0.0, 'warm')['compile_s']:.1f} s in the benchmark below"),
    (D, _lm_4p),
    (D, _lm_cold),
    (D, _lm_warm),
    (D, _lbfgs_4p),
    (D, _lbfgs_chaos),
    (D, _lbfgs_release),
    (D, _adam_4p),
    (D, _adam_long),
    (D, _adam_vs_lm),
    (D, _chaos_shooting),
    # XLA's loop emitters for the evaluation program (benchmarks/fit_compile_parts.py)
    (D, _compile_parts),
    # several starts (benchmarks/bench_multistart.py)
    (D, _multistart),
    # sensor axes, time offsets and the release (scripts/fit_sensor_study.py)
    (D, _sensor_truth),
    (D, _sensor_results),
    (D, _sensor_failed),
    (D, lambda: f"after compilation {_json('docs/fit/sensor_study.json')['summary']['run_s_median']:.1f} s"),
    (D, _sensor_whole),
    # the record (scripts/fit_study.py: recover.json)
    (D, lambda: f"True parameters: {_true_values()}; start: the paper's values"),
    (D, lambda: f"TRUE values of §1–2 ({_signed_offsets()} off this truth)"),
    # coverage (fit_study.py --only coverage)
    (D, _coverage_runs),
    *((D, (lambda n=n: _coverage_row(n))) for n in (*NAMES, "all")),
    (D, lambda: f"The joint rate {100 * _coverage()['joint_all_four_inside']:.0f}%"),
    (D, _coverage_span),
    # the chaotic record (fit_study.py: chaos_*.json)
    (D, _chaos_multiple_below),
    (D, _chaos_gnd_single),
    (D, lambda: f"| fit's start ({_offset_range()}% off) |"),
    (
        D,
        lambda: (
            f"({_json('docs/fit/chaos_multiple_gnd.json')['row']['n_iter']} iterations from {_offset_range()}% off)"
        ),
    ),
    (D, _gradnorm_near),
    (
        D,
        lambda: (
            f"The first full GN step from {_offset_range()}% off takes k_r to {_compare('gn')['values']['k_r']:.1e}".replace(
                "e+", "e"
            )
        ),
    ),
    # the optimiser comparison (fit_study.py: compare.json)
    (D, _compare_lm),
    (D, lambda: f"in {_compare('gn-damped')['n_iter']} iterations, run {_compare('gn-damped')['run_s']:.1f} s"),
    (
        D,
        lambda: (
            f"{_compare('lbfgs')['n_iter']} iterations in {_compare('lbfgs')['run_s']:.0f} s, loss {_compare('lbfgs')['loss']:.0f}"
        ),
    ),
    (D, _compare_se),
    (D, _compare_adam),
]

# numbers that are inputs (a record's length and rate, a noise level applied, a budget, a confidence level)
SETTINGS = [
    (D, "95% interval θ ± 1.96 se"),
    (D, "noise 0 and 1 % of each channel's RMS"),  # the noise levels bench_fit.py applies to problem 4p
    (D, "a sane 1 s record"),
    (D, "100 Hz, 1 s each"),
    (D, "m_Ts 35–50 % off the paper's values"),
    (D, "20 % off in spin"),
    (D, "0.3 s then 1 s"),
    (D, "a 300 s budget"),
    (D, "the 1 % fit re-uses"),
    (D, "(within 2×)"),
    (D, "default 1 % of the channel's RMS"),
    (D, "records with 1 % noise, 8 starts"),
    (D, "gives a 95 % profile interval"),
    (D, "fits the first 0.3 s of every record"),
    (D, "two 1 s records, gyro + accelerometer at 100 Hz with 1 % noise"),
    (D, "the paper's parameter values (35–50 % off)"),
    (D, "1 s at 100 Hz (≈ 2.7 forcing periods)"),
    (D, "1% noise: coverage of the 95% intervals (20 seeds, IMU ω, 1 s)"),
    (D, "four correlated marginal 95% intervals"),
    (D, "the joint 95% region"),
    (D, "standard error of a 95% rate"),
    (D, "40 forcing periods (13.23 s)"),
    (D, "a 600 s wall budget"),
    (D, "by the 600 s budget"),
    (D, "(the multiple-shooting window, 0.33 s)"),
    (D, "| at 1 s | at 3 s | at 6.6 s | at 10 s | at 13.2 s (record) |"),
    (D, "over the same 12.9 s"),
    (D, "IMU ω, 1 s at 100 Hz, 1% noise, seed 123"),
    (D, "420 s wall budget"),
    (D, "by the 420 s budget"),
    (D, "95% interval — with 1% noise"),
    (D, "| true value inside the 95% interval |"),
    (D, "grown over 0.33 s only"),
    (HOW, "default 1 % of each channel's RMS"),
    (HOW, "values with 95 % intervals"),
    (HOW, "fit the first 0.3 s, then the whole"),
    (NB, "95% intervals and the correlation matrix"),
    (NB, 'The "true" parameters are 35–50% away from the paper\'s'),
    (NB, "With 1% noise: how sure are we?"),
    (NB, "Now the gyro has 1% noise"),
    (NB, "(with 1% noise added by hand)"),
    (NB, "defaults to 1% of its RMS"),
    (NB, "20 % off in spin"),
]
