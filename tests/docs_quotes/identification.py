"""Quoted texts of the identification pages (docs/identification.md, docs/how-to/fit-recording.md, notebook 04),
each computed from the result file under docs/fit/ it comes from.

Writers: benchmarks/bench_fit.py (bench_fit.json), benchmarks/fit_records_parallel.py (records_parallel.json),
benchmarks/fit_compile_parts.py (compile_parts.json), benchmarks/bench_multistart.py (multistart.json),
scripts/fit_sensor_study.py (sensor_study.json), scripts/fit_study.py (recover, coverage, chaos_*, gradnorm, compare
and the table it writes next to it, docs/fit/compare_table.md).
"""

from __future__ import annotations

import math
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
    true = _json("docs/fit/recover.json")["true"][worst]  # compare.json's record has the study's true values
    inside = abs(r["values"][worst] - true) <= 1.96 * r["stderr"][worst]
    return f"max relative error {100 * r['max_rel_err']:.1f}% = {worst}, {'inside' if inside else 'outside'} its 95% interval"


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


# ---- whole rows and sentences (the scanner counts every decimal number) ----

CT = "docs/fit/compare_table.md"
WORDS = {1: "one", 2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight", 9: "nine"}


def _e(x: float, digits: int) -> str:
    """2.0368e-07 -> '2.0e-7' (digits after the point), as the identification page writes exponents."""
    m, ex = f"{x:.{digits}e}".split("e")
    return f"{m}e{int(ex)}"


def _bench_rows() -> list[str]:
    """The rows of benchmarks/bench_fit.py's table (``table``), re-implemented from bench_fit.json."""
    out, seen = [], 0
    for r in _json("docs/fit/bench_fit.json")["rows"]:
        cache = "off"
        if r["persistent_cache"]:
            cache = "cold (fills it)" if seen < 2 else "warm (2nd process)"
            seen += 1
        out.append(
            f"| {r.get('problem', '4p')} | {r['optimiser']} | {r['noise']:g} | {cache} | {r['n_iter']} | "
            f"{'yes' if r['converged'] else 'no'} | {r['max_rel_err_vs_true']:.2g} | {r['compile_s']:.1f} | "
            f"{r['run_s']:.1f} | {r['call_total_s']:.1f} |"
        )
    return out


def _bench_versions() -> str:
    d = _json("docs/fit/bench_fit.json")
    v = d["versions"]
    return (
        f"jax {v['jax']}, diffrax {v['diffrax']}, equinox {v['equinox']}, optax {v['optax']}, "
        f"optimistix {v['optimistix']}, Python {v['python']}; {d['machine']['cpus']} CPUs"
    )


def _bench_load() -> str:
    d = _json("docs/fit/bench_fit.json")

    def one(u: str) -> str:
        return u.split("load average:")[1].split(",")[0].strip()

    return (
        f"1-minute load average {one(d['uptime_before'])} before, {one(d['uptime_after'])} after, on the "
        f"{d['machine']['cpus']} CPUs"
    )


RECOVER_LABELS = {
    "state": "full state",
    "omega": "IMU ω only",
    "orientation": "orientation (n, ψ)",
    "centre": "centre path",
}


def _recover_row(label: str) -> str:
    r = next(r for r in _json("docs/fit/recover.json")["rows"] if r["label"] == label)
    return (
        f"| {RECOVER_LABELS[label]} | {r['n_iter']} | {_e(r['max_rel_err'], 1)} | {r['compile_s']:.0f} | "
        f"{r['run_s']:.1f} |"
    )


def _rho_omega() -> str:
    """|ρ| between μ, k_r and b_Ts in the IMU-ω fit of recover.json."""
    c = next(r for r in _json("docs/fit/recover.json")["rows"] if r["label"] == "omega")["corr"]
    rho = [abs(c[0][1]), abs(c[0][2]), abs(c[1][2])]
    return f"{min(rho):.2f}–{max(rho):.2f}"


def _coverage_misses() -> str:
    d = _coverage()
    parts, z_all = [], []
    for r in d["rows"]:
        miss = [n for n in NAMES if not r["covers"][n]]
        if not miss:
            continue
        z = {n: (r["values"][n] - d["true"][n]) / r["stderr"][n] for n in miss}
        z_all += [abs(v) for v in z.values()]
        parts.append(f"seed {r['seed']}: " + ", ".join(f"{GREEK[n]} {_minus(f'{v:+.1f}')}σ" for n, v in z.items()))
    return f"The misses are at {min(z_all):.1f}–{max(z_all):.1f} σ ({'; '.join(parts)})"


def _chaos() -> dict:
    return _json("docs/fit/chaos_record.json")


def _period() -> float:
    """The forcing period of the ω_π = 19 record: its log growths are per period, λ = Σ / (n T)."""
    c = _chaos()
    lg = c["log_growth_rtol1e-09"]
    return sum(lg) / (len(lg) * c["lambda_record"])


def _chaos_validity() -> str:
    c = _chaos()
    n = len(c["log_growth_rtol1e-09"])
    cont = c["continuation_first_invalid_periods"]
    return (
        f"max tilt {c['record_max_tilt_deg']:.1f}°, min N = {c['record_min_N']:.2f} N (> 0). The same motion continued "
        f"tips past 90° (n3 ≤ 0, contact off the lower half-surface) after {cont:.1f} periods — the record stops "
        f"{cont - n:.1f} periods before that"
    )


def _chaos_start() -> str:
    c = _chaos()
    return (
        f"stone released at rest tips past 90° after {c['start_first_invalid_periods']:.1f} periods "
        f"(max tilt {c['start_max_tilt_deg']:.0f}°)"
    )


def _agree_digits(a: float, b: float) -> int:
    """The number of significant digits two values share (from their relative difference)."""
    return int(-math.log10(abs(a - b) / abs(a)))


def _lyapunov() -> str:
    c, tp = _chaos(), _period()
    lg = c["log_growth_rtol1e-09"]
    n = len(lg)
    run = ", ".join(f"{sum(lg[:k]) / (k * tp):.2f} ({k})" for k in (20, 30, 40))
    return (
        f"**λ = {c['lambda_record']:.2f} 1/s, λ·T_record = {c['lambda_T_record']:.1f}**. Convergence: the same value "
        f"to {_agree_digits(c['lambda_record'], c['lambda_record_rtol1e-11'])} digits at rtol 1e-9 and 1e-11; the "
        f"running mean is {sum(lg[:10]) / (10 * tp):.2f} (10 periods; the first period is the tangent's alignment, "
        f"log growth {lg[0]:.2f}), {run} 1/s; without the first period {c['lambda_record_skip1']:.2f} 1/s; second half "
        f"of the record alone (periods {n // 2 + 1}–{n}) {c['lambda_second_half']:.2f} 1/s; "
        f"{c['periods_with_negative_growth']} of the {n} per-period log growths are negative"
    )


def _lyapunov_reference() -> str:
    ref, tp = _chaos()["reference"], _period()
    m = ref["running_mean"]
    late = sum(ref["log_growth"][40:80])
    return (
        f"(spinning ω3 = −3 rad/s, valid for {80 if ref['valid_80_periods'] else 'fewer than 80'} periods, max tilt "
        f"{ref['max_tilt_deg']:.1f}°) gives running means {m['40']:.2f} (40 periods), {m['60']:.2f} (60) and "
        f"{m['80']:.2f} 1/s (80): positive over every horizon measured, but not converged to a single number — its "
        f"periods 41–80 add only {late:.2f} to the log growth (≈ {late / (40 * tp):.2f} 1/s;"
    )


def _fd_separation() -> str:
    fd = _chaos()["fd_log_separation_per_period"]
    return f"separate by e^{fd[19]:.1f} over the first 20 and e^{fd[-1]:.1f} over the 40 periods"


def _contracting_stretch() -> str:
    c = _chaos()
    s = c["log_growth_rtol1e-09"][10:22]  # periods 11–22
    return (
        f"periods 11–22 happen to be a contracting stretch ({sum(x < 0 for x in s)} of the {len(s)} per-period log "
        f"growths negative, sum {_minus(f'{sum(s):.1f}')}); the Benettin average over the same first 20 periods is "
        f"{c['lambda_first_half']:.2f} 1/s"
    )


def _chaos_fit(name: str) -> dict:
    return _json(f"docs/fit/{name}.json")


def _multiple_row() -> str:
    r = _chaos_fit("chaos_multiple_gnd")["row"]
    st = r["settings"]
    worst = max(NAMES, key=lambda n: r["rel_err"][n])
    errs = ", ".join(f"**{_e(r['rel_err'][n], 1)}**" if n == worst else _e(r["rel_err"][n], 1) for n in NAMES)
    return (
        f"| **multiple shooting, {st['windows']} windows (1 period each, states from the {st['window_states']}), damped "
        f"GN, continuity weight {st['continuity_weight']:g}** | {r['n_iter']}, "
        f"{'converged' if r['converged'] else 'not converged'} | {_e(r['loss'], 1)} ({_e(r['loss_history'][0], 2)}) | "
        f"{errs} | {r['compile_s']:.0f} | {r['run_s']:.0f} |"
    )


def _single_row(name: str, label: str) -> str:
    r = _chaos_fit(name)["row"]
    st = r["settings"]
    stop = f"stopped by the {st['max_time']:.0f} s budget" if r["total_s"] >= st["max_time"] else "not stopped"

    def err(x):
        return f"{x:.2f}" if x >= 0.1 else f"{x:.2g}"

    errs = ", ".join(err(r["rel_err"][n]) for n in NAMES)
    if r["values"]["m_Ts"] == 2.0:
        errs += " (m_Ts at its bound 2)"
    return (
        f"| {label} | {r['n_iter']}, {stop} | {_e(r['loss'], 2)} ({_e(r['loss_history'][0], 2)}) | {errs} | — | "
        f"{r['total_s']:.0f} (total) |"
    )


def _multiple_text() -> str:
    r = _chaos_fit("chaos_multiple_gnd")["row"]
    worst = max(NAMES, key=lambda n: r["rel_err"][n])
    return f"{_chaos_multiple_below()} and at {_e(r['max_rel_err'], 1)} ({worst}, the worst) at the end"


def _accepted(h: list[float]) -> list[float]:
    """The loss after each accepted step (a decrease), the start first."""
    out = [h[0]]
    for x in h[1:]:
        if x < out[-1]:
            out.append(x)
    return out


def _single_lm_text() -> str:
    d = _chaos_fit("chaos_single")
    r, truth = d["row"], d["truth"]
    acc = _accepted(r["loss_history"])
    vals = ", ".join(f"{GREEK[n]} {r['values'][n]:.3f}" for n in NAMES)
    return (
        f"{WORDS[len(acc) - 1]} accepted step, from loss {_e(acc[0], 2)} to {_e(acc[1], 2)}, into a wrong region "
        f"({vals} against {', '.join(f'{truth[n]:g}' for n in NAMES)}), then {r['n_iter'] - (len(acc) - 1)} rejected "
        f"steps"
    )


def _single_gnd_text() -> str:
    r = _chaos_fit("chaos_single_gnd")["row"]
    h = r["loss_history"]
    acc = _accepted(h)
    stalled = len(h) - 1 - h.index(acc[-1])
    v = r["values"]
    return (
        f"{WORDS[len(acc) - 1]} accepted steps (loss {' → '.join(_e(x, 2) for x in acc)}), then {WORDS[stalled]} "
        f"iterations in which the line search finds no decrease; it ends at μ {v['mu']:.3f}, k_r {v['k_r']:.3f}, "
        f"b_Ts {v['b_Ts']:.3f}, m_Ts = {v['m_Ts']:.1f} (the upper bound"
    )


def _grad() -> dict:
    return _json("docs/fit/gradnorm.json")


def _grad_points(tag: str) -> tuple[list[str], float, float]:
    d = _grad()["points"][tag]
    T, g = d["T"], d["grad_norm"]
    i = 19  # one period: the record has 20 samples per period
    cols = [i] + [min(range(len(T)), key=lambda j: abs(T[j] - x)) for x in (1.0, 3.0, 6.6, 10.0)] + [len(T) - 1]
    growth = g[-1] / g[i]
    return [_e(g[j], 1) for j in cols], growth, math.log(growth)


def _grad_row(tag: str) -> str:
    cells, growth, ln = _grad_points(tag)
    if tag == "start":
        label = f"fit's start ({_offset_range()}% off)"
    else:
        truth = _json("docs/fit/chaos_single.json")["truth"]
        near = _grad()["points"]["near"]["params"]
        off = {round(100 * abs(near[n] / truth[n] - 1)) for n in NAMES}
        label = f"{'/'.join(map(str, sorted(off)))}% off the truth"
    return f"| {label} | {' | '.join(cells)} | {_e(growth, 1)} = e^{ln:.1f} |"


def _grad_span() -> tuple[float, float]:
    T = _grad()["points"]["start"]["T"]
    return T[19], T[-1] - T[19]


def _grad_bounds() -> str:
    lam = _grad()["lambda_record"]
    _, span = _grad_span()
    return f"For comparison e^{{λT}} = e^{lam * span:.1f} and e^{{2λT}} = e^{2 * lam * span:.1f} over the same {span:.1f} s"


def _grad_window() -> str:
    lam = _grad()["lambda_record"]
    w, _ = _grad_span()
    return f"grown over {w:.2f} s only (e^{{λ·{w:.2f}}} = {math.exp(lam * w):.2f})"


def _cmp_row(label: str) -> str:
    """A row of §4's optimiser table from compare.json (the name column written out below)."""
    r = _compare(label)
    lm = _compare("lm")
    stop = f", stopped by the {r['max_time_s']:.0f} s budget" if r["compile_s"] + r["run_s"] >= r["max_time_s"] else ""
    conv = "yes" if r["converged"] else ("no, diverged" if not math.isfinite(r["max_rel_err"]) else "no")
    if not math.isfinite(r["max_rel_err"]):
        err = ", ".join(
            f"{GREEK[n]} → {'∞' if not math.isfinite(r['values'][n]) else _e(r['values'][n], 1)}"
            for n in NAMES
            if r["rel_err"][n] > 10
        )
        loss = _e(r["loss"], 1)
    elif r["converged"]:
        same = (
            "= statistical" if label == "lm" else ("same optimum" if f"{r['loss']:.8g}" == f"{lm['loss']:.8g}" else "?")
        )
        err = f"{_e(r['max_rel_err'], 1)} ({same})"
        loss = f"{r['loss']:.2f}"
    else:
        err = f"{r['max_rel_err']:.2f}"
        loss = f"{r['loss']:.0f}" if r["loss"] >= 1000 else f"{r['loss']:.1f}"
    return (
        f"| {r['n_iter']} ({r['max_iter']}){stop} | {conv} | {loss} | {err} | {r['compile_s']:.0f} | {r['run_s']:.0f} |"
    )


CMP_NAMES = {
    "lm": "LM (optimistix, fwd Jacobian)",
    "gn": "GN, plain (optimistix)",
    "gn-damped": "GN, damped (Armijo backtracking)",
    "lbfgs": "L-BFGS (optax, reverse mode)",
}


def _compare_lm_full() -> str:
    r = _compare("lm")
    n_data = 3 * (100 + 1)  # compare.json's problem: IMU ω (3 channels), 1 s at 100 Hz
    s2 = 2 * r["loss"] / (n_data - len(NAMES))  # loss = RSS / 2
    return f"(loss {r['loss']:.2f}, s² = {s2:.2f}; {_compare_lm()}"


def _gn_step() -> str:
    g = _compare("gn")
    return (
        f"The first full GN step from {_offset_range()}% off takes k_r to {_e(g['values']['k_r'], 1)} and b_Ts to "
        f"{'∞' if not math.isfinite(g['values']['b_Ts']) else _e(g['values']['b_Ts'], 1)}; the loss goes to "
        f"{_e(g['loss'], 1)}"
    )


def _compare_table_row(label: str) -> str:
    """A row of docs/fit/compare_table.md as scripts/fit_study.py writes it from compare.json."""
    r = _compare(label)
    return (
        f"| {r['optimiser']} | {r['n_iter']} | {r['converged']} | {r['loss']:.4g} | {r['max_rel_err']:.2e} | "
        f"{r['compile_s']:.1f} | {r['run_s']:.1f} |"
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
    ("docs/internals/fit-engine.md", _compile_parts),
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
    (D, _multiple_text),
    (D, _chaos_gnd_single),
    (D, lambda: _grad_row("start")),
    (
        D,
        lambda: (
            f"({_json('docs/fit/chaos_multiple_gnd.json')['row']['n_iter']} iterations from {_offset_range()}% off)"
        ),
    ),
    (D, lambda: _grad_row("near")),
    (D, _gn_step),
    # the optimiser comparison (fit_study.py: compare.json)
    (D, _compare_lm_full),
    (D, lambda: f"in {_compare('gn-damped')['n_iter']} iterations, run {_compare('gn-damped')['run_s']:.1f} s"),
    (
        D,
        lambda: (
            f"{_compare('lbfgs')['n_iter']} iterations in {_compare('lbfgs')['run_s']:.0f} s, loss {_compare('lbfgs')['loss']:.0f}"
        ),
    ),
    (D, _compare_se),
    (D, _compare_adam),
    # the benchmark table, row by row (benchmarks/bench_fit.py's table), its versions and load
    *((D, (lambda i=i: _bench_rows()[i])) for i in range(len(_json("docs/fit/bench_fit.json")["rows"]))),
    (D, _bench_versions),
    (D, _bench_load),
    # §1: noise-free recovery (recover.json), row by row, and the correlations
    *((D, (lambda k=k: _recover_row(k))) for k in RECOVER_LABELS),
    (D, lambda: f"between μ, k_r and b_Ts (|ρ| ≈ {_rho_omega()} for ω)"),
    (D, lambda: f"(μ–k_r–b_Ts |ρ| ≈ {_rho_omega()})"),
    # §2: the coverage misses in standard errors (coverage.json)
    (D, _coverage_misses),
    # §3: the chaotic record (chaos_record.json) and the fits (chaos_*.json)
    (
        D,
        lambda: (
            f"single shooting fails, multiple shooting recovers to "
            f"{_e(_chaos_fit('chaos_multiple_gnd')['row']['max_rel_err'], 1)}"
        ),
    ),
    (D, _chaos_validity),
    (D, _chaos_start),
    (D, _lyapunov),
    (D, _lyapunov_reference),
    (D, lambda: f"expands perturbations by e^{_chaos()['lambda_T_record']:.1f}"),
    (D, _fd_separation),
    (D, _contracting_stretch),
    (D, _multiple_row),
    (D, lambda: _single_row("chaos_single", "single shooting, LM")),
    (D, lambda: _single_row("chaos_single_gnd", "single shooting, damped GN")),
    (D, _single_lm_text),
    (D, _single_gnd_text),
    # gradient norm vs window (gradnorm.json)
    (D, lambda: f"with the record's λ = {_grad()['lambda_record']:.2f} 1/s, both drawn"),
    (D, _grad_bounds),
    (D, lambda: f"the measured e^{_grad_points('near')[2]:.1f} lies between the two bounds"),
    (D, lambda: f"At the start the growth e^{_grad_points('start')[2]:.1f} exceeds"),
    (D, lambda: f"(it tips over after {_chaos()['start_first_invalid_periods']:.1f} periods)"),
    (D, _grad_window),
    # §4: the optimiser table (compare.json), row by row
    *((D, (lambda k=k: f"| {CMP_NAMES[k]} {_cmp_row(k)}")) for k in CMP_NAMES),
    (D, lambda: _cmp_row("adam")),  # its name column, with the learning rate, is a setting
    # the table scripts/fit_study.py writes next to compare.json
    *((CT, (lambda k=k: _compare_table_row(k))) for k in ("lm", "gn", "gn-damped", "lbfgs", "adam")),
]

# numbers that are inputs (a record's length and rate, a noise level applied, a budget, a confidence level)
SETTINGS = [
    (D, "95% interval θ ± 1.96 se"),
    (D, "noise 0 and 1 % of each channel's RMS"),  # the noise levels bench_fit.py applies to problem 4p
    (D, "a sane 1 s record"),
    (D, "100 Hz, 1 s each"),
    (D, "m_Ts 35–50 % off the paper's values"),
    (
        D,
        "releases with headings 0.3 and −0.5 rad, and the release states fitted with the parameters from a guess 0.2 rad off in heading, 3° off in tilt and 20 % off in spin",
    ),
    (D, "the fit is given a release 0.2 rad off in heading, 3° off in tilt and 20 % off in spin"),
    (D, "| Adam (optax, lr 0.02) |"),
    (D, "full state at 20 samples per period (60.5 Hz, 801 samples)"),  # the record's sampling
    (D, "base velocity up to 0.68 m/s"),  # q_π ω_π: the forcing's velocity amplitude
    (D, "0.3 s then 1 s"),
    (D, "a 300 s budget"),
    (D, "the 1 % fit re-uses"),
    (D, "(within 2×)"),
    (D, "default 1 % of the channel's RMS"),
    (D, "records with 1 % noise, 8 starts"),
    (D, "against χ²₁ (3.84) gives a 95 % profile interval"),  # the χ² quantile: a threshold
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
    (D, "IMU ω, 1 s at 100 Hz, 1% noise, seed 123"),
    (D, "420 s wall budget"),
    (D, "by the 420 s budget"),
    (D, "95% interval — with 1% noise"),
    (D, "| true value inside the 95% interval |"),
    (HOW, "default 1 % of each channel's RMS"),
    (HOW, "values with 95 % intervals"),
    (HOW, "fit the first 0.3 s, then the whole"),
    (NB, "95% intervals and the correlation matrix"),
    (NB, 'The "true" parameters are 35–50% away from the paper\'s'),
    (NB, "With 1% noise: how sure are we?"),
    (NB, "Now the gyro has 1% noise"),
    (NB, "(with 1% noise added by hand)"),
    (NB, "defaults to 1% of its RMS"),
    (NB, "a release guessed 3° off in tilt, 20 % off in spin and 0.2 rad off in heading"),
]
