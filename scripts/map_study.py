"""The omega_pi x q_pi regime / Lyapunov map of docs/map/: runs ``jaxcelt map`` (100 x 60 grid by
default) and copies its figure and summary (with the machine's load average before and after)
into docs/map/. Resumable: rerunning continues an interrupted run in --out.

    python scripts/map_study.py [--out out/map_100x60] [--docs docs/map]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

# Shorter than the bifurcation main job (100 + 30 periods, 30 for lambda_1): at 6000 lanes its
# vmapped Lyapunov stage made a run on the loaded 2-core machine take hours.
ARGS = ["--x", "omega_pi=10:20:100", "--y", "q_pi=0.02:0.06:60", "--transient", "50", "--sample", "20",
        "--lyapunov", "10", "--chunk-size", "1500"]  # fmt: skip


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/map_100x60"))
    ap.add_argument("--docs", type=Path, default=Path("docs/map"))
    a = ap.parse_args()
    load_before = os.getloadavg()
    cmd = [sys.executable, "-m", "jaxcelt", "map", *ARGS, "--out", str(a.out)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    wall = time.perf_counter() - t0
    load_after = os.getloadavg()
    summary = json.loads((a.out / "summary.json").read_text())
    summary["whole_command_seconds"] = round(wall, 1)
    summary["load_average_before_after"] = [list(map(float, load_before)), list(map(float, load_after))]
    summary["cpu_count"] = os.cpu_count()
    summary["argv"] = ["jaxcelt", "map", *ARGS]
    from jaxcelt.provenance import write_result

    # the command's own provenance block (its summary.json's) is replaced by this script's
    write_result(a.docs / "map_omega_q_100x60.json", summary, load_at_start=load_before)
    shutil.copyfile(a.out / "map.png", a.docs / "map_omega_q_100x60.png")
    print(f"wrote {a.docs}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
