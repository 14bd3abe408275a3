"""What compilation costs a periodic orbit and a short continuation (writes docs/orbits/orbit_compile.json).

In one fresh process with JAX's persistent cache off (``JAXCELT_CACHE_DIR=off``): `jaxcelt.periodic_orbit` of the
paper's stone at omega_pi = 15.6 rad/s (the guess of ``scripts/orbit_check.py``), then `jaxcelt.continue_orbit` of
it to 15.7 rad/s, each timed, the first program of each kind compiled on the way. Reported: the wall time of both
calls, the XLA compilation time of every program that takes more than 0.2 s (``jax_log_compiles``) and the sum of
all XLA compilation times. These are the programs of the atlas's orbit branches (``jit(_orbit)``, ``jit(corrector)``,
``jit(tangent)``, ``jit(multipliers)``).

    python benchmarks/orbit_compile.py [--out docs/orbits/orbit_compile.json]
"""

from __future__ import annotations

import argparse
import importlib.util
import logging
import os
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from _compile_log import log_compiles  # noqa: E402


class _Compiles(logging.Handler):
    """Collects (program, seconds) of every XLA compilation JAX logs."""

    def __init__(self) -> None:
        super().__init__()
        self.xla: list[tuple[str, float]] = []

    def emit(self, record: logging.LogRecord) -> None:
        m = re.match(r"Finished XLA compilation of (\S+) in ([\d.]+) sec", record.getMessage())
        if m:
            self.xla.append((m.group(1), float(m.group(2))))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "orbits" / "orbit_compile.json")
    a = ap.parse_args(argv)
    os.environ["JAXCELT_CACHE_DIR"] = "off"  # before jaxcelt is imported: every program compiles in this process
    load_at_start = list(os.getloadavg())

    import jaxcelt as jc
    from jaxcelt.provenance import write_result

    compiles = _Compiles()
    log_compiles(compiles)
    spec = importlib.util.spec_from_file_location("orbit_check", ROOT / "scripts" / "orbit_check.py")
    orbit_check = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(orbit_check)
    p = jc.CeltParams.paper(omega_pi=15.6)
    y_guess, t0 = orbit_check.guess(p)
    t = time.perf_counter()
    orbit = jc.periodic_orbit(p, y_guess, t0=t0)
    t_orbit = time.perf_counter() - t
    t = time.perf_counter()
    branch = jc.continue_orbit(p, orbit, "omega_pi", 15.7)
    t_branch = time.perf_counter() - t
    if int(orbit.status) != 0 or branch.stopped != "end value reached":
        print(f"orbit_compile: the orbit or its continuation failed ({int(orbit.status)}, {branch.stopped})")
        return 1
    result = {
        "periodic_orbit_s": round(t_orbit, 3),
        "continue_orbit_s": round(t_branch, 3),
        "branch_points": len(branch.values),
        "newton_steps": int(orbit.newton_steps),
        "multipliers_abs": sorted(float(abs(m)) for m in orbit.multipliers),
        "xla_total_s": round(sum(s for _, s in compiles.xla), 3),
        "programs_compiled": len(compiles.xla),
        "xla_over_0_2_s": [[name, round(s, 3)] for name, s in compiles.xla if s > 0.2],
    }
    write_result(a.out, result, load_at_start=load_at_start)
    print(
        f"periodic_orbit {t_orbit:.2f} s, continue_orbit {t_branch:.2f} s, XLA compilation {result['xla_total_s']:.2f} s"
        f" in {len(compiles.xla)} programs -> {a.out}"
    )
    for name, s in result["xla_over_0_2_s"]:
        print(f"  {name}: {s:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
