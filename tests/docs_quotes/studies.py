"""Quoted texts of the numerical-studies pages (docs/internals/studies.md, docs/contact-laws.md and notebooks 03
and 05), each computed from the committed result file it comes from; SETTINGS lists the inputs they quote."""

from __future__ import annotations

from .files import _json

CL = "docs/contact-laws.md"
NB03 = "notebooks/03_contact_laws.ipynb"
ST = "docs/internals/studies.md"


def _contact() -> dict:
    return _json("docs/contact/summary.json")


def _ladder(scene: str) -> dict:
    """The ladder's results of one scene of scripts/contact_study.py, by rung."""
    return {r["rung"]: r for r in _contact()["ladder"]["results"][scene]}


def _ladder_row(rung: str) -> str:
    """A row of the scene table as jaxcelt.studies.ladder.results_table prints it."""
    cells = []
    for scene in _contact()["ladder"]["results"]:
        r = _ladder(scene)[rung]
        flag = "" if r["status"] == 0 and r["valid"] else " (invalid)" if r["status"] == 0 else f" (status {r['status']})"
        cells.append(f"{r['error']:.1e} / {r['run_s']:.2f} s / {r['steps']}{flag}")
    return f"| {rung} | " + " | ".join(cells) + " |"


def _kl(w3: str) -> dict:
    return _contact()["kane_levinson"][f"w3(0)={w3}"]


def _cal(name: str) -> dict:
    return _contact()["calibration"][name]


def _norr_range() -> tuple[float, float]:
    errs = [r["error"] for s in _contact()["ladder"]["results"] for n, r in _ladder(s).items() if n.endswith(":norr")]
    return 100 * min(errs), 100 * max(errs)


def _speedup_gp() -> tuple[float, float]:
    """Run time of the integral law over the generalised Padé law's, per scene: the smallest and the largest."""
    x = [_ladder(s)["integral"]["run_s"] / _ladder(s)["generalised_pade"]["run_s"] for s in _contact()["ladder"]["results"]]
    return min(x), max(x)


def _uncoupled_steps() -> tuple[float, float]:
    """Steps of Coulomb and Coulomb + spin over the generalised Padé law's on the fixed-table scenes."""
    x = [
        _ladder(s)[law]["steps"] / _ladder(s)["generalised_pade"]["steps"]
        for s in ("spin_reversal", "fast_spin")
        for law in ("coulomb", "coulomb_spin")
    ]
    return min(x), max(x)


QUOTES = [
    # docs/contact-laws.md (scripts/contact_study.py -> docs/contact/summary.json)
    (
        CL,
        lambda: (
            f"the generalisation beats Padé, {_cal('pade')['rms'] / _cal('generalised_pade')['rms']:.1f}× lower RMS with "
            f"the Hertz S_i ({_cal('pade+S')['rms'] / _cal('generalised_pade+S')['rms']:.1f}× when Padé may also bend the S_i"
        ),
    ),
    (CL, lambda: f"Energy drift over 20 s at rtol 1e-12: {_kl('-5.0')['energy_rel_drift_max']:.1e}"),
    (
        CL,
        lambda: (
            f"Then ω3(0) = −5 rad/s reverses (first at t ≈ {_kl('-5.0')['first_reversal_t']:.2f} s, ω3(20 s) = "
            f"{_kl('-5.0')['w3_final']:.2f}) while +5 rad/s never reverses in 20 s (ω3(20 s) = {_kl('5.0')['w3_final']:.2f})"
            if _kl("5.0")["first_reversal_t"] is None
            else "+5 rad/s reverses"
        ),
    ),
    *[(CL, lambda rung=rung: _ladder_row(rung)) for rung in
      ("integral", "generalised_pade", "pade", "coulomb_spin", "coulomb", "generalised_pade:norr", "coulomb:norr", "noslip")],
    (
        CL,
        lambda: (
            f"nothing cheaper than the integral law is within {100 * _contact()['ladder']['tol']:.0f} % for the fast spin "
            f"(generalised Padé {100 * _ladder('fast_spin')['generalised_pade']['errors']['tilt']:.0f} %, tilt amplitude)"
        ),
    ),
    (CL, lambda: f"and {100 * _ladder('fast_spin')['noslip']['error']:.0f} % off on the fast spin"),
    # notebooks/03_contact_laws.ipynb (the same summary.json)
    (
        NB03,
        lambda: (
            f"each step is far cheaper — {_speedup_gp()[0]:.0f}–{_speedup_gp()[1]:.0f}× faster here; it is within "
            f"{100 * _ladder('spin_reversal')['generalised_pade']['error']:.0f} % on the spin reversal and within "
            f"{100 * max(_ladder(s)['generalised_pade']['error'] for s in ('base14', 'base19')):.1f} % on the vibrating base"
        ),
    ),
    (
        NB03,
        lambda: (
            f"are within {100 * _contact()['ladder']['tol']:.0f} % and take the same number of steps"
            if all(_ladder("base19")[law]["error"] <= _contact()["ladder"]["tol"] for law in ("pade", "coulomb"))
            else "not within the tolerance"
        ),
    ),
    (
        NB03,
        lambda: (
            f"spin reversal (Padé {100 * _ladder('spin_reversal')['pade']['error']:.0f} %, Coulomb + spin "
            f"{100 * _ladder('spin_reversal')['coulomb_spin']['error']:.0f} %)"
        ),
    ),
    (
        NB03,
        lambda: (
            f"nothing cheaper is within {100 * _contact()['ladder']['tol']:.0f} % (generalised Padé "
            f"{100 * _ladder('fast_spin')['generalised_pade']['errors']['tilt']:.0f} %, in the tilt amplitude)"
        ),
    ),
    (NB03, lambda: f"rungs are {_norr_range()[0]:.0f}–{_norr_range()[1]:.0f} % off"),
    (
        NB03,
        lambda: (
            f"slower* than the generalised Padé law: {_uncoupled_steps()[0]:.0f}–{_uncoupled_steps()[1]:.0f}× more steps"
        ),
    ),
    (NB03, lambda: f"the stone reverses after about {_kl('-5.0')['first_reversal_t']:.0f} s"),
]

SETTINGS = [
    # the scenes' horizons (jaxcelt.studies.ladder.builtin_scenes) and the simulated span of the no-slip run
    (CL, "ω3(0) = −4 rad/s, 3 s"),
    (CL, "the paper's vibrating base from rest, 1.5 s"),
    (CL, "ω3(0) = +25 rad/s, 1 s"),
    # recommend's tie band (jaxcelt.studies.ladder.recommend)
    (NB03, "laws within 25 % of the fastest count as a tie"),
    (NB03, "over 1.5 s from rest"),
]


