"""Quoted texts of docs/internals/studies.md §4–§7 (stability map, peers, defaults, limits), each computed from the
committed result file it comes from (benchmarks/stability.py → docs/performance/stability_*.json,
benchmarks/peers.py → peers.json / peers_idle.json, benchmarks/mujoco_peer.py → mujoco.json,
benchmarks/work_precision.py → work_precision.json); SETTINGS lists the inputs they quote."""

from __future__ import annotations

import math

from .files import _json

ST = "docs/internals/studies.md"
_PARTS = ("a", "a_implicit", "a_eps1e-10", "b", "c", "d", "e")


def _perf(name: str):
    return _json(f"docs/performance/{name}")


def _sp(n) -> str:
    """An integer with a space as thousands separator."""
    return f"{round(n):,}".replace(",", " ")


def _e(x: float, digits: int = 1) -> str:
    """1.2e-05 → 1.2e-5, 7.3e+04 → 7.3e4 (as the page writes exponents)."""
    m, ex = f"{x:.{digits}e}".split("e")
    return f"{m}e{int(ex)}"


def _minus(s: str) -> str:
    return s.replace("-", "−")


# ---- §4 stability map (benchmarks/stability.py) ----


def _rows(part: str, kind: str | None = None) -> list[dict]:
    return [r for r in _perf(f"stability_{part}.json")["rows"] if kind is None or r.get("kind") == kind]


def _load_text() -> str:
    x = []
    for p in _PARTS:
        d = _perf(f"stability_{p}.json")
        x += [float(d["versions"]["loadavg_at_start"][0]), float(d["loadavg_at_end"][0])]
    return f"load average {min(x):.1f}–{max(x):.1f} on the 2 cores during the runs"


def _agreement_text() -> str:
    a = [r["agreement"] for r in _rows("a", "reference_agreement") if r["agreement"] is not None]
    return f"it agrees with Kvaerno5 + Newton at rtol 1e-9 to {_e(min(a))} … {_e(max(a))}"


def _cell(part: str, method: str, eps: float) -> dict:
    return next(r for r in _rows(part, "cell") if r["method"] == method and r["eps"] == eps)


def _k5_eps10_text() -> str:
    n = _cell("a_eps1e-10", "Kvaerno5-Newton rtol 1e-06", 1e-10)
    c = _cell("a_eps1e-10", "Kvaerno5-chord rtol 1e-06", 1e-10)
    return (
        f"stays ok at ε = 1e-10 ({_sp(n['steps'])} steps, error {_e(n['error_vs_ref'])}). ... "
        f"{_sp(c['steps'])} at ε = 1e-10 (error {_e(c['error_vs_ref'])})"
    )


def _tsit_eps10_text() -> str:
    t = _cell("a_eps1e-10", "Tsit5 rtol 1e-06", 1e-10)
    return f"{_sp(t['accepted'])} + {_sp(t['rejected'])} steps, error {_e(t['error_vs_ref'])} — the largest error in the map"


def _rest_text() -> str:
    r = _rows("a", "rest")
    steps = " / ".join(str(x["steps"]) for x in r)
    eps = " / ".join(_e(x["eps"], 0).replace(".", "") for x in r)
    e = [x["error_vs_ref"] for x in r]
    return f"takes {steps} steps for ε = {eps} with errors {_e(min(e))} … {_e(max(e))}"


def _b_scene(i: int) -> dict:
    return _rows("b", "scene")[i]


def _b_largest_ok(scene: str, method: str) -> str:
    c = max(
        (r for r in _rows("b", "cell") if r["scene"] == scene and r["method"] == method and r["verdict"] == "ok"),
        key=lambda r: r["dt"],
    )
    return c["dt"], c["error_vs_ref"]


def _b_row(i: int, label: str) -> str:
    sc = _b_scene(i)
    rk_dt, rk_err = _b_largest_ok(sc["scene"], "RK4-fixed")
    h_dt, h_err = _b_largest_ok(sc["scene"], "Heun-fixed")
    cells = [r for r in _rows("b", "cell") if r["scene"] == sc["scene"]]
    blow = [r for r in cells if not r["finite"] or r["status"] != 0 or not r["valid"] or r["error_vs_ref"] > 1]
    share = round(100 * sc["frac_samples_rho_above_half_max"], 1)
    share_txt = f"{share:g} %" + (" (only t ≈ 0)" if i == 0 else "")
    return (
        f"| {label} | {_e(sc['spectral_radius'])} ({sc['rho_percentiles_10_50_90'][1]:.0f}) | {share_txt} | "
        f"{_e(sc['dt_limit_RK4'])} | {_e(rk_dt, 0)} ({'err ' if i == 0 else ''}{_e(rk_err)}) | {_e(sc['dt_limit_Heun'])} | "
        f"{_e(h_dt, 0)} ({_e(h_err)}) | {'none' if not blow else len(blow)} |"
    )


