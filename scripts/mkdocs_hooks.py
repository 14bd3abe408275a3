"""MkDocs hooks (``mkdocs.yml: hooks``): the site's home page is the repository's README.md, the changelog
and the benchmark scripts' README and the notebooks are pages, without copying any of them into docs/; links that leave docs/ (to source files,
benchmarks, tests) point to the repository, whose URL is read from pyproject.toml."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
REPO = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["urls"]["Repository"]
BLOB = f"{REPO}/blob/main/"
# site pages whose source lies outside docs/: site page -> source file, relative to the repository root
# (links in each are relative to its source file, as on the repository's web view)
OUTSIDE_PAGES = {"index.md": "README.md", "changelog.md": "CHANGELOG.md", "benchmarks.md": "benchmarks/README.md"}
_LINK = re.compile(r"(!?\[[^\]]*\]\()([^)\s#]+)(#[^)\s]*)?(\))")


@event_priority(100)  # before mkdocs-jupyter's on_files, so the notebooks become notebook pages
def on_files(files, config):
    for uri, src in OUTSIDE_PAGES.items():
        files.append(File.generated(config, uri, abs_src_path=str(ROOT / src)))
    files.append(File.generated(config, "results.md", content=_results_page()))
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        files.append(File(f"notebooks/{nb.name}", str(ROOT), config["site_dir"], config["use_directory_urls"]))
    return files


def _results_page() -> str:
    """The results index (scripts/results_index.py), made for this build."""
    import importlib.util
    import sys

    spec = importlib.util.spec_from_file_location("results_index", ROOT / "scripts" / "results_index.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod.page()


def on_page_markdown(markdown, page, config, files):
    """Rewrite relative links as if the page sat where its source file is in the repository."""
    src = page.file.src_uri
    if src in OUTSIDE_PAGES:
        here, site_here = (ROOT / OUTSIDE_PAGES[src]).parent, Path(".")
    else:
        here, site_here = ROOT / "docs" / Path(src).parent, Path(src).parent

    def fix(m):
        target = m.group(2)
        if re.match(r"^[a-zA-Z][a-zA-Z+.-]*:", target) or target.startswith("/"):
            return m.group(0)
        path = (here / target).resolve()
        anchor = m.group(3) or ""
        try:
            in_site = path.relative_to(ROOT / "docs").as_posix()
        except ValueError:
            in_site = None
        if in_site is None and path.parent == ROOT / "notebooks" and path.suffix == ".ipynb":
            in_site = f"notebooks/{path.name}"
        if in_site is not None:
            rel = Path(_relpath(in_site, site_here.as_posix())).as_posix()
            return f"{m.group(1)}{rel}{anchor}{m.group(4)}"
        if path.exists():
            return f"{m.group(1)}{BLOB}{path.relative_to(ROOT).as_posix()}{anchor}{m.group(4)}"
        return m.group(0)

    return _LINK.sub(fix, markdown)


def _relpath(target: str, start: str) -> str:
    import os.path

    return os.path.relpath(target, start or ".")