# ---- docs/internals/studies.md (result files in docs/performance/) ----


def _perf(name: str):
    return _json(f"docs/performance/{name}")


def _sp(n) -> str:
    """An integer with a space as thousands separator."""
    return f"{round(n):,}".replace(",", " ")


def _wp_runs(scene: str, solver: str | None = None) -> list[dict]:
    sc = next(s for s in _perf("work_precision.json")["scenes"] if s["scene"] == scene)
    return [r for r in sc["runs"] if "run_s" in r and (solver is None or r["solver"] == solver)]


def _wp_run(scene: str, solver: str, rtol: float) -> dict:
    return next(r for r in _wp_runs(scene, solver) if r["rtol"] == rtol)


def _fewest(scene: str, solver: str, target: float) -> int:
    return min(r["rhs_evals"] for r in _wp_runs(scene, solver) if r["status"] == 0 and r["error"] <= target)


def _d8_gain(target: float, scenes: tuple[str, ...]) -> tuple[float, float]:
    """Tsit5's fewest RHS evaluations over Dopri8's at a target error: the smallest and largest over the scenes."""
    x = [_fewest(s, "Tsit5", target) / _fewest(s, "Dopri8", target) for s in scenes]
    return min(x), max(x)


_SLIDING = ("rest14", "rest17", "rest19", "spin_reversal")


def _gain_text() -> str:
    a, b = _d8_gain(1e-8, ("rest14", "rest17", "spin_reversal"))
    c, d = _d8_gain(1e-10, _SLIDING)
    tie = _d8_gain(1e-8, ("rest19",))[0]
    assert 0.9 < tie < 1.1  # "where they tie"
    return f"{a:.1f}–{b:.1f}× fewer at 1e-8 except on rest19, where they tie, and {c:.1f}–{d:.1f}× fewer at 1e-10"


def _chord_pairs():
    """(chord, Newton) Kvaerno5 runs at rtol 1e-4 and 1e-6 on rest17 and stick-slip."""
    return [
        (_wp_run(s, "Kvaerno5-chord", t), _wp_run(s, "Kvaerno5-Newton", t))
        for s in ("rest17", "stick_slip")
        for t in (1e-4, 1e-6)
    ]


def _chord_ratio() -> str:
    x = [c["steps"] / n["steps"] for c, n in _chord_pairs()]
    return f"{min(x):.0f}–{max(x):.0f}×"


def _chord_text() -> str:
    p = _chord_pairs()
    st = lambda r: f"{_sp(r['accepted'])} + {_sp(r['rejected'])}"  # noqa: E731
    t = lambda r: f"{r['run_s']:.1f} s"  # noqa: E731
    return (
        f"Kvaerno5-chord on rest17 needs {st(p[0][0])} steps at rtol 1e-4 and {st(p[1][0])} at 1e-6 ({t(p[0][0])}, "
        f"{t(p[1][0])}) against Kvaerno5-Newton's {st(p[0][1])} and {st(p[1][1])} ({t(p[0][1])}, {t(p[1][1])}); on "
        f"stick–slip {st(p[2][0])} and {st(p[3][0])} ({t(p[2][0])}, {t(p[3][0])}) against {st(p[2][1])} and "
        f"{st(p[3][1])} ({t(p[2][1])}, {t(p[3][1])})"
    )


def _laws_run(law: str, solver: str, rtol: float) -> dict:
    L = next(x for x in _perf("work_precision.json")["laws"] if x["law"] == law)
    return next(r for r in L["runs"] if r["solver"] == solver and r.get("rtol") == rtol)


_CLOSED = ("generalised_pade", "pade", "coulomb_spin", "coulomb")


def _laws_steps_text() -> str:
    acc = [_laws_run(law, "Tsit5", 1e-8)["accepted"] for law in ("generalised_pade", "pade", "coulomb", "integral")]
    cs = _laws_run("coulomb_spin", "Tsit5", 1e-8)["accepted"]
    gp = _laws_run("generalised_pade", "Tsit5", 1e-8)["accepted"]
    d8 = _laws_run("coulomb_spin", "Dopri8", 1e-8)["accepted"] / _laws_run("generalised_pade", "Dopri8", 1e-8)["accepted"]
    return (
        f"(within {100 * (max(acc) / min(acc) - 1):.0f} %: Tsit5 at rtol 1e-8 takes {_sp(min(acc))}–{_sp(max(acc))} accepted "
        f"steps with generalised Padé, Padé, Coulomb and the integral law), except Coulomb + spin ({_sp(cs)}, "
        f"+{100 * (cs / gp - 1):.0f} %; Dopri8 +{100 * (d8 - 1):.0f} %)"
    )


def _laws_time_text() -> str:
    def span(rtol, fmt):
        x = [_laws_run(law, "Tsit5", rtol)["run_s"] for law in _CLOSED]
        return f"{min(x):{fmt}}–{max(x):{fmt}}"

    return (
        f"takes {_laws_run('integral', 'Tsit5', 1e-8)['run_s']:.2f} s for Tsit5 at rtol 1e-8 against {span(1e-8, '.2f')} s "
        f"for the closed-form laws, and {_laws_run('integral', 'Tsit5', 1e-12)['run_s']:.1f} s against "
        f"{span(1e-12, '.2f')} s at 1e-12"
    )


def _stick_1e4_text() -> str:
    imp = [r for r in _wp_runs("stick_slip") if r["kind"] == "implicit" and "Newton" in r["solver"] and r["error"] <= 1e-4]
    ts = min((r for r in _wp_runs("stick_slip", "Tsit5") if r["error"] <= 1e-4), key=lambda r: r["run_s"])
    t = [r["run_s"] for r in imp]
    n = [r["rhs_evals"] for r in imp]
    return (
        f"(Kvaerno3/5-Newton, {min(t):.1f}–{max(t):.1f} s, {_sp(round(min(n), -2))}–{_sp(round(max(n), -2))} counted "
        f"evaluations + Jacobians) and Tsit5 (~{ts['run_s']:.1f} s, {_sp(round(ts['rhs_evals'], -3))} evaluations)"
    )


def _kv3_text() -> str:
    st = [_wp_run("rest17", "Kvaerno3-Newton", t)["steps"] for t in (1e-4, 1e-6, 1e-8)]
    g = (st[2] / st[0]) ** 0.5
    return f"needs ~{g:.0f}× more steps per 100× tolerance (rest17: {_sp(st[0])} → {_sp(st[1])} → {_sp(st[2])} steps"