def _rk4_const() -> float:
    sc = _b_scene(1)
    return sc["dt_limit_RK4"] * sc["spectral_radius"]


def _rho_coeff() -> float:
    """ρ·√ε of the stick–slip scene (ε = 1e-4)."""
    return _b_scene(1)["spectral_radius"] * 1e-2


def _lam() -> list[float]:
    return [r["exponent"] for r in _rows("d", "lyapunov")]


def _lam_text() -> str:
    x = {f"{v:.1f}" for v in _lam()}
    assert len(x) == 1
    return f"λ ≈ {x.pop()} 1/s"


def _grad(w: int, p: int) -> dict:
    return next(r for r in _rows("d", "grad") if r["omega_pi"] == w and r["periods"] == p)


_P = (1, 2, 4, 8, 16, 32)


def _growth(w: int) -> list[float]:
    lg = next(r for r in _rows("d", "lyapunov") if r["omega_pi"] == w)["log_growth"]
    return [math.exp(sum(lg[:p])) for p in _P]


def _g(x: float) -> str:
    return f"{x:.1f}" if x < 20 else _sp(x)


def _grad_rows(w: int) -> str:
    g = " | ".join(f"{abs(_grad(w, p)['grad']):.3g}" for p in _P)
    t = " | ".join(_g(x) for x in _growth(w))
    r = " | ".join(f"{_grad(w, p)['grad_run_s']:.2f} / {_grad(w, p)['fwd_run_s']:.2f}" for p in _P)
    return f"| {w} | \\|dL/dμ\\| | {g} | | {w} | tangent growth | {t} | | {w} | grad / forward run [s] | {r} |"


def _mem_row() -> str:
    m = [{f"{_grad(w, p)['temp_MB']:.2f}" for w in (17, 19)} for p in _P]
    assert all(len(x) == 1 for x in m)
    return "| both | compiled temp memory of value_and_grad [MB] | " + " | ".join(x.pop() for x in m) + " |"


def _rel(w: int, p: int) -> float:
    g = _grad(w, p)
    return abs(g["grad"] - g["grad_fd"]) / abs(g["grad_fd"])


def _fd_text() -> str:
    small = [_rel(w, p) for w in (17, 19) for p in _P if p <= 8 and (w, p) != (19, 8)]
    long = [_rel(w, p) for w in (17, 19) for p in _P if p > 8]
    return (
        f"relative difference ≤ {_e(max(small))} up to 8 periods (except {_e(_rel(19, 8))} at ω_π = 19, P = 8, where "
        f"the gradient is small, {abs(_grad(19, 8)['grad']):.2g}), {_e(min(long), 0)} … {_e(max(long))} at 16 and 32 periods"
    )


def _order_text() -> str:
    g = [abs(_grad(w, p)["grad"]) for w in (17, 19) for p in _P if p <= 8]
    return f"the gradient of this *averaged* loss stays O({min(g):.1f}–{max(g):.0f})"


def _growth_text() -> str:
    lam = _lam()[0]
    horizon = _grad(17, 32)["horizon_s"]
    return f"With λ ≈ {lam:.1f} 1/s the growth is e^{{{lam:.1f}·T}} ≈ {_sp(round(math.exp(lam * horizon), -3))} at 32 periods"


def _memory_text() -> str:
    m = sorted(_rows("d", "memory_vs_max_steps"), key=lambda r: r["max_steps"])
    mb = " / ".join(f"{r['temp_MB']:#.2g}" for r in m)
    ms = " / ".join(f"1e{round(math.log10(r['max_steps']))}" for r in m)
    rss = [r["maxrss_MB"] for r in _rows("d", "grad")]
    big = m[-1]["temp_MB"]
    return (
        f"{mb} MB for max_steps = {ms} (∝ √max_steps); against the horizon at max_steps 1e5 only "
        f"{_grad(17, 1)['temp_MB']:.2f} → {_grad(17, 32)['temp_MB']:.2f} MB from 1 to 32 periods. The process peak RSS "
        f"({min(rss) / 1e3:.1f}–{max(rss) / 1e3:.1f} GB) is XLA compilation. Per vmapped lane the buffer multiplies: "
        f"4 096 lanes at max_steps 1e6 would need ~{4096 * big / 1e3:.1f} GB (estimate from the measured {big:.2f} MB"
    )


