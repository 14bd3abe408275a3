"""Numbers quoted in the README and the guides against the committed result files they come from.

Each check recomputes a quoted number from its JSON file (or from the test collection) and asserts
that the document contains it as written. A failure means a result file was regenerated (or a test
added) without updating the prose, or the prose was edited without a result behind it. The quoted texts are
registered in ``tests/docs_quotes`` (one module per group of pages); ``scripts/results_index.py`` checks that
every measured number on the site lies inside one of them.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from docs_quotes import QUOTES, SETTINGS
from docs_quotes.files import DOCS, ROOT, _json, _starts, _text  # noqa: F401

_DOCS = sorted({d for d, _ in QUOTES} | {d for d, _ in SETTINGS})


@pytest.mark.parametrize("doc", _DOCS)
def test_quoted_numbers_match_their_result_files(doc):
    """Every registered quote of one document, recomputed from its result file, is in the document as written;
    every declared setting is still written there. All mismatches of the document are reported at once."""
    text = _prose(doc)  # line breaks in prose are spaces; a notebook's markdown cells
    missing = []
    for d, quote in QUOTES:
        if d == doc:
            expected = quote()
            if expected not in text:
                missing.append(f"should quote {expected!r} (from its result file)")
    for d, phrase in SETTINGS:
        # a number declared a setting (an input, not a result) must still be written where the registry says
        if d == doc and " ".join(phrase.split()) not in text:
            missing.append(f"should contain the setting {phrase!r}")
    assert not missing, f"{doc}:\n" + "\n".join(missing)


def test_attractor_census_table_from_census_json():
    import importlib.util

    spec = importlib.util.spec_from_file_location("attractor_census", ROOT / "scripts" / "attractor_census.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    text = _text("docs/orbits/README.md")
    for line in mod.markdown_table(_json("docs/orbits/census.json")).splitlines():
        assert line in text, f"docs/orbits/README.md should contain {line!r} (from census.json)"


def test_heading_study_has_sixteen_headings_and_a_roll():
    # "17 starts: rest at 16 headings and a 2° roll" (README, paper-reproduction.md)
    starts = _starts()
    assert sum(s.startswith("rest psi0=") for s in starts) == 16
    assert starts - {s for s in starts if s.startswith("rest psi0=")} == {"roll 2deg"}


def _paper_study():
    import importlib.util

    spec = importlib.util.spec_from_file_location("paper_study", ROOT / "scripts" / "paper_study.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_best_paper_score_by_the_readme_rule():
    """The paper score quoted in the README and docs/paper-reproduction.md: the README's labelling rule
    (period-k, else lambda_1 -+ 2 stderr against 0.02 1/s) re-applied to every stored row, strict score first.
    Rows with a standard error decide the headline; point-estimate-only files can score one more (the 17 rad/s
    lane the standard error makes uncertain), as the document says."""
    ps = _paper_study()
    best = {True: [0, 0], False: [0, 0]}  # has stderr -> [strict, allowed]
    for f in sorted((DOCS / "paper-reproduction").glob("study_*.json")):
        d = json.loads(f.read_text())
        assert d["labelling_rule"].startswith("README"), f.name
        rows = [dict(r) for r in d["rows"]]
        for r in rows:  # the stored labels are the rule's
            se = r.get("lyapunov_stderr")
            assert ps.relabel(r["strict"], r["lyapunov"], se) == r["strict"], (f.name, r)
            assert ps.relabel(r["allowed"], r["lyapunov"], se) == r["allowed"], (f.name, r)
        has_se = all("lyapunov_stderr" in r for r in rows)
        for t in ps.score_table(rows):
            best[has_se][0] = max(best[has_se][0], t["score_strict"])
            best[has_se][1] = max(best[has_se][1], t["score_allowed"])
    assert best[True] == [4, 5]
    assert best[False][0] <= 5
    for doc in ("README.md", "docs/paper-reproduction.md"):
        flat = " ".join(_text(doc).split())
        assert f"{best[True][0]} of 8" in flat and f"{best[True][1]} of 8" in flat, doc
    flat = " ".join(_text("docs/paper-reproduction.md").split())
    assert f"{best[True][0]} of 8 labels with the model's validity enforced" in flat


def test_repository_url_is_declared_once_and_used_by_the_notebooks():
    url = tomllib.loads(_text("pyproject.toml"))["project"]["urls"]["Repository"]
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        src = "".join("".join(c["source"]) for c in json.loads(nb.read_text())["cells"] if c["cell_type"] == "code")
        installs = re.findall(r"%pip install[^\n]*", src)
        assert installs and all(f"git+{url}" in line for line in installs), nb.name
    cff = _text("CITATION.cff")
    assert f'repository-code: "{url}"' in cff
    assert "10.5890/DNC.2014.06.002" in cff and "10.5890/DNC.2014.06.002" in _text("docs/MODEL.md")


def test_notebook_results_are_shipped_with_the_package():
    # every result file notebook 05 reads (jaxcelt.studies.benchmarking.RESULT_FILES) is committed and force-included
    from jaxcelt.plotting.results import RESULT_FILES

    forced = tomllib.loads(_text("pyproject.toml"))["tool"]["hatch"]["build"]["targets"]["wheel"]["force-include"]
    for name in RESULT_FILES:
        assert (DOCS / "performance" / name).is_file(), name
        assert forced[f"docs/performance/{name}"] == f"jaxcelt/_results/performance/{name}"


def test_readme_test_count():
    # "The second runs the default test suite (N tests, ...)": the number pytest collects with -m "not slow"
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-m", "not slow", "-p", "no:cacheprovider"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    m = re.search(r"(\d+)/\d+ tests collected", out) or re.search(r"(\d+) tests collected", out)
    assert m, out[-500:]
    quoted = re.search(r"default test suite \((\d+) tests", _text("README.md"))
    assert quoted and int(quoted[1]) == int(m[1]), f"README says {quoted and quoted[1]}, pytest collects {m[1]}"


def test_gpu_table_from_gpu_map_json():
    """Every GPU run in docs/performance/gpu_map.json appears in the engine's GPU table (times to 0.1 s,
    pool iterations with a space as thousands separator)."""
    text = _text("docs/internals/sweep-engine.md")
    runs = [r for r in _json("docs/performance/gpu_map.json")["runs"] if "run_s" in r]
    assert len(runs) == 5
    for r in runs:
        row = f"| {r['grid'][0]} × {r['grid'][1]} | {r['periods']} | {r['dtype']}"
        assert row in text, row
        for quote in (f"{r['compile_s']:.1f} s", f"{r['run_s']:.1f} s", f"{r['steps_max']:,}".replace(",", " ")):
            assert quote in text, quote


def test_sensor_study_numbers_from_json():
    """The sensor-axes study's summary in docs/identification.md against docs/fit/sensor_study.json."""
    text = " ".join(_text("docs/identification.md").split())
    d = _json("docs/fit/sensor_study.json")
    s = d["summary"]
    quotes = [f"Over {s['seeds']} noise seeds {s['converged']} fits converge"]
    quotes += [f"{n} {100 * s[n]['median_rel_err']:.2f} %" for n in ("mu", "k_r", "b_Ts", "m_Ts")]
    quotes += [f"{n} {100 * s[n]['coverage']:.0f} %" for n in ("mu", "k_r", "b_Ts", "m_Ts")]
    quotes += [f"components {100 * s['rotation']['coverage']:.0f} % and the offsets {100 * s['time_offset']['coverage']:.0f} %"]
    quotes += [f"s² = {d['whole_record_fit_seed0']['s2']:.0f}", f"compilation {s['run_s_median']:.1f} s"]
    for q in quotes:
        assert q in text, q


