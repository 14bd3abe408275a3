"""The user-facing pages against the package: the getting-started page runs as written, and the API reference
documents every public name and every jaxcelt name the notebooks use.

* `test_getting_started_runs`: the ```python blocks of docs/getting-started.md, in order, as one script in a
  fresh interpreter (working directory a temporary folder, ``MPLBACKEND=Agg``); any exception fails.
* `test_api_lists_every_public_name`: every name in ``jaxcelt.__all__`` has a ``::: jaxcelt.NAME`` entry.
* `test_api_documents_notebook_names`: every jaxcelt name a notebook imports (``from jaxcelt... import X``,
  ``import jaxcelt.x``) or reaches (``jc.X``, ``module_alias.X``) is documented in docs/api.md: its object is
  an entry's object, a member of a documented class or module, or a module with a documented member.
* `test_api_entries_resolve`: every ``::: path`` entry names an object that exists (mkdocstrings would fail the
  site build otherwise, but this says which entry at test time).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import os
import re
import subprocess
import sys
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
_FENCE = re.compile(r"^```python[^\n]*\n(.*?)^```", re.S | re.M)
_ENTRY = re.compile(r"^:::\s+([\w.]+)\s*$", re.M)


def python_blocks(path: Path) -> list[str]:
    """The ```python fenced blocks of a markdown page, in order."""
    return _FENCE.findall(path.read_text(encoding="utf-8"))


def test_getting_started_runs(tmp_path):
    blocks = python_blocks(DOCS / "getting-started.md")
    assert len(blocks) >= 4, "getting-started.md should hold its walk-through as ```python blocks"
    script = tmp_path / "getting_started.py"
    script.write_text("\n\n".join(blocks), encoding="utf-8")
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONUNBUFFERED="1")
    proc = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=900
    )
    assert proc.returncode == 0, f"docs/getting-started.md failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-6000:]}"
    # what the page promises it writes
    assert (tmp_path / "out" / "first-sweep" / "sweep.nc").exists()
    assert (tmp_path / "bifurcation.png").exists() and (tmp_path / "trajectory.png").exists()


# --- the API reference --------------------------------------------------------------------------------------


def api_entries() -> list[str]:
    return _ENTRY.findall((DOCS / "api.md").read_text(encoding="utf-8"))


def resolve(path: str):
    """The object a dotted path names (the longest importable module prefix, then attributes)."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return obj
    raise ImportError(path)


def test_api_entries_resolve():
    bad = []
    for entry in api_entries():
        try:
            resolve(entry)
        except (ImportError, AttributeError) as e:
            bad.append(f"{entry} ({type(e).__name__}: {e})")
    assert not bad, "api.md entries that name nothing:\n" + "\n".join(bad)


def test_api_lists_every_public_name():
    import jaxcelt

    entries = set(api_entries())
    missing = [n for n in jaxcelt.__all__ if f"jaxcelt.{n}" not in entries]
    assert not missing, f"names in jaxcelt.__all__ without a '::: jaxcelt.NAME' entry in docs/api.md: {missing}"


def _notebook_sources() -> dict[str, list[str]]:
    out = {}
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        cells = json.loads(nb.read_text(encoding="utf-8"))["cells"]
        srcs = []
        for c in cells:
            if c["cell_type"] != "code":
                continue
            lines = "".join(c["source"]).splitlines()
            # IPython magics and shell lines are not Python: keep the block structure with a `pass`
            lines = [re.sub(r"^(\s*)[%!].*$", r"\1pass", ln) for ln in lines]
            srcs.append("\n".join(lines))
        out[nb.name] = srcs
    return out


def notebook_names() -> dict[str, set[str]]:
    """Dotted jaxcelt paths each notebook imports or reaches: ``from jaxcelt.a import b`` -> jaxcelt.a.b;
    ``jc.X.Y`` -> jaxcelt.X.Y; ``alias.X`` for an imported jaxcelt module -> its path + X."""
    found: dict[str, set[str]] = {}
    for name, cells in _notebook_sources().items():
        aliases = {}  # local name -> dotted jaxcelt path
        names: set[str] = set()
        trees = [ast.parse(src) for src in cells]
        for tree in trees:
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    for a in node.names:
                        if a.name.split(".")[0] == "jaxcelt":
                            aliases[a.asname or a.name.split(".")[0]] = a.name if a.asname else "jaxcelt"
                elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "jaxcelt":
                    for a in node.names:
                        path = f"{node.module}.{a.name}"
                        names.add(path)
                        aliases[a.asname or a.name] = path
        for tree in trees:
            for node in ast.walk(tree):
                if not isinstance(node, ast.Attribute):
                    continue
                chain, n = [], node
                while isinstance(n, ast.Attribute):
                    chain.append(n.attr)
                    n = n.value
                if isinstance(n, ast.Name) and n.id in aliases:
                    base = aliases[n.id]
                    if isinstance(_try_resolve(base), types.ModuleType):
                        names.add(".".join([base, *reversed(chain)]))
        found[name] = names
    return found


def _try_resolve(path: str):
    try:
        return resolve(path)
    except (ImportError, AttributeError):
        return None


def _documented(path: str, entries: list[str], objects: list) -> bool:
    obj = _try_resolve(path)
    parts = path.split(".")
    if obj is None:  # an attribute of an instance (e.g. a dict's method): judge the longest resolvable prefix
        for i in range(len(parts) - 1, 1, -1):
            if _try_resolve(".".join(parts[:i])) is not None:
                return _documented(".".join(parts[:i]), entries, objects)
        return False
    if any(obj is o for o in objects):
        return True
    if isinstance(obj, types.ModuleType):  # a module: documented where one of its members is
        return path in entries or any(e.startswith(path + ".") for e in entries)
    # a member of a documented class or module (CeltParams.paper, orbits.ORBIT_STATUS ...)
    for i in range(len(parts) - 1, 0, -1):
        owner = _try_resolve(".".join(parts[:i]))
        if (inspect.isclass(owner) or isinstance(owner, types.ModuleType)) and any(owner is o for o in objects):
            return True
    return False


def test_api_documents_notebook_names():
    entries = api_entries()
    objects = [_try_resolve(e) for e in entries]
    objects = [o for o in objects if o is not None]
    missing = sorted(
        f"{path} ({nb})"
        for nb, paths in notebook_names().items()
        for path in paths
        if path.split(".")[0] == "jaxcelt" and path != "jaxcelt" and not _documented(path, entries, objects)
    )
    assert not missing, "jaxcelt names the notebooks use but docs/api.md does not document:\n" + "\n".join(missing)


def test_notebook_name_scan_sees_the_notebooks():
    """The scan above is not vacuous: it finds names the notebooks are known to use."""
    names = set().union(*notebook_names().values())
    assert {"jaxcelt.simulate", "jaxcelt.CeltParams", "jaxcelt.sweeps.dataset.to_dataset"} <= names