def _lift_t(x: float) -> str:
    return f"{x:.3f}" if x >= 0.1 else f"{x:.4f}"


def _n_cont(x: float) -> str:
    s = f"{x:.2f}" if abs(x) < 1 else f"{x:.1f}" if abs(x) < 10 else _sp(x)
    return _minus(s)


def _lift(case: str, x: float, stop: bool) -> dict:
    return next(
        r
        for r in _rows("e")
        if r.get("case", "").startswith(f"pitching at {case}") and r["x"] == x and r["stop_on_invalid"] == stop
    )


def _lift_row(tilt: int, ws: tuple, label: str, t_label: str | None = None) -> str:
    c = [_lift(f"{tilt} deg", w, False) for w in ws]
    s = [_lift(f"{tilt} deg", w, True) for w in ws]
    kinds = {r["invalid_kind"] for r in c}
    assert len(kinds) == 1 and label.startswith("n3" if "n3" in kinds.pop() else "lift-off")
    t = t_label or " / ".join(_lift_t(r["first_invalid_t"]) for r in c)
    steps = ", ".join(f"{a['steps']} / {b['steps']}" for a, b in zip(c, s))
    n = ", ".join(f"{_n_cont(a['min_N'])} / " + _minus(f"{b['min_N']:.2g}") for a, b in zip(c, s))
    w = " / ".join(f"{x:g}" for x in ws)
    return f"| {tilt}°, {w} | {label} | {t} | {steps} | {n} |"


def _lift_stop_text() -> str:
    n = [
        r["min_N"]
        for r in _rows("e")
        if r.get("case", "").startswith("pitching")
        and r["stop_on_invalid"]
        and r["invalid_kind"].startswith("lift-off")
    ]
    return _minus(f"N at the stop {max(n):.1g} … {min(n):.2g} N")


# ---- §5 peers (benchmarks/peers.py, benchmarks/mujoco_peer.py) ----

_LABEL = {
    "numba DP5 (hand-written)": "numba hand-written DP5(4) loop",
    "jaxcelt Dopri8": "**jaxcelt Dopri8**",
    "jaxcelt Tsit5": "**jaxcelt Tsit5** (default)",
    "CVODE Adams + numba RHS": "SUNDIALS CVODE Adams + numba RHS",
    "CVODE BDF + numba RHS": "SUNDIALS CVODE BDF + numba RHS",
}


def _ratio(x: float) -> str:
    return "1" if x == 1 else f"{x:.2f}" if x < 2 else f"{x:.1f}" if x < 10 else f"{x:.0f}"


def _ms(x: float) -> str:
    x *= 1e3
    return f"{x:.1f}" if x < 100 else _sp(x)


def _ea_cell(r: dict, evals: bool) -> str:
    rtol = _e(r["rtol"], 0).replace(".", "")
    s = f"{rtol}, {_e(r['error'])}, {_ms(r['run_s'])}"
    if evals:
        s += ", " + ("—" if r["rhs_evals"] is None else _sp(r["rhs_evals"]))
    return f"{s} | {_ratio(r['ratio_vs_jaxcelt'])}"


def _ea_rows(file: str, evals: bool) -> str:
    ea = _perf(file)["equal_accuracy"]
    by = [{r["name"]: r for r in ea[t]} for t in ("1e-05", "1e-08")]
    rows = []
    for r in ea["1e-05"]:  # ordered by the ratio at the first target
        n = r["name"]
        rows.append(f"| {_LABEL.get(n, n)} | {_ea_cell(by[0][n], evals)} | {_ea_cell(by[1][n], evals)} |")
    return " ".join(rows)


def _loads(file: str) -> list[float]:
    v = _perf(file)["versions"]
    return [v[k][0] for k in ("loadavg_start", "loadavg_after_single", "loadavg_end")]


def _scal(name: str, lanes: int) -> dict:
    return next(r for r in _perf("peers.json")["scaling"] if r["name"].startswith(name) and r["lanes"] == lanes)


def _run(x: float) -> str:
    return f"{x:.3f}" if x < 1 else f"{x:.2f}" if x < 10 else f"{x:.1f}"


