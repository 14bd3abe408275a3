#!/usr/bin/env bash
# Reproduce the speed/accuracy study: JSON + PNG under docs/performance/.
#   benchmarks/run_all.sh            full size (hours on 2 CPU cores; minutes on a GPU box)
#   benchmarks/run_all.sh --quick    minutes; writes *_quick.json / *_quick.png
# Runs unchanged on CPU or GPU: JAX picks the device; every script prints versions + device.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-.venv/bin/python}
FLAG=${1:-}
OUT=${OUT:-docs/performance}
$PY benchmarks/reference.py $FLAG --out "$OUT"
$PY benchmarks/work_precision.py $FLAG --out "$OUT"
$PY benchmarks/stability.py $FLAG --out "$OUT"
$PY benchmarks/peers.py $FLAG --out "$OUT"
# MuJoCo / MJX peer (needs the bench extra: pip install -e ".[bench]"); a different contact model
if $PY -c "import mujoco" 2>/dev/null; then $PY benchmarks/mujoco_peer.py --out "$OUT"; else echo "mujoco not installed: skipped"; fi
echo "done: results in $OUT"
