"""The results index: every measured number the docs quote, the result file it comes from and the command that made it.

    python scripts/results_index.py                    # print the counts
    python scripts/results_index.py --show             # ... and every unverified number with its context
    python scripts/results_index.py --check            # exit 1 if a quoted number is unverified (the tests run this)
    python scripts/results_index.py --out results.md   # write the index page (the site builds it the same way)

The site's "Results index" page is this script's page, made when the site is built (``scripts/mkdocs_hooks.py``),
so it always describes the files and the code of the build.

A *quoted number* is a number in the prose of a site page, the README or a notebook's text that is either a measured
quantity — a time (``12.3 s``, ``450 ms``, ``2 min``), a ratio (``2.12×``), a percentage (``17.7 %``), a step count
in millions (``35.2 M``) — or any number written with a decimal point or an exponent (a fraction, an exponent, an
error, a located parameter value). Each one must be either

* **verified**: it lies inside a text that ``tests/test_docs_numbers.py`` recomputes from a committed result file
  (the ``QUOTES`` registry in ``tests/docs_quotes``: document, text computed from the file); the index records which files each such text reads,
  the command that wrote each file (its ``provenance`` block, else the script that writes that file) and whether
  the file is older than the code it describes; or
* **a setting**: an input rather than a result (``t = 300 s``, ``a threshold of 0.02 s⁻¹``, ``1 s gyro records``),
  recognised by the words just before it (``INPUT_CONTEXT``), by being a power of ten (a tolerance), a version or
  section number, or one of the paper's parameter values (``PAPER_VALUES``), or lying inside a phrase of the
  registry's ``SETTINGS`` list (document, phrase: each phrase must occur in its document). The model specification
  (``SPECIFICATION_PAGES``) quotes the paper's equations and parameters, not results.

Everything else is *unverified*, and ``--check`` (run by the test suite) fails on it. The changelog is not scanned:
its entries keep the numbers of their time.
"""

from __future__ import annotations

import argparse
import importlib
import json
import re
import subprocess
import sys
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

# A measured quantity: a number with a unit of time, a ratio, a percentage or millions of steps.
NUMBER = re.compile(
    r"(?<![\w.])(\d+(?:[.,]\d+)*)(?:\s?[–-]\s?\d+(?:\.\d+)?)?"  # 12.3, 1,124, 14–17
    r"(?:\s?(?:s|ms|min|h)\b(?!-)|\s?×(?!\s?\d)|\s?%|\s?M\b(?= (?:steps|lane-steps|lanes? ?steps)))"
)
# any other number written with a decimal point or an exponent (a fraction, an exponent, a multiplier, an error)
DECIMAL = re.compile(r"(?<![\w.\-−/])[−-]?(?:\d+\.\d+(?:\s?[eE][−-]?\d+)?|\d+[eE][−-]?\d+)(?![\w.]*\d)(?!\.\d)")
# powers of ten are tolerances, thresholds and smoothing constants (settings); so are version numbers and the
# numbers of sections, equations and figures
_SETTING_NUMBER = re.compile(r"^[−-]?1(?:\.0+)?(?:\s?[eE][−-]?\d+)$")
_LABEL_CONTEXT = re.compile(
    r"(?:jax|jaxlib|python|diffrax|equinox|optimistix|optax|numba|numpy|scipy|cuda|mkdocs|version|v|§|section|"
    r"sections|eq\.|eqs\.|equation|fig\.|figs\.|figure|table|step|A\d+|ε\s?=\s?ε_R\s?=|\d+\.\d+\.\d+\s?[–-])\s*$",
    re.IGNORECASE,
)
# pages that quote no results: the model specification gives the paper's equations and parameters
SPECIFICATION_PAGES = {"docs/MODEL.md"}
# the paper's parameter values (CeltParams.paper()) and forcing frequencies: inputs wherever they appear
PAPER_VALUES = {
    "0.11", "0.025", "0.5436", "0.0002463", "0.0013589", "0.0013747", "0.0001728", "−0.00429", "-0.00429", "9.81",
    "0.006192", "0.1813", "0.2241", "0.4345", "1.196", "0.1498", "0.1121", "0.0589", "0.5305", "0.2476", "0.8161",
    "0.5366", "0.04", "15.6", "17.0",
}


