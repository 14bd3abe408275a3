"""What the lane pool's stepping program computes per lane: operations in XLA's optimised program.

Compiles the 400 x 300 sweep's pool (omega_pi 10..20 rad/s from rest, rtol 1e-8, stopping at invalid
states, 2 CPU devices; here run for 30 periods, which compiles the same programs) with XLA's dump of
``pool_advance`` after optimisation, and counts the elementwise operations of its fused kernels per
lane (an operation on an array of n elements counts n / slots): divisions, square roots,
exponentials, multiplications, additions, subtractions and selects. The count is static -- every
stage, the controller and both branches of the pool's conditionals once each -- not what one
iteration executes; it shows what XLA's fusion made of the right-hand side, including what it
recomputes in several kernels. A vectorised float64 division or square root costs about as much
as a dozen multiply-adds on current x86 CPUs, so they are listed apart.

    .venv/bin/python benchmarks/pool_ops.py --out /tmp/pool_ops.json
"""

from __future__ import annotations

import argparse
import collections
import glob
import os
import re
import sys
import tempfile
from pathlib import Path

OPS = ("divide", "sqrt", "rsqrt", "exponential", "log", "power", "multiply", "add", "subtract", "select")


def count_ops(hlo_text: str, slots: int) -> dict[str, float]:
    """Elementwise operations of an optimised HLO module per lane (n elements count n / ``slots``)."""
    pattern = r"= (?:f64|f32|s64|s32|pred)\[([0-9,]*)\]\S* (" + "|".join(OPS) + r")\("
    cnt: collections.Counter = collections.Counter()
    for m in re.finditer(pattern, hlo_text):
        n = 1
        for d in (int(x) for x in m.group(1).split(",") if x):
            n *= d
        cnt[m.group(2)] += n / slots
    return {k: round(cnt.get(k, 0.0), 1) for k in OPS}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--n-freq", type=int, default=400)
    ap.add_argument("--periods", type=int, default=30)
    a = ap.parse_args(argv)
    dump = tempfile.mkdtemp(prefix="jaxcelt_pool_ops_")
    os.environ["JAXCELT_CACHE_DIR"] = "off"
    os.environ["XLA_FLAGS"] = (
        os.environ.get("XLA_FLAGS", "") + f" --xla_dump_to={dump} --xla_dump_hlo_module_re=.*pool_advance.*"
        " --xla_dump_hlo_pass_re=^$"
    )
    import jax

    jax.config.update("jax_num_cpu_devices", os.cpu_count() or 1)
    import numpy as np

    import jaxcelt as jc
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    p = jc.CeltParams.paper()
    vals = np.linspace(10.0, 20.0, a.n_freq)
    jc.bifurcation(p, vals, transient_periods=a.periods - a.periods // 3, sample_periods=a.periods // 3, rtol=1e-8,
                   atol=1e-10, stop_on_invalid=True, max_steps=10**6, sort_by_cost=True)  # fmt: skip
    programs = []
    for f in sorted(glob.glob(os.path.join(dump, "*pool_advance.cpu_after_optimizations.txt"))):
        text = Path(f).read_text()
        m = re.search(r"ENTRY .*?\(\w+: \(?f64\[(\d+),13\]", text) or re.search(r"f64\[(\d+),13\]", text)
        slots = int(m.group(1))
        programs.append({"slots_per_device": slots, "fusions": text.count(" fusion("), "ops_per_lane": count_ops(text, slots)})
    if not programs:
        print("no pool_advance program was dumped", file=sys.stderr)
        return 1
    out = write_result(a.out, {"n_freq": a.n_freq, "periods": a.periods, "programs": programs, "versions": versions()})
    for prog in programs:
        print(prog["slots_per_device"], "slots:", prog["ops_per_lane"], f"({prog['fusions']} fusions)")
    print("wrote", out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