def _stab_cells() -> list[dict]:
    """Part (a)'s cells merged as jaxcelt.plotting.results.stability_results merges them."""
    cells: list[dict] = []
    for tag in ("a", "a_implicit", "a_eps1e-10"):
        for r in _perf(f"stability_{tag}.json")["rows"]:
            if r.get("kind") != "cell":
                continue
            old = [c for c in cells if c["method"] == r["method"] and c["eps"] == r["eps"]]
            if tag == "a_eps1e-10" and old and old[0]["verdict"] not in ("unverified", "not run"):
                continue
            cells = [c for c in cells if c not in old] + [r]
    return cells


def _stab(method: str, eps: float) -> dict:
    return next(c for c in _stab_cells() if c["method"] == method and c["eps"] == eps)


_EPS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10)


def _stab_row(method: str) -> str:
    cells = []
    for eps in _EPS:
        c = _stab(method, eps)
        if c["verdict"] == "not run":
            cells.append(f"not run ({c['why']})")
        elif c["verdict"] == "failed":
            cells.append(f"**failed**: {c['accepted']:,}+{c['rejected']:,} (max_steps), {c['run_s']:.3g} s")
        else:
            cells.append(f"{c['verdict']}: {c['accepted']:,}+{c['rejected']:,}, err {c['error_vs_ref']:.0e}, {c['run_s']:.3g} s")
    return f"| {method} | " + " | ".join(cells) + " |"


def _chord_newton_stab() -> str:
    x = [_stab("Kvaerno5-chord rtol 1e-06", e)["steps"] / _stab("Kvaerno5-Newton rtol 1e-06", e)["steps"] for e in _EPS]
    return f"{min(x):.0f}–{max(x):.0f}×"


def _grad(w: int, periods: int) -> dict:
    return next(r for r in _perf("stability_d.json")["rows"] if r.get("kind") == "grad" and r["omega_pi"] == w and r["periods"] == periods)


def _peer(name: str, rtol: float, file: str = "peers.json") -> dict:
    return next(r for r in _perf(file)["single"] if r["name"] == name and r["rtol"] == rtol)


def _scal(name: str, lanes: int, file: str = "peers.json") -> dict:
    return next(r for r in _perf(file)["scaling"] if r["name"].startswith(name) and r["lanes"] == lanes)


def _mj(scene: str) -> dict:
    return {r["name"]: r for r in _perf("mujoco.json")["scenes"][scene]["runs"]}


def _ms(x: float) -> str:
    x *= 1e3
    return f"{x:.1f}" if x < 10 else f"{x:.0f}"


def _mj_row(scene: str, label: str) -> str:
    r = _mj(scene)
    j = r["jaxcelt Tsit5 rtol 1e-8"]
    cols = ("MuJoCo Euler dt 0.002", "MuJoCo Euler dt 0.0002", "MuJoCo RK4 dt 0.002")
    return f"| {label} | {_ms(j['run_s_per_sim_s'])} ({_sp(j['steps'])}) | " + " | ".join(_ms(r[c]["run_s_per_sim_s"]) for c in cols) + " |"


def _mj_ratio(col: str) -> list[float]:
    return [_mj(s)["jaxcelt Tsit5 rtol 1e-8"]["run_s_per_sim_s"] / _mj(s)[col]["run_s_per_sim_s"] for s in _perf("mujoco.json")["scenes"]]


def _mjx_text() -> str:
    m = _perf("mujoco_mjx.json")["mjx"]
    one = next(r for r in m if r["lanes"] == 1)
    many = [r["run_s_per_sim_s_per_lane"] for r in m if r["lanes"] >= 16]
    c = [r["compile_s"] for r in m]
    euler = _mj("rest17")["MuJoCo Euler dt 0.002"]["run_s_per_sim_s"]
    return (
        f"1 lane {one['run_s_per_sim_s_per_lane']:.2f} s per simulated second ({one['run_s_per_sim_s_per_lane'] / euler:.0f}× "
        f"MuJoCo's C loop); 16–1024 lanes {min(many):.3f}–{max(many):.3f} s per lane-simulated-second, i.e. "
        f"{1 / max(many):.0f}–{1 / min(many):.0f} simulated seconds per wall second at any batch size; compile "
        f"{min(c):.0f}–{max(c):.0f} s"
    )


def _idle_row(lanes: int) -> str:
    j, n = _scal("jaxcelt", lanes, "peers_idle.json"), _scal("numba", lanes, "peers_idle.json")
    return (
        f"| {_sp(lanes)} | {j['lanes_per_s']:.0f}, {j['compile_s']:.1f} s | {_sp(n['lanes_per_s'])} | "
        f"{n['lanes_per_s'] / j['lanes_per_s']:.1f} |"
    )


def _idle_ratios() -> dict:
    """Each peer's ratio (run time over jaxcelt Tsit5's) at equal accuracy in the idle run."""
    ea = _perf("peers_idle.json")["equal_accuracy"]
    return ea


