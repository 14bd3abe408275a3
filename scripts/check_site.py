"""Check the docs site as a reader meets it: build it, serve it on localhost, check every internal link and anchor,
and take screenshots of a few pages.

    python scripts/check_site.py                       # build, serve, link check (exit 1 on a broken link)
    python scripts/check_site.py --screenshots out/site  # also screenshots of the home, install, a tutorial, the API

Links are checked by LinkChecker (``pip install linkchecker``, in the ``docs`` extra) with its anchor check on,
crawling from the home page over the served site; links that leave the site (the repository, papers) are not
followed. Screenshots need a headless Chromium (``chromium`` on the PATH, or ``--browser``).
"""

from __future__ import annotations

import argparse
import functools
import http.server
import os
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# page (site path) -> (screenshot name, window height): the home page, the install page, a tutorial with its
# figures (tall enough to reach them), an API page
PAGES = {
    "": ("home.png", 1800),
    "install/": ("install.png", 1800),
    "notebooks/06_periodic_orbits/": ("tutorial_06_periodic_orbits.png", 5200),
    "api/": ("api.png", 1800),
}


def build(site: Path) -> None:
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)], cwd=ROOT, env=env, check=True
    )


def serve(site: Path) -> tuple[http.server.ThreadingHTTPServer, str]:
    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    class Server(http.server.ThreadingHTTPServer):
        def handle_error(self, request, client_address):
            # a crawler or browser that closes a connection early is not an error of the site
            if not isinstance(sys.exc_info()[1], (BrokenPipeError, ConnectionResetError)):
                super().handle_error(request, client_address)

    server = Server(("127.0.0.1", 0), functools.partial(Quiet, directory=str(site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}/"


def check_links(url: str, linkchecker: str) -> int:
    """Run LinkChecker over the served site; returns its exit status (0: no broken link or anchor)."""
    with tempfile.TemporaryDirectory() as tmp:
        cfg = Path(tmp) / "linkcheckerrc"
        # the anchor check plugin reports a link to a missing #anchor; warnings count as failures below
        cfg.write_text("[output]\nstatus=0\n[AnchorCheck]\n")
        proc = subprocess.run(
            [linkchecker, "--config", str(cfg), "--no-robots", "--threads", "4", url],
            capture_output=True,
            text=True,
        )
    out = proc.stdout + proc.stderr
    print(out[-6000:])
    broken = proc.returncode != 0 or "Warning" in proc.stdout or "Error:" in proc.stdout
    return 1 if broken else 0


def screenshots(url: str, out: Path, browser: str) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    shots = []
    for page, (name, height) in PAGES.items():
        path = out / name
        subprocess.run(
            [
                browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                f"--window-size=1280,{height}", f"--screenshot={path}", url + page,
            ],
            check=True,
            capture_output=True,
            timeout=120,
        )
        shots.append(path)
        print(f"screenshot {url + page} -> {path}")
    return shots


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--site", type=Path, help="an already built site to check (default: build one in a temp dir)")
    ap.add_argument("--screenshots", type=Path, help="folder for the screenshots (default: none taken)")
    ap.add_argument("--browser", default=shutil.which("chromium") or shutil.which("chromium-browser") or "chromium")
    ap.add_argument("--linkchecker", default=shutil.which("linkchecker") or "linkchecker")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        site = a.site or Path(tmp) / "site"
        if a.site is None:
            build(site)
        server, url = serve(site)
        try:
            rc = check_links(url, a.linkchecker)
            print("link check:", "clean" if rc == 0 else "BROKEN LINKS OR ANCHORS (see above)")
            if a.screenshots:
                screenshots(url, a.screenshots, a.browser)
        finally:
            server.shutdown()
    return rc


if __name__ == "__main__":
    raise SystemExit(main())