def _scal_row(lanes: int) -> str:
    j, n = _scal("jaxcelt", lanes), _scal("numba", lanes)
    r = j["run_s"] / n["run_s"]
    ratio = f"{r:.2f}" if r < 2 else f"{r:.1f}"
    return (
        f"| {lanes} | {j['lanes_per_s']:.0f} | {_e(j['lane_steps_per_s'])} | {_run(j['run_s'])} | {j['compile_s']:.0f} | "
        f"{j['peak_rss_mb']:.0f} | {n['lanes_per_s']:.0f} | {_e(n['lane_steps_per_s'])} | {_run(n['run_s'])} | "
        f"{n['peak_rss_mb']:.0f} | {ratio} |"
    )


def _single(name: str, rtol: float) -> dict:
    return next(r for r in _perf("peers.json")["single"] if r["name"] == name and r["rtol"] == rtol)


def _mj(scene: str) -> dict:
    return {r["name"]: r for r in _perf("mujoco.json")["scenes"][scene]["runs"]}


_MJ = ("MuJoCo Euler dt 0.002", "MuJoCo Euler dt 0.0002", "MuJoCo RK4 dt 0.002")


def _late_tilt(r: dict) -> float:
    """Largest tilt [deg] in the last 0.5 s of a run."""
    t_end = r["t"][-1]
    return max(math.degrees(a) for a, t in zip(r["tilt"], r["t"]) if t >= t_end - 0.5 - 1e-9)


def _mj_text() -> str:
    rest = [_mj("rest17")[n]["omega_s"][-1] for n in _MJ]
    rev = _mj("spin_reversal")
    right = _mj("spin_right_way")
    j = "jaxcelt Tsit5 rtol 1e-8"
    return (
        f"agree with each other ({min(rest):.1f}–{max(rest):.1f} rad/s at the end; ... afterwards jaxcelt spins up to "
        f"+{max(rev[j]['omega_s']):.2f} rad/s, MuJoCo only to +{max(rev[_MJ[0]]['omega_s']):.2f} ... (10 → "
        f"{right[j]['omega_s'][-1]:.1f} rad/s in jaxcelt, → {right[_MJ[0]]['omega_s'][-1]:.1f} in MuJoCo over 2.5 s), ... "
        f"(tilt at most {_late_tilt(right[j]):.2f}° in the last 0.5 s), MuJoCo keeps rocking (up to "
        f"{max(_late_tilt(right[n]) for n in _MJ):.1f}°)"
    )


# ---- §6 (benchmarks/work_precision.py) ----


def _wp(scene: str, solver: str, rtol: float) -> dict:
    sc = next(s for s in _perf("work_precision.json")["scenes"] if s["scene"] == scene)
    return next(r for r in sc["runs"] if "run_s" in r and r["solver"] == solver and r["rtol"] == rtol)


def _defaults_text() -> str:
    sl = ("rest17", "rest19", "spin_reversal")
    q = [_wp(s, "Tsit5", 1e-8)["error"] / 1e-8 for s in sl]
    q14 = _wp("rest14", "Tsit5", 1e-8)["error"] / 1e-8
    e = [_wp(s, "Tsit5", 1e-8)["error"] for s in (*sl, "rest14")]
    return (
        f"Tsit5's error/rtol is {min(q):.1f}–{max(q):.0f} on rest17, rest19 and the spin scene (but {q14:.0f} on rest14; "
        f'§2 "rtol is not the error"), so rtol 1e-8 gives errors of {_e(min(e), 0)} … {_e(max(e))}'
    )


def _f32_floor_text() -> str:
    fl = [min(r["error"] for r in f["runs"] if r.get("status") == 0) for f in _perf("work_precision.json")["float32"]]
    return f"its error floors at {_e(min(fl), 0)} … {_e(max(fl), 0)}"