QUOTES += [
    (
        ST,
        lambda: (
            lambda r: (
                f"| fixed-table spin reversal, ω0 = (0, 2, −10) rad/s | {r['ts'][-1]:g} s | {r['max_agreement']:.1e} | "
                f"{'all' if r['trusted_index'] == len(r['ts']) - 1 else 'not all'} | {_sp(r['A']['steps'])} | {_sp(r['B']['nfev'])} |"
            )
        )(next(r for r in _perf("reference.json")["results"] if r["scene"] == "spin_reversal")),
    ),
    (
        ST,
        lambda: (
            f"Dopri8 on rest17 took {1e3 * _wp_run('rest17', 'Dopri8', 1e-3)['run_s']:.0f} ms at rtol 1e-3 and "
            f"{1e3 * _wp_run('rest17', 'Dopri8', 1e-11)['run_s']:.0f} ms at 1e-11"
        ),
    ),
    *[
        (ST, lambda s=s: "### " + next(x for x in _perf("work_precision.json")["scenes"] if x["scene"] == s)["description"])
        for s in ("spin_reversal", "spin_reversal_long")
    ],
    (
        ST,
        lambda: (
            lambda f32: f"rest17, Tsit5 rtol 1e-6: {1e3 * f32['run_s']:.0f} ms float32 vs "
            f"{1e3 * _wp_run('rest17', 'Tsit5', 1e-6)['run_s']:.0f} ms float64"
        )(
            next(
                r
                for f in _perf("work_precision.json")["float32"]
                if f["scene"] == "rest17"
                for r in f["runs"]
                if r["solver"] == "Tsit5" and r["rtol"] == 1e-6
            )
        ),
    ),
    (ST, _laws_steps_text),
    (ST, _laws_time_text),
    (ST, _gain_text),
    (
        ST,
        lambda: (
            f"Tsit5 at rtol 1e-5 gives a smaller error ({_wp_run('rest17', 'Tsit5', 1e-5)['error']:.1e} on rest17 in "
            f"{1e3 * _wp_run('rest17', 'Tsit5', 1e-5)['run_s']:.0f} ms, {_wp_run('rest19', 'Tsit5', 1e-5)['error']:.1e} on rest19)"
        ).replace("e-0", "e-"),
    ),
    (ST, _stick_1e4_text),
    (ST, _chord_text),
    (ST, lambda: f"only because it takes {_chord_ratio()} more steps"),
    (ST, lambda: f"Kvaerno5 takes {_chord_ratio()} more steps than with full Newton"),
    (ST, _kv3_text),
    *[
        (ST, lambda m=m: _stab_row(m))
        for m in (
            "Tsit5 rtol 1e-06",
            "Tsit5 rtol 1e-08",
            "Dopri8 rtol 1e-06",
            "Kvaerno5-chord rtol 1e-06",
            "Kvaerno5-Newton rtol 1e-06",
            "Kvaerno5-Newton rtol 1e-08",
        )
    ],
    (ST, lambda: f"needs {_chord_newton_stab()} the steps of Newton"),
    (
        ST,
        lambda: (
            lambda k6, t6, k8, t8: f"({k6['run_s']:.2f} vs {t6['run_s']:.2f} s at ε = 1e-6, {k8['run_s']:.1f} vs "
            f"{t8['run_s']:.1f} s at 1e-8, for {t8['steps'] / k8['steps']:.0f}× fewer steps)"
        )(
            _stab("Kvaerno5-Newton rtol 1e-06", 1e-6),
            _stab("Tsit5 rtol 1e-06", 1e-6),
            _stab("Kvaerno5-Newton rtol 1e-06", 1e-8),
            _stab("Tsit5 rtol 1e-06", 1e-8),
        ),
    ),
    (
        ST,
        lambda: (
            lambda rows: (
                lambda k, k_loaded, t: f"It wins at ε = 1e-10: {k['run_s']:.1f} s ({k_loaded['run_s']:.1f} s in another, "
                f"more loaded run) against {t['run_s']:.1f} s for Tsit5's {_sp(t['steps'])} steps"
            )(
                next(r for r in rows("a_eps1e-10") if r["method"] == "Kvaerno5-Newton rtol 1e-06"),
                next(r for r in rows("a_implicit") if r["method"] == "Kvaerno5-Newton rtol 1e-06" and r["eps"] == 1e-10),
                next(r for r in rows("a_eps1e-10") if r["method"] == "Tsit5 rtol 1e-06"),
            )
        )(lambda tag: [r for r in _perf(f"stability_{tag}.json")["rows"] if r.get("kind") == "cell"]),
    ),
    *[
        (
            ST,
            lambda i=i: (
                lambda sc: f"({sc['rho_percentiles_10_50_90'][1]:.0f}) | {round(100 * sc['frac_samples_rho_above_half_max'], 1):g} %"
            )([r for r in _perf("stability_b.json")["rows"] if r.get("kind") == "scene"][i]),
        )
        for i in range(3)
    ],
    (
        ST,
        lambda: (
            lambda rows: "(n3 ≤ 0 at t = {:.2f} / {:.2f} / {:.2f} s)".format(
                rows["f32"]["first_invalid_t"], rows["f64_loose"]["first_invalid_t"], rows["f32"]["first_invalid_t_f64"]
            )
        )({r["run"]: r for r in _perf("stability_c.json")["rows"] if r.get("omega_pi") == 19}),
    ),
    (ST, lambda: f"~{round(_grad(19, 16)['grad'] / _grad(19, 8)['grad'], -2):.0f}× at ω_π = 19"),
    (
        ST,
        lambda: (
            lambda r: f"with {100 * r['rejected'] / (r['accepted'] + r['rejected']):.0f} % of the steps rejected at δ = 1e-7"
        )(next(r for r in _perf("stability_e.json")["rows"] if r.get("case", "").startswith("n2 -> 1") and r.get("x") == 1e-7)),
    ),
    (
        ST,
        lambda: (
            f"numba DP5: {1e3 * _peer('numba DP5 (hand-written)', 1e-6)['run_s']:.1f} ms at rtol 1e-6, "
            f"{1e3 * _peer('numba DP5 (hand-written)', 1e-5)['run_s']:.1f} ms at 1e-5"
        ),
    ),
    (
        ST,
        lambda: (
            lambda n, j: (
                lambda ns, js: f"is {1e3 * n['run_s']:.1f} ms for {ns} steps, {1e6 * n['run_s'] / ns:.1f} µs per step, "
                f"{1e6 * n['run_s'] / n['rhs_evals']:.1f} µs per RHS evaluation — no framework overhead at all. jaxcelt's "
                f"least-disturbed Tsit5 run is {1e3 * j['run_s']:.1f} ms for {js} steps, ~{1e6 * j['run_s'] / js:.0f} µs per step"
            )(round((n["rhs_evals"] - 1) / 6), round((j["rhs_evals"] - 1) / 6))
        )(_peer("numba DP5 (hand-written)", 1e-6), _peer("jaxcelt Tsit5", 1e-7)),
    ),
    (
        ST,
        lambda: (
            f"4096 lanes: {_scal('jaxcelt', 4096)['run_s']:.0f} s, "
            f"{_scal('jaxcelt', 4096)['run_s'] / _scal('jaxcelt', 1024)['run_s']:.1f}× the 1024-lane time for 4× the lanes"
        ),
    ),
    (
        ST,
        lambda: (
            lambda j, n: f"{min(j):.0f}–{max(j):.0f} s for jaxcelt at every size (the spread is load noise), "
            f"{min(n):.1f}–{max(n):.1f} s for numba"
        )(
            [r["compile_s"] for r in _perf("peers.json")["scaling"] if r["name"].startswith("jaxcelt")],
            [r["compile_s"] for r in _perf("peers.json")["scaling"] if r["name"].startswith("numba")],
        ),
    ),
    (
        ST,
        lambda: _mj_row(
            "rest17", f"from rest, ω_π = 17, 20 periods ({_perf('mujoco.json')['scenes']['rest17']['sim_s']:.2f} s)"
        ),
    ),
    (
        ST,
        lambda: _mj_row(
            "spin_reversal", f"fixed table, ω0 = (0, 2, −10) rad/s, {_perf('mujoco.json')['scenes']['spin_reversal']['sim_s']:g} s"
        ),
    ),
    (
        ST,
        lambda: _mj_row(
            "spin_right_way", f"fixed table, ω0 = (0, 2, +10) rad/s, {_perf('mujoco.json')['scenes']['spin_right_way']['sim_s']:g} s"
        ),
    ),
    (ST, _mjx_text),
    (
        ST,
        lambda: (
            lambda a, b: f"at {min(a):.0f}–{max(a):.0f}× less cost per simulated second with its default 2 ms Euler step, "
            f"and at {min(b):.1f}–{max(b):.1f}× jaxcelt's cost with a 0.2 ms step"
        )(_mj_ratio("MuJoCo Euler dt 0.002"), [1 / x for x in _mj_ratio("MuJoCo Euler dt 0.0002")]),
    ),
    *[(ST, lambda n=n: _idle_row(n)) for n in (1, 64, 1024)],
]