def test_fit_benchmark_table_from_json():
    """The optimiser x problem table in docs/identification.md is the one benchmarks/bench_fit.py
    prints from docs/fit/bench_fit.json, and the multi-start numbers come from docs/fit/multistart.json."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench_fit", Path(__file__).parents[1] / "benchmarks" / "bench_fit.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    text = _text("docs/identification.md")
    for line in bench.table(_json("docs/fit/bench_fit.json")["rows"]).splitlines():
        assert line in text, line
    ms = {r["mode"]: r for r in _json("docs/fit/multistart.json")["rows"]}
    flat = " ".join(text.split())
    for mode in ("vmapped", "sequential"):
        r = ms[mode]
        assert f"{mode}: compile {r['compile_s']:.1f} s, run {r['run_s']:.1f} s" in flat, mode
    assert f"{ms['vmapped']['n_at_best']} of {ms['vmapped']['n_starts']} starts" in flat


def test_gpu_projection_from_step_census_json():
    """The projection of the 400 x 400 map in the engine's GPU section against
    docs/performance/map_step_census.json (benchmarks/map_step_census.py), and the bounds against the step
    counts and the GPU rates they are made of (1e-3 relative: the JSON rounds to 0.1 s)."""
    text = " ".join(_text("docs/internals/sweep-engine.md").split())
    d = _json("docs/performance/map_step_census.json")
    p, q, r, sb = d["projection"], d["projection_without_stiff_lanes"], d["stiff_rerun"], d["stiff_box"]
    rate = d["rates"]["widest_pool_slot_steps_per_s"]
    gpu = [x for x in _json("docs/performance/gpu_map.json")["runs"] if "run_s" in x and x["width"] == 160000]
    assert rate == max(round(x["lanes"] * x["steps_max"] / x["run_s"]) for x in gpu if x["dtype"] == "float64")
    assert p["work_bound_s"] == pytest.approx(d["steps_mean"] * 160000 / rate, rel=1e-3)
    assert p["latency_bound_s"] == pytest.approx(
        d["steps_max"] * d["rates"]["narrowest_pool_us_per_iteration"] * 1e-6, rel=1e-3
    )

    def sp(n):
        return f"{n:,}".replace(",", " ")

    quotes = [
        f"{d['grid'][0]} × {d['grid'][1]} grid of the same box ({d['periods']} periods",
        f"{d['wall_s_including_compile']:.1f} s on the 2-core CPU",
        f"{sp(round(d['steps_mean']))} steps on average (median {sp(round(d['steps_quantiles']['q50']))})",
        f"at least {p['work_bound_s']:.1f} s, even with every slot busy",
        f"{p['slot_step_rate_needed_x']:.2f}× the measured slot-step rate",
        f"({d['stiff_lanes_at_max_steps']} of {d['lanes']})",
        f"least {p['latency_bound_s']:.1f} s.",
        f"{d['stiff_lanes']} of {d['lanes']} lanes, ω_π ≤ {sb['omega_pi'][1]:.1f} rad/s",
        f"q_π ≤ {sb['q_pi'][1]:.3f} m",
        f"carry {100 * d['stiff_share_of_steps']:.1f} % of the steps",
        f"bounds are {q['work_bound_s']:.1f} s and {q['latency_bound_s']:.1f} s",
        f"takes {sp(q['longest_lane_steps'])} steps",
        f"in at most {sp(r['steps_max'])} steps against {sp(r['tsit5_steps_max'])}",
        f"{r['steps_total'] / 1e6:.1f} M in all against {r['tsit5_steps_total'] / 1e6:.1f} M",
        f"took {r['wall_s_including_compile']:.0f} s with Kvaerno5",
        f"{q['slot_step_rate_needed_x']:.2f}× (without the sticking lanes) to {p['slot_step_rate_needed_x']:.2f}× (with them)",
    ]
    for quote in quotes:
        assert quote in text, quote


def test_map_window_check_from_json():
    """The window check in docs/map/README.md against docs/map/lyapunov_window_check.json
    (scripts/map_lyapunov_check.py)."""
    text = " ".join(_text("docs/map/README.md").split())
    d = _json("docs/map/lyapunov_window_check.json")
    s, runs = d["summary"], d["runs"]
    low = [i for i, lane in enumerate(d["lanes"]) if lane["group"] == "low"]
    per = [i for i in low if runs["long_transient"]["label"][i].startswith("period")]
    assert len(per) == s["low_periodic_after_long_transient"]

    def rng(run, idx):
        v = [runs[run]["lyapunov_per_s"][i] for i in idx if runs[run]["lyapunov_per_s"][i] is not None]
        return f"{min(v):.2f} to {max(v):.2f}".replace("-", "−")

    cm = s["chaotic_median_lyapunov_per_s"]
    fl = d["floquet"]["orbits"]
    fe = [o["floquet_exponent_per_s"] for o in fl]
    mu = [o["max_multiplier"] for o in fl]
    lo, lg = s["low_labels"], runs["long_lyapunov"]
    err_map = [runs["map"]["lyapunov_stderr_per_s"][i] for i in low]
    band = [i for i, lane in enumerate(d["lanes"]) if lane["group"] == "chaotic"]
    band_chaotic = [i for i in band if runs["map"]["label"][i] == "chaotic"]
    quotes = [
        f"runs {s['low_lanes']} lanes of the lower left",
        f"From the point estimate with the map's windows {s['low_chaotic_with_map_windows']} of the {s['low_lanes']} lanes are chaotic",
        f"After 300 transient periods {s['low_periodic_after_long_transient']} of the {s['low_lanes']} are period-1",
        f"({sum(runs['map']['label_point_estimate'][i] == 'chaotic' for i in per)} of these were chaotic",
        f"over 160 periods their λ₁ is {rng('long_lyapunov', per)} s⁻¹",
        f"converges for all {s['floquet_converged_stable']} to stable orbits with |μ_max| {min(mu):.3f}–{max(mu):.3f}",
        f"Floquet exponents {min(fe):.3f} to {max(fe):.3f} s⁻¹ ({d['floquet']['seconds']:.1f} s for the {len(fl)})".replace("-", "−"),
        f"for {s['floquet_within_2_stderr']} of {s['floquet_orbits']}",
        f"λ₁ over 10 periods is {rng('long_transient', per)} s⁻¹",
        f"({sum(runs['long_transient']['lyapunov_per_s'][i] > 0.02 for i in per)} of {len(per)} above",
        f"With the map's windows all {lo['map']['uncertain']} lanes are *uncertain*",
        f"(standard errors {min(err_map):.2f}–{max(err_map):.2f} s⁻¹)",
        f"over 160 periods {lo['long_lyapunov']['converging']} are *converging*, {lo['long_lyapunov']['uncertain']} "
        f"*uncertain* and {lo['long_lyapunov']['chaotic']} *chaotic*",
        f"All {s['chaotic_chaotic_with_both_windows']} lanes there are chaotic by the point estimate with both windows",
        f"from {cm['map']:.2f} s⁻¹ over 10 periods to {cm['lyapunov_40']:.2f} over 40 and {cm['long_lyapunov']:.3f} over 160",
        f"again {cm['long_transient']:.2f} s⁻¹",
        f"By the sweeps' rule {len(band_chaotic)} of the {len(band)} are still *chaotic* with the map's windows",
        " and ".join(f"{runs['map']['lyapunov_per_s'][i]:.2f} ± {runs['map']['lyapunov_stderr_per_s'][i]:.2f}" for i in band_chaotic),
        f"all {s['chaotic_labels']['long_lyapunov']['uncertain']} are *uncertain* over 40 and 160 periods",
        f"the 19 lanes take {runs['map']['seconds']:.1f} s with λ₁ over 10 periods and {lg['seconds']:.1f} s over",
    ]
    assert s["chaotic_labels"]["lyapunov_40"] == {"uncertain": len(band)}
    assert lo["lyapunov_40"] == {"uncertain": s["low_lanes"]}
    for quote in quotes:
        assert quote in text, quote


def test_gpu_kernel_table_from_json():
    """The lane kernel's GPU table and bullets in the engine's docs against docs/performance/gpu_map_kernel.json
    (benchmarks/gpu_map.py; times to 0.1 s, counts with a space as thousands separator)."""
    text = _text("docs/bifurcation/README.md")
    flat = " ".join(text.split())
    d = _json("docs/performance/gpu_map_kernel.json")

    def sp(n):
        return f"{n:,}".replace(",", " ")

    maps = [r for r in d["machine_2"] if "grid" in r]
    f64 = next(r for r in maps if r["dtype"] == "float64")
    f32 = next(r for r in maps if r["dtype"] == "float32")
    earlier = next(r for r in d["machine_1"] if "grid" in r and r["dtype"] == "float64")
    final = {r["dtype"]: r for r in d["machine_4"] if "grid" in r}
    for r in (f64, f32, earlier, final["float64"], final["float32"]):
        st = r["status_counts"]
        row = (f"{r['compile_s']:.1f} s", f"{r['run_s']:.1f} s", sp(round(r["lanes_per_s"])),
               f"{r['steps_total'] / 1e10:.3f} × 10¹⁰", sp(round(r["steps_median"])),
               f"{sp(st['0'])} / {sp(st['1'])} / {sp(st['2'])}")  # fmt: skip
        key = f"| {r['compile_s']:.1f} s | {r['run_s']:.1f} s |"
        rows = [ln.replace("**", "") for ln in text.splitlines()]  # bold run times
        line = next((ln for ln in rows if f"| {r['dtype']}, " in ln and key in ln), "")
        for q in row:
            assert q in line, (q, line)
    assert earlier["steps_total"] == f64["steps_total"] == final["float64"]["steps_total"]  # "the same number of lane-steps"
    chk32 = next(r["check"] for r in d["machine_4"] if "check" in r)["float32"]
    comp = next(r["comparison"] for r in d["machine_2"] if "comparison" in r)
    chk = next(r["check"] for r in d["machine_1"] if "check" in r)["float64"]
    quotes = [
        f"**The float64 map in {f64['run_s']:.1f} s, {earlier['run_s']:.1f} s and {final['float64']['run_s']:.1f} s**",
        f"64 of 64 the same status, step counts within {chk32['max_step_difference']} of each other, samples within "
        f"{chk32['max_sample_difference_rel']:.1e}".replace("e-0", "e-"),
        f"{sp(f64['status_counts']['1'])} sticking lanes stop at max_steps",
        f"all {chk['same_status']} lanes had the same status and the same step count",
        f"within {chk['max_sample_difference_rel']:.1e}",
        f"is {f64['run_s'] / f32['run_s']:.1f}× faster",
        f"status in {100 * comp['same_status_fraction']:.1f} % of the cells and its category in "
        f"{100 * comp['same_category_fraction']:.1f} %",
        f"{sp(f64['regime_counts']['period 3-16'])} cells in float64, {f32['regime_counts']['period 3-16']} in float32",
    ]
    side = {r["engine"]: r for r in d["machine_3"] if "grid" in r}  # equal work, one machine
    k, p = side["auto"], side["pool"]
    assert k["engine_used"] == "kernel" and p["engine_used"] == "pool" and k["periods"] == p["periods"]
    quotes += [
        f"the kernel {k['run_s']:.1f} s, the pool {p['run_s']:.1f} s (**{p['run_s'] / k['run_s']:.1f}×**)",
        f"({k['compile_s']:.1f} s and {p['compile_s']:.1f} s); {sp(k['steps_total'])} against {sp(p['steps_total'])} lane-steps",
    ]
    broken = next(r for r in d["machine_1"] if "grid" in r and r["dtype"] == "float32")  # times still float32
    quotes.append(f"collapsed the step of {sp(broken['status_counts']['3'])} of its {sp(broken['lanes'])} lanes")
    assert chk["same_steps"] == chk["same_status"] == 64
    for q in quotes:
        assert q in flat, q
    for path in ("README.md", "docs/map/README.md", "docs/performance.md"):  # the headline number elsewhere
        assert f"{f64['run_s']:.1f} s" in _text(path), path


def test_float32_periodic_check_from_json():
    """The float32-vs-float64 periodic-cell check quoted in the engine's GPU section against
    docs/performance/float32_periodic_check.json (scripts/float32_periodic_check.py)."""
    flat = " ".join(_text("docs/bifurcation/README.md").split())
    cells = _json("docs/performance/float32_periodic_check.json")["cells"]

    def span(run):
        g = [c[run]["gap_at_float64_period"] for c in cells]
        return f"{min(g):.1e}–{max(g):.1e}".replace("e-0", "e-")

    assert all(c["float64_rtol1e-8"]["regime"] == c["float64_rtol1e-6"]["regime"] == "periodic" for c in cells)
    assert all(c["float32_rtol1e-6"]["regime"] == "aperiodic" for c in cells)
    for q in (f"{len(cells)} such cells", f"to {span('float64_rtol1e-8')} in float64 at rtol 1e-8",
              f"to {span('float64_rtol1e-6')} at rtol 1e-6", f"only to {span('float32_rtol1e-6')} (aperiodic)"):
        assert q in flat, q


def _prose(doc: str) -> str:
    """A document's text as a reader reads it (a notebook: its markdown cells), lines joined."""
    if doc.endswith(".ipynb"):
        cells = json.loads(_text(doc))["cells"]
        return " ".join(" ".join("".join(c["source"]) for c in cells if c["cell_type"] == "markdown").split())
    return " ".join(_text(doc).split())
