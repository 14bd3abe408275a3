"""jaxcelt.provenance.write_result, and that every benchmark and study script writes its JSON result files through it."""

import ast
import json
import re
from pathlib import Path

import numpy as np
import pytest

import jaxcelt
from jaxcelt.provenance import append_run, load_average, provenance, write_result

ROOT = Path(__file__).resolve().parents[1]
FROM_CHECKOUT = (ROOT / ".git").exists() and Path(jaxcelt.__file__).resolve().is_relative_to(ROOT)


def test_write_result_writes_data_and_provenance(tmp_path):
    data = {"rows": [1, 2, 3], "name": "x", "nested": {"a": 1.5}}
    path = write_result(tmp_path / "sub" / "r.json", data, load_at_start=[0.5, 0.25, 0.125])
    assert path == tmp_path / "sub" / "r.json"
    got = json.loads(path.read_text())
    assert {k: got[k] for k in data} == data
    assert "provenance" not in data  # the caller's dict is left as it was
    prov = got["provenance"]
    if FROM_CHECKOUT:
        assert re.fullmatch(r"[0-9a-f]{40}", prov["commit"]), prov["commit"]
        assert isinstance(prov["dirty"], bool)
    else:
        assert prov["commit"] is None or re.fullmatch(r"[0-9a-f]{40}", prov["commit"])
    m = prov["machine"]
    assert isinstance(m["cpu"], str) and m["cpu"]
    assert isinstance(m["cpu_cores"], int) and m["cpu_cores"] >= 1
    assert prov["versions"]["jax"]
    la = prov["load_average"]
    if load_average() is not None:
        assert len(la) == 3 and all(isinstance(x, float) for x in la)
    assert prov["load_average_at_start"] == [0.5, 0.25, 0.12]
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00", prov["written_utc"]), prov["written_utc"]


def test_provenance_key_is_replaced(tmp_path):
    got = json.loads(write_result(tmp_path / "r.json", {"provenance": "old", "x": 1}).read_text())
    assert isinstance(got["provenance"], dict) and got["x"] == 1
    assert "load_average_at_start" not in provenance()


@pytest.mark.parametrize("bad", [[1, 2], "text", None, 3.0])
def test_write_result_rejects_non_dict(tmp_path, bad):
    with pytest.raises(ValueError, match="data"):
        write_result(tmp_path / "r.json", bad)
    assert not list(tmp_path.iterdir())


def test_write_result_atomic_and_numpy(tmp_path):
    path = tmp_path / "r.json"
    path.write_text('{"old": true}')
    data = {"f": np.float64(1.25), "i": np.int32(7), "a": np.arange(3), "m": np.eye(2, dtype=np.float32), "p": tmp_path}
    write_result(path, data, indent=None)
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]  # no *.tmp left behind
    got = json.loads(path.read_text())
    assert got["f"] == 1.25 and got["i"] == 7 and isinstance(got["i"], int)
    assert got["a"] == [0, 1, 2] and got["m"] == [[1.0, 0.0], [0.0, 1.0]]
    assert got["p"] == str(tmp_path)
    assert "old" not in got


def test_write_result_default_and_failure(tmp_path):
    class Odd:
        pass

    got = json.loads(write_result(tmp_path / "r.json", {"o": Odd()}, default=lambda x: "odd").read_text())
    assert got["o"] == "odd"
    path = tmp_path / "s.json"
    with pytest.raises(TypeError):
        write_result(path, {"o": Odd()})
    assert not path.exists()


def test_append_run_keeps_earlier_runs_each_with_its_provenance(tmp_path):
    path = tmp_path / "runs.json"
    append_run(path, {"x": 1}, load_at_start=[0.5, 0.5, 0.5])
    append_run(path, {"x": 2})
    got = json.loads(path.read_text())
    assert [r["x"] for r in got["runs"]] == [1, 2]
    assert got["runs"][0]["provenance"]["load_average_at_start"] == [0.5, 0.5, 0.5]
    assert "load_average_at_start" not in got["runs"][1]["provenance"]
    assert "machine" in got["provenance"]
    # the older layout, a bare list of runs, is read as that list
    old = tmp_path / "old.json"
    old.write_text(json.dumps([{"x": 0}]))
    append_run(old, {"x": 1})
    assert [r["x"] for r in json.loads(old.read_text())["runs"]] == [0, 1]


@pytest.mark.parametrize("text", ['{"runs": [1', '{"other": 1}', '"text"'])
def test_append_run_leaves_a_file_it_cannot_read_alone(tmp_path, text):
    path = tmp_path / "runs.json"
    path.write_text(text)
    with pytest.raises(ValueError, match="path: "):
        append_run(path, {"x": 1})
    assert path.read_text() == text
    with pytest.raises(ValueError, match="run: "):
        append_run(tmp_path / "new.json", [1])


# --- every result file of the benchmarks and the study scripts goes through write_result -------------------------

SCRIPTS = sorted(
    p
    for p in [*(ROOT / "benchmarks").glob("*.py"), *(ROOT / "scripts").glob("*.py")]
    if not p.name.startswith("_") and p.name != "mkdocs_hooks.py"
)

# json.dumps calls that are not result files, by file and by the source line's text. The ROW / RESULT lines
# and the bare json.dumps prints are read by a parent process (or by a person) from stdout; they are inside
# print(...) and so need no entry here. Nothing is allowed at present.
ALLOWED: dict[str, set[str]] = {}

# scripts that name .json files but only read them
READERS = {
    "gpu_map_figure.py",  # draws docs/performance/gpu_map.png from the JSON records
    "results_index.py",  # reads every result file to write docs/results.md
}


def _is_json_call(node: ast.AST, name: str) -> bool:
    return (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == name
        and isinstance(node.func.value, ast.Name)
        and node.func.value.id == "json"
    )


def _bypasses(path: Path) -> list[str]:
    """Lines of ``path`` that write JSON without write_result: json.dump(...), and json.dumps(...) outside print."""
    src = path.read_text(encoding="utf-8")
    tree = ast.parse(src)
    lines = src.splitlines()
    in_print: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "print":
            in_print |= {id(n) for n in ast.walk(node)}
    bad = []
    for node in ast.walk(tree):
        if _is_json_call(node, "dump") or (_is_json_call(node, "dumps") and id(node) not in in_print):
            text = lines[node.lineno - 1].strip()
            if text not in ALLOWED.get(path.name, set()):
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno}: {text}")
    return bad


def test_scripts_found():
    names = {p.name for p in SCRIPTS}
    assert {"bench_sweep.py", "work_precision.py", "fit_study.py", "paper_study.py", "paper_figures.py"} <= names


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_result_files_written_through_write_result(path):
    assert not _bypasses(path), "JSON written without jaxcelt.provenance.write_result:\n" + "\n".join(_bypasses(path))
    src = path.read_text(encoding="utf-8")
    names_json = re.search(r"""\.json["']""", src) is not None
    if names_json and path.name not in READERS:
        assert "write_result(" in src or "append_run(" in src, (
            f"{path.name} names a .json file but never calls write_result or append_run"
        )