def _idle_ea(target: str) -> dict:
    return {r["name"]: r["ratio_vs_jaxcelt"] for r in _perf("peers_idle.json")["equal_accuracy"][target]}


def _idle_reading() -> str:
    lib = ("CVODE Adams + numba RHS", "scipy LSODA + numba RHS", "CVODE BDF + numba RHS", "scipy DOP853 + numba RHS")
    ea = [_idle_ea(t) for t in ("1e-05", "1e-08")]
    x = [e[n] for e in ea for n in lib]
    py = [e["scipy DOP853 + Python RHS (interpreted)"] for e in ea]
    nb = [1 / e["numba DP5 (hand-written)"] for e in ea]
    return (
        f"({min(x):.1f}–{max(x):.1f}×: ties at the 1e-5 target go to CVODE/LSODA, at 1e-8 jaxcelt Dopri8/Tsit5 are "
        f"ahead of them), {min(py):.0f}–{max(py):.0f}× faster than the interpreted-Python route, and "
        f"{min(nb):.0f}–{max(nb):.0f}× slower than a hand-written numba loop"
    )


QUOTES += [
    (ST, _idle_reading),
    (
        ST,
        lambda: (
            f"loop (2 threads) is ~{_scal('numba', 1024, 'peers_idle.json')['lanes_per_s'] / _scal('jaxcelt', 1024, 'peers_idle.json')['lanes_per_s']:.0f}× faster"
        ),
    ),
    (
        ST,
        lambda: (
            lambda i, l: f"jaxcelt compiled in {min(i):.1f}–{max(i):.1f} s here ({min(l):.0f}–{max(l):.0f} s under load above)"
        )(
            [r["compile_s"] for r in _perf("peers_idle.json")["scaling"] if r["name"].startswith("jaxcelt")],
            [r["compile_s"] for r in _perf("peers.json")["scaling"] if r["name"].startswith("jaxcelt")],
        ),
    ),
    (
        ST,
        lambda: (
            lambda lam: f"λ ≈ {lam[0]:.1f} s⁻¹)" if len({f"{x:.1f}" for x in lam}) == 1 else "λ differs"
        )([r["exponent"] for r in _perf("stability_d.json")["rows"] if r.get("kind") == "lyapunov"]),
    ),
    (
        ST,
        lambda: (
            lambda x: f"where Tsit5 is {min(x):.1f}–{max(x):.1f}× cheaper"
        )([_fewest("stick_slip", "Dopri8", t) / _fewest("stick_slip", "Tsit5", t) for t in (1e-4, 1e-6, 1e-8, 1e-10)]),
    ),
    (ST, lambda: f"Dopri8 would need {_d8_gain(1e-8, ('rest14', 'rest17', 'spin_reversal'))[0]:.1f}–{_d8_gain(1e-8, ('rest14', 'rest17', 'spin_reversal'))[1]:.1f}× fewer evaluations"),
    (
        ST,
        lambda: (
            f"({_d8_gain(1e-8, ('rest14', 'rest17', 'spin_reversal'))[0]:.1f}–{_d8_gain(1e-8, ('rest14', 'rest17', 'spin_reversal'))[1]:.1f}× "
            f"fewer than Tsit5 at 1e-8, {_d8_gain(1e-10, _SLIDING)[0]:.1f}–{_d8_gain(1e-10, _SLIDING)[1]:.1f}× at 1e-10)"
        ),
    ),
]

SETTINGS += [
    # scene horizons, sample spacing, budgets and time steps chosen for the studies (inputs of the scripts)
    (ST, "the fixed-table spin scene over 1.25 s (5 samples every 0.25 s"),
    (ST, "over 2.5 s through the reversal"),
    (ST, "run slower than 10 s, or after 300 s of wall time"),
    (ST, "(1 for runs over 2 s)"),
    (ST, "ε₃₂ = 1.2e-7 × state scale"),  # float32's machine epsilon, a constant
    (ST, "spin reversal to 1.25 s"),
    (ST, "Through the spin reversal (2.5 s"),
    (ST, "spin scene up to 1.25 s"),
    (ST, "spin reversal (2.5 s:"),
    (ST, "with a 300 s cell budget"),
    (ST, "one base period (0.37 s)"),
    (ST, "constant steps dt = 1e-2 … 2e-6 s"),
    (ST, "at 32 periods (11.8 s)"),
    (ST, "half a base period (0.185 s)"),
    (ST, "within 0.185 s"),
    (ST, "Treat ratios within ~3× as ties"),  # the page's reading rule for the loaded run
    (ST, "2 periods (0.739 s simulated)"),
    (ST, "(0.37 s simulated each"),
    (ST, "370 steps of 2 ms"),
    (ST, "in MuJoCo over 2.5 s"),
    (ST, "in the last 0.5 s"),
    (ST, "240 s scaling budget"),
    (ST, "(the 2.5 s scene)"),
    (ST, "by its 300 s budget"),
]


# ---- the work–precision tables of docs/internals/studies.md §2 (benchmarks/work_precision.py --report) ----


def _wp_best(scene: str, target: float, key: str, explicit_only: bool = False) -> list[dict]:
    """Per solver the successful run reaching ``target`` with the least ``key``; the solvers ordered by it."""
    ok = [
        r
        for r in _wp_runs(scene)
        if r["status"] == 0
        and r.get("error") is not None
        and r["error"] <= target
        and r.get(key) is not None
        and not (explicit_only and r["kind"] == "implicit")
    ]
    best = {s: min((r for r in ok if r["solver"] == s), key=lambda r: r[key]) for s in {r["solver"] for r in ok}}
    return sorted(best.values(), key=lambda r: r[key])


