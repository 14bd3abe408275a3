"""Readers of the committed study results (``docs/performance``, ``docs/orbits``) for the docs and notebooks.

`results_dir` finds them (package data in a wheel, ``docs/`` in a checkout); `load_results` and
`stability_results` read the speed/accuracy study back; `markdown_table` and `cheapest_at_accuracy` shape rows
for reports. Nothing here computes physics.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["RESULT_FILES", "results_dir", "load_results", "stability_results", "markdown_table", "cheapest_at_accuracy"]



_A_ORDER = [
    "Tsit5 rtol 1e-06",
    "Tsit5 rtol 1e-08",
    "Dopri8 rtol 1e-06",
    "Kvaerno5-chord rtol 1e-06",
    "Kvaerno5-Newton rtol 1e-06",
    "Kvaerno5-Newton rtol 1e-08",
]


def stability_results(folder: str = "docs/performance") -> dict[str, list[dict]]:
    """Rows of the stability study (``benchmarks/stability.py``), one list per part a-e.

    Part (a) merges ``stability_a.json`` with the re-runs: a (method, eps) cell is replaced by
    the one in ``stability_a_implicit.json`` (implicit re-run with a larger budget) where that
    file has it, then -- only where the cell was unverified or not run -- by
    ``stability_a_eps1e-10.json`` (eps = 1e-10 with a 3e6-step budget, which lets the reference
    finish; explicit cells keep their 3e5-step verdict so the map has one budget).
    """
    import json
    import pathlib

    out: dict[str, list[dict]] = {}
    folder = pathlib.Path(folder)
    cells: list[dict] = []
    for tag in ("a", "a_implicit", "a_eps1e-10"):
        f = folder / f"stability_{tag}.json"
        if not f.exists():
            continue
        for r in json.loads(f.read_text())["rows"]:
            if r.get("kind") != "cell":
                continue
            old = [c for c in cells if c["method"] == r["method"] and c["eps"] == r["eps"]]
            if tag == "a_eps1e-10" and old and old[0]["verdict"] not in ("unverified", "not run"):
                continue
            cells = [c for c in cells if c not in old] + [r]
    if cells:
        key = lambda r: (_A_ORDER.index(r["method"]) if r["method"] in _A_ORDER else 99, -r["eps"])  # noqa: E731
        out["a"] = sorted(cells, key=key)
    for part in ("b", "c", "d", "e"):
        f = folder / f"stability_{part}.json"
        if f.exists():
            out[part] = json.loads(f.read_text())["rows"]
    return out


# The committed result files of the speed/accuracy study that notebooks read (shipped in the wheel
# under jaxcelt/_results/performance, see [tool.hatch.build.targets.wheel.force-include]).
RESULT_FILES: tuple[str, ...] = (
    "reference.json",
    "work_precision.json",
    "peers.json",
    "peers_idle.json",
    "stability_a.json",
    "stability_a_implicit.json",
    "stability_a_eps1e-10.json",
    "stability_b.json",
    "stability_c.json",
    "stability_d.json",
    "stability_e.json",
)


def results_dir(kind: str = "performance") -> Any:
    """The folder holding committed results of one kind: ``"performance"`` (the speed/accuracy
    results, `RESULT_FILES`) or ``"orbits"`` (periodic-orbit branches, census, bifurcation points).

    An installed wheel has them as package data (``jaxcelt/_results/<kind>``); a checkout
    (editable install) reads ``docs/<kind>`` of the repository. Raises ``FileNotFoundError``
    when neither holds them, rather than letting a notebook show nothing."""
    import pathlib
    from importlib import resources

    marker = {"performance": "reference.json", "orbits": "branches.json"}
    if kind not in marker:
        raise ValueError(f"kind must be one of {sorted(marker)}, got {kind!r}")
    candidates = [
        pathlib.Path(str(resources.files("jaxcelt") / "_results" / kind)),
        pathlib.Path(__file__).resolve().parents[2] / "docs" / kind,
    ]
    for c in candidates:
        if (c / marker[kind]).is_file():
            return c
    raise FileNotFoundError(
        f"the committed {kind} results ({marker[kind]}, ...) were found in neither "
        + " nor ".join(str(c) for c in candidates)
        + '; install jaxcelt from the repository (pip install "jaxcelt @ git+https://github.com/jaxcelt/jaxcelt")'
    )


def load_results(folder: Any = None, quick: bool = False) -> dict[str, Any]:
    """The JSON files written by ``benchmarks/*.py`` (missing ones are left out); the stability
    study's per-part files come back as ``["stability"]`` = `stability_results` (full size only).
    ``folder`` defaults to `results_dir` (the committed results)."""
    import json
    import pathlib

    if folder is None:
        folder = results_dir()
    tag = "_quick" if quick else ""
    out = {}
    for name in ("reference", "work_precision", "peers", "peers_idle"):
        f = pathlib.Path(folder) / f"{name}{tag}.json"
        if f.exists():
            out[name] = json.loads(f.read_text())
    if not quick:
        st = stability_results(folder)
        if st:
            out["stability"] = st
    return out


def markdown_table(rows: list[dict], columns: list[str], fmt: dict[str, str] | None = None) -> str:
    """A Markdown table of ``rows`` (dicts) restricted to ``columns``; floats via ``fmt``."""
    fmt = fmt or {}

    def cell(r, c):
        v = r.get(c)
        if v is None:
            return ""
        if isinstance(v, float):
            return format(v, fmt.get(c, ".3g"))
        return str(v)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(r, c) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def cheapest_at_accuracy(runs: list[dict], target: float) -> list[dict]:
    """Per solver, the fastest run whose error is <= ``target`` (work-precision at equal accuracy)."""
    best: dict[str, dict] = {}
    for r in runs:
        err = r.get("error")
        if r.get("status", 0) == 0 and err is not None and np.isfinite(err) and err <= target:
            if r["solver"] not in best or r["run_s"] < best[r["solver"]]["run_s"]:
                best[r["solver"]] = r
    return sorted(best.values(), key=lambda r: r["run_s"])