# words before a number that make it a setting, not a result (checked on the 40 characters before it)
INPUT_CONTEXT = re.compile(
    r"(?:\bt|\bt_end|\bT|\bdt|horizon|transient|--[\w-]+|timeout|time limit|at most|threshold|tolerance|noise|"
    r"rtol|atol|ε|eps|±|[<>≤≥])\s*(?:of|=|:|∈|\[)?\s*$",
    re.IGNORECASE,
)


@dataclass
class Quote:
    doc: str
    text: str
    files: list[str] = field(default_factory=list)
    ok: bool = True


def site_documents() -> list[Path]:
    """The pages a reader sees: the site's markdown (docs/), README, CHANGELOG, benchmarks/README, notebooks."""
    pages = sorted(p for p in DOCS.rglob("*.md") if "contact/scene_table" not in p.as_posix())
    return [ROOT / "README.md", *pages, ROOT / "benchmarks" / "README.md", *sorted((ROOT / "notebooks").glob("*.ipynb"))]


def prose(path: Path) -> str:
    """The text a reader reads: markdown without code blocks; a notebook's markdown cells."""
    if path.suffix == ".ipynb":
        nb = json.loads(path.read_text(encoding="utf-8"))
        text = "\n\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown")
    else:
        text = path.read_text(encoding="utf-8")
    text = re.sub(r"```.*?```", " ", text, flags=re.S)  # code blocks: commands and their settings
    text = re.sub(r"`[^`\n]*`", lambda m: " " * len(m.group(0)), text)  # inline code: flags, names
    text = re.sub(r"\]\([^)]*\)", "]()", text)  # link targets
    return " ".join(text.split())


def load_quotes() -> tuple[list[Quote], list[Quote]]:
    """Evaluate the registry's QUOTES (``tests/docs_quotes``), recording the files each quoted text reads."""
    sys.path.insert(0, str(ROOT / "tests"))
    try:
        registry = importlib.import_module("docs_quotes")
    finally:
        sys.path.remove(str(ROOT / "tests"))
    reads: list[str] = []
    original = Path.read_text

    def recording(self, *a, **k):
        p = Path(self).resolve()
        if p.suffix in (".json", ".npz") or (p.suffix == ".md" and "docs" in p.parts and p.parent != DOCS):
            try:
                reads.append(p.relative_to(ROOT).as_posix())
            except ValueError:
                pass
        return original(self, *a, **k)

    quotes = []
    settings = [Quote(doc, " ".join(phrase.split()), [], True) for doc, phrase in registry.SETTINGS]
    Path.read_text = recording
    try:
        for doc, fn in registry.QUOTES:
            reads.clear()
            try:
                text = fn()
            except Exception as e:  # a quote that cannot be computed is reported, not hidden
                quotes.append(Quote(doc, f"<error: {type(e).__name__}: {e}>", [], False))
                continue
            files = sorted({r for r in reads if not r.endswith(".md") or r != doc})
            quotes.append(Quote(doc, " ".join(text.split()), files, True))
    finally:
        Path.read_text = original
    return quotes, settings


def _spans(text: str, phrases: list[Quote]) -> list[tuple[int, int]]:
    return [(m.start(), m.end()) for q in phrases for m in re.finditer(re.escape(_prose_of(q.text)), text)]


def scan(quotes: list[Quote], settings: list[Quote]) -> dict[str, dict]:
    """Per document: quoted numbers, verified / input / unverified (with their context)."""
    by_doc = defaultdict(list)
    for q in quotes:
        by_doc[q.doc].append(q)
    set_by_doc = defaultdict(list)
    for q in settings:
        set_by_doc[q.doc].append(q)
    out = {}
    for path in site_documents():
        rel = path.relative_to(ROOT).as_posix()
        text = prose(path)
        raw = " ".join(path.read_text(encoding="utf-8").split()) if path.suffix != ".ipynb" else text
        n_quotes_found = sum(q.ok and q.text in raw for q in by_doc.get(rel, []))
        covered = _spans(text, by_doc.get(rel, []))  # spans of verified quote texts, in the prose
        declared = _spans(text, set_by_doc.get(rel, []))  # spans of declared settings
        rec = {"verified": [], "input": [], "unverified": [], "quotes": len(by_doc.get(rel, [])), "quotes_found": n_quotes_found}
        for m in _numbers(text):
            ctx = text[max(0, m.start() - 60) : m.end() + 30]
            before = text[max(0, m.start() - 40) : m.start()]
            if any(a <= m.start() and m.end() <= b for a, b in covered):
                rec["verified"].append(m.group(0))
            elif (
                rel in SPECIFICATION_PAGES
                or any(a <= m.start() and m.end() <= b for a, b in declared)
                or INPUT_CONTEXT.search(before)
                or _is_setting_number(m.group(0), before)
            ):
                rec["input"].append(m.group(0))
            else:
                rec["unverified"].append(ctx)
        out[rel] = rec
    return out