def _wp_label(r: dict) -> str:
    how = f"rtol {r['rtol']:.0e}" if r.get("rtol") is not None else f"dt {r['dt0']:g} s"
    return f"{r['solver']} {how}"


def _wp_table_row(scene: str, target: float) -> str:
    """One row of a scene's 'cheapest run reaching each target error' table."""
    fast = _wp_best(scene, target, "run_s")
    fewest = _wp_best(scene, target, "rhs_evals", explicit_only=True)[0]
    cell = lambda r: f"{_wp_label(r)}: {1e3 * r['run_s']:.0f} ms, err {r['error']:.1e}"  # noqa: E731
    return f"| {target:.0e} | {cell(fast[0])} | {cell(fast[1])} | {_wp_label(fewest)}: {_sp(fewest['rhs_evals'])} |"


QUOTES += [
    (ST, lambda s=s, t=t: _wp_table_row(s, t))
    for s in ("rest14", "rest17", "rest19", "spin_reversal", "spin_reversal_long", "stick_slip")
    for t in (1e-4, 1e-6, 1e-8, 1e-10)
]


def _laws_ref_text() -> str:
    """The integral law's reference run and its first (compiling) run per solver."""
    L = next(x for x in _perf("work_precision.json")["laws"] if x["law"] == "integral")
    c = [max(r["compile_s"] for r in L["runs"] if r["solver"] == s and "run_s" in r) for s in ("Tsit5", "Dopri8")]
    ref = _perf("work_precision.json")["references"]["rest17/5/integral"]
    return f"(reference {_sp(ref['steps'])} steps, compile {min(c):.0f}–{max(c):.0f} s per solver)"


def _rejected_text() -> str:
    x = [
        100 * r["rejected"] / (r["accepted"] + r["rejected"])
        for s in _SLIDING
        for r in _wp_runs(s)
        if r["kind"] == "explicit"
    ]
    return f"{min(x):.0f}–{max(x):.0f} % of explicit steps are rejected on the non-stiff scenes"


def _stab_ref(eps: float, tag: str = "a") -> dict:
    return next(
        r
        for r in _perf(f"stability_{tag}.json")["rows"]
        if r.get("kind") == "reference" and r["method"].startswith("Dopri8") and r["eps"] == eps
    )


def _stick_wrong_text() -> str:
    e = [
        r["error_vs_ref"]
        for r in _perf("stability_b.json")["rows"]
        if r.get("kind") == "cell" and r["scene"].startswith("stick-slip") and r["dt"] >= 2e-4
    ]
    return f"(stick–slip: errors {min(e):.1e} … {max(e):.2g} for dt ≥ 2e-4 s)".replace("e-0", "e-")


def _f32_invalid_text() -> str:
    import math

    r = next(r for r in _perf("stability_c.json")["rows"] if r["omega_pi"] == 19 and r["run"] == "f32")
    lo = _perf("stability_c.json")["rows"]
    t = [x["first_invalid_t"] for x in lo if x["omega_pi"] == 19] + [r["first_invalid_t_f64"]]
    per = (min(t) + max(t)) / 2 * 19 / (2 * math.pi)
    return f"at {min(t):.1f}–{max(t):.1f} s (≈ {per:.0f} periods)"


def _tip_text() -> str:
    rows = [r for r in _perf("stability_e.json")["rows"] if r.get("case", "").startswith("tilt towards") and r["x"] >= 85]
    t = ", ".join(f"{r['first_invalid_t']:.2g}" for r in rows)
    n = [r["steps"] for r in rows]
    return f'half-surface (n3 ≤ 0)" at t = {t} s, the solve itself reports success ({min(n)}–{max(n)} steps)'


def _k5n8_eps10_text() -> str:
    import re

    why = _stab("Kvaerno5-Newton rtol 1e-08", 1e-10)["why"]
    pred = re.search(r"predicted (\d+) s", why).group(1)
    return f"1e-8, ε = 1e-10 was not run (predicted {pred} s)"


QUOTES += [
    (
        ST,
        lambda: (
            lambda r: f"1e-8 took {_sp(round(r['steps'], -2))} steps and {r['run_s']:.0f} s on rest17"
        )(_wp_run("rest17", "Kvaerno3-Newton", 1e-8)),
    ),
    (
        ST,
        lambda: (
            lambda t: f"Kvaerno5-Newton at rtol 1e-4 takes {min(t):.1f}–{max(t):.1f} s on rest17/rest19"
        )([_wp_run(s, "Kvaerno5-Newton", 1e-4)["run_s"] for s in ("rest17", "rest19")]),
    ),
    (ST, _laws_ref_text),
    (ST, _rejected_text),
    (
        ST,
        lambda: (
            f"at ε = 1e-8 it took {_sp(_stab_ref(1e-8)['steps'])} steps; at ε = 1e-10 it needs "
            f"{_sp(_stab_ref(1e-10, 'a_eps1e-10')['steps'])} steps ({_stab_ref(1e-10, 'a_eps1e-10')['run_s']:.0f} s)"
        ),
    ),
    (
        ST,
        lambda: (
            lambda a, b: f"it is ok to ε = 1e-6 ({_sp(a['steps'])} steps) but needs {_sp(b['steps'])} steps "
            f"({100 * b['rejected'] / b['steps']:.0f} % rejected) at ε = 1e-8"
        )(_stab("Kvaerno5-Newton rtol 1e-08", 1e-6), _stab("Kvaerno5-Newton rtol 1e-08", 1e-8)),
    ),
    (ST, _stick_wrong_text),
    (ST, _f32_invalid_text),
    (ST, _tip_text),
    (ST, _k5n8_eps10_text),
]

SETTINGS += [
    # the no-slip energy test's tolerance and horizon (tests/test_noslip.py::test_energy_conserved_10s)
    (CL, "(test: ≤ 1e-10 over 10 s)"),
]


# ---- docs/internals/studies.md §1–§3: reference table, conditions, float32, contact-law family, observations ----


def _e(x: float, p: int = 1) -> str:
    """A number in the page's short exponent form: 3.9e-5 (no leading zero in the exponent)."""
    import re

    return re.sub(r"e([+-])0*(\d)", lambda m: f"e{'-' if m.group(1) == '-' else ''}{m.group(2)}", f"{x:.{p}e}")


