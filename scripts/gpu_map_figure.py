"""Figure of the 400 x 400 omega_pi x q_pi maps run on a GPU (`benchmarks/gpu_map.py --labels`).

Reads the category labels the benchmark saved for the float64 and float32 maps and the timing
records (docs/performance/gpu_map_kernel.json) and draws the two regime maps side by side.

    python scripts/gpu_map_figure.py   # -> docs/performance/gpu_map.png
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

DOCS = Path(__file__).resolve().parents[1] / "docs" / "performance"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--float64", type=Path, default=DOCS / "gpu_map_labels_float64.npz")
    ap.add_argument("--float32", type=Path, default=DOCS / "gpu_map_labels_float32.npz")
    ap.add_argument("--records", type=Path, default=DOCS / "gpu_map_kernel.json")
    ap.add_argument("--out", type=Path, default=DOCS / "gpu_map.png")
    a = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    from jaxcelt.plotting.map import PARAM_LABELS, map_categories

    cats = map_categories(np.zeros(0, int), np.zeros(0, int))[1]
    runs = [r for r in json.loads(a.records.read_text())["machine_2"] if "grid" in r]
    t = {r["dtype"]: r for r in runs}
    cmap = ListedColormap([c for _, c in cats])
    norm = BoundaryNorm(np.arange(len(cats) + 1) - 0.5, len(cats))
    fig, axes = plt.subplots(1, 2, figsize=(13.5, 5.4), constrained_layout=True, sharey=True)
    present: set[int] = set()
    for ax, (dtype, path) in zip(axes, (("float64", a.float64), ("float32", a.float32))):
        d = np.load(path)
        cat = d["category"]
        present |= set(np.unique(cat).tolist())
        xs, ys = d["omega_pi"], d["q_pi"]
        ax.pcolormesh(xs, ys, cat.T, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        r = t[dtype]
        ax.set_title(f"{dtype}, rtol {r['rtol']:g}: {r['run_s']:.1f} s run + {r['compile_s']:.1f} s compile", fontsize=11)
        ax.set_xlabel(PARAM_LABELS["omega_pi"])
    axes[0].set_ylabel(PARAM_LABELS["q_pi"])
    handles = [Patch(facecolor=cats[i][1], edgecolor="0.3", lw=0.4, label=cats[i][0]) for i in sorted(present)]
    axes[1].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8.5, title="local regime",
                   title_fontsize=9, frameon=False)  # fmt: skip
    r = t["float64"]
    fig.suptitle(
        f"{r['grid'][0]} x {r['grid'][1]} lanes x {r['periods']} periods from rest on one {r['device_kind']} "
        f"(lane kernel, stop at invalid states, no Lyapunov stage)",
        fontsize=11,
    )
    a.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(a.out, dpi=110)
    print(a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