def _numbers(text: str) -> list[re.Match]:
    """Measured quantities (NUMBER) and the other decimal numbers (DECIMAL) not inside one, in order."""
    found = list(NUMBER.finditer(text))
    spans = [(m.start(), m.end()) for m in found]
    for m in DECIMAL.finditer(text):
        if not any(a <= m.start() < b for a, b in spans):
            found.append(m)
    return sorted(found, key=lambda m: m.start())


def _is_setting_number(number: str, before: str) -> bool:
    """A power of ten, a version or section number, or one of the paper's parameter values."""
    return bool(
        _SETTING_NUMBER.match(number.strip())
        or number.strip() in PAPER_VALUES
        or _LABEL_CONTEXT.search(before)
    )


def _prose_of(s: str) -> str:
    s = re.sub(r"`[^`\n]*`", lambda m: " " * len(m.group(0)), s)
    return " ".join(s.split())


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout.strip()


def file_record(rel: str) -> dict:
    """What made a result file: its provenance block, else the script that writes it; and its age."""
    path = ROOT / rel
    rec: dict = {"file": rel}
    prov = None
    if path.suffix == ".json":
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            prov = data.get("provenance") if isinstance(data, dict) else None
        except (OSError, ValueError):
            prov = None
    committed = _git("log", "-1", "--format=%h %cs", "--", rel)
    rec["committed"] = committed or "not committed"
    if prov:
        rec["command"] = prov.get("command")
        rec["commit"] = (prov.get("commit") or "")[:10] + (" (dirty tree)" if prov.get("dirty") else "")
        m = prov.get("machine", {})
        rec["machine"] = f"{m.get('accelerator') or m.get('cpu')}, {m.get('cpu_cores')} cores"
        load = prov.get("load_average_at_start") or prov.get("load_average")
        rec["load"] = load[0] if load else None
        base = prov.get("commit")
    else:
        rec["command"] = LEGACY_COMMANDS.get(rel)
        rec["commit"] = None
        rec["machine"] = None
        rec["load"] = None
        # without a recorded commit: the commit that added the file is the latest code it can describe
        base = _git("log", "-1", "--format=%H", "--", rel) or None
    if base:
        changed = _git("rev-list", "--count", f"{base}..HEAD", "--", "jaxcelt")
        rec["code_commits_since"] = int(changed) if changed.isdigit() else None
    else:
        rec["code_commits_since"] = None
    return rec