def _ref_row(scene: str, periods: int) -> str:
    """A row of §1's reference-agreement table (benchmarks/reference.py -> reference.json)."""
    r = next(x for x in _perf("reference.json")["results"] if x["scene"] == scene and x["periods"] == periods)
    p = r["params"]
    if scene.startswith("rest"):
        label = f"from rest, ω_π = {p['omega_pi']:g} | {periods} periods"
    else:  # stick_slip: 'periods' counts samples, T/5 apart
        label = (
            f"stick–slip, q_π = {p['q_pi']:g} m, ε = ε_R = {_e(p['eps'], 0)} | {periods // 5} periods ({periods} samples)"
        )
    trusted = "all" if r["trusted_index"] == len(r["ts"]) - 1 else "not all"
    return f"| {label} | {_e(r['max_agreement'])} | {trusted} | {_sp(r['A']['steps'])} | {_sp(r['B']['nfev'])} |"


def _ref_growth_text() -> str:
    x = [r["max_agreement"] for r in _perf("reference.json")["results"] if r["periods"] == 50]
    import math

    return f"(≈ 1e-13 → {math.floor(min(x) * 1e9)}–{math.ceil(max(x) * 1e9)}e-9 over 50 periods"


def _all_wp_runs() -> list[dict]:
    w = _perf("work_precision.json")
    return [r for part in ("scenes", "float32", "laws") for g in w[part] for r in g["runs"] if "run_s" in r]


def _f32(scene: str) -> list[dict]:
    return next(f for f in _perf("work_precision.json")["float32"] if f["scene"] == scene)["runs"]


def _f32_run(scene: str, solver: str, rtol: float) -> dict:
    return next(r for r in _f32(scene) if r["solver"] == solver and r["rtol"] == rtol)


def _f32_best(scene: str, solver: str) -> dict:
    return min((r for r in _f32(scene) if r["solver"] == solver and r["status"] == 0), key=lambda r: r["error"])


def _f32_floor_text() -> str:
    b = {(s, v): _f32_best(s, v) for s in ("rest17", "stick_slip") for v in ("Dopri8", "Tsit5")}
    floor = lambda s: _e(min(b[(s, "Dopri8")]["error"], b[(s, "Tsit5")]["error"]), 0)  # noqa: E731
    cell = lambda s, v: f"{v} at {'rtol ' if (s, v) == ('rest17', 'Dopri8') else ''}{_e(b[(s, v)]['rtol'], 0)} ({_e(b[(s, v)]['error'])})"  # noqa: E731
    return (
        f"float32 floors at an error of ~{floor('rest17')} (rest17) and ~{floor('stick_slip')} (stick–slip)**: the best "
        f"float32 runs are {cell('rest17', 'Dopri8')} and {cell('rest17', 'Tsit5')} on rest17, "
        f"{cell('stick_slip', 'Dopri8')} and {cell('stick_slip', 'Tsit5')} on stick–slip"
    )


def _f32_match_text() -> str:
    a, b = _f32_run("rest17", "Tsit5", 1e-5), _wp_run("rest17", "Tsit5", 1e-5)
    c, d = _f32_run("stick_slip", "Tsit5", 1e-5), _wp_run("stick_slip", "Tsit5", 1e-5)
    return (
        f"(rest17, Tsit5 rtol 1e-5: {_e(a['error'], 2)} vs {_e(b['error'], 2)}; stick–slip, Tsit5 1e-5: "
        f"{_e(c['error'])} vs {_e(d['error'])})"
    )


def _f32_budget_text() -> str:
    r = _f32_run("rest17", "Dopri8", 1e-8)
    assert r["status"] != 0 and _f32_run("stick_slip", "Dopri8", 1e-8)["status"] != 0
    assert _f32_run("stick_slip", "Tsit5", 1e-8)["status"] != 0
    return (
        f"(rest17 Tsit5 1e-8: {_e(_f32_run('rest17', 'Tsit5', 1e-8)['error'])}) and rejected steps explode because "
        f"round-off noise"
    ), (
        f"hit the {_sp(r['accepted'] + r['rejected'])}-step budget on both scenes (rest17: {_sp(r['accepted'])} accepted, "
        f"{_sp(r['rejected'])} rejected; status {r['status']}, no result)"
    )


def _f32_table_row(scene: str, solver: str, dtype: str) -> str:
    """A row of the float32-vs-float64 table as benchmarks/work_precision.py --report prints it."""
    rtols = _perf("work_precision.json")["config"]["f32_rtols"]
    rr = _f32(scene) if dtype == "float32" else _wp_runs(scene)
    by = {r["rtol"]: r for r in rr if r["solver"] == solver and "run_s" in r}
    cells = [
        "" if t not in by else f"{by[t]['error']:.1e}" + ("" if by[t]["status"] == 0 else " (fail)") for t in rtols
    ]
    return " ".join((f"| {scene} | {solver} {dtype} | " + " | ".join(cells) + " |").split())  # the page collapses spaces


def _laws_d8_text() -> str:
    """Dopri8 and Tsit5 at rtol 1e-8 over the five laws: RHS evaluations (to hundreds) and errors."""

    def span(solver):
        rr = [_laws_run(L["law"], solver, 1e-8) for L in _perf("work_precision.json")["laws"]]
        n = [round(r["rhs_evals"], -2) for r in rr]
        e = [r["error"] for r in rr]
        exp = int(f"{max(e):.1e}".split("e")[1])
        return f"{_sp(min(n))}–{_sp(max(n))}", f"{min(e) / 10**exp:.1f}–{max(e) / 10**exp:.1f}e{exp}"

    (nd, ed), (nt, et) = span("Dopri8"), span("Tsit5")
    return f"(rtol 1e-8: Dopri8 {nd} evaluations for errors {ed}, Tsit5 {nt} for {et})"


def _laws_table_row(law: str, r: dict) -> str:
    return (
        f"| {law} | {r['solver']} | {r['rtol']:.0e} | {r['error']:.2e} | {r['accepted']}+{r['rejected']} | "
        f"{_sp(r['rhs_evals'])} | {1e3 * r['run_s']:.1f} | {r['compile_s']:.1f} |"
    )


def _laws_rows() -> list[tuple[str, dict]]:
    return [(L["law"], r) for L in _perf("work_precision.json")["laws"] for r in L["runs"] if "run_s" in r]


