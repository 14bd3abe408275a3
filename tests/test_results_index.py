"""Every measured number the site quotes is verified, and the results index page is made from the registry.

``scripts/results_index.py --check`` finds each time, ratio, percentage and step count in the prose of the site's
pages, the README and the notebooks' text, and fails unless it lies inside a text recomputed from a committed
result file (tests/docs_quotes) or is declared a setting.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _index():
    spec = importlib.util.spec_from_file_location("results_index", ROOT / "scripts" / "results_index.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # its dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


def test_every_quoted_number_is_verified(capsys):
    rc = _index().main(["--check", "--show"])
    out = capsys.readouterr()
    assert rc == 0, out.out[-4000:] + out.err


def test_scanner_finds_measured_numbers_and_skips_settings():
    idx = _index()
    found = [m.group(0) for m in idx.NUMBER.finditer("took 12.3 s, 2.12× faster, 17.7 % of peak, 35.2 M steps")]
    assert found == ["12.3 s", "2.12×", "17.7 %", "35.2 M"]
    # a grid size is not a ratio; a word is not a unit
    assert not list(idx.NUMBER.finditer("a 400 × 300 sweep over 60 values of 3 sizes"))
    text = "integrated to t = 300 s with a threshold of 0.02 s⁻¹"
    for m in idx.NUMBER.finditer(text):
        assert idx.INPUT_CONTEXT.search(text[max(0, m.start() - 40) : m.start()]), m.group(0)


def test_index_page_lists_every_quoted_text_and_its_files():
    idx = _index()
    quotes, settings = idx.load_quotes()
    page = idx.render(quotes, idx.scan(quotes, settings))
    assert all(q.ok for q in quotes), [q.text for q in quotes if not q.ok]
    assert f"**{len(quotes)} quoted texts**" in page
    files = {f for q in quotes for f in q.files}
    assert files and all(f"| `{f}` |" in page for f in files)
    # a quoted text that reads no committed file would be a number with nothing behind it
    assert [q.text for q in quotes if not q.files] == []


def test_every_quoted_file_names_the_command_that_made_it():
    # a file with a provenance block records its command; an older one is listed in LEGACY_COMMANDS, whose
    # scripts must exist
    idx = _index()
    quotes, _ = idx.load_quotes()
    for f in sorted({f for q in quotes for f in q.files if f.endswith(".json")}):
        rec = idx.file_record(f)
        assert rec["command"], f"{f}: no provenance block and no entry in LEGACY_COMMANDS"
        script = rec["command"].split()[1] if rec["command"].startswith("python ") else None
        if script:
            assert (ROOT / script).exists(), f"{f}: {script} does not exist"