# The command that wrote each committed result file that records none (files written before the provenance
# block; a new file records its own command). Checked by tests/test_results_index.py: every quoted file is covered.
LEGACY_COMMANDS = {
    "docs/bifurcation/bench_sweep_400x300.json": "python benchmarks/bench_sweep.py --n-freq 400 --periods 300 --out docs/bifurcation",
    "docs/bifurcation/drain.json": "python benchmarks/bench_drain.py --out docs/bifurcation",
    "docs/bifurcation/main_job_compile.json": "python benchmarks/main_job_compile.py",
    "docs/bifurcation/max_steps_study.json": "python benchmarks/max_steps_study.py --out docs/bifurcation",
    "docs/bifurcation/pool_width.json": "python benchmarks/bench_pool_width.py --out docs/bifurcation",
    "docs/bifurcation/processes.json": "python benchmarks/bench_processes.py --out docs/bifurcation",
    "docs/bifurcation/roofline.json": "python benchmarks/roofline.py --out docs/bifurcation",
    "docs/bifurcation/step_parts.json": "python benchmarks/bench_step_parts.py --out docs/bifurcation",
    "docs/bifurcation/vector_width.json": "python benchmarks/vector_width.py --out docs/bifurcation",
    "docs/contact/summary.json": "python scripts/contact_study.py",
    "docs/fit/bench_fit.json": "python benchmarks/bench_fit.py",
    "docs/fit/chaos_multiple_gnd.json": "python scripts/fit_study.py --only chaos",
    "docs/fit/chaos_record.json": "python scripts/fit_study.py --only chaos",
    "docs/fit/chaos_single.json": "python scripts/fit_study.py --only chaos",
    "docs/fit/chaos_single_gnd.json": "python scripts/fit_study.py --only chaos",
    "docs/fit/compare.json": "python scripts/fit_study.py --only compare",
    "docs/fit/compile_parts.json": "python benchmarks/fit_compile_parts.py",
    "docs/fit/coverage.json": "python scripts/fit_study.py --only coverage",
    "docs/fit/gradnorm.json": "python scripts/fit_study.py --only gradnorm",
    "docs/fit/multistart.json": "python benchmarks/bench_multistart.py",
    "docs/fit/records_parallel.json": "python benchmarks/fit_records_parallel.py",
    "docs/fit/recover.json": "python scripts/fit_study.py --only recover",
    "docs/fit/sensor_study.json": "python scripts/fit_sensor_study.py",
    "docs/map/lyapunov_window_check.json": "python scripts/map_lyapunov_check.py",
    "docs/map/map_omega_q_100x60.json": "python scripts/map_study.py",
    "docs/orbits/bifurcation_grad.json": "python scripts/bifurcation_grad.py",
    "docs/orbits/branches.json": "python scripts/orbit_branches.py",
    "docs/orbits/celt_fold_grad.json": "python scripts/celt_fold_grad.py",
    "docs/orbits/census.json": "python scripts/attractor_census.py",
    "docs/orbits/census_long14/census.json": "python scripts/attractor_census.py --out docs/orbits/census_long14 --omega 14",
    "docs/orbits/duffing_cascade.json": "python scripts/duffing_cascade.py",
    "docs/orbits/known_answers.json": "python scripts/periodic_known_answers.py",
    "docs/orbits/orbit_check.json": "python scripts/orbit_check.py",
    "docs/paper-reproduction/figures_psi157.5.json": "python scripts/paper_figures.py",
    "docs/paper-reproduction/study_eps1e-6.json": "python scripts/paper_study.py (its settings are in the file)",
    "docs/paper-reproduction/study_eps1e-8.json": "python scripts/paper_study.py (its settings are in the file)",
    "docs/paper-reproduction/study_eps_large.json": "python scripts/paper_study.py (its settings are in the file)",
    "docs/paper-reproduction/study_long2000.json": "python scripts/paper_study.py (its settings are in the file)",
    "docs/paper-reproduction/study_stageA.json": "python scripts/paper_study.py (its settings are in the file)",
    "docs/paper-reproduction/study_tol1e-10.json": "python scripts/paper_study.py (its settings are in the file)",
    "docs/performance/compile_options.json": "python benchmarks/compile_options.py",
    "docs/performance/float32_periodic_check.json": "python scripts/float32_periodic_check.py",
    "docs/performance/gpu_map.json": "python benchmarks/gpu_map.py (on a GPU)",
    "docs/performance/gpu_map_kernel.json": "python benchmarks/gpu_map.py (on a GPU; records of separate machines)",
    "docs/performance/map_step_census.json": "python benchmarks/map_step_census.py",
    "docs/performance/mujoco.json": "python benchmarks/mujoco_peer.py --out docs/performance",
    "docs/performance/mujoco_mjx.json": "python benchmarks/mujoco_peer.py --out docs/performance",
    "docs/performance/peers.json": "python benchmarks/peers.py --out docs/performance",
    "docs/performance/peers_idle.json": "python benchmarks/peers.py --out docs/performance --lanes 1,64,1024",
    "docs/performance/reference.json": "python benchmarks/reference.py --out docs/performance",
    "docs/performance/stability_a.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/stability_a_eps1e-10.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/stability_a_implicit.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/stability_b.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/stability_c.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/stability_d.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/stability_e.json": "python benchmarks/stability.py --out docs/performance",
    "docs/performance/work_precision.json": "python benchmarks/work_precision.py --out docs/performance",
}