QUOTES = [
    (ST, _load_text),
    (ST, _agreement_text),
    (ST, lambda: _k5_eps10_text().split(" ... ")[0]),
    (ST, lambda: _k5_eps10_text().split(" ... ")[1]),
    (ST, _tsit_eps10_text),
    (ST, _rest_text),
    (ST, lambda: _b_row(0, "from rest, ω_π = 17, 2 periods (ε = 1e-4)")),
    (ST, lambda: _b_row(1, "stick–slip, ε = 1e-4, 1 period")),
    (ST, lambda: _b_row(2, "stick–slip, ε = 1e-6, 1 period")),
    (ST, lambda: f"The linear stability limits {_rk4_const():.3f}/ρ (RK4)"),
    (ST, lambda: f"the linear estimate {_rk4_const():.3f}/ρ marks"),
    (ST, lambda: f"{_rk4_const():.3f}/ρ ≈ {_e(_rk4_const() / _rho_coeff())}·√ε s"),
    (
        ST,
        lambda: (
            f"ρ ≈ {round(_rho_coeff(), -1):.0f}/√ε 1/s: {_e(_b_scene(1)['spectral_radius'])} at ε = 1e-4, "
            f"{_e(_b_scene(2)['spectral_radius'])} at ε = 1e-6"
        ),
    ),
    (ST, _lam_text),
    (
        ST,
        lambda: (
            "**" + ", ".join(f"{r['exponent']:.3f} 1/s at ω_π = {r['omega_pi']}" for r in _rows("d", "lyapunov")) + "**"
        ),
    ),
    (ST, lambda: _grad_rows(17)),
    (ST, lambda: _grad_rows(19)),
    (ST, _mem_row),
    (ST, _fd_text),
    (ST, _order_text),
    (ST, _growth_text),
    (ST, _memory_text),
    (
        ST,
        lambda: (lambda r: f"(|ψ| up to {r['max_abs_psi']:.1f} rad within")(
            next(r for r in _rows("e") if r.get("case", "").startswith("n2 -> 1") and r.get("x") == 1e-7)
        ),
    ),
    (ST, lambda: _lift_row(40, (10.0,), "n3 ≤ 0 (tips over)")),
    (ST, lambda: _lift_row(40, (11.0,), "lift-off (N ≤ 0)")),
    (ST, lambda: _lift_row(40, (12.0,), "lift-off")),
    (ST, lambda: _lift_row(40, (13.0,), "lift-off")),
    (ST, lambda: _lift_row(40, (14.0, 16.0, 20.0), "lift-off", "0 (N < 0 in the initial state)")),
    (ST, lambda: _lift_row(20, (12.0,), "n3 ≤ 0")),
    (ST, lambda: _lift_row(20, (16.0, 20.0, 25.0), "lift-off")),
    (ST, _lift_stop_text),
    (ST, lambda: f"Tsit5 finishes with {_cell('a_eps1e-10', 'Tsit5 rtol 1e-06', 1e-10)['steps'] / 1e5:.1f}·10⁵ steps"),
    (
        ST,
        lambda: (
            f"where Tsit5 needs {_cell('a', 'Tsit5 rtol 1e-06', 1e-8)['steps'] / 1e5:.1f}·10⁵ (ε = 1e-8) and "
            f"{_cell('a_eps1e-10', 'Tsit5 rtol 1e-06', 1e-10)['steps'] / 1e5:.1f}·10⁵ steps (ε = 1e-10)"
        ),
    ),
    # §5
    (ST, lambda: f"with a load average of {min(_loads('peers.json')):.1f}–{max(_loads('peers.json')):.1f}"),
    (ST, lambda: _ea_rows("peers.json", True)),
    (ST, lambda: _ea_rows("peers_idle.json", False)),
    (ST, lambda: f"(rtol 1e-7 already gives {_e(_single('jaxcelt Dopri8', 1e-7)['error'])})"),
    (
        ST,
        lambda: (
            f"jaxcelt Tsit5 {_e(_single('jaxcelt Tsit5', 1e-8)['error'])}, numba DP5 "
            f"{_e(_single('numba DP5 (hand-written)', 1e-8)['error'])}, i.e. about equal accuracy"
        ),
    ),
    *[(ST, lambda n=n: _scal_row(n)) for n in (1, 4, 16, 64, 256, 1024, 4096)],
    *[(ST, lambda i=i: _mj_text().split(" ... ")[i]) for i in range(4)],
    (ST, lambda: f"(load average {_loads('peers_idle.json')[0]:.1f} at the start"),
    # §6
    (ST, _defaults_text),
    (ST, _f32_floor_text),
]

SETTINGS = [
    # inputs of the scripts: the scene, the stone's semi-axes (the paper's), the tilt of the tip test, the noise
    (ST, "(ω_π = 17, q_π = 0.01 m, from rest)"),
    (ST, "semi-axes a = (0.110, 0.025, 0.025) m"),
    (ST, "θ = 85°, 89°, 89.9°"),
    (ST, "initial spin + N(0, 0.05²) rad/s per component"),
    # the MuJoCo model's inputs, made from the paper's parameters (benchmarks/mujoco_peer.py)
    (ST, "(semi-axes 0.110, 0.025, 0.025 m) with the mass centre 4.29 mm below its centre"),
    (ST, "torsional μ â 4E S2 = 0.65 mm"),
    (ST, "rolling â π S3 k_r = 0.50 mm"),
    # initial_state's refusal threshold 1 − 1e-12 on |n2|, written as a bound on δ
    (ST, "(δ ≤ ~1.4e-6)"),
]
