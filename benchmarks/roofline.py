"""How far is one right-hand-side evaluation from what the CPU can do? A roofline for the RHS.

For the paper's stone at a batch width W (the pool's slots per device), this script reports:

* XLA's own cost analysis of the vmapped vector field (flops, transcendental calls, bytes);
* which elementary functions the compiled CPU code calls as scalar library functions rather than
  computing in vector registers (from XLA's optimised LLVM IR: ``call`` instructions to libm-style
  symbols, counted per kernel);
* the measured time per lane-evaluation (vmapped RHS inside one jitted loop, best of 5, one device),
  as a wide lane pool runs it (the contact law's ``wide_batch`` form, with its vectorised
  logarithm, compiled with ``pool_compiler_options``: 512-bit vectors on a CPU) and as the default
  law compiled with XLA's defaults (256-bit vectors, libm logarithms); the IR analysed is the former's;
* the machine's double-precision peak from its vector ISA (AVX-512: 8 doubles per register,
  AVX2: 4), two FMA pipes per core (an assumption stated in the output: true for Zen 3/4 and
  Skylake-SP and later server cores) and the clock that ``/proc/cpuinfo`` reports;

and from these the fraction of peak the RHS reaches and the lower bound on time per evaluation
if every flop ran at peak (transcendental calls counted at an assumed 20 flops each, the cost of
a vectorised polynomial kernel). Memory is no bound here: the working set of W lanes is a few kB.

    .venv/bin/python benchmarks/roofline.py --width 96 --out docs/bifurcation
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import re
import sys
import tempfile
import time
from pathlib import Path

FLOPS_PER_TRANSCENDENTAL = 20  # assumed cost of one vectorised exp/sin/... (polynomial + range reduction)


def cpu_facts() -> dict:
    info = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    flags = set(re.search(r"^flags\s*:\s*(.*)$", info, re.M).group(1).split()) if "flags" in info else set()
    model = re.search(r"^model name\s*:\s*(.*)$", info, re.M)
    mhz = [float(x) for x in re.findall(r"^cpu MHz\s*:\s*([\d.]+)", info, re.M)]
    doubles = 8 if "avx512f" in flags else 4 if "avx2" in flags else 2
    ghz = (max(mhz) / 1000) if mhz else float("nan")
    return {
        "model": model.group(1).strip() if model else "unknown",
        "isa": "AVX-512" if doubles == 8 else "AVX2" if doubles == 4 else "SSE2",
        "doubles_per_vector": doubles,
        "fma": "fma" in flags,
        "ghz": ghz,
        "cores": os.cpu_count(),
        "peak_gflops_per_core": 2 * 2 * doubles * ghz,  # 2 FMA pipes x 2 flops x lanes x GHz
        "peak_assumption": "2 FMA pipes per core, clock from /proc/cpuinfo (turbo not counted)",
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=96)
    ap.add_argument("--reps", type=int, default=2000)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    dump = tempfile.mkdtemp(prefix="jaxcelt_roofline_")
    os.environ["XLA_FLAGS"] = (
        os.environ.get("XLA_FLAGS", "") + f" --xla_dump_to={dump} --xla_dump_hlo_module_re=.*rhs_roofline.*"
    )
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaxcelt as jc
    from jaxcelt._compile_options import pool_compiler_options
    from jaxcelt.physics.contact.registry import get_contact_law
    from jaxcelt.physics.model import vector_field
    from jaxcelt.provenance import write_result
    from jaxcelt.versions import versions

    p = jc.CeltParams.paper()
    W = a.width
    # only the forcing frequency varies across lanes, as in a frequency sweep: the pool keeps
    # lane-constant parameters out of the slots, so XLA hoists what depends on them alone
    pb = jnp.linspace(12.0, 19.0, W)
    rng = np.random.default_rng(0)
    y0 = np.tile(np.asarray(jc.initial_state(p, omega=(0.3, -0.2, 2.0))), (W, 1))
    y0 = y0 + 1e-3 * rng.normal(size=y0.shape) * np.r_[np.ones(6), np.zeros(7)]

    # the RHS as a wide pool runs it: the contact law's `wide_batch` form (vectorised logarithm)
    wide_law = get_contact_law(None).wide_batch()

    def rhs_loop(y, pb, reps, law):
        # a loop of dependent RHS evaluations (y <- y + 1e-9 f(y)), so nothing is hoisted
        def body(_, y):
            return y + 1e-9 * jax.vmap(lambda yy, w: vector_field(0.0, yy, p.replace(omega_pi=w), law))(y, pb)

        return jax.lax.fori_loop(0, reps, body, y)

    def rhs_roofline(y, pb, reps):  # as the wide pool: wide_batch law, compiled with the pool's options
        return rhs_loop(y, pb, reps, wide_law)

    def rhs_roofline_default(y, pb, reps):  # the default law, compiled with XLA's default options
        return rhs_loop(y, pb, reps, None)

    one = jax.jit(lambda y, pb: jax.vmap(lambda yy, w: vector_field(0.0, yy, p.replace(omega_pi=w), wide_law))(y, pb))
    cost = one.lower(jnp.asarray(y0), pb).compile().cost_analysis()
    cost = cost[0] if isinstance(cost, list) else cost

    def us_per_lane_eval(fn, options):
        f = jax.jit(fn, static_argnums=2).lower(jnp.asarray(y0), pb, a.reps).compile(options)
        jax.block_until_ready(f(jnp.asarray(y0), pb))
        best = np.inf
        for _ in range(5):
            t0 = time.perf_counter()
            jax.block_until_ready(f(jnp.asarray(y0), pb))
            best = min(best, time.perf_counter() - t0)
        return best / (a.reps * W) * 1e6

    # the lane pool's compiler options (512-bit vectors on a CPU) and XLA's defaults (256-bit)
    us_default = us_per_lane_eval(rhs_roofline_default, None)
    us_pool = us_per_lane_eval(rhs_roofline, pool_compiler_options(jax.default_backend(), W))

    # scalar library calls left in the optimised IR of the loop
    # LLVM's x86 back end turns sqrt/floor/fabs/min/max intrinsics into vector instructions but
    # scalarises log/pow/exp/sin/cos/atan2 intrinsics into one libm call per element (no vector
    # math library is linked into XLA's CPU code), so those are the ones that cost.
    calls: dict[str, int] = {}
    libm: dict[str, int] = {}
    for ll in glob.glob(os.path.join(dump, "*.jit_rhs_roofline.*ir-with-opt*.ll")):
        for name in re.findall(r"call[^@\n]*@([A-Za-z_][\w.]*)\(", Path(ll).read_text()):
            if name.startswith(("llvm.lifetime", "llvm.assume", "llvm.mem", "llvm.experimental", "llvm.stack")):
                continue
            calls[name] = calls.get(name, 0) + 1
            m = re.match(r"llvm\.(log|log2|log10|exp|exp2|pow|sin|cos|tan|atan2|atan|asin|acos)\.(v(\d+))?f64$", name)
            if m or not name.startswith("llvm."):
                libm[name] = libm.get(name, 0) + 1

    cpu = cpu_facts()
    flops = float(cost.get("flops", float("nan"))) / W
    trans = float(cost.get("transcendentals", float("nan"))) / W
    eff_flops = flops + FLOPS_PER_TRANSCENDENTAL * trans
    ideal_us = eff_flops / (cpu["peak_gflops_per_core"] * 1e3)
    res = {
        "width": W,
        "cpu": cpu,
        "xla_cost_per_lane_eval": {
            "flops": flops,
            "transcendentals": trans,
            "bytes_accessed": float(cost.get("bytes accessed", float("nan"))) / W,
        },  # fmt: skip
        "flops_per_transcendental_assumed": FLOPS_PER_TRANSCENDENTAL,
        "effective_flops_per_lane_eval": eff_flops,
        "compiler_options": pool_compiler_options(jax.default_backend(), W),
        "measured_us_per_lane_eval_one_core": us_pool,
        "measured_us_per_lane_eval_one_core_xla_defaults": us_default,
        "ideal_us_per_lane_eval_one_core": ideal_us,
        "fraction_of_peak": ideal_us / us_pool,
        "fraction_of_peak_xla_defaults": ideal_us / us_default,
        "intrinsic_and_function_calls_in_optimised_ir": dict(sorted(calls.items(), key=lambda kv: -kv[1])),
        "calls_lowered_to_scalar_libm": libm,
        "load_average_at_start": list(os.getloadavg()),
        "versions": versions(),
    }
    print(json.dumps(res, indent=1))
    if a.out:
        write_result(Path(a.out) / "roofline.json", res, load_at_start=res["load_average_at_start"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