def render(quotes: list[Quote], scanned: dict[str, dict]) -> str:
    files = sorted({f for q in quotes for f in q.files})
    recs = {f: file_record(f) for f in files}
    n_num = sum(len(r["verified"]) + len(r["input"]) + len(r["unverified"]) for r in scanned.values())
    n_ver = sum(len(r["verified"]) for r in scanned.values())
    n_in = sum(len(r["input"]) for r in scanned.values())
    n_un = sum(len(r["unverified"]) for r in scanned.values())
    lines = [
        "# Results index",
        "",
        "Made by `scripts/results_index.py` when the site is built. Every measured number the site, the",
        "README and the notebooks quote (a time, a ratio, a percentage, a step count) is either recomputed from the",
        "result file below by `tests/test_docs_numbers.py`, or is a setting rather than a result. A file that records",
        "no commit predates the provenance block; its *code commits since* counts the commits to `jaxcelt/` after",
        "the commit that added the file — a result older than the code it describes. The changelog is not counted:",
        "its entries keep the numbers of their time.",
        "",
        f"**{len(quotes)} quoted texts** checked against **{len(files)} result files**; over all pages, "
        f"**{n_num} quoted numbers**: {n_ver} verified, {n_in} settings, {n_un} unverified.",
        "",
        "## Result files",
        "",
        "| file | made by | commit | machine | load | code commits since |",
        "|---|---|---|---|---|---|",
    ]
    for f in files:
        r = recs[f]
        lines.append(
            f"| `{f}` | `{r['command'] or '?'}` | {r['commit'] or 'not recorded'} | {r['machine'] or 'not recorded'} "
            f"| {'' if r['load'] is None else r['load']} | {'' if r['code_commits_since'] is None else r['code_commits_since']} |"
        )
    lines += ["", "## Quoted texts, by page", ""]
    by_doc = defaultdict(list)
    for q in quotes:
        by_doc[q.doc].append(q)
    for doc in sorted(by_doc):
        lines += [f"### `{doc}`", "", "| quoted | from |", "|---|---|"]
        for q in by_doc[doc]:
            t = q.text.replace("|", "\\|")
            if len(t) > 140:
                t = t[:137] + "…"
            lines.append(f"| {t} | {', '.join(f'`{f}`' for f in q.files) or '(the test collection)'} |")
        lines.append("")
    lines += [
        "## Quoted numbers per page",
        "",
        "| page | quoted numbers | verified | settings | unverified |",
        "|---|---|---|---|---|",
    ]
    for doc, r in scanned.items():
        n = len(r["verified"]) + len(r["input"]) + len(r["unverified"])
        if n:
            lines.append(f"| `{doc}` | {n} | {len(r['verified'])} | {len(r['input'])} | {len(r['unverified'])} |")
    return "\n".join(lines) + "\n"


def page() -> str:
    """The index page as the site shows it."""
    quotes, settings = load_quotes()
    return render(quotes, scan(quotes, settings))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if a quoted number is unverified")
    ap.add_argument("--show", action="store_true", help="print every unverified number with its context")
    ap.add_argument("--out", type=Path, help="write the index page (markdown) here")
    a = ap.parse_args(argv)
    quotes, settings = load_quotes()
    scanned = scan(quotes, settings)
    unverified = {d: r["unverified"] for d, r in scanned.items() if r["unverified"]}
    if a.show:
        for d, ctxs in unverified.items():
            for c in ctxs:
                print(f"{d}: …{c}…")
    broken = [q for q in quotes if not q.ok]
    for q in broken:
        print(f"{q.doc}: a quoted text could not be computed: {q.text}")
    n_un = sum(map(len, unverified.values()))
    print(
        f"{len(quotes)} quoted texts, {len(settings)} declared settings; quoted numbers: "
        + ", ".join(f"{k} {sum(len(r[k]) for r in scanned.values())}" for k in ("verified", "input", "unverified"))
    )
    if a.out:
        a.out.write_text(render(quotes, scanned), encoding="utf-8")
        print(f"wrote {a.out}")
    if a.check and (n_un or broken):
        print(f"{n_un} quoted numbers are not verified (--show lists them)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