def _ratio_text() -> str:
    """error/rtol of Tsit5 (and Dopri8) at rtol ≤ 1e-7 per scene, and of Tsit5 at rtol 1e-3 … 1e-5 on the from-rest scenes."""
    import math

    def q(scene, solver, lo, hi):
        return [
            r["error"] / r["rtol"] for r in _wp_runs(scene, solver) if r["status"] == 0 and lo <= r["rtol"] <= hi
        ]

    def span(scene, f1, f2):
        x = q(scene, "Tsit5", 0, 1e-7)
        return f"{min(x):{f1}}–{max(x):{f2}}"

    d8 = max(x for s in _wp_scene_names() for x in q(s, "Dopri8", 0, 1e-7))
    loose = [max(q(s, "Tsit5", 1e-5, 1e-3)) for s in ("rest14", "rest17", "rest19")]
    dec = max(abs(math.log10(x)) for s in _wp_scene_names() for v in ("Tsit5", "Dopri8") for x in q(s, v, 0, 1e-7))
    return (
        f"Tsit5's error/rtol ratio (rtol ≤ 1e-7) is {span('rest17', '.0f', '.1f')} on rest17, {span('rest14', '.0f', '.1f')} "
        f"on rest14, {span('rest19', '.1f', '.1f')} on rest19, {span('spin_reversal', '.1f', '.0f')} on the spin scene "
        f"({span('spin_reversal_long', '.0f', '.0f')} through the reversal) and {span('stick_slip', '.1f', '.1f')} on "
        f"stick–slip; Dopri8's is ≤ {d8:.1f} everywhere. At loose tolerances (1e-3 … 1e-5) the ratio reaches "
        f"{min(loose):.0f}–{max(loose):.0f} on the from-rest scenes. A tolerance buys an error within ~{dec:.1f} decades"
    )


def _wp_scene_names() -> list[str]:
    return [s["scene"] for s in _perf("work_precision.json")["scenes"]]


def _fixed_text() -> str:
    """RK4/Heun fixed-step errors: convergence on the short spin scene, the stall on rest17 and the long spin scene."""
    import math

    def ladder(scene, solver):
        return sorted(_wp_runs(scene, solver), key=lambda r: -r["dt0"])

    def order(rr):
        return math.log(rr[0]["error"] / rr[-1]["error"]) / math.log(rr[0]["dt0"] / rr[-1]["dt0"])

    rk, he = ladder("spin_reversal", "RK4-fixed"), ladder("spin_reversal", "Heun-fixed")
    us = lambda r: f"{1e6 * r['dt0']:.0f} µs"  # noqa: E731
    r17 = ladder("rest17", "RK4-fixed")[-3:]
    lg = ladder("spin_reversal_long", "RK4-fixed")[-3:]
    return (
        f"RK4 converges ({_e(rk[0]['error'])} at dt = {1e3 * rk[0]['dt0']:g} ms → {_e(rk[-1]['error'])} at {us(rk[-1])}, "
        f"measured order ≈ {order(rk):.1f}) and Heun at order {order(he):.1f} ({_e(he[0]['error'])} → {_e(he[-1]['error'])}). "
        f"On the driven from-rest scenes both **stall at ~1e-4** (RK4 on rest17: {_e(r17[0]['error'])} at dt = {us(r17[0])}, "
        f"{_e(r17[1]['error'])} at {us(r17[1])}, {_e(r17[2]['error'])} at {us(r17[2])}), and so does RK4 through the spin "
        f"reversal (2.5 s: {_e(lg[0]['error'])} at {us(lg[0])}, {_e(lg[1]['error'])} at {us(lg[1])}, {_e(lg[2]['error'])} "
        f"at {us(lg[2])})"
    )


def _stick_fixed_text() -> str:
    e = [r["error"] for v in ("RK4-fixed", "Heun-fixed") for r in _wp_runs("stick_slip", v)]
    return f"errors stay ≥ {_e(min(e))}"


def _k5_same_error_text() -> str:
    a, b = (_wp_run(s, "Kvaerno5-Newton", 1e-4)["error"] for s in ("rest17", "stick_slip"))
    assert _e(a, 2) == _e(b, 2)
    return f"Kvaerno5-Newton at rtol 1e-4 gives the same error, {_e(a, 2)}, on rest17 and stick–slip"


QUOTES += [
    (
        ST,
        lambda: (
            f"re-run with a load average of {_perf('peers_idle.json')['versions']['loadavg_start'][0]:.1f} at the start"
        ),
    ),
    *[(ST, lambda s=s, n=n: _ref_row(s, n)) for s in ("rest14", "rest17", "rest19") for n in (5, 50)],
    (ST, lambda: _ref_row("stick_slip", 15)),
    (ST, _ref_growth_text),
    (
        ST,
        lambda: (
            lambda la: f"the 1-min load average recorded with every run was **{min(la):.1f}–{max(la):.1f}** during this study"
        )([r["loadavg_1min"] for r in _all_wp_runs()]),
    ),
    (ST, _f32_floor_text),
    (ST, _f32_match_text),
    (ST, lambda: _f32_budget_text()[0]),
    (ST, lambda: _f32_budget_text()[1]),
    *[
        (ST, lambda s=s, v=v, t=t: _f32_table_row(s, v, t))
        for s in ("rest17", "stick_slip")
        for v in ("Tsit5", "Dopri8")
        for t in ("float32", "float64")
    ],
    (ST, _laws_d8_text),
    *[(ST, lambda i=i: _laws_table_row(*_laws_rows()[i])) for i in range(50)],
    (ST, _ratio_text),
    (ST, _fixed_text),
    (ST, _stick_fixed_text),
    (ST, _k5_same_error_text),
]

SETTINGS += [
    # RK4's stability interval on the negative real axis (a constant of the method) over the friction relaxation
    # rate 355/√ε computed just before it on the page
    (ST, "dt ≲ 2.8/(3.6e4 s⁻¹)"),
]

QUOTES += [
    # §2's stick–slip heading is the scene's description in work_precision.json
    (ST, lambda: "### " + next(x for x in _perf("work_precision.json")["scenes"] if x["scene"] == "stick_slip")["description"]),
]


def _stick_slip_steps() -> str:
    """Section 3: steps of Kvaerno5-Newton and of Tsit5 (rtol 1e-6 to 1e-10) on the stick-slip scene."""
    runs = next(s for s in _json("docs/performance/work_precision.json")["scenes"] if s["scene"] == "stick_slip")["runs"]
    f64 = [r for r in runs if "steps" in r and r["dtype"] == "float64" and r["law_name"] == "generalised_pade"]
    k5 = {r["rtol"]: r["steps"] for r in f64 if r["solver"] == "Kvaerno5-Newton"}
    ts = [r["steps"] for r in f64 if r["solver"] == "Tsit5" and 1e-10 * 0.99 <= r["rtol"] <= 1e-6 * 1.01]
    return (
        f"Kvaerno5-Newton takes {k5[1e-4]} and {k5[1e-6]} steps at rtol 1e-4 and 1e-6 against "
        f"{min(ts):,}–{max(ts):,} for Tsit5 at rtol 1e-6 to 1e-10".replace(",", " ")
    )


QUOTES.append((ST, _stick_slip_steps))
